// The multibody participant. The seed's single-wheel rig is driven through the seed's procedure
// (drop locked, drive, stop at steady slip) and writes rig.csv and the steady report; every
// other model (rover, mole, a user's URDF mechanism) runs to the end time and writes mbs.csv,
// its observables and the soil's wrench on each of its coupled bodies.
#include "MultibodySide.hpp"
#include "Nodes.hpp"
#include "SoilSide.hpp"
#include "grainlink/coupling/ParticipantNode.hpp"
#include "grainlink/dem/BedPreparation.hpp"
#include "grainlink/dem/RigidFloor.hpp"
#include "grainlink/dem/ScenarioRun.hpp"
#include "grainlink/dem/Series.hpp"
#include "grainlink/dem/SteadySignal.hpp"
#include "grainlink/mbs/Mole.hpp"
#include "grainlink/mbs/WheelTest.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <stdexcept>

namespace grainlink::apps {

namespace {

/// What a run writes and decides beyond the common window loop: its time series, whether the
/// experiment is complete after a window, and its closing report.
struct Report {
    std::string checkpoint_file; ///< the model's state inside a checkpoint directory
    std::string series_file;
    std::string header;
    /// Writes the window's row and says whether the experiment is complete.
    std::function<bool(std::ostream &, const std::vector<mbs::Wrench> &)> after_window;
    /// The closing report; returns the node's exit status (non-zero: the experiment failed).
    std::function<int()> finish;
    /// The procedure's own state in a checkpoint directory, beside the model's; none for a
    /// model run to its end time.
    std::function<void(const std::string &directory)> write_checkpoint = [](const auto &) {};
    std::function<void(const std::string &directory)> read_checkpoint = [](const auto &) {};
    /// The procedure's state at a window's start and back (implicit coupling); none for a
    /// model run to its end time.
    std::function<void()> save_state = [] {};
    std::function<void()> restore_state = [] {};
    /// What the progress line adds to the simulated time (the rig: its phase and slip).
    std::function<std::string()> progress_note = [] { return std::string(); };
};

/// The seed's single-wheel procedure (mbs/WheelTest): rig.csv, the steady-state report
/// (rig_summary.txt and .json), and the run ends at steady slip — or, with a phase past its
/// maximum, as a failure: the node then exits with status 3, and `grainlink run` with it.
Report wheelTestReport(const config::ConfigNode &root, mbs::SingleWheelRig &rig,
                       const NodeOptions &options) {
    const auto test_node = root.optional("wheel_test");
    auto test = std::make_shared<mbs::WheelTest>(test_node ? mbs::parseWheelTest(*test_node)
                                                           : mbs::WheelTestSettings{});
    const double x0 = rig.settings().start_position_m.x();
    Report r;
    r.checkpoint_file = "rig.txt";
    r.series_file = "rig.csv";
    // The rig's own quantities unprefixed, the soil's load on the wheel as <wheel>.<quantity>
    // (docs/scenario.md, "Output files").
    const std::string wheel = rig.settings().wheel_name + ".";
    r.header = "time_s,phase,x_m,z_m,vx_m_s,vz_m_s,omega_rad_s,slip,motor_torque_N_m," + wheel +
               "Fx_N," + wheel + "Fy_N," + wheel + "Fz_N," + wheel + "Ty_N_m,travel_m";
    r.after_window = [test, &rig, x0](std::ostream &series, const std::vector<mbs::Wrench> &soil) {
        const bool done = test->afterWindow(rig, soil[0]);
        const auto o = rig.observables();
        const auto &w = soil[0];
        series << rig.time() << ',' << test->phaseName() << ',' << o.at("carriage_x_m") << ','
               << o.at("carriage_z_m") << ',' << o.at("carriage_vx_m_s") << ','
               << o.at("carriage_vz_m_s") << ',' << o.at("wheel_omega_rad_s") << ',' << o.at("slip")
               << ',' << o.at("motor_torque_N_m") << ',' << w.force_N.x() << ',' << w.force_N.y()
               << ',' << w.force_N.z() << ',' << w.torque_N_m.y() << ','
               << o.at("carriage_x_m") - x0 << '\n';
        return done;
    };
    // The procedure's phase, drive start and samples: without them a run resumed while
    // driving would drop the wheel again and judge its steady state from the resume on.
    r.write_checkpoint = [test](const std::string &directory) {
        test->writeCheckpoint(directory + "/wheel_test.txt");
    };
    r.read_checkpoint = [test](const std::string &directory) {
        test->readCheckpoint(directory + "/wheel_test.txt");
    };
    r.progress_note = [test, &rig] {
        char note[64];
        std::snprintf(note, sizeof note, "phase %s  slip %.3f", test->phaseName().c_str(),
                      rig.observables().at("slip"));
        return std::string(note);
    };
    auto saved = std::make_shared<std::optional<mbs::WheelTest>>();
    r.save_state = [test, saved] { *saved = *test; };
    r.restore_state = [test, saved] { *test = **saved; };
    r.finish = [test, &rig, options] {
        const std::string summary = test->summary(rig.time());
        std::printf("%s\n", summary.c_str());
        std::ofstream(options.output_directory + "/rig_summary.txt") << summary << '\n';
        const auto &rig_settings = rig.settings();
        test->writeSummaryJson(options.output_directory + "/rig_summary.json", rig.time(),
                               rig_settings.normal_load_kg * rig_settings.gravity_m_s2.norm());
        if (test->succeeded())
            return 0;
        std::fprintf(stderr, "%s\n", summary.c_str());
        return 3;
    };
    return r;
}

/// mbs_summary.json of a model run to its end time: its observables at the end and, for the
/// mole, its strokes (mbs::moleStrokes, from the run's whole series: a resumed run's too) with
/// the advance per stroke from the second on — the first also holds the sinking into a loose
/// surface. Written aside and renamed, as the rig's summary: a study sees all of it or none.
void writeModelSummary(const mbs::MultibodyModel &model, const std::string &series_path,
                       const std::string &path) {
    using nlohmann::json;
    json j{{"time_s", model.time()}, {"observables", model.observables()}};
    auto c = dem::readSeries(series_path);
    // Every column's mean, fluctuation and batch-means standard error over the windows of the
    // run's second half (each window one sample; the run starts at t = 0). A body's column
    // `<body>.Fz_N` is nested, second_half.<body>.Fz_N, so a study's dotted path reaches it.
    const std::vector<double> &time = c["time_s"];
    const double from_s = 0.5 * (time.empty() ? 0.0 : time.back());
    const std::size_t first =
        std::size_t(std::lower_bound(time.begin(), time.end(), from_s) - time.begin());
    json half = json::object();
    for (const auto &[name, values] : c) {
        if (name == "time_s" || values.size() <= first)
            continue;
        const auto v = dem::summarizeSignal({values.begin() + long(first), values.end()});
        std::string pointer = "/" + name;
        std::replace(pointer.begin(), pointer.end(), '.', '/');
        half[json::json_pointer(pointer)] = {
            {"mean", v.mean}, {"sd", v.sd}, {"standard_error", v.standard_error}};
    }
    j["second_half"] = half;
    j["second_half_from_s"] = from_s;
    if (const auto *mole = dynamic_cast<const mbs::Mole *>(&model)) {
        const std::string force = mole->settings().hull_name + ".Fz_N";
        if (!c.count(force))
            throw std::runtime_error(series_path + " has no column '" + force + "'");
        const auto strokes =
            mbs::moleStrokes(c["time_s"], c["stroke_count"], c["penetration_m"], c[force]);
        // A run that ends within a stroke's impact window (phase 1, "released") cut that
        // stroke short: it is listed, marked incomplete, and left out of the statistics.
        const bool cut = !c["phase"].empty() &&
                         std::lround(c["phase"].back()) == int(mbs::Mole::Phase::Released);
        json list = json::array();
        std::vector<double> advance;
        for (const mbs::MoleStroke &s : strokes) {
            const bool complete = !(cut && &s == &strokes.back());
            list.push_back({{"stroke", s.stroke},
                            {"complete", complete},
                            {"end_time_s", s.end_time_s},
                            {"penetration_m", s.penetration_m},
                            {"advance_m", s.advance_m},
                            {"peak_hull_force_N", s.peak_hull_force_N},
                            {"mean_hull_force_N", s.mean_hull_force_N},
                            {"hull_impulse_N_s", s.hull_impulse_N_s}});
            if (s.stroke >= 2 && complete)
                advance.push_back(s.advance_m);
        }
        j["strokes"] = list;
        j["stroke_count"] = strokes.size();
        j["penetration_m"] = j["observables"]["penetration_m"]; // at the end
        j["first_stroke_penetration_m"] =
            strokes.empty() ? json(nullptr) : json(strokes.front().penetration_m);
        // Mean, sample sd and standard error over strokes 2..N, one batch a stroke (null with
        // fewer than two).
        const auto a = dem::summarizeSignal(advance, advance.size());
        const bool two = advance.size() >= 2;
        json per_stroke{{"count", advance.size()}, {"from_stroke", 2}};
        per_stroke["mean"] = advance.empty() ? json(nullptr) : json(a.mean);
        per_stroke["sd"] = two ? json(a.sd) : json(nullptr);
        per_stroke["standard_error"] = two ? json(a.standard_error) : json(nullptr);
        j["advance_per_stroke_m"] = per_stroke;
    }
    const std::string partial = path + ".partial";
    std::ofstream(partial) << j.dump(2) << '\n';
    std::filesystem::rename(partial, path);
}

/// Any other model: mbs.csv with every observable the model reports (sorted by name) and the
/// soil's wrench on each coupled body; the run goes to its end time.
Report observablesReport(const mbs::MultibodyModel &model, const NodeOptions &options) {
    auto names = std::make_shared<std::vector<std::string>>();
    for (const auto &[name, value] : model.observables())
        names->push_back(name);
    Report r;
    r.checkpoint_file = "model.txt";
    r.series_file = "mbs.csv";
    r.header = "time_s";
    for (const auto &name : *names)
        r.header += "," + name;
    for (const auto &body : model.coupledBodies())
        for (const char *c : {"Fx_N", "Fy_N", "Fz_N", "Tx_N_m", "Ty_N_m", "Tz_N_m"})
            r.header += "," + body.name + "." + c;
    r.after_window = [names, &model](std::ostream &series, const std::vector<mbs::Wrench> &soil) {
        const auto observed = model.observables();
        series << model.time();
        for (const auto &name : *names)
            series << ',' << observed.at(name);
        for (const auto &w : soil)
            series << ',' << w.force_N.x() << ',' << w.force_N.y() << ',' << w.force_N.z() << ','
                   << w.torque_N_m.x() << ',' << w.torque_N_m.y() << ',' << w.torque_N_m.z();
        series << '\n';
        return false;
    };
    r.finish = [&model, options, series_file = r.series_file] {
        std::printf("%s: t = %.6g s;", options.name.c_str(), model.time());
        for (const auto &[name, value] : model.observables())
            std::printf(" %s %.6g", name.c_str(), value);
        std::printf("\n");
        writeModelSummary(model, options.output_directory + "/" + series_file,
                          options.output_directory + "/mbs_summary.json");
        return 0;
    };
    return r;
}

/// Any model as the multibody participant: applies the soil's wrenches, advances, reports the
/// states, the work and the model's hint for the next macro step (the mole asks for small ones
/// around its impacts); rolls back for implicit coupling; checkpoints.
class MultibodyNode final : public coupling::ParticipantNode {
public:
    MultibodyNode(mbs::MultibodyModel &model, Report report, const NodeOptions &options)
        : model_(model), report_(std::move(report)), options_(options),
          bodies_(model.coupledBodies()), soil_(bodies_.size()), progress_(options) {}

