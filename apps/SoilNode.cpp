// The soil participant: the DEM bed (settled once, cached) with the coupled bodies' meshes moved
// along each window's motion, returning the window-averaged wrench (impulse / window).
#include "Nodes.hpp"
#include "SoilSide.hpp"
#include "grainlink/coupling/ParticipantNode.hpp"
#include "grainlink/coupling/WindowLoads.hpp"
#include "grainlink/dem/BedPreparation.hpp"
#include "grainlink/dem/Checkpoint.hpp"
#include "grainlink/dem/ScenarioRun.hpp"
#include "grainlink/dem/Series.hpp"
#include "grainlink/dem/VtkWriter.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

namespace grainlink::apps {

namespace {

class SoilNode final : public coupling::ParticipantNode {
public:
    SoilNode(const NodeOptions &options, const config::ConfigNode &root)
        : options_(options), scenario_(parseSoilSection(root, options.section)),
          mirror_(MirrorSymmetry::parse(root)),
          // Its files: soil.csv and snapshots/ for the usual single bed, named after the
          // section when several soil nodes share a run.
          snapshot_directory_(options.output_directory + (options.section == "soil"
                                                              ? "/snapshots"
                                                              : "/snapshots_" + options.section)),
          vtk_(snapshot_directory_, scenario_.output.contact_network), progress_(options) {
        sys_ = dem::prepareSoil(scenario_, options.progress_interval_s);
        surface_ = dem::bedSurface(sys_->particles());
        std::fprintf(stderr, "[%s] %zu particles, bed surface at z = %.4f m\n",
                     options.name.c_str(), sys_->particles().size(), surface_);
    }

    void start(const coupling::RunInfo &run) override {
        // Every consumed body becomes a mesh body; its motion is set each window.
        for (std::size_t b = 0; b < options_.bodies.size(); ++b) {
            dem::MeshBody body(options_.bodies[b],
                               meshOf(describedBody(run, options_.bodies[b]), mirror_.has_value()),
                               dem::RigidBodyState{});
            const auto &d = scenario_.deposition;
            const std::string implausible = dem::implausibleMeshSize(
                body.mesh(), 2.0 * d.radius.largest(), (d.region_upper_m - d.region_lower_m).maxCoeff());
            if (!implausible.empty())
                throw coupling::CouplingError("body '" + options_.bodies[b] +
                                              "' as the multibody side describes it: " +
                                              implausible);
            sys_->addBody(std::move(body));
        }
        dem_offset_s_ = sys_->time() - run.start_tick * run.tick_s; // DEM time - coupling time
        resumed_ = run.restore.has_value();
        progress_.start(run);
        std::filesystem::create_directories(options_.output_directory);
        series_.emplace(
            options_.output_directory + "/" + options_.section + ".csv",
            "time_s,body,sinkage_m,Fx_N,Fy_N,Fz_N,Tx_N_m,Ty_N_m,Tz_N_m,contacts,end_wall_ahead_N,"
            "end_wall_behind_N",
            run.restore ? std::optional(dem::SeriesRestart{double(run.restore->tick) * run.tick_s})
                        : std::nullopt);
        first_step_ = sys_->stepCount();
        implicit_ = run.scheme == coupling::SchemeKind::Implicit;
        end_walls_ = dem::endWallsAlongX(sys_->planes());
    }

    // Implicit coupling repeats a window until the wrenches converge: the DEM goes back to the
    // window's start bit for bit (DemSystem::State), and so do the node's own records: a
    // window's rows are written when the next window begins, a rejected try's dropped.
    void saveState() override {
        series_->write(); // the previous window was accepted
        saved_.emplace(Saved{sys_->saveState(), vtk_.count(), vtk_.times(), closest_});
    }
    void restoreState() override {
        series_->discard();
        sys_->restoreState(saved_->dem);
        vtk_.resumeAt(saved_->snapshots, saved_->snapshot_times);
        closest_ = saved_->closest;
    }

