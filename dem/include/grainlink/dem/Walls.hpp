#pragma once
// Boundaries the particles touch: infinite planes (with an optional friction track) and rigid
// bodies carrying triangle meshes, moved by their BodyMotion (BodyMotion.hpp).
#include "grainlink/dem/BodyMotion.hpp"
#include "grainlink/dem/ContactLaw.hpp"
#include "grainlink/dem/TriangleMesh.hpp"

#include <optional>
#include <string>
#include <vector>

namespace grainlink::dem {

/// Rectangle on a plane where another friction applies (the seed's friction track in its bin).
struct FrictionTrack {
    Vec3 lower_m; ///< axis-aligned box containing the track's contact points
    Vec3 upper_m;
    double friction_coefficient = 0.0;
    bool contains(const Vec3 &p) const {
        return (p.array() >= lower_m.array()).all() && (p.array() <= upper_m.array()).all();
    }
};

/// Infinite plane; particles live on the side the normal points to.
struct PlaneWall {
    std::string name;
    Vec3 point_m = Vec3::Zero();
    Vec3 normal = Vec3::UnitZ();
    /// Wall friction coefficient; unset means the particle law's own Coulomb angles.
    std::optional<double> friction_coefficient;
    std::optional<FrictionTrack> track;
    Material material; ///< wall elasticity; defaults to the particles' material
};

/// A bin's end walls along x: the planes facing -x (ahead of a travel along +x) and +x (behind).
struct EndWalls {
    std::vector<int> ahead, behind;
};
EndWalls endWallsAlongX(const std::vector<PlaneWall> &planes);

/// The share of a push along x (a wheel's on the soil, [N]) that the bin's end wall it goes
/// towards takes: that wall's rise over its value before the drive, over max(|push|, 0.1 load)
/// (a wheel that hardly pushes is judged against a tenth of its load). Above about a half the
/// steady values are the bin's, not the soil's (docs/lab.md, "The bin's end").
double endWallShare(double ahead_rise_N, double behind_rise_N, double push_N, double load_N);

/// A mesh body's wrench of the last step and its accumulated impulse (MeshBody's members).
struct BodyLoads {
    Vec3 force_N = Vec3::Zero();
    Vec3 torque_N_m = Vec3::Zero(); ///< about the body origin
    Vec3 impulse_N_s = Vec3::Zero();
    Vec3 angular_impulse_N_m_s = Vec3::Zero();
    double accumulated_time_s = 0.0;
};

/// Rigid body carrying a triangle mesh (wheel, plate, mole hull). Its state is imposed; the
/// particles' reaction is accumulated as a wrench about the body origin.
class MeshBody {
public:
    MeshBody(std::string name, TriangleMesh mesh_body_frame, RigidBodyState initial);

    const std::string &name() const { return name_; }
    const TriangleMesh &mesh() const { return mesh_; }
    const RigidBodyState &state() const { return state_; }
    /// Imposes pose and velocity (DemSystem does it every step from the body's motion).
    void setState(const RigidBodyState &state);
    /// Sets a state that state() returned, bit for bit (setState would normalize it again).
    void restoreState(const RigidBodyState &saved);

    std::optional<double> friction_coefficient; ///< unset: particle law's Coulomb angles
    Material material;                          ///< defaults to the particles' material
    bool record_triangle_loads = false;

    // Filled by the DEM step: reaction of the particles on the body during the last step.
    Vec3 force_N = Vec3::Zero();
    Vec3 torque_N_m = Vec3::Zero();     ///< about the body origin
    std::vector<Vec3> triangle_force_N; ///< per triangle, when recorded
    // Impulse summed since the last resetAccumulatedImpulse() (window averages for coupling).
    Vec3 impulse_N_s = Vec3::Zero();
    Vec3 angular_impulse_N_m_s = Vec3::Zero();
    double accumulated_time_s = 0.0;
    void resetAccumulatedImpulse();
    /// The members above as one value, and back (checkpoints, in-memory snapshots).
    BodyLoads loads() const {
        return {force_N, torque_N_m, impulse_N_s, angular_impulse_N_m_s, accumulated_time_s};
    }
    void setLoads(const BodyLoads &loads);

    /// World-frame vertices at the current pose.
    const std::vector<Vec3> &worldVertices() const { return world_vertices_; }
    /// The same at another (normalized) state, e.g. one state() returned earlier.
    void worldVerticesAt(const RigidBodyState &state, std::vector<Vec3> &out) const;
    double boundingRadius() const { return bounding_radius_; }

private:
    void placeVertices(); ///< world vertices at state_
    std::string name_;
    TriangleMesh mesh_;
    RigidBodyState state_;
    std::vector<Vec3> world_vertices_;
    double bounding_radius_ = 0.0;
};

} // namespace grainlink::dem
