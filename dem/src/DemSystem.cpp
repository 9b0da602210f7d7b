#include "grainlink/dem/DemSystem.hpp"

#include "grainlink/dem/ContactKernel.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>

namespace grainlink::dem {

SimulationError::SimulationError(std::uint64_t step_, ParticleId particle_,
                                 const std::string &quantity_, const std::string &detail)
    : std::runtime_error("step " + std::to_string(step_) + ", particle " +
                         std::to_string(particle_) + ": " + quantity_ + " " + detail),
      step(step_), particle(particle_), quantity(quantity_) {}

DemSystem::DemSystem(ContactLaw law, std::vector<Material> materials, DemSettings settings)
    : settings_(settings), law_(std::move(law)), materials_(std::move(materials)) {
    if (materials_.empty())
        throw std::invalid_argument("DemSystem needs at least one material");
    for (const Material &m : materials_)
        m.validate();
    law_.finalize();
    if (!(settings_.time_step_s > 0.0))
        throw std::invalid_argument("time_step_s must be > 0, got " +
                                    std::to_string(settings_.time_step_s));
    if (settings_.threads < 1)
        throw std::invalid_argument("threads must be >= 1");
    if (settings_.integrator == Integrator::Newmark &&
        !(settings_.newmark_beta >= 0.0 && settings_.newmark_gamma >= 0.5))
        throw std::invalid_argument("Newmark needs beta >= 0 and gamma >= 0.5");
    const std::size_t nm = materials_.size();
    pair_props_.resize(nm * nm);
    for (std::size_t a = 0; a < nm; ++a)
        for (std::size_t b = 0; b < nm; ++b)
            pair_props_[a * nm + b] = pairProperties(materials_[a], materials_[b], law_);
    // Phases in step order; the two passes over all particles fuse the cheap per-particle work.
    phase_.kick_drift =
        timer_.phase(settings_.integrator == Integrator::Newmark ? "predict+clearForces"
                                                                 : "halfKick+drift+clearForces");
    phase_.bodies = timer_.phase("moveBodies");
    phase_.neighbours = timer_.phase("updateNeighbours");
    phase_.contacts = timer_.phase("pairContacts+planeContacts");
    phase_.meshes = timer_.phase("meshContacts");
    phase_.check = timer_.phase("checkOverlaps");
    phase_.finish = timer_.phase(
        settings_.integrator == Integrator::Newmark ? "bodyForces+correct" : "bodyForces+halfKick");
}

int DemSystem::addPlane(PlaneWall wall) {
    if (!(wall.normal.norm() > 0.0))
        throw std::invalid_argument("plane '" + wall.name + "' has a zero normal");
    wall.normal.normalize();
    if (wall.material.youngs_modulus_Pa == 0.0)
        wall.material = materials_[0];
    wall.material.validate();
    planes_.push_back(std::move(wall));
    initialised_ = false;
    return int(planes_.size() - 1);
}

int DemSystem::addBody(MeshBody body, std::function<RigidBodyState(double)> motion) {
    if (body.material.youngs_modulus_Pa == 0.0)
        body.material = materials_[0];
    body.material.validate();
    bodies_.push_back(std::move(body));
    body_motion_.push_back(std::move(motion));
    initialised_ = false;
    candidates_stale_ = true;
    return int(bodies_.size() - 1);
}

void DemSystem::prepareWalls() {
    const std::size_t nm = materials_.size();
    plane_props_.assign(planes_.size(), {});
    for (std::size_t w = 0; w < planes_.size(); ++w) {
        const PlaneWall &p = planes_[w];
        for (std::size_t m = 0; m < nm; ++m)
            plane_props_[w].push_back(
                p.friction_coefficient
                    ? pairProperties(materials_[m], p.material, law_, *p.friction_coefficient)
                    : pairProperties(materials_[m], p.material, law_));
        for (std::size_t m = 0; m < nm && p.track; ++m)
            plane_props_[w].push_back(
                pairProperties(materials_[m], p.material, law_, p.track->friction_coefficient));
    }
    body_props_.assign(bodies_.size(), {});
    for (std::size_t b = 0; b < bodies_.size(); ++b)
        for (std::size_t m = 0; m < nm; ++m)
            body_props_[b].push_back(
                bodies_[b].friction_coefficient
                    ? pairProperties(materials_[m], bodies_[b].material, law_,
                                     *bodies_[b].friction_coefficient)
                    : pairProperties(materials_[m], bodies_[b].material, law_));
    plane_force_.assign(planes_.size(), Vec3::Zero());
}

void DemSystem::resizeWallHistories() {
    // New particles are appended, so per-particle blocks keep their place; a changed plane
    // count changes the layout, and those histories start afresh.
    const std::size_t n = particles_.size();
    if (history_planes_ != planes_.size())
        plane_history_.clear();
    history_planes_ = planes_.size();
    plane_history_.resize(n * planes_.size());
    mesh_slots_.resize(n * kMeshSlots);
}

void DemSystem::initialise() {
    for (int m : particles_.material)
        if (m < 0 || std::size_t(m) >= materials_.size())
            throw std::invalid_argument("particle refers to material " + std::to_string(m) +
                                        ", but only " + std::to_string(materials_.size()) +
                                        " are defined");
    prepareWalls();
    if (settings_.skin_m <= 0.0)
        settings_.skin_m = 0.4 * particles_.minRadius();
    if (settings_.check_time_step)
        validateTimeStep();
    const int threads = settings_.threads;
    const std::size_t n = particles_.size();
    side_.assign(std::size_t(threads), {});
    if (planes_.size() > 64)
        throw std::invalid_argument("at most 64 planes are supported; use a mesh for more");
    // Each thread adds into its own wall and body sums at every wall or mesh contact. Separate
    // small allocations may lie side by side in memory: a cache line of slack after each keeps
    // two threads off one line (false sharing would bounce it between cores on every contact).
    const auto perThreadSums = [](std::size_t n) {
        constexpr std::size_t kSlack = (64 + sizeof(Vec3) - 1) / sizeof(Vec3);
        std::vector<Vec3> sums;
        sums.reserve(n + kSlack);
        sums.resize(n, Vec3::Zero());
        return sums;
    };
    thread_body_force_.resize(std::size_t(threads));
    thread_body_torque_.resize(std::size_t(threads));
    thread_plane_force_.resize(std::size_t(threads));
    for (std::size_t t = 0; t < std::size_t(threads); ++t) {
        thread_body_force_[t] = perThreadSums(bodies_.size());
        thread_body_torque_[t] = perThreadSums(bodies_.size());
        thread_plane_force_[t] = perThreadSums(planes_.size());
    }
    thread_triangle_force_.assign(threads, {});
    for (auto &per_thread : thread_triangle_force_)
        for (const MeshBody &b : bodies_)
            per_thread.emplace_back(b.record_triangle_loads ? b.mesh().triangleCount() : 0,
                                    Vec3::Zero());
    thread_max_overlap_.assign(threads, 0.0);
    thread_max_overlap_pair_.assign(threads, {0, 0});
    // Histories may already be restored from a checkpoint; keep them if the size fits.
    if (plane_history_.size() != n * planes_.size() || mesh_slots_.size() != n * kMeshSlots ||
        history_planes_ != planes_.size())
        resizeWallHistories();
    body_reference_.resize(bodies_.size());
    neighbours_.keepRollingHistory(std::holds_alternative<RollingEpsd>(law_.rolling) ||
                                   std::holds_alternative<RollingGrainShape>(law_.rolling));
    if (const auto *shape = std::get_if<RollingGrainShape>(&law_.rolling))
        if (shape->inertia == RollingGrainShape::Inertia::SeedEq12)
            for (std::size_t i = 0; i < n; ++i) {
                // Seed eq. 12 per local axis (docs/physics.md §2.6.1); idempotent.
                const double r = particles_.radius[i];
                const double density = particles_.mass[i] / (4.0 / 3.0 * M_PI * r * r * r);
                particles_.inertia[i] = grainShapeInertia(*shape, r, density);
            }
    initialised_ = true;
    prepared_particles_ = n;
    if (reference_position_.size() != n)
        rebuildNeighbours();
    else {
        // Restored: rebuild the pair list at the saved reference so the rebuild schedule and
        // the storage order continue exactly as in the run that wrote the checkpoint.
        // This rebuild only recreates the list: it does not count towards the re-sort schedule.
        const std::uint64_t builds = neighbours_.buildCount();
        neighbours_.build(reference_position_, particles_.radius, settings_.skin_m, {}, threads);
        neighbours_.restoreBuildCount(builds);
        updatePlaneMasks();
        // The thread split is estimated from the contacts at a rebuild, and only there: a
        // re-initialisation (a body added, a checkpoint read) keeps the last rebuild's split,
        // saved in the checkpoint, or the summation order would change with it.
        if (contact_split_.size() != std::size_t(threads) + 1 || contact_split_.back() != n)
            balanceContactWork();
    }
    candidates_stale_ = true;
}

void DemSystem::validateTimeStep() const {
    const double estimate = stableTimeStepEstimate();
    if (settings_.time_step_s > estimate) {
        std::ostringstream msg;
        msg << "time_step_s = " << settings_.time_step_s << " s is above the stability estimate "
            << estimate << " s (docs/physics.md §3.3); reduce it or set check_time_step: false";
        throw std::invalid_argument(msg.str());
    }
}

double DemSystem::stableTimeStepEstimate() const {
    double estimate = std::numeric_limits<double>::infinity();
    if (particles_.empty())
        return estimate;
    // Rayleigh time step of the smallest grain of each material.
    for (std::size_t m = 0; m < materials_.size(); ++m) {
        double r_min = std::numeric_limits<double>::infinity(), rho = 0.0;
        for (std::size_t i = 0; i < particles_.size(); ++i)
            if (std::size_t(particles_.material[i]) == m && particles_.radius[i] < r_min) {
                r_min = particles_.radius[i];
                rho = particles_.mass[i] / (4.0 / 3.0 * M_PI * std::pow(r_min, 3));
            }
        if (!std::isfinite(r_min))
            continue;
        const Material &mat = materials_[m];
        const double shear = mat.youngs_modulus_Pa / (2.0 * (1.0 + mat.poisson_ratio));
        const double rayleigh =
            M_PI * r_min * std::sqrt(rho / shear) / (0.1631 * mat.poisson_ratio + 0.8766);
        // Half the Rayleigh time: a settled bed of Table 1 soil starts to rattle at 0.41 T_R
        // and blows up at 0.71 T_R (IntegratorStabilityTest), so T_R itself is not safe.
        estimate = std::min(estimate, 0.5 * rayleigh);
    }
    // An explicit dashpot c is stable only for dt < 2 m*/c (lightest pair, m* = m/2).
    if (const auto *viscous = std::get_if<DampingViscous>(&law_.damping)) {
        const double m_min = *std::min_element(particles_.mass.begin(), particles_.mass.end());
        if (viscous->coefficient_N_s_m > 0.0)
            estimate = std::min(estimate, m_min / viscous->coefficient_N_s_m);
    }
    if (law_.background_damping_1_s > 0.0)
        estimate = std::min(estimate, 2.0 / law_.background_damping_1_s);
    return estimate;
}

void DemSystem::setTimeStep(double dt_s) {
    if (!(dt_s > 0.0))
        throw std::invalid_argument("time step must be > 0");
    time_offset_s_ = time();
    step_offset_ = step_;
    settings_.time_step_s = dt_s;
    if (initialised_ && settings_.check_time_step)
        validateTimeStep();
}

void DemSystem::setRolling(RollingModel rolling) {
    const auto *old_shape = std::get_if<RollingGrainShape>(&law_.rolling);
    const bool had_eq12 = old_shape && old_shape->inertia == RollingGrainShape::Inertia::SeedEq12;
    law_.rolling = std::move(rolling);
    law_.finalize(); // the pair properties do not depend on the rolling slot
    // Histories of another law mean nothing to this one (a moment against an angle).
    neighbours_.clearRollingHistory();
    for (ContactHistory &h : plane_history_)
        h.rolling_N_m.setZero();
    for (MeshContactSlot &slot : mesh_slots_)
        slot.history.rolling_N_m.setZero();
    // initialise() sets seed eq. 12's moments; leaving that law returns to solid spheres.
    if (had_eq12)
        for (std::size_t i = 0; i < particles_.size(); ++i) {
            const double r = particles_.radius[i];
            particles_.inertia[i].setConstant(0.4 * particles_.mass[i] * r * r);
        }
    initialised_ = false;
    forces_valid_ = false;
}

// ---------------------------------------------------------------------------------------------
// The step: few fused passes over the particle arrays (each pass is one timed phase).

void DemSystem::step() {
    // Particles added since the last step (rain deposition) need lists and wall data.
    if (!initialised_ || particles_.size() != prepared_particles_)
        initialise();
    if (!forces_valid_) {
        // Forces at the initial state, needed by the first half kick / predictor.
        moveBodies(time());
        clearForces();
        displacement_known_ = false;
        computeForces();
        finishStep(false);
        forces_valid_ = true;
    }
    const double t_next = time() + settings_.time_step_s;
    advanceAndClear();
    moveBodies(t_next);
    computeForces();
    finishStep(true);
    ++step_;
}

void DemSystem::run(std::uint64_t steps) {
    for (std::uint64_t k = 0; k < steps; ++k)
        step();
}

inline void DemSystem::angularAcceleration(std::size_t i, Vec3 &alpha) const {
    const Vec3 &inertia = particles_.inertia[i];
    if (particles_.isotropic(i))
        alpha = particles_.torque[i] / inertia.x();
    else
        alpha = anisotropicAngularAcceleration(i);
}

Vec3 DemSystem::anisotropicAngularAcceleration(std::size_t i) const {
    // Euler's equations in the particle frame (per-axis inertia, seed eq. 2).
    const Vec3 &inertia = particles_.inertia[i];
    const Mat3 rot = particles_.orientation[i].toRotationMatrix();
    const Vec3 w = rot.transpose() * particles_.angular_velocity[i];
    const Vec3 t = rot.transpose() * particles_.torque[i];
    const Vec3 body_alpha = (t - w.cross(inertia.cwiseProduct(w))).cwiseQuotient(inertia);
    return rot * body_alpha;
}

namespace {
/// Turns q by the rotation vector `turn` (world frame). Small turns, the rule in a DEM step,
/// use the exact series of the exponential map and so need no trigonometric functions.
inline void rotate(Quat &q, const Vec3 &turn) {
    const Vec3 half = 0.5 * turn;
    const double s2 = half.squaredNorm();
    Quat dq;
    if (s2 < 1e-6) { // |half| < 1e-3: series truncation error below 1e-19
        dq.w() = 1.0 - s2 * (0.5 - s2 / 24.0);
        dq.vec() = half * (1.0 - s2 * (1.0 / 6.0 - s2 / 120.0));
    } else {
        dq = rotationFromVector(turn);
    }
    q = dq * q;
    if (s2 >= 1e-6)
        q.normalize(); // the series keeps |dq| = 1 to round-off
}
} // namespace

void DemSystem::advanceAndClear() {
    // Velocity Verlet: half kick, drift. Newmark: predictor. Both then clear the forces and
    // measure the displacement that decides the next neighbour-list rebuild.
    PhaseTimer::Scope scope(timer_, phase_.kick_drift);
    const bool newmark = settings_.integrator == Integrator::Newmark;
    const double dt = settings_.time_step_s, h = 0.5 * dt;
    const double drift_a = dt * dt * (0.5 - settings_.newmark_beta);
    const double kick_a = dt * (1.0 - settings_.newmark_gamma);
    auto &p = particles_;
    const std::size_t n = p.size();
    const bool track_mesh = !bodies_.empty() && !candidates_stale_;
    double max_sq = 0.0, max_mesh_sq = 0.0;
#pragma omp parallel for schedule(static) num_threads(settings_.threads)                           \
    reduction(max                                                                                  \
              : max_sq, max_mesh_sq)
    for (std::size_t i = 0; i < n; ++i) {
        Vec3 alpha;
        angularAcceleration(i, alpha);
        if (newmark) {
            const Vec3 a = p.inv_mass[i] * p.force[i];
            p.position[i] += dt * p.velocity[i] + drift_a * a;
            p.velocity[i] += kick_a * a;
            rotate(p.orientation[i], dt * p.angular_velocity[i] + drift_a * alpha);
            p.angular_velocity[i] += kick_a * alpha;
        } else {
            p.velocity[i] += (h * p.inv_mass[i]) * p.force[i];
            p.angular_velocity[i] += h * alpha;
            p.position[i] += dt * p.velocity[i];
            rotate(p.orientation[i], dt * p.angular_velocity[i]);
        }
        p.force[i].setZero();
        p.torque[i].setZero();
        max_sq = std::max(max_sq, (p.position[i] - reference_position_[i]).squaredNorm());
        if (track_mesh)
            max_mesh_sq =
                std::max(max_mesh_sq, (p.position[i] - mesh_reference_position_[i]).squaredNorm());
    }
    max_displacement_sq_ = max_sq;
    max_mesh_displacement_sq_ = max_mesh_sq;
    displacement_known_ = true;
}

void DemSystem::finishStep(bool advance) {
    // Adds gravity and drag, checks the forces, then (if `advance`) the second half kick of
    // velocity Verlet or the Newmark corrector. `advance` is false at the initial evaluation.
    PhaseTimer::Scope scope(timer_, phase_.finish);
    const bool newmark = settings_.integrator == Integrator::Newmark;
    const double dt = settings_.time_step_s, h = 0.5 * dt;
    const double drift_a = settings_.newmark_beta * dt * dt;
    const double kick_a = settings_.newmark_gamma * dt;
    auto &p = particles_;
    const std::size_t n = p.size();
    std::size_t bad = n;
#pragma omp parallel for schedule(static) num_threads(settings_.threads) reduction(min : bad)
    for (std::size_t i = 0; i < n; ++i) {
        addBodyForces(i);
        // Checked before any update: the state stays finite for the failure snapshot.
        if (!p.force[i].allFinite() || !p.torque[i].allFinite() || !p.position[i].allFinite()) {
            bad = std::min(bad, i);
            continue;
        }
        if (!advance)
            continue;
        Vec3 alpha;
        angularAcceleration(i, alpha);
        if (newmark) {
            const Vec3 a = p.inv_mass[i] * p.force[i];
            p.position[i] += drift_a * a;
            p.velocity[i] += kick_a * a;
            rotate(p.orientation[i], drift_a * alpha);
            p.angular_velocity[i] += kick_a * alpha;
        } else {
            p.velocity[i] += (h * p.inv_mass[i]) * p.force[i];
            p.angular_velocity[i] += h * alpha;
        }
    }
    if (bad < n)
        reportNonFinite(bad);
}

inline void DemSystem::addBodyForces(std::size_t i) {
    auto &p = particles_;
    p.force[i] += p.mass[i] * settings_.gravity_m_s2;
    const double k_h = law_.background_damping_1_s;
    if (k_h > 0.0) {
        // Background damping k_h (docs/physics.md §2.8); mean moment for anisotropic grains.
        p.force[i] -= (k_h * p.mass[i]) * p.velocity[i];
        p.torque[i] -= (k_h * p.inertia[i].mean()) * p.angular_velocity[i];
    }
}

void DemSystem::reportNonFinite(std::size_t i) const {
    const auto &p = particles_;
    const std::string what = !p.position[i].allFinite() ? "position"
                             : !p.force[i].allFinite()  ? "force"
                                                        : "torque";
    throw SimulationError(step_ + 1, p.id[i], what, "is not finite");
}

void DemSystem::clearForces() {
    std::fill(particles_.force.begin(), particles_.force.end(), Vec3::Zero());
    std::fill(particles_.torque.begin(), particles_.torque.end(), Vec3::Zero());
}

void DemSystem::moveBodies(double t_s) {
    PhaseTimer::Scope scope(timer_, phase_.bodies);
    for (std::size_t b = 0; b < bodies_.size(); ++b)
        if (body_motion_[b])
            bodies_[b].setState(body_motion_[b](t_s));
}

void DemSystem::computeForces() {
    updateNeighbours();
    pairContacts();
    meshContacts();
    checkOverlaps();
}

// ---------------------------------------------------------------------------------------------
// Neighbours

void DemSystem::updateNeighbours() {
    PhaseTimer::Scope scope(timer_, phase_.neighbours);
    const std::size_t n = particles_.size();
    const auto &x = particles_.position;
    const bool have_bodies = !bodies_.empty();
    if (!displacement_known_) {
        // Only at the first force evaluation; later the kick-drift pass measures this.
        const bool track_mesh = have_bodies && !candidates_stale_;
        max_displacement_sq_ = max_mesh_displacement_sq_ = 0.0;
        for (std::size_t i = 0; i < n; ++i) {
            max_displacement_sq_ =
                std::max(max_displacement_sq_, (x[i] - reference_position_[i]).squaredNorm());
            if (track_mesh)
                max_mesh_displacement_sq_ = std::max(
                    max_mesh_displacement_sq_, (x[i] - mesh_reference_position_[i]).squaredNorm());
        }
    }
    displacement_known_ = false;
    const double skin = settings_.skin_m;
    if (2.0 * std::sqrt(max_displacement_sq_) > skin)
        rebuildNeighbours();
    if (!have_bodies)
        return;
    // A particle-triangle pair may approach by the particle's and the mesh's displacement.
    double body_move = 0.0;
    for (std::size_t b = 0; b < bodies_.size() && !candidates_stale_; ++b) {
        const RigidBodyState &now = bodies_[b].state(), &ref = body_reference_[b];
        const double angle =
            2.0 *
            std::acos(std::min(1.0, std::abs((now.orientation * ref.orientation.conjugate()).w())));
        body_move = std::max(body_move, (now.position_m - ref.position_m).norm() +
                                            angle * bodies_[b].boundingRadius());
    }
    if (candidates_stale_ || std::sqrt(max_mesh_displacement_sq_) + body_move > skin)
        rebuildMeshCandidates();
}

void DemSystem::rebuildNeighbours() {
    const std::size_t n = particles_.size();
    std::vector<std::size_t> old_to_new;
    const bool resort =
        settings_.resort_every_builds > 0 &&
        neighbours_.buildCount() % std::uint64_t(settings_.resort_every_builds) == 0;
    if (resort && n > 0) {
        // Spatial re-sort by cell for memory locality; histories follow by index map.
        CellGrid grid;
        grid.bin(particles_.position, 2.0 * particles_.maxRadius() + settings_.skin_m);
        std::vector<std::size_t> order(n);
        std::iota(order.begin(), order.end(), 0);
        const auto &cell = grid.particleCell();
        std::stable_sort(order.begin(), order.end(),
                         [&](std::size_t a, std::size_t b) { return cell[a] < cell[b]; });
        old_to_new.resize(n);
        for (std::size_t k = 0; k < n; ++k)
            old_to_new[order[k]] = k;
        particles_.permute(order);
        permuteWallHistories(order);
        candidates_stale_ = true;
    }
    neighbours_.build(particles_.position, particles_.radius, settings_.skin_m, old_to_new,
                      settings_.threads);
    reference_position_ = particles_.position;
    updatePlaneMasks();
    balanceContactWork();
}

void DemSystem::updatePlaneMasks() {
    // Planes within reach (radius + skin) of each particle; the others cannot touch it before
    // the next rebuild, so their history lapses now.
    const std::size_t n = particles_.size(), np = planes_.size();
    plane_mask_.assign(n, 0);
    const double skin = settings_.skin_m;
#pragma omp parallel for schedule(static) num_threads(settings_.threads)
    for (std::size_t i = 0; i < n; ++i) {
        std::uint64_t mask = 0;
        for (std::size_t w = 0; w < np; ++w) {
            const double dist =
                (particles_.position[i] - planes_[w].point_m).dot(planes_[w].normal);
            if (dist < particles_.radius[i] + skin)
                mask |= std::uint64_t(1) << w;
            else if (plane_history_[i * np + w].active())
                plane_history_[i * np + w] = ContactHistory{};
        }
        plane_mask_[i] = mask;
    }
    // The same as a list of (particle, plane) in particle order, walked by the contact loop.
    plane_candidates_.clear();
    for (std::size_t i = 0; i < n; ++i)
        for (std::uint64_t mask = plane_mask_[i]; mask != 0; mask &= mask - 1)
            plane_candidates_.push_back({i, std::size_t(__builtin_ctzll(mask))});
}

void DemSystem::balanceContactWork() {
    // Splits the particles of the contact pass into thread ranges of about equal work. A contact
    // costs about 12 times a listed pair that does not touch, and contacts crowd at the floor and
    // walls of a bed; so the work of a particle is estimated from its listed pairs, those of
    // them in contact at the rebuild, and its plane candidates. The split depends only on the
    // lists, so a run stays deterministic for a given thread count.
    const std::size_t n = particles_.size();
    const int threads = settings_.threads;
    const auto &first = neighbours_.first;
    const auto &state = neighbours_.state;
    std::vector<std::uint64_t> work(n, 0);
    for (const PlaneCandidate &c : plane_candidates_)
        work[c.particle] += 12;
    std::uint64_t total = 0;
    for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t k = first[i]; k < first[i + 1]; ++k)
            work[i] += (state[k] & NeighbourList::kTouching) ? 13 : 1;
        total += work[i];
    }
    contact_split_.assign(std::size_t(threads) + 1, n);
    contact_split_[0] = 0;
    std::uint64_t sum = 0;
    int t = 1;
    for (std::size_t i = 0; i < n && t < threads; ++i) {
        sum += work[i];
        while (t < threads && sum * std::uint64_t(threads) >= total * std::uint64_t(t))
            contact_split_[std::size_t(t++)] = i + 1;
    }
}