    coupling::WindowOutputs advance(const coupling::WindowInputs &in) override {
        const double dt = scenario_.settings.time_step_s;
        const double steps_real = in.duration_s / dt;
        const auto steps = static_cast<std::uint64_t>(std::llround(steps_real));
        if (steps == 0 || std::abs(steps_real - double(steps)) > 1e-6)
            throw coupling::CouplingError("the macro step " + std::to_string(in.duration_s) +
                                          " s is not a whole number of DEM time steps (" +
                                          std::to_string(dt) + " s)");
        // The window's motion (dem::WindowMotion), handed to the DEM once: it takes the start
        // state now and follows the motion at every step's end.
        for (std::size_t b = 0; b < bodyCount(); ++b) {
            sys_->setBodyMotion(int(b), windowMotion(in, b, dem_offset_s_));
            if (in.window == 0 && !resumed_)
                std::fprintf(stderr, "[%s] %s; lowest point %.2f mm above the bed surface\n",
                             options_.name.c_str(),
                             dem::describeMesh(options_.bodies[b], sys_->body(int(b)).mesh(),
                                               in.start_states.at(b).position_m,
                                               2.0 * scenario_.deposition.radius.largest())
                                 .c_str(),
                             1000.0 * (lowestPoint(b) - surface_));
            if (in.window == 0 && !resumed_ && scenario_.bury_bodies) {
                // Placed in the ground before the test: the grains where it stands go.
                const std::size_t gone = dem::bury(*sys_, int(b));
                std::fprintf(stderr, "[%s] body '%s' buried: %zu grains in its place removed\n",
                             options_.name.c_str(), options_.bodies[b].c_str(), gone);
            } else if (in.window == 0 && !resumed_ && lowestPoint(b) < surface_)
                throw coupling::CouplingError(
                    "body '" + options_.bodies[b] + "' starts " +
                    std::to_string(1000.0 * (surface_ - lowestPoint(b))) +
                    " mm inside the settled bed (surface at z = " + std::to_string(surface_) +
                    " m): start it higher, or bury it (soil.bury_bodies: true)");
            if (in.window == 0 && !resumed_)
                refuseStartingOverlap(b);
        }
        coupling::WindowLoads loads(options_.bodies);
        // The soil's push on the bin's end walls along x over the window (a travel's ahead and
        // behind): `grainlink run` judges the rig's steady state by it (dem::endWallShare).
        double ahead_N = 0.0, behind_N = 0.0;
        for (std::uint64_t k = 0; k < steps; ++k) {
            sys_->step();
            for (std::size_t b = 0; b < bodyCount(); ++b) {
                const auto &body = sys_->body(int(b));
                loads.add(b, body.force_N, body.torque_N_m, body.state().linear_velocity_m_s,
                          body.state().angular_velocity_rad_s, dt);
            }
            for (int p : end_walls_.ahead)
                ahead_N += sys_->planeForce(p).x();
            for (int p : end_walls_.behind)
                behind_N -= sys_->planeForce(p).x();
        }
        ahead_N /= double(steps);
        behind_N /= double(steps);
        watchClearance(in.end_s);
        coupling::WindowOutputs out = loads.outputs(in.duration_s);
        for (std::size_t b = 0; b < bodyCount(); ++b) {
            auto &w = out.wrenches[b];
            if (mirror_) {
                mirror_->check(in.end_states.at(b));
                MirrorSymmetry::complete(w.force_N, w.torque_N_m);
                out.work[b].work_J *= 2.0;
            }
            series_->rows() << in.end_s << ',' << w.body << ',' << surface_ - lowestPoint(b) << ','
                            << w.force_N.x() << ',' << w.force_N.y() << ',' << w.force_N.z() << ','
                            << w.torque_N_m.x() << ',' << w.torque_N_m.y() << ','
                            << w.torque_N_m.z() << ',' << sys_->wallContactCount() << ',' << ahead_N
                            << ',' << behind_N << '\n';
        }
        if (!implicit_)
            series_->write();
        // Particle and wheel snapshots for ParaView (soil.output.snapshot_interval_s), at the
        // first window end past each multiple of the interval.
        const double interval_s = scenario_.output.snapshot_interval_s;
        if (interval_s > 0.0 && in.end_s >= interval_s * double(vtk_.count()) - 1e-12) {
            std::filesystem::create_directories(snapshot_directory_);
            vtk_.write(*sys_, in.end_s);
        }
        progress_.update(in.end_s, (sys_->stepCount() - first_step_) * sys_->particles().size(),
                         "");
        return out;
    }

    void finish() override {
        series_->write();
        if (closest_.body.empty())
            return;
        std::fprintf(stderr,
                     "[%s] closest approach to a wall: body '%s' %.2f mm from wall '%s' at t = "
                     "%.3f s (soil.wall_clearance_m = %.2f mm)\n",
                     options_.name.c_str(), closest_.body.c_str(), 1000.0 * closest_.distance_m,
                     closest_.wall.c_str(), closest_.time_s, 1000.0 * scenario_.wall_clearance_m);
    }

    // The snapshots' times travel in the checkpoint, so a resumed run keeps them in its .pvd.
    void writeCheckpoint(const std::string &directory) override {
        series_->write();
        dem::CheckpointExtras extras = dem::scenarioFingerprint(scenario_);
        extras["dem_offset_s"] = dem_offset_s_;
        extras["snapshots"] = double(vtk_.count());
        for (int k = 0; k < vtk_.count(); ++k)
            extras["snapshot" + std::to_string(k) + "_s"] = vtk_.times()[std::size_t(k)];
        dem::writeCheckpoint(*sys_, directory + "/soil.bin", extras);
    }

