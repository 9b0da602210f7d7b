#include "grainlink/dem/DemSystem.hpp"

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

DemSystem::DemSystem(ContactLaws laws, std::vector<Material> materials, DemSettings settings)
    : settings_(settings), laws_(std::move(laws)), materials_(std::move(materials)) {
    if (materials_.empty())
        throw std::invalid_argument("DemSystem needs at least one material");
    for (const Material &m : materials_)
        m.validate();
    laws_.finalize();
    if (!(settings_.time_step_s > 0.0))
        throw std::invalid_argument("time_step_s must be > 0, got " +
                                    std::to_string(settings_.time_step_s));
    if (settings_.threads < 1)
        throw std::invalid_argument("threads must be >= 1");
    if (settings_.integrator == Integrator::Newmark &&
        !(settings_.newmark_beta >= 0.0 && settings_.newmark_gamma >= 0.5))
        throw std::invalid_argument("Newmark needs beta >= 0 and gamma >= 0.5");
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
    if (wall.material.youngs_modulus_Pa == 0.0)
        wall.material = materials_[0];
    const int k = planes_.add(std::move(wall));
    initialized_ = false;
    return k;
}

int DemSystem::addBody(MeshBody body, BodyMotion motion) {
    if (body.material.youngs_modulus_Pa == 0.0)
        body.material = materials_[0];
    const int k = meshes_.add(std::move(body), std::move(motion), time());
    initialized_ = false;
    return k;
}

void DemSystem::setBodyMotion(int k, BodyMotion motion) {
    if (k < 0 || k >= meshes_.size())
        throw std::out_of_range("setBodyMotion: no mesh body " + std::to_string(k) +
                                " (there are " + std::to_string(meshes_.size()) + ")");
    meshes_.setMotion(k, std::move(motion), time());
}

void DemSystem::initialize() {
    for (int m : particles_.material)
        if (m < 0 || std::size_t(m) >= materials_.size())
            throw std::invalid_argument("particle refers to material " + std::to_string(m) +
                                        ", but only " + std::to_string(materials_.size()) +
                                        " are defined");
    if (skin_m_ <= 0.0) // chosen once: from the settings or the first particles' radii
        skin_m_ = settings_.skin_m > 0.0 ? settings_.skin_m : 0.4 * particles_.minRadius();
    if (settings_.check_time_step)
        validateTimeStep();
    const int threads = settings_.threads;
    const std::size_t n = particles_.size();
    // Each part's properties and per-thread buffers; histories may already be restored from a
    // checkpoint and are kept where their layout fits.
    pairs_.prepare(materials_, laws_.grain_grain, threads);
    planes_.prepare(materials_, laws_.grain_wall, n, threads);
    meshes_.prepare(materials_, laws_.grain_tool, n, threads);
    worst_.assign(std::size_t(threads), WorstOverlap{});
    if (const auto *shape = std::get_if<RollingGrainShape>(&laws_.grain_grain.rolling))
        if (shape->inertia == RollingGrainShape::Inertia::SeedEq12)
            for (std::size_t i = 0; i < n; ++i) {
                // Seed eq. 12 per local axis (docs/physics.md §2.6.1); idempotent.
                const double r = particles_.radius[i];
                const double density = particles_.mass[i] / (4.0 / 3.0 * M_PI * r * r * r);
                particles_.inertia[i] = grainShapeInertia(*shape, r, density);
            }
    initialized_ = true;
    prepared_particles_ = n;
    if (!pairs_.hasReference(n)) {
        rebuildNeighbours();
    } else {
        // Restored: the pair list is recreated at the saved reference so that the rebuild
        // schedule and the storage order continue exactly as in the run that saved it.
        pairs_.rebuildAtReference(particles_, skin_m_, threads);
        planes_.updateCandidates(pairs_.referencePositions(), particles_.radius, skin_m_, threads);
        // The thread split is estimated from the contacts at a rebuild, and only there: a
        // re-initialization (a body added, a checkpoint read) keeps the last rebuild's split,
        // saved in the checkpoint, or the summation order would change with it.
        if (!pairs_.splitFits(threads, n))
            balanceContactWork();
    }
    meshes_.markStale();
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
    // An explicit dashpot c is stable only for dt < 2 m*/c: the lightest pair (m* = m/2), the
    // lightest grain on a wall or a tool (m* = m), each under its type's c.
    const double m_min = *std::min_element(particles_.mass.begin(), particles_.mass.end());
    for (ContactType type :
         {ContactType::GrainGrain, ContactType::GrainWall, ContactType::GrainTool})
        if (const auto *viscous = std::get_if<DampingViscous>(&laws_.of(type).damping))
            if (viscous->coefficient_N_s_m > 0.0)
                estimate = std::min(estimate, (type == ContactType::GrainGrain ? 1.0 : 2.0) *
                                                  m_min / viscous->coefficient_N_s_m);
    const double k_h = laws_.grain_grain.background_damping_1_s;
    if (k_h > 0.0)
        estimate = std::min(estimate, 2.0 / k_h);
    return estimate;
}