void DemSystem::permuteWallHistories(const std::vector<std::size_t> &order) {
    const std::size_t np = planes_.size();
    std::vector<ContactHistory> planes(plane_history_.size());
    std::vector<MeshContactSlot> slots(mesh_slots_.size());
    for (std::size_t k = 0; k < order.size(); ++k) {
        for (std::size_t w = 0; w < np; ++w)
            planes[k * np + w] = plane_history_[order[k] * np + w];
        for (int s = 0; s < kMeshSlots; ++s)
            slots[k * kMeshSlots + s] = mesh_slots_[order[k] * kMeshSlots + s];
    }
    plane_history_.swap(planes);
    mesh_slots_.swap(slots);
}

void DemSystem::rebuildMeshCandidates() {
    const std::size_t n = particles_.size();
    const double skin = settings_.skin_m, r_max = particles_.maxRadius();
    mesh_grid_.bin(particles_.position, 2.0 * r_max + skin);
    const auto &start = mesh_grid_.cellStart();
    const auto &members = mesh_grid_.cellParticles();
    // Triangles are shared out among threads; the sort below makes the result independent of
    // the thread count.
    std::vector<std::pair<int, int>> triangles;
    for (std::size_t b = 0; b < bodies_.size(); ++b)
        for (std::size_t t = 0; t < bodies_[b].mesh().triangles.size(); ++t)
            triangles.push_back({int(b), int(t)});
    const int threads = settings_.threads;
    using Found = std::vector<std::pair<std::size_t, std::pair<int, int>>>;
    std::vector<Found> found_by(static_cast<std::size_t>(threads));
#pragma omp parallel for schedule(static) num_threads(threads)
    for (std::size_t k = 0; k < triangles.size(); ++k) {
        auto &found = found_by[std::size_t(omp_get_thread_num())];
        const auto [b, t] = triangles[k];
        const MeshBody &body = bodies_[std::size_t(b)];
        const auto &v = body.worldVertices();
        const auto &tri = body.mesh().triangles[std::size_t(t)];
        const Vec3 &a = v[tri[0]], &bb = v[tri[1]], &c = v[tri[2]];
        const Vec3 pad = Vec3::Constant(r_max + skin);
        const Eigen::Vector3i lo = mesh_grid_.cellCoords(a.cwiseMin(bb).cwiseMin(c) - pad);
        const Eigen::Vector3i hi = mesh_grid_.cellCoords(a.cwiseMax(bb).cwiseMax(c) + pad);
        const Vec3 normal = (bb - a).cross(c - a).normalized();
        for (int z = lo.z(); z <= hi.z(); ++z)
            for (int y = lo.y(); y <= hi.y(); ++y)
                for (int x = lo.x(); x <= hi.x(); ++x) {
                    const int cell = mesh_grid_.cellIndex({x, y, z});
                    for (int m = start[cell]; m < start[cell + 1]; ++m) {
                        const std::size_t i = std::size_t(members[m]);
                        const Vec3 &p = particles_.position[i];
                        const double reach = particles_.radius[i] + skin;
                        // Cheap plane test first: most cell members are far off the plane.
                        if (std::abs((p - a).dot(normal)) >= reach)
                            continue;
                        if ((closestPointOnTriangle(p, a, bb, c) - p).squaredNorm() < reach * reach)
                            found.push_back({i, {b, t}});
                    }
                }
    }
    Found found;
    for (const Found &part : found_by)
        found.insert(found.end(), part.begin(), part.end());
    std::sort(found.begin(), found.end());
    std::vector<std::size_t> first(n + 1, 0);
    mesh_candidates_.clear();
    for (const auto &f : found) {
        ++first[f.first + 1];
        mesh_candidates_.push_back(f.second);
    }
    for (std::size_t i = 0; i < n; ++i)
        first[i + 1] += first[i];
    // Particles out of every mesh's reach drop their mesh histories (they cannot touch).
    for (std::size_t i = 0; i < n; ++i)
        if (first[i] == first[i + 1] && mesh_slots_[i * kMeshSlots].body >= 0)
            for (int s = 0; s < kMeshSlots; ++s)
                mesh_slots_[i * kMeshSlots + s] = MeshContactSlot{};
    mesh_particles_.clear();
    mesh_candidate_first_.clear();
    for (std::size_t i = 0; i < n; ++i)
        if (first[i] < first[i + 1]) {
            mesh_particles_.push_back(i);
            mesh_candidate_first_.push_back(first[i]);
        }
    mesh_candidate_first_.push_back(first[n]);
    mesh_reference_position_ = particles_.position;
    for (std::size_t b = 0; b < bodies_.size(); ++b)
        body_reference_[b] = bodies_[b].state();
    candidates_stale_ = false;
}

