#include "grainlink/dem/BedPreparation.hpp"

#include "grainlink/dem/LoadServo.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace grainlink::dem {

namespace {

[[noreturn]] void badMember(const char *spec, const char *member, double value, const char *rule) {
    std::ostringstream msg;
    msg << spec << ": " << member << " = " << value << " " << rule;
    throw std::invalid_argument(msg.str());
}

double lowestBottom(const ParticleStore &p) {
    double bottom = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < p.size(); ++i)
        bottom = std::min(bottom, p.position[i].z() - p.radius[i]);
    return bottom;
}

double highestTop(const ParticleStore &p) {
    double top = -std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < p.size(); ++i)
        top = std::max(top, p.position[i].z() + p.radius[i]);
    return top;
}

} // namespace

void CompactionSpec::validate() const {
    if (!(pressure_Pa > 0.0) || !std::isfinite(pressure_Pa))
        badMember("compaction", "pressure_Pa", pressure_Pa,
                  "must be > 0 (a plate at 0 Pa changes nothing: leave compaction out)");
    if (!(hold_time_s > 0.0) || !std::isfinite(hold_time_s))
        badMember("compaction", "hold_time_s", hold_time_s, "must be > 0");
    if (!(speed_m_s > 0.0) || !std::isfinite(speed_m_s))
        badMember("compaction", "speed_m_s", speed_m_s, "must be > 0");
}

void CrustSpec::validate() const {
    if (!(thickness_m > 0.0) || !std::isfinite(thickness_m))
        badMember("crust", "thickness_m", thickness_m, "must be > 0");
    if (!(youngs_modulus_factor > 0.0) || !std::isfinite(youngs_modulus_factor))
        badMember("crust", "youngs_modulus_factor", youngs_modulus_factor, "must be > 0");
    if (youngs_modulus_factor == 1.0)
        badMember("crust", "youngs_modulus_factor", youngs_modulus_factor,
                  "changes nothing (a crust of the soil itself): leave crust out");
}

Material crustMaterial(const Material &soil, const CrustSpec &crust) {
    Material m = soil;
    m.name = soil.name + "_crust";
    m.youngs_modulus_Pa = soil.youngs_modulus_Pa * crust.youngs_modulus_factor;
    return m;
}

double bedSurface(const ParticleStore &p) {
    if (p.empty())
        return 0.0;
    std::vector<double> tops(p.size());
    for (std::size_t i = 0; i < p.size(); ++i)
        tops[i] = p.position[i].z() + p.radius[i];
    const std::size_t k = std::min(p.size() - 1, std::size_t(0.98 * double(p.size())));
    std::nth_element(tops.begin(), tops.begin() + std::ptrdiff_t(k), tops.end());
    return tops[k];
}

std::string startingOverlapError(const DemSystem &system, int body, double max_overlap_ratio) {
    const double overlap_limit = 0.5 * max_overlap_ratio;
    const ParticleStore &p = system.particles();
    const MeshBody &mesh_body = system.body(body);
    const GrainOverlap deepest =
        deepestGrainOverlap(p.position, p.radius, mesh_body.worldVertices(), mesh_body.mesh());
    if (deepest.ratio <= overlap_limit)
        return "";
    const std::size_t i = deepest.particle;
    char text[400];
    std::snprintf(text, sizeof text,
                  "body '%s' starts cutting %.2f of grain %zu's radius (%.2f mm; the grain's top "
                  "is %.2f mm above the bed surface): start it at least %.1f mm higher (the limit "
                  "is half of max_overlap_ratio, %.3g)",
                  mesh_body.name().c_str(), deepest.ratio, i, 1000.0 * deepest.ratio * p.radius[i],
                  1000.0 * (p.position[i].z() + p.radius[i] - bedSurface(p)),
                  1000.0 * deepest.ratio * p.radius[i] + 0.1, overlap_limit);
    return text;
}

double packingFraction(const ParticleStore &p, double footprint_area_m2) {
    if (p.empty() || !(footprint_area_m2 > 0.0))
        throw std::invalid_argument("packingFraction needs grains and a footprint area > 0");
    double volume = 0.0;
    for (double r : p.radius)
        volume += 4.0 / 3.0 * M_PI * r * r * r;
    return volume / (footprint_area_m2 * (bedSurface(p) - lowestBottom(p)));
}