void DemSystem::setTimeStep(double dt_s) {
    if (!(dt_s > 0.0))
        throw std::invalid_argument("time step must be > 0");
    time_offset_s_ = time();
    step_offset_ = step_;
    settings_.time_step_s = dt_s;
    if (initialized_ && settings_.check_time_step)
        validateTimeStep();
}

void DemSystem::setRolling(RollingModel rolling) {
    ContactLaws laws;
    laws.grain_grain.rolling = laws.grain_wall.rolling = laws.grain_tool.rolling = rolling;
    setRolling(laws);
}

void DemSystem::setRolling(const ContactLaws &rolling) {
    const auto *old_shape = std::get_if<RollingGrainShape>(&laws_.grain_grain.rolling);
    const bool had_eq12 = old_shape && old_shape->inertia == RollingGrainShape::Inertia::SeedEq12;
    laws_.grain_grain.rolling = rolling.grain_grain.rolling;
    laws_.grain_wall.rolling = rolling.grain_wall.rolling;
    laws_.grain_tool.rolling = rolling.grain_tool.rolling;
    laws_.finalize(); // the pair properties do not depend on the rolling slot
    // Histories of another law mean nothing to this one (a moment against an angle).
    pairs_.list().clearRollingHistory();
    planes_.clearRollingHistories();
    meshes_.clearRollingHistories();
    // initialize() sets seed eq. 12's moments; leaving that law returns to solid spheres.
    if (had_eq12)
        for (std::size_t i = 0; i < particles_.size(); ++i) {
            const double r = particles_.radius[i];
            particles_.inertia[i].setConstant(0.4 * particles_.mass[i] * r * r);
        }
    initialized_ = false;
    forces_valid_ = false;
}

// ---------------------------------------------------------------------------------------------
// The step: few fused passes over the particle arrays (each pass is one timed phase).

void DemSystem::step() {
    // Particles added since the last step (rain deposition) need lists and wall data.
    if (!initialized_ || particles_.size() != prepared_particles_)
        initialize();
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

void DemSystem::computeForces() {
    updateNeighbours();
    pairContacts();
    meshContacts();
    checkOverlaps();
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
    const bool track_mesh = meshes_.tracksDisplacement();
    const Vec3 *reference = pairs_.referencePositions().data();
    const Vec3 *mesh_reference = track_mesh ? meshes_.referencePositions().data() : nullptr;
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
        max_sq = std::max(max_sq, (p.position[i] - reference[i]).squaredNorm());
        if (track_mesh)
            max_mesh_sq = std::max(max_mesh_sq, (p.position[i] - mesh_reference[i]).squaredNorm());
    }
    max_displacement_sq_ = max_sq;
    max_mesh_displacement_sq_ = max_mesh_sq;
    displacement_known_ = true;
}

// flatten: GCC kept some of Eigen's small-vector kernels of this loop out of line (+16 % of
// the pass's instructions); inlined, the pass is as lean as advanceAndClear's.
[[gnu::flatten]] void DemSystem::finishStep(bool advance) {
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
    const double k_h = laws_.grain_grain.background_damping_1_s;
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
    meshes_.move(t_s);
}

// ---------------------------------------------------------------------------------------------
// Neighbours

void DemSystem::updateNeighbours() {
    PhaseTimer::Scope scope(timer_, phase_.neighbours);
    const std::size_t n = particles_.size();
    const auto &x = particles_.position;
    if (!displacement_known_) {
        // Only at the first force evaluation; later the kick-drift pass measures this.
        const bool track_mesh = meshes_.tracksDisplacement();
        const auto &reference = pairs_.referencePositions();
        max_displacement_sq_ = max_mesh_displacement_sq_ = 0.0;
        for (std::size_t i = 0; i < n; ++i) {
            max_displacement_sq_ =
                std::max(max_displacement_sq_, (x[i] - reference[i]).squaredNorm());
            if (track_mesh)
                max_mesh_displacement_sq_ =
                    std::max(max_mesh_displacement_sq_,
                             (x[i] - meshes_.referencePositions()[i]).squaredNorm());
        }
    }
    displacement_known_ = false;
    if (2.0 * std::sqrt(max_displacement_sq_) > skin_m_)
        rebuildNeighbours();
    meshes_.update(particles_, max_mesh_displacement_sq_, skin_m_, settings_.threads);
}