// ---------------------------------------------------------------------------------------------
// Forces

void DemSystem::pairContacts() {
    // Particle-particle, then particle-plane contacts, one parallel pass.
    PhaseTimer::Scope scope(timer_, phase_.contacts);
    const int threads = settings_.threads;
    const std::size_t np = planes_.size();
    const std::size_t nm = materials_.size();
    const double dt = settings_.time_step_s;
    auto &p = particles_;
    withConcreteLaw(law_, [&](const auto &normal, const auto &damping, const auto &tangential,
                              const auto &rolling, const auto &cohesion) {
        using Normal = std::decay_t<decltype(normal)>;
        using Rolling = std::decay_t<decltype(rolling)>;
        constexpr bool kGrainShape = std::is_same_v<Rolling, RollingGrainShape>;
        constexpr bool kRolling = std::is_same_v<Rolling, RollingEpsd> || kGrainShape;
#pragma omp parallel num_threads(threads)
        {
            // Thread t owns particles [begin, end) and writes their forces directly. The
            // reaction on a particle of a later thread goes to a side list, added after the
            // barrier in thread order: deterministic and without full-size buffers.
            const int t = omp_get_thread_num();
            const std::size_t begin = contact_split_[std::size_t(t)];
            const std::size_t end = contact_split_[std::size_t(t) + 1];
            auto &side = side_[std::size_t(t)];
            side.clear();
            // Raw, non-aliasing pointers: the stores to forces then cannot force reloads of
            // the arrays' addresses from the store object inside the loop.
            Vec3 *__restrict force = p.force.data();
            Vec3 *__restrict torque = p.torque.data();
            const Vec3 *__restrict position = p.position.data();
            const Vec3 *__restrict velocity = p.velocity.data();
            const Vec3 *__restrict spin = p.angular_velocity.data();
            const double *__restrict radius = p.radius.data();
            const double *__restrict inv_mass = p.inv_mass.data();
            const int *__restrict material = p.material.data();
            double max_ratio = 0.0;
            std::pair<ParticleId, ParticleId> max_pair{0, 0};
            const int *__restrict neighbour = neighbours_.neighbour.data();
            std::uint8_t *__restrict state = neighbours_.state.data();
            Vec3 *__restrict tangential_history = neighbours_.tangential_m.data();
            Vec3 *__restrict rolling_history = neighbours_.rolling_N_m.data();
            const int *__restrict owner = neighbours_.owner.data();
            // Entries are walked in order, in batches, not row by row: rows are short (4 pairs)
            // and of varying length, and each row's end would be a mispredicted branch.
            constexpr std::size_t kBatch = 128;
            std::size_t overlapping[kBatch], lost[kBatch];
            const std::size_t k_end = neighbours_.first[end];
            // Plane contacts of this thread's particles, in the same pass: candidates (within
            // reach at the last rebuild) are in particle order, and a particle's are handled
            // once its row of pairs is done, while its data are still in cache. Its force then
            // sums pairs, then planes, as before.
            auto &plane_force = thread_plane_force_[std::size_t(t)];
            std::fill(plane_force.begin(), plane_force.end(), Vec3::Zero());
            const auto by_particle = [](const PlaneCandidate &c, std::size_t i) {
                return c.particle < i;
            };
            const auto c_begin = std::lower_bound(plane_candidates_.begin(),
                                                  plane_candidates_.end(), begin, by_particle);
            const auto c_end = std::lower_bound(c_begin, plane_candidates_.end(), end, by_particle);
            // As for pairs: first which candidates touch (no branch on it), then the contacts,
            // so that consecutive contacts overlap in the processor instead of waiting on a
            // mispredicted branch each.
            const PlaneCandidate *candidate = plane_candidates_.data();
            const std::size_t p_begin = std::size_t(c_begin - plane_candidates_.begin());
            const std::size_t p_end = std::size_t(c_end - plane_candidates_.begin());
            const auto plane_distance = [&](const PlaneCandidate &c) {
                const PlaneWall &wall = planes_[c.plane];
                return (position[c.particle] - wall.point_m).dot(wall.normal);
            };
            std::size_t next_candidate = p_begin;
            const auto planeContactsBefore = [&](std::size_t limit) {
                std::size_t stop = next_candidate;
                while (stop < p_end && candidate[stop].particle < limit)
                    ++stop;
                for (std::size_t c0 = next_candidate; c0 < stop; c0 += kBatch) {
                    const std::size_t c1 = std::min(c0 + kBatch, stop);
                    std::size_t count = 0, apart_count = 0;
                    for (std::size_t c = c0; c < c1; ++c) {
                        // Histories of the few particles at walls are scattered over a large
                        // array: fetch them now, for the contacts below.
                        const ContactHistory *h =
                            &plane_history_[candidate[c].particle * np + candidate[c].plane];
                        __builtin_prefetch(h, 1);
                        __builtin_prefetch(reinterpret_cast<const char *>(h + 1) - 1, 1);
                        __builtin_prefetch(&p.mass[candidate[c].particle]);
                        const unsigned touches =
                            plane_distance(candidate[c]) < radius[candidate[c].particle];
                        overlapping[count] = c;
                        count += touches;
                        lost[apart_count] = c;
                        apart_count += touches ^ 1u;
                    }
                    // Candidates apart from their plane: an active history lapses.
                    for (std::size_t k = 0; k < apart_count; ++k) {
                        const PlaneCandidate &c = candidate[lost[k]];
                        ContactHistory &h = plane_history_[c.particle * np + c.plane];
                        if (h.active())
                            h = ContactHistory{};
                    }
                    for (std::size_t k = 0; k < count; ++k) {
                        const std::size_t i = candidate[overlapping[k]].particle;
                        const std::size_t w = candidate[overlapping[k]].plane;
                        const PlaneWall &wall = planes_[w];
                        ContactHistory &h = plane_history_[i * np + w];
                        const double ri = radius[i];
                        const double dist = plane_distance(candidate[overlapping[k]]);
                        ContactGeometry g;
                        g.normal = wall.normal;
                        g.overlap_m = ri - dist;
                        g.radius_eff_m = ri;
                        g.mass_eff_kg = p.mass[i];
                        g.arm_i_m = dist;
                        g.arm_j_m = 0.0;
                        g.contact_velocity_m_s = velocity[i] - dist * spin[i].cross(g.normal);
                        g.relative_spin_rad_s = spin[i];
                        if constexpr (kGrainShape) {
                            g.orientation_i = &p.orientation[i];
                            g.orientation_j = nullptr;
                        }
                        const Vec3 contact_point = position[i] - dist * wall.normal;
                        std::size_t slot = std::size_t(material[i]);
                        if (wall.track && wall.track->contains(contact_point))
                            slot += nm;
                        ContactResult r;
                        evaluateContact<Normal>(damping, tangential, rolling, cohesion,
                                                plane_props_[w][slot], g, dt, h, r);
                        force[i] += r.force_on_i_N;
                        torque[i] += r.torque_on_i_N_m;
                        plane_force[w] -= r.force_on_i_N;
                        if (g.overlap_m > max_ratio * ri) {
                            max_ratio = g.overlap_m / ri;
                            max_pair = {p.id[i], p.id[i]};
                        }
                    }
                }
                next_candidate = stop;
            };

            for (std::size_t k0 = neighbours_.first[begin]; k0 < k_end; k0 += kBatch) {
                const std::size_t k1 = std::min(k0 + kBatch, k_end);
                // 1. Which listed pairs overlap, and which contacts were just lost, without a
                //    branch on either answer: about half the pairs overlap, unpredictably.
                std::size_t count = 0, lost_count = 0;
                for (std::size_t k = k0; k < k1; ++k) {
                    const std::size_t i = std::size_t(owner[k]);
                    const std::size_t j = std::size_t(neighbour[k]);
                    const double r_sum = radius[i] + radius[j];
                    const unsigned overlaps =
                        (position[i] - position[j]).squaredNorm() < r_sum * r_sum;
                    overlapping[count] = k;
                    count += overlaps;
                    lost[lost_count] = k;
                    lost_count += unsigned(state[k] != 0) & (overlaps ^ 1u);
                }
                // A contact just lost drops its history.
                for (std::size_t c = 0; c < lost_count; ++c) {
                    state[lost[c]] = 0;
                    tangential_history[lost[c]].setZero();
                    if constexpr (kRolling)
                        rolling_history[lost[c]].setZero();
                }
                // 2. The contacts, in entry order: forces on i and j are summed in that order.
                for (std::size_t c = 0; c < count; ++c) {
                    const std::size_t k = overlapping[c];
                    const std::size_t i = std::size_t(owner[k]);
                    const std::size_t j = std::size_t(neighbour[k]);
                    const Vec3 d = position[i] - position[j];
                    const double dist = std::sqrt(d.squaredNorm());
                    const double ri = radius[i], rj = radius[j];
                    const double r_sum = ri + rj;
                    ContactGeometry g;
                    g.normal = d * (1.0 / dist);
                    g.overlap_m = r_sum - dist;
                    g.radius_eff_m = ri * rj / r_sum;
                    g.mass_eff_kg = 1.0 / (inv_mass[i] + inv_mass[j]);
                    g.arm_i_m = ri - 0.5 * g.overlap_m;
                    g.arm_j_m = rj - 0.5 * g.overlap_m;
                    g.contact_velocity_m_s =
                        velocity[i] - velocity[j] -
                        (g.arm_i_m * spin[i] + g.arm_j_m * spin[j]).cross(g.normal);
                    g.relative_spin_rad_s = spin[i] - spin[j];
                    if constexpr (kGrainShape) {
                        g.orientation_i = &p.orientation[i];
                        g.orientation_j = &p.orientation[j];
                    }
                    ContactHistory h;
                    h.tangential_m = tangential_history[k];
                    if constexpr (kRolling)
                        h.rolling_N_m = rolling_history[k];
                    h.sliding = (state[k] & NeighbourList::kSliding) != 0;
                    ContactResult r;
                    evaluateContact<Normal>(
                        damping, tangential, rolling, cohesion,
                        pair_props_[std::size_t(material[i]) * nm + std::size_t(material[j])], g,
                        dt, h, r);
                    tangential_history[k] = h.tangential_m;
                    if constexpr (kRolling)
                        rolling_history[k] = h.rolling_N_m;
                    state[k] = std::uint8_t(NeighbourList::kTouching |
                                            (h.sliding ? NeighbourList::kSliding : 0));
                    force[i] += r.force_on_i_N;
                    torque[i] += r.torque_on_i_N_m;
                    if (j < end) {
                        force[j] -= r.force_on_i_N;
                        torque[j] += r.torque_on_j_N_m;
                    } else {
                        side.push_back({j, -r.force_on_i_N, r.torque_on_j_N_m});
                    }
                    const double r_min = std::min(ri, rj);
                    if (g.overlap_m > max_ratio * r_min) {
                        max_ratio = g.overlap_m / r_min;
                        max_pair = {p.id[i], p.id[j]};
                    }
                }
                // Rows before the one the next batch starts in are complete.
                if (k1 < k_end)
                    planeContactsBefore(std::size_t(owner[k1]));
            }
            planeContactsBefore(end);
            thread_max_overlap_[std::size_t(t)] = max_ratio;
            thread_max_overlap_pair_[std::size_t(t)] = max_pair;
            if (threads > 1) {
#pragma omp barrier
                for (int s = 0; s < t; ++s)
                    for (const SideContribution &c : side_[std::size_t(s)])
                        if (c.particle >= begin && c.particle < end) {
                            force[c.particle] += c.force_N;
                            torque[c.particle] += c.torque_N_m;
                        }
            }
        }
    });
    for (std::size_t w = 0; w < np; ++w) {
        plane_force_[w].setZero();
        for (int t = 0; t < threads; ++t)
            plane_force_[w] += thread_plane_force_[std::size_t(t)][w];
    }
}

