#pragma once
// How a mesh body moves: a value the DEM evaluates itself at the end of every step, set once
// for a run, once per lab control interval or once per coupling window (docs/physics.md §7.2).
#include "grainlink/dem/Types.hpp"

#include <variant>
#include <vector>

namespace grainlink::dem {

/// Pose and velocity of a rigid body, world frame, about the body's origin.
struct RigidBodyState {
    Vec3 position_m = Vec3::Zero();
    Quat orientation = Quat::Identity();        ///< body frame -> world frame
    Vec3 linear_velocity_m_s = Vec3::Zero();    ///< [m/s] of the body origin
    Vec3 angular_velocity_rad_s = Vec3::Zero(); ///< [rad/s], world frame
    /// Velocity of the body-fixed point now at world position p [m/s].
    Vec3 pointVelocity(const Vec3 &p) const {
        return linear_velocity_m_s + angular_velocity_rad_s.cross(p - position_m);
    }
};

/// The body keeps the state it has: as built, or as last set with MeshBody::setState.
struct HeldMotion {};

/// A stretch of constant linear and angular velocity.
struct MotionSegment {
    double duration_s = 0.0;
    Vec3 linear_velocity_m_s = Vec3::Zero();
    Vec3 angular_velocity_rad_s = Vec3::Zero();
};

/// Piecewise-constant velocities from `start` at time `start_s` (the scenario's `motion:`, the
/// lab's drives): until `start_s` the body is at `start`; after the last segment it rests.
struct SegmentedMotion {
    RigidBodyState start;
    double start_s = 0.0; ///< [s], DEM time
    std::vector<MotionSegment> segments;
    RigidBodyState at(double t_s) const;
};

/// Constant linear and angular velocity (those of `start`) from `start` at `start_s` on.
SegmentedMotion constantVelocity(const RigidBodyState &start, double start_s = 0.0);

/// One coupling window from state `a` at `start_s` to state `b` at `start_s + duration_s`:
/// cubic Hermite position through both positions and velocities, its derivative as velocity,
/// slerp orientation, angular velocity linear in time; held at the ends outside the window.
/// Both end states are reproduced exactly (the orientation up to its sign), also at times
/// within 1e-9 of the window of its ends.
struct WindowMotion {
    double start_s = 0.0;    ///< [s], DEM time
    double duration_s = 1.0; ///< [s]
    RigidBodyState a, b;
    RigidBodyState at(double t_s) const;
};

/// What a mesh body does between steps; DemSystem::setBodyMotion sets it.
using BodyMotion = std::variant<HeldMotion, SegmentedMotion, WindowMotion>;

} // namespace grainlink::dem
