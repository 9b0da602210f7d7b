#pragma once
// The one interface every multibody model implements (design.md, mbs/): the bodies it couples to
// the soil, the wrenches it applies, how it advances, the states it reports, save/restore.
// No ZeroMQ, no protobuf: the multibody node (apps/) translates to and from the wire.
#include "grainlink/body/BodyDescription.hpp"

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

// A body that touches the soil, described once (grainlink/body): the handshake carries it
// unchanged and the soil builds its mesh from it.
using body::BodyDescription;
using body::GrouserShape;
using body::MassProperties;
using body::MeshShape;
using body::WheelShape;

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

    virtual std::vector<BodyDescription> coupledBodies() const = 0;
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