void DemSystem::meshContacts() {
    if (bodies_.empty())
        return;
    PhaseTimer::Scope scope(timer_, phase_.meshes);
    const int threads = settings_.threads;
    const std::size_t nb = bodies_.size();
    const double dt = settings_.time_step_s;
    auto &p = particles_;
    withConcreteLaw(law_, [&](const auto &normal, const auto &damping, const auto &tangential,
                              const auto &rolling, const auto &cohesion) {
        using Normal = std::decay_t<decltype(normal)>;
#pragma omp parallel num_threads(threads)
        {
            const int t = omp_get_thread_num();
            auto &body_force = thread_body_force_[t];
            auto &body_torque = thread_body_torque_[t];
            auto &triangle_force = thread_triangle_force_[t];
            std::fill(body_force.begin(), body_force.end(), Vec3::Zero());
            std::fill(body_torque.begin(), body_torque.end(), Vec3::Zero());
            for (auto &loads : triangle_force)
                std::fill(loads.begin(), loads.end(), Vec3::Zero());
            struct Touch {
                int body, triangle;
                Vec3 point;
                double dist;
            };
            constexpr int kMaxTouches = 16;
            Touch touches[kMaxTouches];
            MeshContactSlot next[kMeshSlots];
            ContactGeometry g;
            ContactResult r;
            double max_ratio = thread_max_overlap_[std::size_t(t)]; // the pair pass's
            std::pair<ParticleId, ParticleId> max_pair = thread_max_overlap_pair_[std::size_t(t)];
            const std::size_t candidates = mesh_particles_.size();
#pragma omp for schedule(static)
            for (std::size_t c_index = 0; c_index < candidates; ++c_index) {
                const std::size_t i = mesh_particles_[c_index];
                MeshContactSlot *slots = &mesh_slots_[i * kMeshSlots];
                const std::size_t c0 = mesh_candidate_first_[c_index];
                const std::size_t c1 = mesh_candidate_first_[c_index + 1];
                const Vec3 xi = p.position[i];
                const double ri = p.radius[i];
                int count = 0;
                for (std::size_t c = c0; c < c1; ++c) {
                    const auto [b, tri] = mesh_candidates_[c];
                    const auto &v = bodies_[std::size_t(b)].worldVertices();
                    const auto &ids = bodies_[std::size_t(b)].mesh().triangles[std::size_t(tri)];
                    const Vec3 q = closestPointOnTriangle(xi, v[ids[0]], v[ids[1]], v[ids[2]]);
                    const double dist_sq = (xi - q).squaredNorm();
                    if (dist_sq >= ri * ri || count == kMaxTouches)
                        continue;
                    touches[count++] = {b, tri, q, std::sqrt(dist_sq)};
                }
                // Nearest first. A touch whose point lies in (or behind) the tangent plane of a
                // nearer accepted touch of the same body is that surface again, seen through a
                // neighbouring triangle's edge or vertex (a point shared by two triangles is the
                // extreme case): counting it would add a second, tilted force wherever a sphere
                // overlaps a flat mesh near an edge. Concave corners keep both faces.
                std::sort(touches, touches + count, [](const Touch &a, const Touch &b) {
                    return a.dist != b.dist
                               ? a.dist < b.dist
                               : (a.body != b.body ? a.body < b.body : a.triangle < b.triangle);
                });
                int used = 0, accepted_count = 0;
                int accepted[kMaxTouches];
                Vec3 accepted_normal[kMaxTouches];
                for (int k = 0; k < count; ++k) {
                    const Touch &touch = touches[k];
                    bool duplicate = false;
                    for (int m = 0; m < accepted_count && !duplicate; ++m) {
                        const Touch &nearer = touches[accepted[m]];
                        duplicate =
                            nearer.body == touch.body &&
                            (touch.point - nearer.point).dot(accepted_normal[m]) <= 1e-9 * ri;
                    }
                    if (duplicate)
                        continue;
                    // Same triangle, or a neighbour of it with the same normal, keeps history.
                    const Vec3 n_c =
                        touch.dist > 0.0 ? Vec3((xi - touch.point) / touch.dist) : Vec3::UnitZ();
                    accepted[accepted_count] = k;
                    accepted_normal[accepted_count++] = n_c;
                    ContactHistory h;
                    int best = -1;
                    for (int s = 0; s < kMeshSlots; ++s)
                        if (slots[s].body == touch.body && slots[s].triangle == touch.triangle)
                            best = s;
                    for (int s = 0; s < kMeshSlots && best < 0; ++s)
                        if (slots[s].body == touch.body && slots[s].normal.dot(n_c) > 0.99)
                            best = s;
                    if (best >= 0) {
                        h = slots[best].history;
                        slots[best].body = -1; // consumed
                    }
                    const MeshBody &body = bodies_[std::size_t(touch.body)];
                    g.normal = n_c;
                    g.overlap_m = ri - touch.dist;
                    g.radius_eff_m = ri;
                    g.mass_eff_kg = p.mass[i];
                    g.arm_i_m = touch.dist;
                    g.arm_j_m = 0.0;
                    g.contact_velocity_m_s = p.velocity[i] -
                                             touch.dist * p.angular_velocity[i].cross(n_c) -
                                             body.state().pointVelocity(touch.point);
                    g.relative_spin_rad_s =
                        p.angular_velocity[i] - body.state().angular_velocity_rad_s;
                    if constexpr (std::is_same_v<std::decay_t<decltype(rolling)>,
                                                 RollingGrainShape>) {
                        g.orientation_i = &p.orientation[i];
                        g.orientation_j = nullptr;
                    }
                    const auto &props =
                        body_props_[std::size_t(touch.body)][std::size_t(p.material[i])];
                    evaluateContact<Normal>(damping, tangential, rolling, cohesion, props, g, dt, h,
                                            r);
                    p.force[i] += r.force_on_i_N;
                    p.torque[i] += r.torque_on_i_N_m;
                    body_force[std::size_t(touch.body)] -= r.force_on_i_N;
                    body_torque[std::size_t(touch.body)] +=
                        (touch.point - body.state().position_m).cross(-r.force_on_i_N) +
                        r.torque_on_j_N_m;
                    auto &loads = triangle_force[std::size_t(touch.body)];
                    if (!loads.empty())
                        loads[std::size_t(touch.triangle)] -= r.force_on_i_N;
                    const double ratio = g.overlap_m / ri;
                    if (ratio > max_ratio) {
                        max_ratio = ratio;
                        max_pair = {p.id[i], p.id[i]};
                    }
                    if (used < kMeshSlots)
                        next[used++] = {touch.body, touch.triangle, n_c, h};
                }
                for (int s = 0; s < kMeshSlots; ++s)
                    slots[s] = s < used ? next[s] : MeshContactSlot{};
            }
            thread_max_overlap_[std::size_t(t)] = max_ratio;
            thread_max_overlap_pair_[std::size_t(t)] = max_pair;
        }
    });
    for (std::size_t b = 0; b < nb; ++b) {
        MeshBody &body = bodies_[b];
        body.force_N.setZero();
        body.torque_N_m.setZero();
        for (int t = 0; t < threads; ++t) {
            body.force_N += thread_body_force_[t][b];
            body.torque_N_m += thread_body_torque_[t][b];
        }
        if (body.record_triangle_loads) {
            std::fill(body.triangle_force_N.begin(), body.triangle_force_N.end(), Vec3::Zero());
            for (int t = 0; t < threads; ++t)
                for (std::size_t k = 0; k < body.triangle_force_N.size(); ++k)
                    body.triangle_force_N[k] += thread_triangle_force_[t][b][k];
        }
        body.impulse_N_s += dt * body.force_N;
        body.angular_impulse_N_m_s += dt * body.torque_N_m;
        body.accumulated_time_s += dt;
    }
}

