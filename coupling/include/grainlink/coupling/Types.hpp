#pragma once
// The coupling's vocabulary as plain C++ values. Wire (protobuf) types never appear outside
// coupling/src; participants and the coordinator's users see only these.
#include "grainlink/body/BodyDescription.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace grainlink::coupling {

using Vec3 = Eigen::Vector3d;
using Quat = Eigen::Quaterniond;
/// Time on the wire is an integer count of ticks (RunInfo::tick_s seconds each).
using Ticks = std::uint64_t;
/// The longest run in ticks: below 2^53, so that every tick count is exact as a double.
constexpr double kMaxTicks = 1e15;

/// The protocol this build speaks; a peer with another major version is refused.
constexpr std::uint32_t kProtocolMajor = 1;
constexpr std::uint32_t kProtocolMinor = 1; // 1.1: WindowDone.run_complete

enum class Role {
    Multibody, ///< integrates the bodies: wrenches in, states out
    Soil,      ///< loads the bodies: states in, wrenches out
};

enum class SchemeKind { ExplicitSerial, ExplicitParallel, Implicit };

const char *roleName(Role role);
const char *schemeName(SchemeKind scheme);

/// Any failure of the coupled run: names the participant, the window and the reason.
class CouplingError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// A call to the participant API out of lifecycle order; the message says what to do instead.
class LifecycleError : public std::logic_error {
public:
    using std::logic_error::logic_error;
};

// A coupled body's description is the value the multibody models give and the soil builds its
// mesh from (grainlink/body): the handshake carries it unchanged.
using body::BodyDescription;
using body::GrouserShape;
using body::MassProperties;
using body::MeshShape;
using body::WheelShape;

/// A rigid body's state in the world frame.
struct BodyState {
    std::string body;
    Vec3 position_m = Vec3::Zero();             ///< [m] body origin
    Quat orientation = Quat::Identity();        ///< body to world
    Vec3 linear_velocity_m_s = Vec3::Zero();    ///< [m/s] of the body origin
    Vec3 angular_velocity_rad_s = Vec3::Zero(); ///< [rad/s]
};

/// The soil's load on a body, averaged over a window so that force x window = impulse.
struct Wrench {
    std::string body;
    Vec3 force_N = Vec3::Zero();         ///< [N] world frame
    Vec3 torque_N_m = Vec3::Zero();      ///< [N m] about the body origin, world frame
    std::vector<Vec3> triangle_forces_N; ///< [N] optional, one per mesh triangle
};

/// The work [J] the coupling wrench did on a body over a window, as one side integrated it.
struct BodyWork {
    std::string body;
    double work_J = 0.0; ///< [J]
};

struct Capabilities {
    bool rollback = false;       ///< can save/restore its state (implicit coupling)
    bool checkpoint = false;     ///< can write/read checkpoints on disk
    bool triangle_loads = false; ///< soil: reports per-triangle loads
};

/// Where a resumed run continues: the checkpoint this participant wrote earlier.
struct RestorePoint {
    std::uint64_t window = 0;
    Ticks tick = 0;
    std::string checkpoint_directory;
};

} // namespace grainlink::coupling
