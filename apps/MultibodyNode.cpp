// The multibody participant: the seed's single-wheel rig in Simbody, driven through the seed's
// procedure (drop locked, drive, stop at steady slip); writes rig.csv and the steady report.
#include "Nodes.hpp"
#include "grainlink/coupling/Participant.hpp"
#include "grainlink/mbs/WheelTest.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>

namespace grainlink::apps {

namespace {

coupling::BodyDescription describe(const mbs::CoupledBody &body) {
    coupling::BodyDescription d;
    d.name = body.name;
    d.mass.mass_kg = body.mass_kg;
    d.mass.inertia_diagonal_kg_m2 = body.inertia_diagonal_kg_m2;
    if (body.mesh) {
        coupling::MeshGeometry m;
        m.vertices_m = body.mesh->vertices_m;
        for (const auto &t : body.mesh->triangles)
            m.triangles.insert(m.triangles.end(), {std::uint32_t(t[0]), std::uint32_t(t[1]),
                                                   std::uint32_t(t[2])});
        d.geometry = m;
        return d;
    }
    coupling::WheelGeometry w;
    w.diameter_m = body.wheel.diameter_m;
    w.width_m = body.wheel.width_m;
    w.rim_thickness_m = body.wheel.rim_thickness_m;
    w.grouser_count = body.wheel.grouser_count;
    w.grouser_height_m = body.wheel.grouser_height_m;
    w.grouser_thickness_m = body.wheel.grouser_thickness_m;
    w.grouser_shape =
        body.wheel.chevron ? coupling::GrouserShape::Chevron : coupling::GrouserShape::Straight;
    w.chevron_angle_deg = body.wheel.chevron_angle_deg;
    w.closed_sides = body.wheel.closed_sides;
    d.geometry = w;
    return d;
}

coupling::BodyState toCoupling(const std::string &name, const mbs::RigidState &s) {
    coupling::BodyState out;
    out.body = name;
    out.position_m = s.position_m;
    out.orientation = s.orientation;
    out.linear_velocity_m_s = s.linear_velocity_m_s;
    out.angular_velocity_rad_s = s.angular_velocity_rad_s;
    return out;
}

} // namespace

int runMultibodyNode(const NodeOptions &options) {
    const auto root = config::ConfigNode::loadFile(options.scenario_path);
    mbs::SingleWheelRig rig(mbs::parseSingleWheelRig(root["rig"]));
    const auto test_node = root.optional("wheel_test");
    mbs::WheelTest test(test_node ? mbs::parseWheelTest(*test_node) : mbs::WheelTestSettings{});
    const std::string body = rig.coupledBodies()[0].name;

    coupling::ParticipantConfig config;
    config.name = options.name;
    config.role = coupling::Role::Multibody;
    config.endpoint = options.endpoint;
    config.provides = {describe(rig.coupledBodies()[0])};
    config.initial_states = {toCoupling(body, rig.bodyStates()[0])};
    config.capabilities.rollback = true;
    config.capabilities.checkpoint = true;
    if (!options.keys_directory.empty())
        config.curve = coupling::loadClientKeys(options.keys_directory, options.name);
    coupling::Participant participant(config);
    const auto &run = participant.initialize();
    if (run.restore)
        rig.readCheckpoint(run.restore->checkpoint_directory + "/rig.txt");

    std::filesystem::create_directories(options.output_directory);
    const std::string series_path = options.output_directory + "/rig.csv";
    // A resumed run keeps the rows before its restart time.
    std::vector<std::string> kept;
    if (run.restore) {
        std::ifstream in(series_path);
        std::string line;
        std::getline(in, line);
        while (std::getline(in, line))
            if (std::stod(line.substr(0, line.find(','))) <= rig.time() + 1e-12)
                kept.push_back(line);
    }
    std::ofstream series(series_path, std::ios::trunc);
    series << "time_s,phase,x_m,z_m,vx_m_s,vz_m_s,omega_rad_s,slip,motor_torque_N_m,"
              "soil_Fx_N,soil_Fy_N,soil_Fz_N,soil_Ty_N_m,travel_m\n";
    for (const auto &line : kept)
        series << line << '\n';
    series.precision(10);
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

} // namespace grainlink::apps
