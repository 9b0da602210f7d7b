#pragma once
// The DEM soil simulator: particles, contact law, walls and mesh bodies, advanced by a step that
// reads as named, timed phases (docs/physics.md §3).
#include "grainlink/dem/ContactLaw.hpp"
#include "grainlink/dem/MeshContacts.hpp"
#include "grainlink/dem/PairContacts.hpp"
#include "grainlink/dem/ParticleStore.hpp"
#include "grainlink/dem/PhaseTimer.hpp"
#include "grainlink/dem/PlaneContacts.hpp"
#include "grainlink/dem/Walls.hpp"

#include <cstdint>
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
    double skin_m = 0.0; ///< neighbour skin [m]; 0: 0.4 x the smallest radius at the first step
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

/// The DEM: particles advanced by a step that reads as named, timed phases, their contacts
/// computed by three parts that each own their candidates, histories and properties: grain-grain
/// (PairContacts), grain-plane (PlaneContacts) and grain-mesh (MeshContacts).
class DemSystem {
public:
    /// `laws`: one ContactLaw for every contact type, or one per type (ContactLaws).
    DemSystem(ContactLaws laws, std::vector<Material> materials, DemSettings settings);

    ParticleStore &particles() { return particles_; }
    const ParticleStore &particles() const { return particles_; }
    const ContactLaws &laws() const { return laws_; }
    const ContactLaw &law() const { return laws_.grain_grain; } ///< the grain-grain law
    const DemSettings &settings() const { return settings_; }
    /// The gravity from now on (deposition.gravity: settle level, run on a slope).
    void setGravity(const Vec3 &gravity_m_s2) { settings_.gravity_m_s2 = gravity_m_s2; }
    const std::vector<Material> &materials() const { return materials_; }

    /// Adds a plane; a material left unset (E = 0) is the particles' first material.
    int addPlane(PlaneWall wall);
    std::vector<PlaneWall> &planes() { return planes_.planes(); }
    const std::vector<PlaneWall> &planes() const { return planes_.planes(); }
    /// Reaction force of the particles on plane k during the last step [N].
    const Vec3 &planeForce(int k) const { return planes_.force(k); }

    /// Adds a mesh body moving by `motion` (held: it keeps its state); a material left unset is
    /// the particles' first material. Returns its index.
    int addBody(MeshBody body, BodyMotion motion = HeldMotion{});
    /// Sets how body k moves from now on (once per run, control interval or coupling window):
    /// it takes the motion's state at time() at once and follows it at every step's end time.
    void setBodyMotion(int k, BodyMotion motion);
    MeshBody &body(int k) { return meshes_.body(k); }
    const MeshBody &body(int k) const { return meshes_.body(k); }
    int bodyCount() const { return meshes_.size(); }

