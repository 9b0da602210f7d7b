// The multibody participant. The seed's single-wheel rig is driven through the seed's procedure
// (drop locked, drive, stop at steady slip) and writes rig.csv and the steady report; every
// other model (rover, mole, a user's URDF mechanism) runs to the end time and writes mbs.csv,
// its observables and the soil's wrench on each of its coupled bodies.
#include "MultibodySide.hpp"
#include "Nodes.hpp"
#include "grainlink/coupling/Participant.hpp"
#include "grainlink/mbs/WheelTest.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>

namespace grainlink::apps {

namespace {

coupling::ParticipantConfig participantConfig(const NodeOptions &options,
                                              const config::ConfigNode &root,
                                              const mbs::MultibodyModel &model) {
    coupling::ParticipantConfig config;
    config.handshake_timeout_s = handshakeTimeout(root);
    config.name = options.name;
    config.role = coupling::Role::Multibody;
    config.endpoint = options.endpoint;
    config.provides = model.coupledBodies(); // the model's own descriptions, unchanged
    const auto states = model.bodyStates();
    for (std::size_t b = 0; b < config.provides.size(); ++b)
        config.initial_states.push_back(toCoupling(config.provides[b].name, states[b]));
    config.capabilities.rollback = true;
    config.capabilities.checkpoint = true;
    if (!options.keys_directory.empty())
        config.curve = coupling::loadClientKeys(options.keys_directory, options.name);
    return config;
}

/// What a run writes and decides beyond the common window loop: its time series, whether the
/// experiment is complete after a window, and its closing report.
struct Report {
    std::string checkpoint_file; ///< the model's state inside a checkpoint directory
    std::string series_file;
    std::string header;
    /// Writes the window's row and says whether the experiment is complete.
    std::function<bool(std::ostream &, const std::vector<mbs::Wrench> &)> after_window;
    std::function<void()> finish;
};

/// The seed's single-wheel procedure (mbs/WheelTest): rig.csv, the steady-state report, and the
/// run ends at steady slip.
Report wheelTestReport(const config::ConfigNode &root, mbs::SingleWheelRig &rig,
                       const NodeOptions &options) {
    const auto test_node = root.optional("wheel_test");
    auto test = std::make_shared<mbs::WheelTest>(test_node ? mbs::parseWheelTest(*test_node)
                                                           : mbs::WheelTestSettings{});
    const double x0 = rig.settings().start_position_m.x();
    Report r;
    r.checkpoint_file = "rig.txt";
    r.series_file = "rig.csv";
    r.header = "time_s,phase,x_m,z_m,vx_m_s,vz_m_s,omega_rad_s,slip,motor_torque_N_m,soil_Fx_N,"
               "soil_Fy_N,soil_Fz_N,soil_Ty_N_m,travel_m";
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
    r.finish = [test, options] {
        const std::string summary = test->summary();
        std::printf("%s\n", summary.c_str());
        std::ofstream(options.output_directory + "/rig_summary.txt") << summary << '\n';
    };
    return r;
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
            r.header += "," + body.name + "_" + c;
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
    r.finish = [&model, options] {
        std::printf("%s: t = %.6g s;", options.name.c_str(), model.time());
        for (const auto &[name, value] : model.observables())
            std::printf(" %s %.6g", name.c_str(), value);
        std::printf("\n");
    };
    return r;
}

/// The window loop every model shares: apply the soil's wrenches, advance, report the states,
/// the work and the model's hint for the next macro step (the mole asks for small ones around
/// its impacts); roll back for implicit coupling; checkpoints.
int runWindows(const config::ConfigNode &root, mbs::MultibodyModel &model, const Report &report,
               const NodeOptions &options) {
    coupling::Participant participant(participantConfig(options, root, model));
    const auto &run = participant.initialize();
    if (run.restore)
        model.readCheckpoint(run.restore->checkpoint_directory + "/" + report.checkpoint_file);
    std::filesystem::create_directories(options.output_directory);
    std::ofstream series =
        openSeries(options.output_directory + "/" + report.series_file, report.header,
                   run.restore ? std::optional<double>(model.time()) : std::nullopt);

    const auto bodies = model.coupledBodies();
    std::vector<mbs::Wrench> soil(bodies.size());
    for (;;) {
        switch (participant.waitForCommand()) {
        case coupling::Command::WriteCheckpoint:
            model.writeCheckpoint(participant.checkpointDirectory() + "/" + report.checkpoint_file);
            series.flush();
            participant.checkpointWritten();
            break;
        case coupling::Command::Advance: {
            const auto &in = participant.inputs();
            if (in.restore_state)
                model.restoreState();
            if (in.save_state)
                model.saveState();
            for (std::size_t b = 0; b < bodies.size(); ++b)
                soil[b] = {in.wrenches.at(b).force_N, in.wrenches.at(b).torque_N_m};
            model.applyWrenches(soil);
            const auto work = model.advanceTo(in.end_s);
            coupling::WindowOutputs out;
            out.run_complete = report.after_window(series, soil);
            const auto states = model.bodyStates();
            for (std::size_t b = 0; b < bodies.size(); ++b) {
                out.states.push_back(toCoupling(bodies[b].name, states[b]));
                out.work.push_back({bodies[b].name, work[b]});
            }
            out.suggested_macro_step_s = model.suggestedMacroStep_s();
            participant.writeOutputs(std::move(out));
            participant.advance();
            break;
        }
        case coupling::Command::Finish:
            participant.finalize();
            series.flush();
            report.finish();
            return 0;
        }
    }
}

} // namespace

int runMultibodyNode(const NodeOptions &options) {
    const auto root = config::ConfigNode::loadFile(options.scenario_path);
    if (root.has("rig")) {
        mbs::SingleWheelRig rig(mbs::parseSingleWheelRig(root["rig"]));
        return runWindows(root, rig, wheelTestReport(root, rig, options), options);
    }
    const auto model = makeModel(root, options.scenario_path);
    return runWindows(root, *model, observablesReport(*model, options), options);
}

} // namespace grainlink::apps
