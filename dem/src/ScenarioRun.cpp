#include "grainlink/dem/ScenarioRun.hpp"

#include "grainlink/dem/BedPreparation.hpp"
#include "grainlink/dem/Checkpoint.hpp"
#include "grainlink/dem/Progress.hpp"
#include "grainlink/dem/Series.hpp"
#include "grainlink/dem/VtkWriter.hpp"

#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

namespace grainlink::dem {

namespace fs = std::filesystem;

namespace {

/// An exclusive flock on a packing's lock file for the lifetime of the object; says so when
/// another process holds it (that process is settling the same packing).
class PackingLock {
public:
    explicit PackingLock(const std::string &path)
        : fd_(open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644)) {
        if (fd_ < 0)
            throw std::runtime_error("cannot open the packing cache's lock file '" + path + "'");
        if (flock(fd_, LOCK_EX | LOCK_NB) != 0) {
            std::fprintf(stderr,
                         "[deposition] another process is settling this packing: "
                         "waiting for it (%s)\n",
                         path.c_str());
            while (flock(fd_, LOCK_EX) != 0)
                if (errno != EINTR)
                    throw std::runtime_error("cannot lock '" + path + "'");
        }
    }
    ~PackingLock() { close(fd_); }
    PackingLock(const PackingLock &) = delete;
    PackingLock &operator=(const PackingLock &) = delete;

private:
    int fd_;
};

/// A number a scenario run keeps in its checkpoint; a checkpoint without it was written by
/// another program or another scenario (a bare std::map::at would say neither).
double extra(const CheckpointExtras &extras, const std::string &key, const std::string &path) {
    const auto found = extras.find(key);
    if (found == extras.end())
        throw std::runtime_error("cannot resume from '" + path + "': it has no '" + key +
                                 "' (not a checkpoint of this scenario's run)");
    return found->second;
}

} // namespace

CheckpointExtras scenarioFingerprint(const DemScenario &scenario) {
    const auto &d = scenario.deposition;
    CheckpointExtras f{{"simulation.time_step_s", scenario.settings.time_step_s},
                       {"deposition.count", double(d.count)},
                       {"deposition.seed", double(d.seed)},
                       {"deposition.radius (smallest)", d.radius.smallest()},
                       {"deposition.radius (largest)", d.radius.largest()},
                       {"material.youngs_modulus_Pa", scenario.material.youngs_modulus_Pa},
                       {"material.density_kg_m3", scenario.material.density_kg_m3},
                       {"bodies (count)", double(scenario.bodies.size())}};
    for (const BodySpec &b : scenario.bodies) {
        f["bodies." + b.name + " (triangles)"] = double(b.mesh.triangleCount());
        f["bodies." + b.name + " (size, m)"] = b.mesh.extent().norm();
    }
    CheckpointExtras named;
    for (const auto &[key, value] : f)
        named["fingerprint:" + key] = value;
    return named;
}

void checkFingerprint(const CheckpointExtras &saved, const DemScenario &scenario,
                      const std::string &path) {
    const auto now = scenarioFingerprint(scenario);
    bool any = false;
    for (const auto &[key, value] : saved)
        any = any || key.rfind("fingerprint:", 0) == 0;
    if (!any)
        return; // written before fingerprints existed
    std::string changed;
    const auto differ = [](double a, double b) {
        return std::abs(a - b) > 1e-12 * std::max(std::abs(a), std::abs(b));
    };
    const auto describe = [](double v) {
        char text[32];
        std::snprintf(text, sizeof text, "%.6g", v);
        return std::string(text);
    };
    for (const auto &[key, value] : now) {
        const auto found = saved.find(key);
        const std::string name = key.substr(std::string("fingerprint:").size());
        if (found == saved.end())
            changed += "; " + name + " is new";
        else if (differ(found->second, value))
            changed += "; " + name + " was " + describe(found->second) + ", is " + describe(value);
    }
    for (const auto &[key, value] : saved)
        if (key.rfind("fingerprint:", 0) == 0 && !now.count(key))
            changed += "; " + key.substr(std::string("fingerprint:").size()) + " is gone";
    if (!changed.empty())
        throw std::runtime_error("cannot resume from '" + path +
                                 "': the scenario changed since it was written (" +
                                 changed.substr(2) +
                                 "); start the run again, or restore the scenario");
}