namespace {

/// Keeps the grains at `kept` (ascending) with every history among them: the state a checkpoint
/// holds, with the other grains' entries dropped, restored.
void keepParticles(DemSystem &system, const std::vector<std::size_t> &kept) {
    system.prepare(); // histories and list references sized for the grains
    const std::size_t n = system.particles().size();
    DemSystem::Internals state = system.saveInternals();
    std::vector<std::size_t> new_index(n, n);
    for (std::size_t k = 0; k < kept.size(); ++k)
        new_index[kept[k]] = k;
    std::vector<NeighbourList::StoredContact> contacts;
    for (NeighbourList::StoredContact c : state.contacts)
        if (new_index[c.i] < n && new_index[c.j] < n) {
            c.i = new_index[c.i]; // the order is kept, so i < j still
            c.j = new_index[c.j];
            contacts.push_back(c);
        }
    state.contacts = std::move(contacts);
    // Per-grain blocks of `block` entries; an array not laid out per grain is rebuilt anyway.
    const auto keepBlocks = [&](auto &values, std::size_t block) {
        std::decay_t<decltype(values)> out;
        if (values.size() == n * block)
            for (std::size_t i : kept)
                for (std::size_t b = 0; b < block; ++b)
                    out.push_back(values[i * block + b]);
        values.swap(out);
    };
    keepBlocks(state.plane_history, system.planes().size());
    keepBlocks(state.mesh_slots, std::size_t(MeshContacts::kSlots));
    keepBlocks(state.reference_position, 1);
    keepBlocks(state.mesh_reference_position, 1);
    state.contact_split.clear(); // re-estimated for the grains left
    state.forces_valid = false;  // the stored forces include the removed grains'
    system.particles().keep(kept);
    system.restoreInternals(state);
}

/// Copies the grains and their histories from `from` into `to`, a system of the same laws,
/// materials and planes but other mesh bodies (whose contact histories start afresh).
void moveGrains(DemSystem &from, DemSystem &to) {
    from.prepare();
    DemSystem::Internals state = from.saveInternals();
    const std::size_t n = from.particles().size();
    state.mesh_slots.assign(n * MeshContacts::kSlots, MeshContactSlot{});
    state.body_states.clear();
    for (int b = 0; b < to.bodyCount(); ++b)
        state.body_states.push_back(to.body(b).state());
    state.body_loads.clear(); // `to`'s bodies keep their own
    // The mesh candidates are built afresh where the grains and `to`'s bodies are now.
    state.mesh_reference_position = from.particles().position;
    state.body_reference = state.body_states;
    state.forces_valid = false; // the bodies' forces differ
    to.particles() = from.particles();
    to.restoreInternals(state);
}

/// The plate's speed is set once per this interval from the reaction measured over the last;
/// the servo's integral time is kIntegralIntervals of them (docs/physics.md §6.1).
constexpr double kControlInterval_s = 1e-3;
constexpr double kIntegralIntervals = 2.0;
/// Largest time step, in units of sqrt(m / k) of a loaded contact, at which a compacted bed's
/// packing does not depend on the step (measured, docs/physics.md §6.1).
constexpr double kLoadedStepFactor = 0.2;

/// Stiffness dF/ddelta = 3/2 F / delta [N/m] of a Hertz contact carrying force_N (§2.1).
double hertzStiffness(double force_N, double effective_modulus_Pa, double radius_eff_m) {
    const double overlap =
        std::pow(3.0 * force_N / (4.0 * effective_modulus_Pa * std::sqrt(radius_eff_m)), 2.0 / 3.0);
    return 1.5 * force_N / overlap;
}

/// What the compaction's estimates need of the bed: mean grain, weight, moduli.
struct BedScales {
    double radius_m = 0.0, mass_kg = 0.0; ///< means
    double weight_N = 0.0;
    double grain_modulus_Pa = 0.0; ///< E* grain-grain
    double plate_modulus_Pa = 0.0; ///< E* grain-plate (the plate is of material 0)
    explicit BedScales(const DemSystem &system) {
        const ParticleStore &p = system.particles();
        const double n = double(p.size());
        for (std::size_t i = 0; i < p.size(); ++i) {
            radius_m += p.radius[i] / n;
            mass_kg += p.mass[i] / n;
            weight_N += p.mass[i] * system.settings().gravity_m_s2.norm();
        }
        const Material &grain = system.materials()[std::size_t(p.material[0])];
        grain_modulus_Pa =
            pairProperties(grain, grain, system.laws().grain_grain).effective_modulus_Pa;
        plate_modulus_Pa = pairProperties(grain, system.materials()[0], system.laws().grain_tool)
                               .effective_modulus_Pa;
    }
    /// Grains in a layer of the footprint: one per (2 r)^2.
    double layer(double area_m2) const {
        return std::max(1.0, area_m2 / (4.0 * radius_m * radius_m));
    }
};

/// Upper bound on the stiffness the plate meets at the target load: a layer of grains touches
/// it, each a Hertz contact carrying its share; the layers below act in series and only soften
/// it. A servo gain of 1 / (this x interval) then converges without overshoot (§12.11).
double plateStiffness(const BedScales &bed, double target_force_N, double area_m2) {
    const double grains = bed.layer(area_m2);
    return grains * hertzStiffness(target_force_N / grains, bed.plate_modulus_Pa, bed.radius_m);
}

/// Largest time step at which the bed under the plate keeps its packing: its lowest grains carry
/// the plate and the bed's weight, their contacts stiffen with the load.
double loadedTimeStep(const BedScales &bed, double target_force_N, double area_m2) {
    const double force = (target_force_N + bed.weight_N) / bed.layer(area_m2);
    const double k = hertzStiffness(force, bed.grain_modulus_Pa, 0.5 * bed.radius_m);
    return kLoadedStepFactor * std::sqrt(bed.mass_kg / k);
}

} // namespace

