#pragma once
// The DEM soil simulator: particles, contact law, walls and mesh bodies, advanced by a step that
// reads as named, timed phases (docs/physics.md).
#include "grainlink/dem/ContactLaw.hpp"
#include "grainlink/dem/NeighbourList.hpp"
#include "grainlink/dem/ParticleStore.hpp"
#include "grainlink/dem/PhaseTimer.hpp"
#include "grainlink/dem/Walls.hpp"

#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace grainlink::dem {

enum class Integrator {
    VelocityVerlet, ///< explicit, second order (docs/physics.md §3.1)
    Newmark,        ///< the seed's semi-implicit Newmark predictor-corrector (§3.2)
};

struct DemSettings {
    double time_step_s = 5e-5;
    Integrator integrator = Integrator::VelocityVerlet;
    double newmark_beta = 0.25; ///< beta = 0, gamma = 1/2 is velocity Verlet
    double newmark_gamma = 0.5;
    Vec3 gravity_m_s2 = Vec3(0.0, 0.0, -9.81);
    double skin_m = 0.0;          ///< neighbour skin; 0 picks 0.4 * smallest radius
    int resort_every_builds = 25; ///< spatial re-sort every this many list builds (0: never)
    int threads = 1;
    double max_overlap_ratio = 0.4; ///< overlap / smaller radius beyond which the run stops
    bool check_time_step = true;    ///< refuse a time step above the stability estimate
};

/// A run stopped by a non-physical state; says where and what.
class SimulationError : public std::runtime_error {
public:
    SimulationError(std::uint64_t step, ParticleId particle, const std::string &quantity,
                    const std::string &detail);
    std::uint64_t step;
    ParticleId particle;
    std::string quantity;
};

struct Energies {
    double translational_J = 0.0;
    double rotational_J = 0.0;
    double gravitational_J = 0.0; ///< -m g.x, zero at the origin
    double elastic_J = 0.0;       ///< normal Hertz plus tangential spring energy
    double total() const { return translational_J + rotational_J + gravitational_J + elastic_J; }
};

class DemSystem {
public:
    DemSystem(ContactLaw law, std::vector<Material> materials, DemSettings settings);

    ParticleStore &particles() { return particles_; }
    const ParticleStore &particles() const { return particles_; }
    const ContactLaw &law() const { return law_; }
    const DemSettings &settings() const { return settings_; }
    const std::vector<Material> &materials() const { return materials_; }

    int addPlane(PlaneWall wall);
    /// Adds a mesh body; `motion`, if given, imposes its state at each step's end time.
    int addBody(MeshBody body, std::function<RigidBodyState(double)> motion = {});
    std::vector<PlaneWall> &planes() { return planes_; }
    const std::vector<PlaneWall> &planes() const { return planes_; }
    MeshBody &body(int k) { return bodies_[std::size_t(k)]; }
    const MeshBody &body(int k) const { return bodies_[std::size_t(k)]; }
    int bodyCount() const { return int(bodies_.size()); }
    /// Reaction force of the particles on plane k during the last step [N].
    const Vec3 &planeForce(int k) const { return plane_force_[std::size_t(k)]; }

    /// Builds neighbour lists and wall data now rather than at the first step (idempotent).
    void prepare() {
        if (!initialised_)
            initialise();
    }
    /// One time step of the chosen integrator.
    void step();
    void run(std::uint64_t steps);

    std::uint64_t stepCount() const { return step_; }
    double time() const {
        return time_offset_s_ + double(step_ - step_offset_) * settings_.time_step_s;
    }
    /// Changes the time step between steps (the clock stays exact in steps of the old size).
    void setTimeStep(double dt_s);
    /// Replaces the rolling slot between steps, e.g. to test several rolling laws on one
    /// settled packing (docs/scenario.md, deposition.rolling). Every rolling history starts
    /// afresh; the moments of inertia follow the new law (seed eq. 12 or solid spheres).
    void setRolling(RollingModel rolling);

    /// Largest safe step estimate: half the Rayleigh time of the smallest grain, the viscous
    /// dashpot limit m_min/k_n where one is set, 2/k_h (docs/physics.md §3.3).
    double stableTimeStepEstimate() const;
    Energies energies() const;
    std::size_t contactCount() const;     ///< particle-particle contacts
    std::size_t wallContactCount() const; ///< particle-plane and particle-mesh contacts
    std::size_t neighbourPairs() const { return neighbours_.pairCount(); }
    std::uint64_t neighbourBuilds() const { return neighbours_.buildCount(); }
    double maxOverlapRatio() const { return max_overlap_ratio_; }
    PhaseTimer &timer() { return timer_; }

    /// Everything a checkpoint needs beyond the particle arrays (see Checkpoint.hpp).
    struct Internals;
    Internals saveInternals() const;
    void restoreInternals(const Internals &state);