std::unique_ptr<DemSystem> prepareSoil(const DemScenario &scenario, double progress_interval_s,
                                       bool *from_cache) {
    auto sys = makeSystem(scenario);
    // deposition.rolling: the packing (settled or cached) is that law's; the run goes on with
    // its own law, every rolling history starting afresh (docs/scenario.md). Likewise
    // deposition.gravity: settled under it, run under simulation.gravity (a slope).
    const auto &settling_rolling = scenario.deposition.rolling;
    if (settling_rolling)
        sys->setRolling(*settling_rolling);
    if (scenario.deposition.gravity_m_s2)
        sys->setGravity(*scenario.deposition.gravity_m_s2);
    const auto runLaw = [&] {
        if (settling_rolling)
            sys->setRolling(contactLaws(scenario));
        sys->setGravity(scenario.settings.gravity_m_s2);
        return std::move(sys);
    };
    const std::string key = packingKey(scenario);
    const fs::path cache =
        scenario.packing_cache_directory.empty()
            ? fs::path()
            : fs::path(scenario.packing_cache_directory) / ("packing-" + key + ".bin");
    const auto readCached = [&] {
        readCheckpoint(*sys, cache.string());
        if (from_cache)
            *from_cache = true;
        std::fprintf(stderr, "[deposition] reusing cached packing %s (%zu particles)\n",
                     cache.c_str(), sys->particles().size());
        return runLaw();
    };
    // A complete packing file is only ever renamed into place, so it can be read unlocked.
    // Check, settle and write happen under the packing's lock: two processes needing the same
    // packing at once settle it once, the second reads what the first wrote.
    std::optional<PackingLock> lock;
    if (!cache.empty()) {
        if (fs::exists(cache))
            return readCached();
        fs::create_directories(cache.parent_path());
        lock.emplace(cache.string() + ".lock");
        if (fs::exists(cache))
            return readCached();
    }
    Progress progress("deposition", progress_interval_s);
    const auto report = deposit(*sys, scenario.deposition, [&](const DepositionReport &r) {
        progress.update(
            sys->time(), std::min(1.0, r.settle_time_s / scenario.deposition.max_settle_time_s),
            sys->stepCount() * sys->particles().size(),
            "KE/particle " + std::to_string(r.final_kinetic_energy_per_particle_J) + " J");
    });
    std::fprintf(stderr,
                 "[deposition] %zu particles, settled %s after %.3f s (KE/particle %.3g J)\n",
                 report.inserted, report.settled ? "" : "NOT (time limit)", report.settle_time_s,
                 report.final_kinetic_energy_per_particle_J);
    if (const std::string prepared = report.preparationSummary(); !prepared.empty())
        std::fprintf(stderr, "[deposition] %s\n", prepared.c_str());
    if (!cache.empty()) {
        writeCheckpoint(*sys, cache.string()); // through a temporary file and a rename
        // Go on from the packing as stored, as every later run of it does: the settled system
        // in memory differs from a restored one in round-off (a study's points would depend on
        // which of them settled the packing).
        sys = makeSystem(scenario);
        if (settling_rolling)
            sys->setRolling(*settling_rolling);
        readCheckpoint(*sys, cache.string());
    }
    if (from_cache)
        *from_cache = false;
    return runLaw();
}