namespace {
/// Storage order by grid cell for memory locality (stable within a cell).
std::vector<std::size_t> spatialOrder(const ParticleStore &p, double cell_m) {
    CellGrid grid;
    grid.bin(p.position, cell_m);
    std::vector<std::size_t> order(p.size());
    std::iota(order.begin(), order.end(), 0);
    const auto &cell = grid.particleCell();
    std::stable_sort(order.begin(), order.end(),
                     [&](std::size_t a, std::size_t b) { return cell[a] < cell[b]; });
    return order;
}
} // namespace

void DemSystem::rebuildNeighbours() {
    const std::size_t n = particles_.size();
    std::vector<std::size_t> old_to_new;
    const bool resort = settings_.resort_every_builds > 0 &&
                        neighbourBuilds() % std::uint64_t(settings_.resort_every_builds) == 0;
    if (resort && n > 0) {
        // Spatial re-sort; every part's histories follow by index map.
        const std::vector<std::size_t> order =
            spatialOrder(particles_, 2.0 * particles_.maxRadius() + skin_m_);
        old_to_new.resize(n);
        for (std::size_t k = 0; k < n; ++k)
            old_to_new[order[k]] = k;
        particles_.permute(order);
        planes_.permuteHistories(order);
        meshes_.permuteHistories(order);
    }
    pairs_.rebuild(particles_, skin_m_, old_to_new, settings_.threads);
    planes_.updateCandidates(particles_.position, particles_.radius, skin_m_, settings_.threads);
    balanceContactWork();
}

void DemSystem::balanceContactWork() {
    // Thread ranges of the contact pass by estimated work: pairs, contacts, plane candidates.
    std::vector<std::uint64_t> work(particles_.size(), 0);
    planes_.estimateWork(work);
    pairs_.estimateWork(work);
    pairs_.splitThreads(work, settings_.threads);
}

// ---------------------------------------------------------------------------------------------
// Forces

void DemSystem::pairContacts() {
    // Particle-particle contacts, each thread's plane contacts fused in: one parallel pass.
    PhaseTimer::Scope scope(timer_, phase_.contacts);
    const int threads = settings_.threads;
    const double dt = settings_.time_step_s;
    withConcreteLaw(laws_.grain_grain, [&](const auto &grain_grain) {
        // The wall law has the same models (ContactLaws::finalize), hence the same types.
        using Law = std::decay_t<decltype(grain_grain)>;
        const Law grain_wall = Law::of(laws_.grain_wall);
#pragma omp parallel num_threads(threads)
        {
            const int t = omp_get_thread_num();
            auto plane_pass =
                planes_.threadPass(t, pairs_.begin(t), pairs_.end(t), particles_, grain_wall, dt);
            pairs_.threadPass(t, particles_, grain_grain, dt, worst_[std::size_t(t)], plane_pass);
            pairs_.addSideContributions(t, threads, particles_);
        }
    });
    planes_.sumForces(threads);
}

void DemSystem::meshContacts() {
    if (meshes_.empty())
        return;
    PhaseTimer::Scope scope(timer_, phase_.meshes);
    const double dt = settings_.time_step_s;
    withConcreteLaw(laws_.grain_tool, [&](const auto &grain_tool) {
        meshes_.compute(particles_, grain_tool, dt, worst_, settings_.threads);
    });
    meshes_.sumLoads(dt, settings_.threads);
}