std::size_t strikeOff(DemSystem &system, double height_m) {
    const ParticleStore &p = system.particles();
    std::vector<std::size_t> kept;
    for (std::size_t i = 0; i < p.size(); ++i)
        if (p.position[i].z() <= height_m)
            kept.push_back(i);
    if (kept.empty()) {
        std::ostringstream msg;
        msg << "strike_off_height_m = " << height_m
            << " m lies below every grain's centre: nothing of the bed would be left";
        throw std::invalid_argument(msg.str());
    }
    const std::size_t removed = p.size() - kept.size();
    if (removed > 0)
        keepParticles(system, kept);
    return removed;
}

std::size_t bury(DemSystem &system, int body) {
    const ParticleStore &p = system.particles();
    const MeshBody &b = system.body(body);
    const std::vector<std::size_t> gone =
        grainsInMesh(p.position, p.radius, b.worldVertices(), b.mesh());
    if (gone.empty())
        return 0;
    std::vector<std::size_t> kept;
    kept.reserve(p.size() - gone.size());
    for (std::size_t i = 0, g = 0; i < p.size(); ++i)
        if (g < gone.size() && gone[g] == i)
            ++g;
        else
            kept.push_back(i);
    keepParticles(system, kept);
    return gone.size();
}

CompactionReport compact(DemSystem &system, const CompactionSpec &spec, const Vec3 &lower_m,
                         const Vec3 &upper_m) {
    spec.validate();
    if (system.bodyCount() != 0)
        throw std::invalid_argument("compaction: the bed must have no mesh bodies yet");
    if (system.particles().empty())
        throw std::invalid_argument("compaction: there is no bed to compact");
    const Vec3 size = upper_m - lower_m;
    const double area = size.x() * size.y();
    if (!(size.x() > 0.0 && size.y() > 0.0))
        throw std::invalid_argument("compaction: the footprint must have a positive area");
    CompactionReport report;
    report.target_force_N = spec.pressure_Pa * area;

    const BedScales bed(system);
    // Under the plate the contacts stiffen: the press runs at the step at which the loaded bed
    // keeps its packing where the scenario's is longer (docs/physics.md §6.1); the bed's own
    // system keeps its step.
    DemSettings press_settings = system.settings();
    report.time_step_s = std::min(press_settings.time_step_s,
                                  loadedTimeStep(bed, report.target_force_N, area));
    press_settings.time_step_s = report.time_step_s;
    const double dt = report.time_step_s;

    // The plate, a rectangle over the footprint, starts a smallest radius above the highest grain,
    // in a copy of the system that has it as its one mesh body.
    const ParticleStore &p = system.particles();
    const double top = highestTop(p), gap = p.minRadius(), floor = lowestBottom(p);
    // Its contacts are of the mesh type (the system's grain-tool law), the floor's and side
    // walls' of the wall type, as in the bed's own system.
    DemSystem press(system.laws(), system.materials(), press_settings);
    for (const PlaneWall &w : system.planes())
        press.addPlane(w);
    RigidBodyState start;
    start.position_m =
        Vec3(0.5 * (lower_m.x() + upper_m.x()), 0.5 * (lower_m.y() + upper_m.y()), top + gap);
    press.addBody(MeshBody("compaction_plate", makeRectangle(size.x(), size.y(), 1, 1), start));
    moveGrains(system, press);

    const auto steps = std::max<std::int64_t>(1, std::llround(kControlInterval_s / dt));
    const double interval_s = double(steps) * dt;
    LoadServo servo;
    servo.target_force_N = report.target_force_N;
    servo.max_speed_m_s = spec.speed_m_s;
    servo.gain_m_s_per_N = 1.0 / (plateStiffness(bed, report.target_force_N, area) * interval_s);
    servo.integral_gain_m_s2_per_N = servo.gain_m_s_per_N / (kIntegralIntervals * interval_s);
    servo.validate();
    MeshBody &body = press.body(0);
    // The plate's height, a straight line through each control interval: its motion is a
    // constant velocity from where it is, set once per interval (dem::BodyMotion).
    RigidBodyState plate = start;
    double plate_since_s = press.time();
    const auto plateZ = [&](double t_s) {
        return plate.position_m.z() + plate.linear_velocity_m_s.z() * (t_s - plate_since_s);
    };
    // One control interval at vertical speed vz; returns the plate's mean reaction along +z.
    const auto run = [&](double vz_m_s) {
        plate.position_m.z() = plateZ(press.time());
        plate.linear_velocity_m_s.z() = vz_m_s;
        plate_since_s = press.time();
        press.setBodyMotion(0, constantVelocity(plate, plate_since_s));
        body.resetAccumulatedImpulse();
        press.run(std::uint64_t(steps));
        return body.impulse_N_s.z() / body.accumulated_time_s;
    };

    // Down at the set speed until the plate carries the target, as a press loads at a constant
    // rate; then held there by the servo, the second half of the hold averaged.
    const double t0 = press.time();
    double force = 0.0;
    while (force < report.target_force_N) {
        if (plateZ(press.time()) < floor) {
            std::ostringstream msg;
            msg << "compaction: the plate reached the floor without carrying "
                << report.target_force_N << " N (" << spec.pressure_Pa << " Pa)";
            throw std::runtime_error(msg.str());
        }
        force = run(-spec.speed_m_s);
    }
    const auto hold = std::max<std::int64_t>(1, std::llround(spec.hold_time_s / interval_s));
    double held_sum = 0.0;
    for (std::int64_t k = 0; k < hold; ++k) {
        force = run(-servo.update(force, interval_s));
        if (2 * k >= hold)
            held_sum += force;
    }
    report.hold_force_N = held_sum / double(hold - hold / 2);

    // Up at full speed until the plate carries nothing and is clear of every grain.
    const double lift_limit_s = press.time() + 2.0 * (top + gap - floor) / spec.speed_m_s;
    while (!(force == 0.0 && plateZ(press.time()) > highestTop(press.particles()))) {
        if (press.time() > lift_limit_s)
            throw std::runtime_error("compaction: the bed still touches the lifted plate");
        force = run(spec.speed_m_s);
    }
    report.time_s = press.time() - t0;
    moveGrains(press, system);
    return report;
}