    // History of a particle's contacts with planes and meshes.
    struct MeshContactSlot {
        int body = -1;
        int triangle = -1;
        Vec3 normal = Vec3::Zero();
        ContactHistory history;
    };
    static constexpr int kMeshSlots = 4;

private:
    void initialise();
    void prepareWalls();
    void validateTimeStep() const;
    void advanceAndClear();
    void finishStep(bool advance);
    void addBodyForces(std::size_t i);
    [[noreturn]] void reportNonFinite(std::size_t i) const;
    void clearForces();
    void moveBodies(double t_s);
    void updateNeighbours();
    void rebuildNeighbours();
    void updatePlaneMasks();
    void balanceContactWork();
    void rebuildMeshCandidates();
    void computeForces();
    void pairContacts(); ///< and plane contacts
    void meshContacts();
    void checkOverlaps();
    void angularAcceleration(std::size_t i, Vec3 &alpha) const;
    Vec3 anisotropicAngularAcceleration(std::size_t i) const;
    void resizeWallHistories();
    void permuteWallHistories(const std::vector<std::size_t> &order);

    DemSettings settings_;
    ContactLaw law_;
    std::vector<Material> materials_;
    std::vector<PairProperties> pair_props_; ///< materials x materials
    ParticleStore particles_;
    std::vector<PlaneWall> planes_;
    std::vector<std::vector<PairProperties>> plane_props_; ///< [plane][material], [.. + track]
    std::vector<Vec3> plane_force_;
    std::vector<MeshBody> bodies_;
    std::vector<std::function<RigidBodyState(double)>> body_motion_;
    std::vector<std::vector<PairProperties>> body_props_;

    NeighbourList neighbours_;
    std::vector<Vec3> reference_position_;      ///< positions at the last list build
    std::vector<Vec3> mesh_reference_position_; ///< positions at the last mesh-candidate build
    std::vector<RigidBodyState> body_reference_;
    std::vector<std::size_t> mesh_particles_;          ///< particles with mesh candidates
    std::vector<std::size_t> mesh_candidate_first_;    ///< per entry of mesh_particles_, + end
    std::vector<std::pair<int, int>> mesh_candidates_; ///< (body, triangle)
    std::vector<std::uint64_t> plane_mask_;            ///< planes within reach, bit per plane
    struct PlaneCandidate {
        std::size_t particle, plane;
    };
    std::vector<PlaneCandidate> plane_candidates_; ///< the masks as a list, in particle order
    std::vector<std::size_t> contact_split_; ///< thread t owns particles [split[t], split[t+1])
    double max_displacement_sq_ = 0.0, max_mesh_displacement_sq_ = 0.0;
    bool displacement_known_ = false;
    CellGrid mesh_grid_;
    std::vector<ContactHistory> plane_history_; ///< [particle * planes + plane]
    std::vector<MeshContactSlot> mesh_slots_;   ///< [particle * kMeshSlots + slot]
    bool candidates_stale_ = true;
    std::size_t prepared_particles_ = 0; ///< particle count the lists were built for
    std::size_t history_planes_ = 0;     ///< plane count plane_history_ is laid out for

    /// Reaction on a particle owned by a later thread, added after the pair loop.
    struct SideContribution {
        std::size_t particle;
        Vec3 force_N;
        Vec3 torque_N_m;
    };
    std::vector<std::vector<SideContribution>> side_;                       // [thread]
    std::vector<std::vector<Vec3>> thread_body_force_, thread_body_torque_; // [thread][body]
    std::vector<std::vector<std::vector<Vec3>>> thread_triangle_force_;     // [thread][body][tri]
    std::vector<std::vector<Vec3>> thread_plane_force_;
    std::vector<double> thread_max_overlap_;
    std::vector<std::pair<ParticleId, ParticleId>> thread_max_overlap_pair_;

    std::uint64_t step_ = 0;
    std::uint64_t step_offset_ = 0; ///< steps taken before the last time-step change
    double time_offset_s_ = 0.0;
    bool initialised_ = false;
    bool forces_valid_ = false;
    double max_overlap_ratio_ = 0.0;
    PhaseTimer timer_;
    struct PhaseIds {
        int kick_drift, bodies, neighbours, contacts, meshes, check, finish;
    } phase_{};
};

/// Saved state besides the particle arrays: clock, wall histories, list references.
struct DemSystem::Internals {
    std::uint64_t step = 0;
    std::vector<NeighbourList::StoredContact> contacts; ///< storage indices, i < j
    std::vector<ContactHistory> plane_history;
    std::vector<MeshContactSlot> mesh_slots;
    std::vector<Vec3> reference_position;
    std::vector<Vec3> mesh_reference_position;
    std::vector<RigidBodyState> body_states;
    std::vector<RigidBodyState> body_reference;
    std::uint64_t neighbour_builds = 0;
    bool forces_valid = false;
    std::uint64_t step_offset = 0; ///< clock: t = time_offset + (step - step_offset) dt
    double time_offset_s = 0.0;
    double max_overlap_ratio = 0.0;
    /// Contact-pass thread split (thread count + 1 entries); empty in version-1 checkpoints.
    std::vector<std::size_t> contact_split;
};

} // namespace grainlink::dem
