#include "grainlink/dem/RigidFloor.hpp"

#include <stdexcept>

namespace grainlink::dem {

RigidFloorSettings parseRigidFloor(const config::ConfigNode &node) {
    RigidFloorSettings c;
    c.height_m = node.number("height_m", c.height_m);
    c.stiffness_N_m = node.number("stiffness_N_m", c.stiffness_N_m);
    c.damping_N_s_m = node.number("damping_N_s_m", c.damping_N_s_m);
    c.tangential_stiffness_N_m =
        node.number("tangential_stiffness_N_m", c.tangential_stiffness_N_m);
    c.tangential_damping_N_s_m =
        node.number("tangential_damping_N_s_m", c.tangential_damping_N_s_m);
    c.friction_coefficient = node.number("friction_coefficient", c.friction_coefficient);
    c.time_step_s = node.number("time_step_s", c.time_step_s);
    if (!(c.time_step_s > 0.0))
        node["time_step_s"].fail("time_step_s must be positive");
    node.finish();
    return c;
}

RigidFloor::RigidFloor(const RigidFloorSettings &settings, TriangleMesh mesh)
    : settings_(settings), mesh_(std::move(mesh)),
      stretch_m_(mesh_.vertices_m.size(), Vec3::Zero()), touching_(mesh_.vertices_m.size(), 0) {
    if (!(settings_.stiffness_N_m > 0.0) || !(settings_.tangential_stiffness_N_m > 0.0) ||
        settings_.damping_N_s_m < 0.0 || settings_.tangential_damping_N_s_m < 0.0 ||
        settings_.friction_coefficient < 0.0)
        throw std::invalid_argument("rigid floor: stiffnesses must be positive, dampings and "
                                    "the friction coefficient non-negative");
}

void RigidFloor::step(const RigidBodyState &state, double dt_s, Vec3 &force_N, Vec3 &torque_N_m) {
    force_N.setZero();
    torque_N_m.setZero();
    touching_count_ = 0;
    deepest_m_ = 0.0;
    const auto &s = settings_;
    for (std::size_t v = 0; v < mesh_.vertices_m.size(); ++v) {
        const Vec3 p = state.position_m + state.orientation * mesh_.vertices_m[v];
        const double depth = s.height_m - p.z();
        if (depth <= 0.0) {
            touching_[v] = 0;
            stretch_m_[v].setZero();
            continue;
        }
        const Vec3 velocity = state.pointVelocity(p);
        // Normal: a spring-dashpot that never pulls.
        const double normal =
            std::max(0.0, s.stiffness_N_m * depth - s.damping_N_s_m * velocity.z());
        // Tangential: the spring stretches with the vertex's sliding velocity; beyond the Coulomb
        // limit it slips, the stretch shortened to what the limit holds.
        Vec3 &stretch = stretch_m_[v];
        stretch += Vec3(velocity.x(), velocity.y(), 0.0) * dt_s;
        Vec3 tangential = -s.tangential_stiffness_N_m * stretch -
                          s.tangential_damping_N_s_m * Vec3(velocity.x(), velocity.y(), 0.0);
        const double limit = s.friction_coefficient * normal;
        if (tangential.norm() > limit) {
            tangential *= limit / tangential.norm();
            stretch = -tangential / s.tangential_stiffness_N_m;
        }
        const Vec3 f = tangential + Vec3(0.0, 0.0, normal);
        force_N += f;
        torque_N_m += (p - state.position_m).cross(f);
        touching_[v] = 1;
        ++touching_count_;
        deepest_m_ = std::max(deepest_m_, depth);
    }
}

} // namespace grainlink::dem