namespace {

std::string seriesHeader(const DemSystem &sys) {
    std::string h = "time_s,run_time_s,step,kinetic_J,rotational_J,gravitational_J,elastic_J,"
                    "contacts,wall_contacts,max_overlap_ratio";
    for (int b = 0; b < sys.bodyCount(); ++b) {
        const std::string &n = sys.body(b).name();
        for (const char *c : {"x_m", "y_m", "z_m", "vx_m_s", "vz_m_s", "wy_rad_s", "Fx_N", "Fy_N",
                              "Fz_N", "Tx_N_m", "Ty_N_m", "Tz_N_m"})
            h += "," + n + "." + c; // docs/scenario.md, "Output files"
    }
    return h;
}

/// A body's force and torque averaged over one series interval.
struct BodyLoad {
    Vec3 force_N = Vec3::Zero();
    Vec3 torque_N_m = Vec3::Zero();
};

/// One row; body forces are averaged over the interval since the last row (impulse / time),
/// and kept in `loads` for the summary.
std::string seriesRow(DemSystem &sys, double run_time_s, std::vector<BodyLoad> &loads) {
    sys.prepare(); // contacts are counted from the neighbour list
    const Energies e = sys.energies();
    std::ostringstream row;
    row.precision(10);
    row << sys.time() << ',' << run_time_s << ',' << sys.stepCount() << ',' << e.translational_J
        << ',' << e.rotational_J << ',' << e.gravitational_J << ',' << e.elastic_J << ','
        << sys.contactCount() << ',' << sys.wallContactCount() << ',' << sys.maxOverlapRatio();
    for (int b = 0; b < sys.bodyCount(); ++b) {
        MeshBody &body = sys.body(b);
        const RigidBodyState &s = body.state();
        const double span = body.accumulated_time_s > 0.0 ? body.accumulated_time_s : 1.0;
        const Vec3 f = body.impulse_N_s / span, t = body.angular_impulse_N_m_s / span;
        row << ',' << s.position_m.x() << ',' << s.position_m.y() << ',' << s.position_m.z() << ','
            << s.linear_velocity_m_s.x() << ',' << s.linear_velocity_m_s.z() << ','
            << s.angular_velocity_rad_s.y() << ',' << f.x() << ',' << f.y() << ',' << f.z() << ','
            << t.x() << ',' << t.y() << ',' << t.z();
        loads.resize(std::size_t(sys.bodyCount()));
        loads[std::size_t(b)] = {f, t};
        body.resetAccumulatedImpulse();
    }
    return row.str();
}

void addBody(DemSystem &sys, const BodySpec &spec, const RigidBodyState &start,
             double run_start_s) {
    MeshBody body(spec.name, spec.mesh, start);
    body.friction_coefficient = spec.friction_coefficient;
    body.record_triangle_loads = spec.record_triangle_loads;
    sys.addBody(std::move(body), SegmentedMotion{start, run_start_s, spec.motion});
}

/// Start poses: a clearance above the bed puts the lowest mesh point that far above the surface.
std::vector<RigidBodyState> startPoses(const DemSystem &sys, const DemScenario &scenario) {
    const double surface = bedSurface(sys.particles());
    std::vector<RigidBodyState> starts;
    for (const BodySpec &spec : scenario.bodies) {
        RigidBodyState start = spec.start;
        if (spec.clearance_above_bed_m) {
            double lowest = 1e300;
            for (const Vec3 &v : spec.mesh.vertices_m)
                lowest = std::min(lowest, (start.orientation * v).z());
            start.position_m.z() = surface + *spec.clearance_above_bed_m - lowest;
        }
        starts.push_back(start);
    }
    return starts;
}

nlohmann::json vector(const Vec3 &v) {
    return {v.x(), v.y(), v.z()};
}

/// The run's machine-readable summary (a study's observables, docs/scenario.md): written
/// last, so its presence means the run finished.
void writeSummaryJson(const DemSystem &sys, const DemScenario &scenario, const RunSummary &summary,
                      const std::vector<BodyLoad> &loads, double wall_s, const std::string &path) {
    nlohmann::json j = {{"scenario", scenario.name},
                        {"particles", summary.particles},
                        {"steps", summary.steps},
                        {"final_time_s", sys.time()},
                        {"run_time_s", summary.simulated_s},
                        {"wall_s", wall_s},
                        {"bodies", nlohmann::json::object()}};
    for (int b = 0; b < sys.bodyCount(); ++b) {
        const RigidBodyState &s = sys.body(b).state();
        const BodyLoad load = std::size_t(b) < loads.size() ? loads[std::size_t(b)] : BodyLoad{};
        j["bodies"][sys.body(b).name()] = {{"position_m", vector(s.position_m)},
                                           {"velocity_m_s", vector(s.linear_velocity_m_s)},
                                           {"force_N", vector(load.force_N)},
                                           {"torque_N_m", vector(load.torque_N_m)}};
    }
    std::ofstream file(path, std::ios::trunc);
    file << j.dump(2) << '\n';
    if (!file)
        throw std::runtime_error("cannot write '" + path + "'");
}

} // namespace

