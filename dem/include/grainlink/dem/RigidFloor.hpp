#pragma once
// A rigid, flat floor (the plane z = height) that a rigid body's mesh rests and rolls on: the
// reference ground of the coupled stack's verification (a wheel on a floor must carry exactly
// its load and roll without slip), with no grains in the way. Each mesh vertex below the plane
// is a penalty contact: a normal spring-dashpot, and a tangential spring anchored where the
// vertex touched down, capped by Coulomb friction, so that a rolling wheel truly sticks.
#include "grainlink/config/ConfigNode.hpp"
#include "grainlink/dem/TriangleMesh.hpp"
#include "grainlink/dem/Walls.hpp"

#include <vector>

namespace grainlink::dem {

struct RigidFloorSettings {
    double height_m = 0.0;                   ///< [m] the floor is the plane z = height
    double stiffness_N_m = 2.0e5;            ///< [N/m] per vertex, normal
    double damping_N_s_m = 500.0;            ///< [N s/m] per vertex, normal
    double tangential_stiffness_N_m = 2.0e5; ///< [N/m] per vertex
    double tangential_damping_N_s_m = 500.0; ///< [N s/m] per vertex
    double friction_coefficient = 0.8;       ///< Coulomb limit of the tangential force
    double time_step_s = 1.0e-5;             ///< [s] contact sub-step of the floor node
};

/// The `floor:` section of a coupled scenario (docs/scenario.md).
RigidFloorSettings parseRigidFloor(const config::ConfigNode &node);

class RigidFloor {
public:
    RigidFloor(const RigidFloorSettings &settings, TriangleMesh mesh);

    /// Contact force and torque about the body origin for the body at `state`, advancing each
    /// touching vertex's tangential spring by `dt_s`.
    void step(const RigidBodyState &state, double dt_s, Vec3 &force_N, Vec3 &torque_N_m);
    /// Vertices touching the floor after the last step.
    int touching() const { return touching_count_; }
    /// Deepest penetration after the last step [m].
    double penetration_m() const { return deepest_m_; }

private:
    RigidFloorSettings settings_;
    TriangleMesh mesh_;
    std::vector<Vec3> stretch_m_; ///< tangential spring of each vertex (x, y), zero when free
    std::vector<char> touching_;
    int touching_count_ = 0;
    double deepest_m_ = 0.0;
};

} // namespace grainlink::dem
