#pragma once
// The one interface every multibody model implements (design.md, mbs/): the bodies it couples to
// the soil, the wrenches it applies, how it advances, the states it reports, save/restore.
// No ZeroMQ, no protobuf: the multibody node (apps/) translates to and from the wire.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace grainlink::mbs {

using Vec3 = Eigen::Vector3d;
using Quat = Eigen::Quaterniond;

class ModelError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// Parameters of a wheel both sides build the same mesh from (axis = body y).
struct WheelShape {
    double diameter_m = 0.25;       ///< [m] rim outer diameter
    double width_m = 0.1;           ///< [m]
    double rim_thickness_m = 0.005; ///< [m]
    unsigned grouser_count = 0;
    double grouser_height_m = 0.0;    ///< [m]
    double grouser_thickness_m = 0.0; ///< [m]
    bool chevron = false;
    double chevron_angle_deg = 0.0; ///< [deg]
    bool closed_sides = true;
};

/// A closed triangle mesh in the body frame (outward normals by the right-hand rule), for
/// coupled bodies that are not wheels (the mole's hull, a user's mesh).
struct MeshShape {
    std::vector<Vec3> vertices_m;              ///< [m] body frame
    std::vector<std::array<int, 3>> triangles; ///< vertex indices, counter-clockwise from outside
};

/// A body that touches the soil.
struct CoupledBody {
    std::string name;
    double mass_kg = 0.0;                       ///< [kg]
    Vec3 center_of_mass_m = Vec3::Zero();       ///< [m] body frame
    Vec3 inertia_diagonal_kg_m2 = Vec3::Zero(); ///< [kg m^2] about the centre of mass
    WheelShape wheel;                           ///< its geometry, unless `mesh` is set
    std::optional<MeshShape> mesh;              ///< replaces `wheel` when set
};

/// Pose and velocity of a body origin, world frame.
struct RigidState {
    Vec3 position_m = Vec3::Zero();
    Quat orientation = Quat::Identity();
    Vec3 linear_velocity_m_s = Vec3::Zero();
    Vec3 angular_velocity_rad_s = Vec3::Zero();
};

/// Force and torque about the body origin, world frame, held constant while advancing.
struct Wrench {
    Vec3 force_N = Vec3::Zero();
    Vec3 torque_N_m = Vec3::Zero();
};

class MultibodyModel {
public:
    virtual ~MultibodyModel() = default;

    virtual std::vector<CoupledBody> coupledBodies() const = 0;
    /// The soil's wrench on each coupled body (in coupledBodies() order) until the next call.
    virtual void applyWrenches(const std::vector<Wrench> &wrenches) = 0;
    /// Integrates to `time_s`; returns the work [J] the applied wrenches did on each body.
    virtual std::vector<double> advanceTo(double time_s) = 0;
    virtual double time() const = 0;
    virtual std::vector<RigidState> bodyStates() const = 0;
    /// Named quantities for the time series (slip, sinkage, motor torque, ...).
    virtual std::map<std::string, double> observables() const = 0;
    /// The macro step this model would like next [s]; 0: no preference. The coordinator's
    /// adaptive stepping takes it as a hint (e.g. small steps around the mole's impacts).
    virtual double suggestedMacroStep_s() const { return 0.0; }

    virtual void saveState() = 0;
    virtual void restoreState() = 0;
    virtual void writeCheckpoint(const std::string &path) const = 0;
    virtual void readCheckpoint(const std::string &path) = 0;
};

} // namespace grainlink::mbs