RunSummary runScenario(const DemScenario &scenario, const RunOptions &options) {
    const auto started = std::chrono::steady_clock::now();
    RunSummary summary;
    const fs::path out = options.output_directory;
    fs::create_directories(out);
    const std::string latest = (out / "checkpoint.bin").string();
    std::string checkpoint = latest; // the one a resume reads
    // The one before the latest, kept so that a damaged latest one costs an interval, not the run.
    const std::string previous = (out / "checkpoint.previous.bin").string();
    const std::string series_path = (out / "series.csv").string();
    auto sys = makeSystem(scenario);
    const double dt = scenario.settings.time_step_s;

    // --- phase 1: deposition, or the cached packing of an identical soil setup ---------------
    CheckpointExtras extras;
    double run_start_s = 0.0;
    std::vector<RigidBodyState> starts;
    if (options.resume) {
        if (!fs::exists(checkpoint) && !fs::exists(previous))
            throw std::runtime_error("cannot resume: no checkpoint at '" + checkpoint + "'");
        // Bodies must exist before their state is restored; their start is stored in extras.
        try {
            extras = readCheckpointExtras(checkpoint);
        } catch (const std::exception &e) {
            if (!fs::exists(previous))
                throw;
            std::fprintf(stderr, "[resume] %s; resuming from the previous checkpoint %s\n",
                         e.what(), previous.c_str());
            checkpoint = previous;
            extras = readCheckpointExtras(checkpoint);
        }
        checkFingerprint(extras, scenario, checkpoint);
        run_start_s = extra(extras, "run_start_s", checkpoint);
        for (std::size_t b = 0; b < scenario.bodies.size(); ++b) {
            RigidBodyState start = scenario.bodies[b].start;
            start.position_m.z() =
                extra(extras, "body" + std::to_string(b) + "_start_z_m", checkpoint);
            starts.push_back(start);
            addBody(*sys, scenario.bodies[b], start, run_start_s);
        }
        readCheckpoint(*sys, checkpoint);
        std::fprintf(stderr, "[resume] from %s at t = %.4f s (step %llu)\n", checkpoint.c_str(),
                     sys->time(), static_cast<unsigned long long>(sys->stepCount()));
    } else {
        sys = prepareSoil(scenario, options.progress_interval_s, &summary.packing_from_cache);
        run_start_s = sys->time();
        starts = startPoses(*sys, scenario);
        for (std::size_t b = 0; b < scenario.bodies.size(); ++b) {
            addBody(*sys, scenario.bodies[b], starts[b], run_start_s);
            std::fprintf(stderr, "[bodies] %s\n",
                         describeMesh(scenario.bodies[b].name, scenario.bodies[b].mesh,
                                      starts[b].position_m,
                                      2.0 * scenario.deposition.radius.largest())
                             .c_str());
            // The coupled soil node's refusal, before the first step (not on a resume: a body
            // in a checkpoint may overlap grains up to max_overlap_ratio by then).
            const std::string error = startingOverlapError(*sys, int(b), scenario.settings.max_overlap_ratio);
            if (!error.empty())
                throw std::runtime_error(scenario.file + ": " + error);
        }
        if (fs::exists(series_path))
            fs::remove(series_path);
    }

    // --- phase 2: the run -----------------------------------------------------------------
    const auto steps_per_row =
        std::max<std::uint64_t>(1, std::llround(scenario.output.series_interval_s / dt));
    const auto rows_per_checkpoint =
        scenario.output.checkpoint_interval_s > 0.0
            ? std::max<std::uint64_t>(1, std::llround(scenario.output.checkpoint_interval_s /
                                                      (double(steps_per_row) * dt)))
            : 0;
    const auto steps_per_snapshot =
        scenario.output.snapshot_interval_s > 0.0
            ? std::max<std::uint64_t>(1, std::llround(scenario.output.snapshot_interval_s / dt))
            : 0;
    const auto run_start_step = std::uint64_t(std::llround(run_start_s / dt));
    const auto run_steps = std::uint64_t(std::llround(scenario.duration_s / dt));
    const std::uint64_t first_step = sys->stepCount();

    VtkWriter vtk(out.string(), scenario.output.contact_network);
    // Resumed: the whole rows up to the checkpoint's step are kept, rows after it redone.
    Series series(series_path, seriesHeader(*sys),
                  options.resume ? std::optional(SeriesRestart{double(sys->stepCount()), 2})
                                 : std::nullopt);
    if (options.resume) {
        std::vector<double> times;
        for (int k = 0; k < int(extra(extras, "snapshots", checkpoint)); ++k)
            times.push_back(extra(extras, "snapshot" + std::to_string(k) + "_s", checkpoint));
        vtk.resumeAt(int(times.size()), times);
    }
    std::vector<BodyLoad> loads;
    // A full disk stops the run with the last complete checkpoint, never "finished" with a
    // series cut short.
    const auto writeRow = [&](const std::string &row) {
        series.rows() << row << '\n';
        try {
            series.write();
        } catch (const std::runtime_error &e) {
            throw std::runtime_error(e.what() + (fs::exists(latest)
                                                     ? "; resume from " + latest + " with --resume"
                                                     : std::string()));
        }
    };
    if (!options.resume)
        writeRow(seriesRow(*sys, 0.0, loads));
    if (!options.resume && steps_per_snapshot)
        vtk.write(*sys, 0.0);

    auto saveCheckpoint = [&] {
        CheckpointExtras e = scenarioFingerprint(scenario);
        e["run_start_s"] = run_start_s;
        for (std::size_t b = 0; b < starts.size(); ++b)
            e["body" + std::to_string(b) + "_start_z_m"] = starts[b].position_m.z();
        e["snapshots"] = vtk.count();
        for (int k = 0; k < vtk.count(); ++k)
            e["snapshot" + std::to_string(k) + "_s"] = vtk.times()[std::size_t(k)];
        // The latest becomes the previous by a second name, not a move: a run killed at any
        // instant leaves a checkpoint.bin (a study resumes only from that name), and
        // writeCheckpoint replaces it by a rename.
        if (fs::exists(latest)) {
            const std::string linking = previous + ".partial";
            fs::remove(linking);
            std::error_code no_links;
            fs::create_hard_link(latest, linking, no_links);
            if (no_links)
                fs::copy_file(latest, linking);
            fs::rename(linking, previous);
        }
        writeCheckpoint(*sys, latest, e);
    };

    Progress progress("run", options.progress_interval_s);
    std::uint64_t rows = 0;
    try {
        while (sys->stepCount() < run_start_step + run_steps) {
            sys->step();
            const std::uint64_t done = sys->stepCount() - run_start_step;
            if (done % steps_per_row == 0) {
                writeRow(seriesRow(*sys, double(done) * dt, loads));
                ++rows;
                if (rows_per_checkpoint && rows % rows_per_checkpoint == 0)
                    saveCheckpoint();
            }
            if (steps_per_snapshot && done % steps_per_snapshot == 0)
                vtk.write(*sys, double(done) * dt);
            progress.update(double(done) * dt, double(done) / double(run_steps),
                            (sys->stepCount() - first_step) * sys->particles().size());
        }
    } catch (const SimulationError &e) {
        // Keep what is readable: the series so far (every row is on disk), and the last
        // finite particle state.
        const std::string snapshot = (out / "failure_particles.vtu").string();
        VtkWriter::writeParticles(sys->particles(), snapshot);
        std::ostringstream msg;
        msg << e.what() << "; series so far in " << series_path << ", state at failure in "
            << snapshot;
        if (fs::exists(latest))
            msg << ", resume from " << latest << " with --resume";
        throw std::runtime_error(msg.str());
    }
    saveCheckpoint();

    summary.particles = sys->particles().size();
    // The whole run's steps, a resumed run's too; the speed and wall time are this process's.
    summary.steps = sys->stepCount() - run_start_step;
    summary.simulated_s = double(summary.steps) * dt;
    summary.wall_s = progress.wallSeconds();
    summary.particle_steps_per_s =
        progress.rate((sys->stepCount() - first_step) * summary.particles);
    std::ostringstream text;
    text << "grainlink dem: scenario '" << scenario.name << "' finished\n"
         << "  particles            " << summary.particles << "\n"
         << "  steps                " << summary.steps << " (dt = " << dt << " s)\n"
         << "  simulated time       " << summary.simulated_s << " s\n"
         << "  wall time            " << formatDuration(summary.wall_s) << "\n"
         << "  particle-steps/s     " << summary.particle_steps_per_s / 1e6 << " M on "
         << scenario.settings.threads << " thread(s)\n"
         << "  neighbour builds     " << sys->neighbourBuilds() << "\n"
         << "  outputs              " << series_path << ", " << vtk.count()
         << " snapshots (particles.pvd), " << latest << "\n\n"
         << sys->timer().table();
    std::fprintf(stderr, "%s", text.str().c_str());
    std::ofstream(out / "summary.txt") << text.str();
    writeSummaryJson(
        *sys, scenario, summary, loads,
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count(),
        (out / "summary.json").string());
    return summary;
}

} // namespace grainlink::dem
