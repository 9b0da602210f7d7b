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
    const auto bodies = model.coupledBodies();
    const auto states = model.bodyStates();
    for (std::size_t b = 0; b < bodies.size(); ++b) {
        config.provides.push_back(describe(bodies[b]));
        config.initial_states.push_back(toCoupling(bodies[b].name, states[b]));
    }
    config.capabilities.rollback = true;
    config.capabilities.checkpoint = true;
    if (!options.keys_directory.empty())
        config.curve = coupling::loadClientKeys(options.keys_directory, options.name);
    return config;
}

int runRig(const config::ConfigNode &root, const NodeOptions &options) {
    mbs::SingleWheelRig rig(mbs::parseSingleWheelRig(root["rig"]));
    const auto test_node = root.optional("wheel_test");
    mbs::WheelTest test(test_node ? mbs::parseWheelTest(*test_node) : mbs::WheelTestSettings{});
    const std::string body = rig.coupledBodies()[0].name;
    coupling::Participant participant(participantConfig(options, root, rig));
    const auto &run = participant.initialize();
    if (run.restore)
        rig.readCheckpoint(run.restore->checkpoint_directory + "/rig.txt");

    std::filesystem::create_directories(options.output_directory);
    std::ofstream series = openSeries(
        options.output_directory + "/rig.csv",
        "time_s,phase,x_m,z_m,vx_m_s,vz_m_s,omega_rad_s,slip,motor_torque_N_m,soil_Fx_N,soil_Fy_N,"
        "soil_Fz_N,soil_Ty_N_m,travel_m",
        run.restore ? std::optional<double>(rig.time()) : std::nullopt);
    const double x0 = rig.settings().start_position_m.x();

    for (;;) {
        switch (participant.waitForCommand()) {
        case coupling::Command::WriteCheckpoint:
            rig.writeCheckpoint(participant.checkpointDirectory() + "/rig.txt");
            series.flush();
            participant.checkpointWritten();
            break;
        case coupling::Command::Advance: {
            const auto &in = participant.inputs();
            if (in.restore_state)
                rig.restoreState();
            if (in.save_state)
                rig.saveState();
            mbs::Wrench soil;
            soil.force_N = in.wrenches.at(0).force_N;
            soil.torque_N_m = in.wrenches.at(0).torque_N_m;
            rig.applyWrenches({soil});
            const double work = rig.advanceTo(in.end_s)[0];
            const bool done = test.afterWindow(rig, soil);
            const auto o = rig.observables();
            series << rig.time() << ',' << test.phaseName() << ',' << o.at("carriage_x_m") << ','
                   << o.at("carriage_z_m") << ',' << o.at("carriage_vx_m_s") << ','
                   << o.at("carriage_vz_m_s") << ',' << o.at("wheel_omega_rad_s") << ','
                   << o.at("slip") << ',' << o.at("motor_torque_N_m") << ',' << soil.force_N.x()
                   << ',' << soil.force_N.y() << ',' << soil.force_N.z() << ','
                   << soil.torque_N_m.y() << ',' << o.at("carriage_x_m") - x0 << '\n';
            coupling::WindowOutputs out;
            out.states = {toCoupling(body, rig.bodyStates()[0])};
            out.work = {{body, work}};
            out.run_complete = done;
            participant.writeOutputs(std::move(out));
            participant.advance();
            break;
        }
        case coupling::Command::Finish: {
            participant.finalize();
            const std::string summary = test.summary();
            std::printf("%s\n", summary.c_str());
            std::ofstream(options.output_directory + "/rig_summary.txt") << summary << '\n';
            return 0;
        }
        }
    }
}

/// Any other model: advance window by window to the end time, forwarding the model's hint for
/// the next macro step (the mole asks for small ones around its impacts).
int runModel(const config::ConfigNode &root, mbs::MultibodyModel &model,
             const NodeOptions &options) {
    coupling::Participant participant(participantConfig(options, root, model));
    const auto &run = participant.initialize();
    if (run.restore)
        model.readCheckpoint(run.restore->checkpoint_directory + "/model.txt");
    const auto bodies = model.coupledBodies();
    // The columns: every observable the model reports (sorted by name), then the soil's wrench
    // on each coupled body.
    std::vector<std::string> names;
    for (const auto &[name, value] : model.observables())
        names.push_back(name);
    std::string header = "time_s";
    for (const auto &name : names)
        header += "," + name;
    for (const auto &body : bodies)
        for (const char *c : {"Fx_N", "Fy_N", "Fz_N", "Tx_N_m", "Ty_N_m", "Tz_N_m"})
            header += "," + body.name + "_" + c;
    std::filesystem::create_directories(options.output_directory);
    std::ofstream series =
        openSeries(options.output_directory + "/mbs.csv", header,
                   run.restore ? std::optional<double>(model.time()) : std::nullopt);

    std::vector<mbs::Wrench> soil(bodies.size());
    for (;;) {
        switch (participant.waitForCommand()) {
        case coupling::Command::WriteCheckpoint:
            model.writeCheckpoint(participant.checkpointDirectory() + "/model.txt");
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
            const auto observed = model.observables();
            series << model.time();
            for (const auto &name : names)
                series << ',' << observed.at(name);
            for (const auto &w : soil)
                series << ',' << w.force_N.x() << ',' << w.force_N.y() << ',' << w.force_N.z()
                       << ',' << w.torque_N_m.x() << ',' << w.torque_N_m.y() << ','
                       << w.torque_N_m.z();
            series << '\n';
            coupling::WindowOutputs out;
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
        case coupling::Command::Finish: {
            participant.finalize();
            series.flush();
            std::printf("%s: t = %.6g s;", options.name.c_str(), model.time());
            for (const auto &[name, value] : model.observables())
                std::printf(" %s %.6g", name.c_str(), value);
            std::printf("\n");
            return 0;
        }
        }
    }
}

} // namespace

int runMultibodyNode(const NodeOptions &options) {
    const auto root = config::ConfigNode::loadFile(options.scenario_path);
    if (root.has("rig"))
        return runRig(root, options);
    const auto model = makeModel(root, options.scenario_path);
    return runModel(root, *model, options);
}

} // namespace grainlink::apps