    void start(const coupling::RunInfo &run) override {
        implicit_ = run.scheme == coupling::SchemeKind::Implicit;
        progress_.start(run);
        std::filesystem::create_directories(options_.output_directory);
        series_.emplace(
            options_.output_directory + "/" + report_.series_file, report_.header,
            run.restore ? std::optional(dem::SeriesRestart{double(run.restore->tick) * run.tick_s})
                        : std::nullopt);
    }

    coupling::WindowOutputs advance(const coupling::WindowInputs &in) override {
        for (std::size_t b = 0; b < bodies_.size(); ++b)
            soil_[b] = {in.wrenches.at(b).force_N, in.wrenches.at(b).torque_N_m};
        model_.applyWrenches(soil_);
        const auto work = model_.advanceTo(in.end_s);
        coupling::WindowOutputs out;
        out.run_complete = report_.after_window(series_->rows(), soil_);
        if (!implicit_) // implicit: written when the window is accepted (saveState)
            series_->write();
        const auto states = model_.bodyStates();
        for (std::size_t b = 0; b < bodies_.size(); ++b) {
            out.states.push_back(toCoupling(bodies_[b].name, states[b]));
            out.work.push_back({bodies_[b].name, work[b]});
        }
        out.suggested_macro_step_s = model_.suggestedMacroStep_s();
        if (progress_.due()) // the note reads the rig's observables: only when printed
            progress_.update(in.end_s, 0, report_.progress_note());
        return out;
    }