void DemSystem::checkOverlaps() {
    PhaseTimer::Scope scope(timer_, phase_.check);
    max_overlap_ratio_ = 0.0;
    std::pair<ParticleId, ParticleId> worst{0, 0};
    for (std::size_t t = 0; t < thread_max_overlap_.size(); ++t)
        if (thread_max_overlap_[t] > max_overlap_ratio_) {
            max_overlap_ratio_ = thread_max_overlap_[t];
            worst = thread_max_overlap_pair_[t];
        }
    for (double &v : thread_max_overlap_)
        v = 0.0;
    if (max_overlap_ratio_ > settings_.max_overlap_ratio) {
        std::ostringstream msg;
        msg << "= " << max_overlap_ratio_ << " of the radius"
            << (worst.first != worst.second ? " against particle " + std::to_string(worst.second)
                                            : std::string(" against a wall"))
            << " exceeds max_overlap_ratio " << settings_.max_overlap_ratio
            << " (time step too large or stiffness too low)";
        throw SimulationError(step_ + 1, worst.first, "overlap", msg.str());
    }
}

// ---------------------------------------------------------------------------------------------
// Diagnostics and state

std::size_t DemSystem::contactCount() const {
    std::size_t count = 0;
    const auto &p = particles_;
    for (std::size_t i = 0; i + 1 < neighbours_.first.size(); ++i)
        for (std::size_t k = neighbours_.first[i]; k < neighbours_.first[i + 1]; ++k) {
            const std::size_t j = std::size_t(neighbours_.neighbour[k]);
            const double r = p.radius[i] + p.radius[j];
            if ((p.position[i] - p.position[j]).squaredNorm() < r * r)
                ++count;
        }
    return count;
}