std::string DemSystem::overlapHint(const WorstOverlap &worst) const {
    const std::string usual = "time step too large or stiffness too low";
    const auto index = [&](ParticleId id) {
        return std::size_t(std::find(particles_.id.begin(), particles_.id.end(), id) -
                           particles_.id.begin());
    };
    const std::size_t i = index(worst.i), j = index(worst.j);
    if (i >= particles_.size() || j >= particles_.size())
        return usual;
    const ContactType type = worst.i != worst.j ? ContactType::GrainGrain
                             : worst.plane >= 0 ? ContactType::GrainWall
                                                : ContactType::GrainTool;
    const auto *cohesion = std::get_if<CohesionLinear>(&laws_.of(type).cohesion);
    if (!cohesion || !(cohesion->energy_density_J_m3 > 0.0))
        return usual;
    const Material &grain = materials_[std::size_t(particles_.material[i])];
    const Material &other =
        type == ContactType::GrainGrain  ? materials_[std::size_t(particles_.material[j])]
        : type == ContactType::GrainWall ? planes_.planes()[std::size_t(worst.plane)].material
                                         : meshes_.body(worst.body).material;
    const double e_star = pairProperties(grain, other, laws_.of(type)).effective_modulus_Pa;
    const double ri = particles_.radius[i], rj = type == ContactType::GrainGrain
                                                     ? particles_.radius[j]
                                                     : std::numeric_limits<double>::infinity();
    const double radius_eff = std::isfinite(rj) ? ri * rj / (ri + rj) : ri;
    // Where cohesion balances Hertz: d0 = R* (3 pi k_c / 4 E*)^2, docs/physics.md §2.7.
    const double resting = radius_eff / std::min(ri, rj) *
                           std::pow(3.0 * M_PI * cohesion->energy_density_J_m3 / (4.0 * e_star), 2);
    // Released at first touch, a grain falls in to (5/4)^2 d0 undamped: from half the limit on,
    // cohesion is the likely cause.
    if (resting < 0.5 * settings_.max_overlap_ratio)
        return usual;
    std::ostringstream hint;
    hint << "cohesion alone holds this contact at " << resting
         << " of the radius: energy_density_J_m3 = " << cohesion->energy_density_J_m3
         << " against E* = " << e_star
         << " Pa, docs/physics.md §2.7; lower the cohesion or stiffen the grains";
    return hint.str();
}

void DemSystem::checkOverlaps() {
    PhaseTimer::Scope scope(timer_, phase_.check);
    max_overlap_ratio_ = 0.0;
    WorstOverlap worst;
    for (WorstOverlap &w : worst_) {
        if (w.ratio > max_overlap_ratio_) {
            max_overlap_ratio_ = w.ratio;
            worst = w;
        }
        w.ratio = 0.0;
    }
    if (max_overlap_ratio_ > settings_.max_overlap_ratio) {
        // Name what the grain overlaps: a plane (a box's side) and a mesh body (a plate, a
        // wheel) are both walls to the contact law, but call for different looks.
        std::string against;
        if (worst.i != worst.j)
            against = "particle " + std::to_string(worst.j);
        else if (worst.plane >= 0)
            against = "plane '" + planes_.planes()[std::size_t(worst.plane)].name + "'";
        else if (worst.body >= 0)
            against = "body '" + meshes_.body(worst.body).name() + "'";
        else
            against = "a wall";
        std::ostringstream msg;
        msg << "= " << max_overlap_ratio_ << " of the radius against " << against
            << " exceeds max_overlap_ratio " << settings_.max_overlap_ratio << " ("
            << overlapHint(worst) << ")";
        throw SimulationError(step_ + 1, worst.i, "overlap", msg.str());
    }
}

// ---------------------------------------------------------------------------------------------
// Diagnostics and state

std::size_t DemSystem::contactCount() const {
    return pairs_.contactCount(particles_);
}

std::size_t DemSystem::wallContactCount() const {
    return planes_.activeContacts() + meshes_.activeContacts();
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
    // Stored elastic energy of the pair and plane contacts (docs/physics.md §2).
    pairs_.addElasticEnergy(p, laws_.grain_grain, e.elastic_J);
    planes_.addElasticEnergy(p, laws_.grain_wall, e.elastic_J);
    return e;
}

DemSystem::Internals DemSystem::saveInternals() const {
    Internals s;
    s.step = step_;
    s.contacts = pairs_.list().activeContacts();
    s.plane_history = planes_.histories();
    s.mesh_slots = meshes_.slots();
    s.reference_position = pairs_.referencePositions();
    s.mesh_reference_position = meshes_.referencePositions();
    for (int b = 0; b < meshes_.size(); ++b)
        s.body_states.push_back(meshes_.body(b).state());
    s.body_reference = meshes_.bodyReference();
    s.neighbour_builds = neighbourBuilds();
    s.forces_valid = forces_valid_;
    s.step_offset = step_offset_;
    s.time_offset_s = time_offset_s_;
    s.max_overlap_ratio = max_overlap_ratio_;
    s.contact_split = pairs_.split();
    s.skin_m = skin_m_;
    for (int b = 0; b < meshes_.size(); ++b)
        s.body_loads.push_back(meshes_.body(b).loads());
    s.plane_force = planes_.forces();
    return s;
}