    /// Builds neighbour lists and wall data now rather than at the first step (idempotent).
    void prepare() {
        if (!initialized_)
            initialize();
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
    /// Replaces the rolling slot of every contact type between steps, e.g. to test several
    /// rolling laws on one settled packing (docs/scenario.md, deposition.rolling). Every
    /// rolling history starts afresh; the moments of inertia follow the new grain-grain law
    /// (seed eq. 12 or solid spheres).
    void setRolling(RollingModel rolling);
    /// The same with each contact type's rolling slot from `laws` (back to a run's own laws).
    void setRolling(const ContactLaws &laws);

    /// Largest safe step estimate: half the Rayleigh time of the smallest grain, the viscous
    /// dashpot limit m_min/k_n where one is set, 2/k_h (docs/physics.md §3.3).
    double stableTimeStepEstimate() const;
    Energies energies() const;
    std::size_t contactCount() const;     ///< particle-particle contacts
    /// The grain-grain contact network now: each touching pair and its elastic normal force.
    std::vector<PairForce> contactNetwork() const { return pairs_.touchingPairs(particles_); }
    std::size_t wallContactCount() const; ///< particle-plane and particle-mesh contacts
    std::size_t neighbourPairs() const { return pairs_.list().pairCount(); }
    std::uint64_t neighbourBuilds() const { return pairs_.list().buildCount(); }
    double maxOverlapRatio() const { return max_overlap_ratio_; }
    /// The neighbour skin in use [m]: settings().skin_m, or if that is 0 chosen from the
    /// particles' radii at the first step (0 before it).
    double skin() const { return skin_m_; }
    PhaseTimer &timer() { return timer_; }

    /// Everything a checkpoint needs beyond the particle arrays (see Checkpoint.hpp).
    struct Internals;
    Internals saveInternals() const;
    void restoreInternals(const Internals &state);

    /// The complete state in memory, for implicit coupling (repeat a window) or a retry:
    ///     const DemSystem::State start = sys.saveState();
    ///     sys.run(n);                      // one try
    ///     sys.restoreState(start);         // back, bit for bit
    ///     sys.setBodyMotion(0, corrected); // the motions are inputs: set them again
    ///     sys.run(n);                      // as if the first try never happened
    /// Particles, every contact history (rolling and grain-shape state included), the
    /// neighbour list and the mesh and plane candidates as they are, the bodies' states and
    /// accumulated loads, the clock. The setup (laws, materials, planes, bodies, settings other
    /// than the time step) must be the same as when it was saved.
    struct State;
    State saveState() const;
    void restoreState(const State &state);

private:
    void initialize();
    /// Why a contact may overlap too far: cohesion when its own resting overlap is deep
    /// (docs/physics.md §2.7), else the time step or the stiffness.
    std::string overlapHint(const WorstOverlap &worst) const;
    void validateTimeStep() const;
    // The phases of a step, in order; each is timed (PhaseIds).
    void advanceAndClear();
    void moveBodies(double t_s);
    void updateNeighbours();
    void pairContacts(); ///< with each thread's plane contacts fused in
    void meshContacts();
    void checkOverlaps();
    void finishStep(bool advance);
    // Their parts.
    void computeForces();
    void clearForces();
    void rebuildNeighbours();
    void balanceContactWork();
    void addBodyForces(std::size_t i);
    void angularAcceleration(std::size_t i, Vec3 &alpha) const;
    Vec3 anisotropicAngularAcceleration(std::size_t i) const;
    [[noreturn]] void reportNonFinite(std::size_t i) const;

    // What the system is.
    DemSettings settings_;
    ContactLaws laws_;
    std::vector<Material> materials_;
    // Its state: the particles and the contact parts.
    ParticleStore particles_;
    PairContacts pairs_;
    PlaneContacts planes_;
    MeshContacts meshes_;
    // The clock: t = time_offset + (step - step_offset) dt.
    std::uint64_t step_ = 0;
    std::uint64_t step_offset_ = 0; ///< steps taken before the last time-step change
    double time_offset_s_ = 0.0;
    // The step's bookkeeping.
    double skin_m_ = 0.0; ///< neighbour skin in use [m] (skin())
    bool initialized_ = false;
    bool forces_valid_ = false;
    std::size_t prepared_particles_ = 0;    ///< particle count the lists were built for
    bool displacement_known_ = false;       ///< measured by the kick-drift pass for this step
    double max_displacement_sq_ = 0.0;      ///< since the pair list's build [m^2]
    double max_mesh_displacement_sq_ = 0.0; ///< since the mesh candidates' build [m^2]
    std::vector<WorstOverlap> worst_;       ///< [thread], this step
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
    /// The neighbour skin in use, set from the first particles' radii at the first step and
    /// kept since [m]; 0 in version-1 and -2 checkpoints (then derived again).
    double skin_m = 0.0;
    std::vector<BodyLoads> body_loads; ///< per body; empty before version 3
    std::vector<Vec3> plane_force;     ///< of the last step, per plane; empty before version 3
};

struct DemSystem::State {
    std::size_t plane_count = 0;
    ParticleStore particles;
    PairContacts::State pairs;
    PlaneContacts::State planes;
    MeshContacts::State meshes;
    std::uint64_t step = 0, step_offset = 0;
    double time_offset_s = 0.0, time_step_s = 0.0;
    double skin_m = 0.0, max_overlap_ratio = 0.0;
    bool initialized = false, forces_valid = false;
    std::size_t prepared_particles = 0;
    /// Memory the snapshot holds: its arrays' elements and the struct itself [bytes].
    std::size_t bytes() const;
};

} // namespace grainlink::dem