std::size_t DemSystem::wallContactCount() const {
    std::size_t count = 0;
    for (const ContactHistory &h : plane_history_)
        count += h.active() ? 1 : 0;
    for (const MeshContactSlot &s : mesh_slots_)
        count += s.body >= 0 ? 1 : 0;
    return count;
}

Energies DemSystem::energies() const {
    Energies e;
    const auto &p = particles_;
    for (std::size_t i = 0; i < p.size(); ++i) {
        e.translational_J += 0.5 * p.mass[i] * p.velocity[i].squaredNorm();
        const Mat3 rot = p.orientation[i].toRotationMatrix();
        const Vec3 w = rot.transpose() * p.angular_velocity[i];
        e.rotational_J += 0.5 * w.dot(p.inertia[i].cwiseProduct(w));
        e.gravitational_J -= p.mass[i] * settings_.gravity_m_s2.dot(p.position[i]);
    }
    // Stored elastic energy: Hertz 8/15 E* sqrt(R*) delta^(5/2) plus 1/2 k_t |delta_t|^2.
    const std::size_t nm = materials_.size();
    auto tangential_energy = [&](const PairProperties &props, double r_eff, double overlap,
                                 const ContactHistory &h) {
        double k_t = 0.0;
        if (const auto *lin = std::get_if<TangentialLinear>(&law_.tangential))
            k_t = lin->stiffness_N_m;
        else
            k_t = 8.0 * props.effective_shear_modulus_Pa * std::sqrt(r_eff * overlap);
        return 0.5 * k_t * h.tangential_m.squaredNorm();
    };
    auto hertz_energy = [](const PairProperties &props, double r_eff, double overlap) {
        return 8.0 / 15.0 * props.effective_modulus_Pa * std::sqrt(r_eff) * std::pow(overlap, 2.5);
    };
    for (std::size_t i = 0; i + 1 < neighbours_.first.size(); ++i)
        for (std::size_t k = neighbours_.first[i]; k < neighbours_.first[i + 1]; ++k) {
            const std::size_t j = std::size_t(neighbours_.neighbour[k]);
            const double r_sum = p.radius[i] + p.radius[j];
            const double overlap = r_sum - (p.position[i] - p.position[j]).norm();
            if (overlap <= 0.0)
                continue;
            const PairProperties &props =
                pair_props_[std::size_t(p.material[i]) * nm + std::size_t(p.material[j])];
            const double r_eff = p.radius[i] * p.radius[j] / r_sum;
            e.elastic_J += hertz_energy(props, r_eff, overlap) +
                           tangential_energy(props, r_eff, overlap, neighbours_.history(k));
        }
    for (std::size_t i = 0; i < p.size() && !plane_props_.empty(); ++i)
        for (std::size_t w = 0; w < planes_.size(); ++w) {
            const double overlap =
                p.radius[i] - (p.position[i] - planes_[w].point_m).dot(planes_[w].normal);
            if (overlap <= 0.0)
                continue;
            const PairProperties &props = plane_props_[w][std::size_t(p.material[i])];
            e.elastic_J += hertz_energy(props, p.radius[i], overlap) +
                           tangential_energy(props, p.radius[i], overlap,
                                             plane_history_[i * planes_.size() + w]);
        }
    return e;
}