    void readCheckpoint(const std::string &directory) override {
        dem::checkFingerprint(dem::readCheckpointExtras(directory + "/soil.bin"), scenario_,
                              directory + "/soil.bin");
        const auto extras = dem::readCheckpoint(*sys_, directory + "/soil.bin");
        dem_offset_s_ = extras.at("dem_offset_s");
        std::vector<double> times;
        for (int k = 0; k < int(extras.at("snapshots")); ++k)
            times.push_back(extras.at("snapshot" + std::to_string(k) + "_s"));
        vtk_.resumeAt(int(times.size()), times);
        first_step_ = sys_->stepCount();
    }

private:
    std::size_t bodyCount() const { return options_.bodies.size(); }

    /// The closest any body came to a wall (the mirror's symmetry wall, which a half wheel
    /// touches by design, left out); closer than soil.wall_clearance_m stops the run: its
    /// grains would be crushed against the wall or the answers would depend on it. Only a
    /// body's part at or below the highest grain counts: above every grain it presses none
    /// against a wall (the mole's hull standing out of its column, tilted towards a wall).
    void watchClearance(double t) {
        const dem::ParticleStore &p = sys_->particles();
        double top = -1e300;
        for (std::size_t i = 0; i < p.size(); ++i)
            top = std::max(top, p.position[i].z() + p.radius[i]);
        for (std::size_t b = 0; b < bodyCount(); ++b)
            for (const auto &wall : sys_->planes()) {
                if (mirror_ && std::abs(std::abs(wall.normal.y()) - 1.0) < 1e-12 &&
                    std::abs(wall.point_m.y() - mirror_->plane_y_m) < 1e-12)
                    continue;
                double distance = 1e300;
                for (const auto &v : sys_->body(int(b)).worldVertices())
                    if (v.z() <= top)
                        distance = std::min(distance, wall.normal.dot(v - wall.point_m));
                if (distance < closest_.distance_m)
                    closest_ = {distance, options_.bodies[b], wall.name, t};
            }
        const double limit = scenario_.wall_clearance_m;
        if (limit > 0.0 && closest_.distance_m < limit) {
            char text[400];
            std::snprintf(text, sizeof text,
                          "body '%s' came within %.3g mm of wall '%s' (soil.wall_clearance_m = "
                          "%.3g mm): the bin is too small for this run (too shallow, short or "
                          "narrow) and its answers would depend on the wall; enlarge the bin or "
                          "end the run earlier",
                          closest_.body.c_str(), 1000.0 * closest_.distance_m,
                          closest_.wall.c_str(), 1000.0 * limit);
            throw coupling::CouplingError(text);
        }
    }
    /// Said before the first step rather than as an overlap failure in it (dem::BedPreparation).
    void refuseStartingOverlap(std::size_t b) const {
        const std::string error =
            dem::startingOverlapError(*sys_, int(b), scenario_.settings.max_overlap_ratio);
        if (!error.empty())
            throw coupling::CouplingError(error);
    }

    double lowestPoint(std::size_t b) const {
        double lowest = 1e300;
        for (const auto &v : sys_->body(int(b)).worldVertices())
            lowest = std::min(lowest, v.z());
        return lowest;
    }

    NodeOptions options_;
    dem::DemScenario scenario_;
    std::optional<MirrorSymmetry> mirror_;
    std::string snapshot_directory_;
    std::unique_ptr<dem::DemSystem> sys_;
    double surface_ = 0.0;      ///< [m] the settled bed's top
    struct Closest {
        double distance_m = 1e300;
        std::string body, wall;
        double time_s = 0.0;
    } closest_; ///< the closest approach of any body to a wall so far
    double dem_offset_s_ = 0.0; ///< [s] DEM time - coupling time
    bool resumed_ = false;
    dem::VtkWriter vtk_;
    std::optional<dem::Series> series_;
    NodeProgress progress_;
    std::uint64_t first_step_ = 0;
    bool implicit_ = false; ///< implicit coupling: windows may be repeated
    dem::EndWalls end_walls_; ///< the planes facing -x and +x (dem::endWallsAlongX)
    struct Saved {
        dem::DemSystem::State dem;
        int snapshots;
        std::vector<double> snapshot_times;
        Closest closest;
    };
    std::optional<Saved> saved_; ///< the current window's start (implicit coupling)
};

} // namespace

int runSoilNode(const NodeOptions &options) {
    const auto root = config::ConfigNode::loadFile(options.scenario_path);
    SoilNode node(options, root);
    auto config = soilParticipantConfig(options, root);
    config.capabilities.checkpoint = true;
    config.capabilities.rollback = true;
    coupling::Participant participant(config);
    coupling::runParticipant(participant, node);
    return 0;
}

} // namespace grainlink::apps
