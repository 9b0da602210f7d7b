// The soil participant: the DEM bed (settled once, cached) with the coupled bodies' meshes moved
// along each window's motion, returning the window-averaged wrench (impulse / window).
#include "Nodes.hpp"
#include "Series.hpp"
#include "SoilSide.hpp"
#include "grainlink/coupling/Participant.hpp"
#include "grainlink/dem/Checkpoint.hpp"
#include "grainlink/dem/Progress.hpp"
#include "grainlink/dem/ScenarioRun.hpp"
#include "grainlink/dem/VtkWriter.hpp"
#include "grainlink/dem/WheelMesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

namespace grainlink::apps {

int runSoilNode(const NodeOptions &options) {
    const auto root = config::ConfigNode::loadFile(options.scenario_path);
    const dem::DemScenario scenario = dem::parseScenario(root[options.section], true);
    // Its files: soil.csv and snapshots/ for the usual single bed, named after the section when
    // several soil nodes share a run.
    const bool single = options.section == "soil";
    const std::string series_name = options.section + ".csv";
    const std::string snapshot_directory =
        options.output_directory + (single ? "/snapshots" : "/snapshots_" + options.section);
    auto sys = dem::prepareSoil(scenario, options.progress_interval_s);
    const double surface = dem::bedSurface(sys->particles());
    const double dt = scenario.settings.time_step_s;
    std::fprintf(stderr, "[%s] %zu particles, bed surface at z = %.4f m\n", options.name.c_str(),
                 sys->particles().size(), surface);

    auto config = soilParticipantConfig(options, root);
    config.capabilities.checkpoint = true;
    coupling::Participant participant(config);
    const auto &run = participant.initialize();
    const auto mirror = MirrorSymmetry::parse(root);

    // Every consumed body becomes a mesh body; its motion is set each window.
    const std::size_t body_count = options.bodies.size();
    for (std::size_t b = 0; b < options.bodies.size(); ++b) {
        const auto description = std::find_if(
            run.bodies.begin(), run.bodies.end(),
            [&](const coupling::BodyDescription &d) { return d.name == options.bodies[b]; });
        dem::MeshBody body(options.bodies[b], meshOf(*description, mirror.has_value()),
                           dem::RigidBodyState{});
        sys->addBody(std::move(body));
    }
    double dem_offset_s = sys->time() - run.start_tick * run.tick_s; // DEM time - coupling time
    // Particle and wheel snapshots for ParaView (soil.output.snapshot_interval_s), at the first
    // window end past each multiple of the interval; their times are kept in the checkpoint.
    const double snapshot_interval_s = scenario.output.snapshot_interval_s;
    dem::VtkWriter vtk(snapshot_directory);
    if (run.restore) {
        const auto extras =
            dem::readCheckpoint(*sys, run.restore->checkpoint_directory + "/soil.bin");
        dem_offset_s = extras.at("dem_offset_s");
        std::vector<double> times;
        for (int k = 0; k < int(extras.at("snapshots")); ++k)
            times.push_back(extras.at("snapshot" + std::to_string(k) + "_s"));
        vtk.resumeAt(int(times.size()), times);
    }

    std::filesystem::create_directories(options.output_directory);
    std::ofstream series =
        openSeries(options.output_directory + "/" + series_name,
                   "time_s,body,sinkage_m,Fx_N,Fy_N,Fz_N,Tx_N_m,Ty_N_m,Tz_N_m,contacts",
                   run.restore ? std::optional<double>(double(run.restore->tick) * run.tick_s)
                               : std::nullopt);
    dem::Progress progress(options.name, options.progress_interval_s);
    const std::uint64_t first_step = sys->stepCount();
    const double end_s = run.end_tick * run.tick_s;

    for (;;) {
        switch (participant.waitForCommand()) {
        case coupling::Command::WriteCheckpoint:
        {
            dem::CheckpointExtras extras{{"dem_offset_s", dem_offset_s},
                                         {"snapshots", double(vtk.count())}};
            for (int k = 0; k < vtk.count(); ++k)
                extras["snapshot" + std::to_string(k) + "_s"] = vtk.times()[std::size_t(k)];
            dem::writeCheckpoint(*sys, participant.checkpointDirectory() + "/soil.bin", extras);
            series.flush();
            participant.checkpointWritten();
            break;
        }
        case coupling::Command::Advance: {
            const auto &in = participant.inputs();
            const double steps_real = in.duration_s / dt;
            const auto steps = static_cast<std::uint64_t>(std::llround(steps_real));
            if (steps == 0 || std::abs(steps_real - double(steps)) > 1e-6)
                throw coupling::CouplingError("participant '" + options.name +
                                              "': the macro step " + std::to_string(in.duration_s) +
                                              " s is not a whole number of DEM time steps (" +
                                              std::to_string(dt) + " s)");
            for (std::size_t b = 0; b < body_count; ++b) {
                sys->setBodyMotion(int(b), windowMotion(in, b, dem_offset_s));
                sys->body(int(b)).resetAccumulatedImpulse();
                if (in.window == 0 && !run.restore) { // a body must not start buried in the bed
                    double lowest = 1e300;
                    for (const auto &v : sys->body(int(b)).worldVertices())
                        lowest = std::min(lowest, v.z());
                    if (lowest < surface)
                        throw coupling::CouplingError(
                            "participant '" + options.name + "': body '" + options.bodies[b] +
                            "' starts " + std::to_string(1000.0 * (surface - lowest)) +
                            " mm inside the settled bed (surface at z = " +
                            std::to_string(surface) + " m): start it higher");
                }
            }
            std::vector<double> work(body_count, 0.0);
            for (std::uint64_t k = 0; k < steps; ++k) {
                sys->step();
                for (std::size_t b = 0; b < body_count; ++b) {
                    const auto &body = sys->body(int(b));
                    work[b] += (body.force_N.dot(body.state().linear_velocity_m_s) +
                                body.torque_N_m.dot(body.state().angular_velocity_rad_s)) *
                               dt;
                }
            }
            // The soil's load on the body: the impulse over the window divided by the window.
            coupling::WindowOutputs out;
            for (std::size_t b = 0; b < body_count; ++b) {
                const auto &body = sys->body(int(b));
                coupling::Wrench w;
                w.body = options.bodies[b];
                w.force_N = body.impulse_N_s / in.duration_s;
                w.torque_N_m = body.angular_impulse_N_m_s / in.duration_s;
                if (mirror) {
                    mirror->check(in.end_states.at(b));
                    MirrorSymmetry::complete(w.force_N, w.torque_N_m);
                    work[b] *= 2.0;
                }
                out.wrenches.push_back(w);
                out.work.push_back({w.body, work[b]});
                double lowest = 1e300;
                for (const auto &v : body.worldVertices())
                    lowest = std::min(lowest, v.z());
                series << in.end_s << ',' << w.body << ',' << surface - lowest << ','
                       << w.force_N.x() << ',' << w.force_N.y() << ',' << w.force_N.z() << ','
                       << w.torque_N_m.x() << ',' << w.torque_N_m.y() << ',' << w.torque_N_m.z()
                       << ',' << sys->wallContactCount() << '\n';
            }
            if (snapshot_interval_s > 0.0 &&
                in.end_s >= snapshot_interval_s * double(vtk.count()) - 1e-12) {
                std::filesystem::create_directories(snapshot_directory);
                vtk.write(*sys, in.end_s);
            }
            participant.writeOutputs(std::move(out));
            participant.advance();
            progress.update(in.end_s, in.end_s / end_s,
                            (sys->stepCount() - first_step) * sys->particles().size(), "");
            break;
        }
        case coupling::Command::Finish:
            participant.finalize();
            series.flush();
            return 0;
        }
    }
}

} // namespace grainlink::apps