DemSystem::Internals DemSystem::saveInternals() const {
    Internals s;
    s.step = step_;
    s.contacts = neighbours_.activeContacts();
    s.plane_history = plane_history_;
    s.mesh_slots = mesh_slots_;
    s.reference_position = reference_position_;
    s.mesh_reference_position = mesh_reference_position_;
    for (const MeshBody &b : bodies_)
        s.body_states.push_back(b.state());
    s.body_reference = body_reference_;
    s.neighbour_builds = neighbours_.buildCount();
    s.forces_valid = forces_valid_;
    s.step_offset = step_offset_;
    s.time_offset_s = time_offset_s_;
    s.max_overlap_ratio = max_overlap_ratio_;
    s.contact_split = contact_split_;
    return s;
}

void DemSystem::restoreInternals(const Internals &s) {
    if (s.body_states.size() != bodies_.size())
        throw std::runtime_error("checkpoint has " + std::to_string(s.body_states.size()) +
                                 " mesh bodies, the scenario defines " +
                                 std::to_string(bodies_.size()));
    step_ = s.step;
    step_offset_ = s.step_offset;
    time_offset_s_ = s.time_offset_s;
    max_overlap_ratio_ = s.max_overlap_ratio;
    if (s.plane_history.size() != particles_.size() * planes_.size())
        throw std::runtime_error("checkpoint has plane histories for another number of planes (" +
                                 std::to_string(planes_.size()) + " in the scenario)");
    plane_history_ = s.plane_history;
    history_planes_ = planes_.size();
    mesh_slots_ = s.mesh_slots;
    reference_position_ = s.reference_position;
    mesh_reference_position_ = s.mesh_reference_position;
    for (std::size_t b = 0; b < bodies_.size(); ++b)
        bodies_[b].setState(s.body_states[b]);
    body_reference_ = s.body_reference;
    neighbours_ = NeighbourList{};
    neighbours_.setPendingContacts(s.contacts);
    neighbours_.restoreBuildCount(s.neighbour_builds);
    forces_valid_ = s.forces_valid;
    contact_split_ = s.contact_split; // empty from version-1 files: re-estimated
    initialised_ = false;
}

} // namespace grainlink::dem