    // Implicit coupling repeats a window: the model and the procedure go back to its start,
    // its rows are written once the next window begins, a rejected try's dropped.
    void saveState() override {
        series_->write();
        model_.saveState();
        report_.save_state();
    }
    void restoreState() override {
        series_->discard();
        model_.restoreState();
        report_.restore_state();
    }

    void writeCheckpoint(const std::string &directory) override {
        series_->write();
        model_.writeCheckpoint(directory + "/" + report_.checkpoint_file);
        report_.write_checkpoint(directory);
    }
    void readCheckpoint(const std::string &directory) override {
        model_.readCheckpoint(directory + "/" + report_.checkpoint_file);
        report_.read_checkpoint(directory);
    }

    void finish() override {
        series_->write();
        exit_status_ = report_.finish();
    }
    int exitStatus() const { return exit_status_; }

private:
    mbs::MultibodyModel &model_;
    Report report_;
    NodeOptions options_;
    std::vector<mbs::BodyDescription> bodies_;
    std::vector<mbs::Wrench> soil_; ///< the soil's wrenches of the current window
    std::optional<dem::Series> series_;
    int exit_status_ = 0;
    bool implicit_ = false; ///< implicit coupling: windows may be repeated
    NodeProgress progress_;
};

int runWindows(const config::ConfigNode &root, mbs::MultibodyModel &model, Report report,
               const NodeOptions &options) {
    MultibodyNode node(model, std::move(report), options);
    coupling::Participant participant(multibodyParticipantConfig(options, root, model));
    coupling::runParticipant(participant, node);
    return node.exitStatus();
}

} // namespace

/// The rig's start height for `rig.clearance_above_bed_m`: the wheel's lowest point (of the mesh
/// the soil builds from it) that far above the settled bed surface, or above the rigid floor.
/// The bed is the soil section's cached packing (settled once, whichever node needs it first).
double startHeightAboveBed(const config::ConfigNode &root, const mbs::SingleWheelRigSettings &s) {
    double surface = 0.0;
    if (root.has("soil")) {
        const auto sys = dem::prepareSoil(parseSoilSection(root, "soil"), 0.0);
        surface = dem::bedSurface(sys->particles());
    } else if (root.has("floor")) {
        surface = dem::parseRigidFloor(root["floor"]).height_m;
    } else {
        root["rig"]["clearance_above_bed_m"].fail(
            "a clearance above the bed needs a bed: a `soil:` section (grainlink dem-node) or "
            "a `floor:` (grainlink floor-node)");
    }
    body::BodyDescription wheel;
    wheel.name = s.wheel_name;
    wheel.geometry = s.wheel;
    double lowest = 1e300;
    for (const auto &v : meshOf(wheel).vertices_m)
        lowest = std::min(lowest, v.z());
    const double z = surface + *s.clearance_above_bed_m - lowest;
    std::fprintf(stderr,
                 "rig: bed surface at z = %.4f m; wheel centre starts at z = %.4f m, its lowest "
                 "point %.4g mm above it (rig.clearance_above_bed_m)\n",
                 surface, z, 1000.0 * *s.clearance_above_bed_m);
    return z;
}

int runMultibodyNode(const NodeOptions &options) {
    const auto root = config::ConfigNode::loadFile(options.scenario_path);
    if (root.has("rig")) {
        auto settings = mbs::parseSingleWheelRig(root["rig"]);
        if (settings.clearance_above_bed_m)
            settings.start_position_m.z() = startHeightAboveBed(root, settings);
        mbs::SingleWheelRig rig(settings);
        return runWindows(root, rig, wheelTestReport(root, rig, options), options);
    }
    const auto model = makeModel(root, options.scenario_path);
    return runWindows(root, *model, observablesReport(*model, options), options);
}

} // namespace grainlink::apps