void DemSystem::restoreInternals(const Internals &s) {
    if (s.body_states.size() != std::size_t(meshes_.size()))
        throw std::runtime_error("checkpoint has " + std::to_string(s.body_states.size()) +
                                 " mesh bodies, the scenario defines " +
                                 std::to_string(meshes_.size()));
    if (s.plane_history.size() != particles_.size() * planes_.size())
        throw std::runtime_error("checkpoint has plane histories for another number of planes (" +
                                 std::to_string(planes_.size()) + " in the scenario)");
    for (const MeshContactSlot &slot : s.mesh_slots)
        if (slot.body >= 0 && (slot.body >= meshes_.size() || slot.triangle < 0 ||
                               std::size_t(slot.triangle) >=
                                   meshes_.body(slot.body).mesh().triangles.size()))
            throw std::runtime_error("checkpoint has a mesh contact on body " +
                                     std::to_string(slot.body) + ", triangle " +
                                     std::to_string(slot.triangle) + ", which the scenario lacks");
    step_ = s.step;
    step_offset_ = s.step_offset;
    time_offset_s_ = s.time_offset_s;
    max_overlap_ratio_ = s.max_overlap_ratio;
    planes_.setHistories(s.plane_history);
    for (std::size_t b = 0; b < s.body_states.size(); ++b)
        meshes_.body(int(b)).restoreState(s.body_states[b]);
    for (std::size_t b = 0; b < s.body_loads.size() && b < s.body_states.size(); ++b)
        meshes_.body(int(b)).setLoads(s.body_loads[b]);
    if (s.plane_force.size() == planes_.size())
        planes_.setForces(s.plane_force);
    if (settings_.skin_m <= 0.0 && s.skin_m > 0.0)
        skin_m_ = s.skin_m; // automatic: as the saving run chose it, not from today's radii
    meshes_.restore(s.mesh_slots, s.mesh_reference_position, s.body_reference);
    pairs_.restore(s.contacts, s.reference_position, s.neighbour_builds, s.contact_split);
    forces_valid_ = s.forces_valid;
    initialized_ = false;
}

namespace {
template <class T> std::size_t bytesOf(const std::vector<T> &v) {
    return v.size() * sizeof(T);
}
template <class T, class... Rest> std::size_t bytesOf(const T &first, const Rest &...rest) {
    return bytesOf(first) + bytesOf(rest...);
}
} // namespace

std::size_t DemSystem::State::bytes() const {
    const ParticleStore &p = particles;
    std::size_t n = sizeof(State) +
                    bytesOf(p.id, p.position, p.velocity, p.angular_velocity, p.orientation,
                            p.force, p.torque, p.radius, p.mass, p.inv_mass, p.inertia,
                            p.material);
    const auto &l = pairs.list;
    n += bytesOf(l.first, l.owner, l.neighbour, l.state, l.tangential_m, l.rolling_N_m,
                 l.pending, pairs.reference_position, pairs.split);
    n += bytesOf(planes.history, planes.candidates, planes.force);
    n += bytesOf(meshes.slots, meshes.particles, meshes.first, meshes.candidates,
                 meshes.reference_position, meshes.body_reference, meshes.body_state,
                 meshes.body_loads, meshes.triangle_force);
    for (const auto &forces : meshes.triangle_force)
        n += bytesOf(forces);
    return n;
}

DemSystem::State DemSystem::saveState() const {
    return {planes_.size(),  particles_,         pairs_.state(),
            planes_.state(), meshes_.state(),    step_,
            step_offset_,    time_offset_s_,     settings_.time_step_s,
            skin_m_,         max_overlap_ratio_, initialized_,
            forces_valid_,   prepared_particles_};
}

void DemSystem::restoreState(const State &s) {
    if (s.plane_count != planes_.size() ||
        s.meshes.body_state.size() != std::size_t(meshes_.size()))
        throw std::invalid_argument(
            "restoreState: the state was saved with " + std::to_string(s.plane_count) +
            " planes and " + std::to_string(s.meshes.body_state.size()) +
            " mesh bodies, the system has " + std::to_string(planes_.size()) + " and " +
            std::to_string(meshes_.size()) + ": restore a state of this system, as it was set up");
    planes_.restore(s.planes);
    meshes_.restore(s.meshes);
    particles_ = s.particles;
    pairs_.restore(s.pairs);
    step_ = s.step;
    step_offset_ = s.step_offset;
    time_offset_s_ = s.time_offset_s;
    settings_.time_step_s = s.time_step_s;
    skin_m_ = s.skin_m;
    max_overlap_ratio_ = s.max_overlap_ratio;
    initialized_ = s.initialized;
    forces_valid_ = s.forces_valid;
    prepared_particles_ = s.prepared_particles;
}

} // namespace grainlink::dem