std::size_t applyCrust(DemSystem &system, const CrustSpec &crust) {
    crust.validate();
    ParticleStore &p = system.particles();
    const std::vector<Material> &materials = system.materials();
    if (crust.material < 0 || std::size_t(crust.material) >= materials.size())
        throw std::invalid_argument(
            "crust: the system has no material " + std::to_string(crust.material) +
            " (its table must hold the crust, crustMaterial(), as makeSystem builds it)");
    const Material &stiff = materials[std::size_t(crust.material)];
    const double surface = bedSurface(p);
    std::vector<std::size_t> grains;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.position[i].z() + p.radius[i] <= surface - crust.thickness_m)
            continue;
        const Material own = crustMaterial(materials[std::size_t(p.material[i])], crust);
        if (own.youngs_modulus_Pa != stiff.youngs_modulus_Pa ||
            own.poisson_ratio != stiff.poisson_ratio || own.density_kg_m3 != stiff.density_kg_m3)
            throw std::invalid_argument("crust: material " + std::to_string(crust.material) +
                                        " is not the crust of material " +
                                        std::to_string(p.material[i]) +
                                        " (E x youngs_modulus_factor, same nu and density)");
        grains.push_back(i);
    }
    const std::vector<int> before = p.material;
    for (std::size_t i : grains)
        p.material[i] = crust.material;
    const DemSettings &settings = system.settings();
    const double stable_s = system.stableTimeStepEstimate();
    if (settings.check_time_step && settings.time_step_s > stable_s) {
        p.material = before;
        std::ostringstream msg;
        msg << "crust: time_step_s = " << settings.time_step_s
            << " s is above the stability estimate " << stable_s << " s of the stiffer crust (E x "
            << crust.youngs_modulus_factor << ", docs/physics.md §3.3); reduce it";
        throw std::invalid_argument(msg.str());
    }
    return grains.size();
}

} // namespace grainlink::dem
