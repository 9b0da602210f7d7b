// The rigid-floor participant: a soil-role process whose ground is a flat rigid plane instead of
// grains (dem/RigidFloor.hpp). It verifies the coupled stack against exact answers: a body on a
// floor carries exactly its weight, a driven wheel rolls without slip.
#include "Nodes.hpp"
#include "SoilSide.hpp"
#include "grainlink/coupling/Participant.hpp"
#include "grainlink/dem/RigidFloor.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>

namespace grainlink::apps {

int runFloorNode(const NodeOptions &options) {
    const auto root = config::ConfigNode::loadFile(options.scenario_path);
    const dem::RigidFloorSettings floor = dem::parseRigidFloor(root["floor"]);

    auto config = soilParticipantConfig(options, root);
    coupling::Participant participant(config);
    const auto &run = participant.initialize();

    std::vector<dem::RigidFloor> floors;
    for (const auto &name : options.bodies) {
        const auto description =
            std::find_if(run.bodies.begin(), run.bodies.end(),
                         [&](const coupling::BodyDescription &d) { return d.name == name; });
        floors.emplace_back(floor, meshOf(*description));
    }

    std::filesystem::create_directories(options.output_directory);
    std::ofstream series(options.output_directory + "/floor.csv");
    series << "time_s,body,Fx_N,Fy_N,Fz_N,Tx_N_m,Ty_N_m,Tz_N_m,touching_vertices,"
              "penetration_m\n";
    series.precision(10);

    for (;;) {
        switch (participant.waitForCommand()) {
        case coupling::Command::WriteCheckpoint:
            throw coupling::CouplingError("participant '" + options.name +
                                          "': the rigid floor does not write checkpoints");
        case coupling::Command::Advance: {
            const auto &in = participant.inputs();
            const auto steps =
                std::max<long long>(1, std::llround(in.duration_s / floor.time_step_s));
            const double dt = in.duration_s / double(steps);
            coupling::WindowOutputs out;
            for (std::size_t b = 0; b < floors.size(); ++b) {
                const dem::WindowMotion motion = windowMotion(in, b);
                // The impulse over the window, midpoint in time, divided by the window.
                dem::Vec3 impulse = dem::Vec3::Zero(), angular = dem::Vec3::Zero(), force, torque;
                double work = 0.0;
                for (long long k = 0; k < steps; ++k) {
                    const auto state = motion.at(in.start_s + (double(k) + 0.5) * dt);
                    floors[b].step(state, dt, force, torque);
                    impulse += force * dt;
                    angular += torque * dt;
                    work += (force.dot(state.linear_velocity_m_s) +
                             torque.dot(state.angular_velocity_rad_s)) *
                            dt;
                }
                coupling::Wrench w;
                w.body = options.bodies[b];
                w.force_N = impulse / in.duration_s;
                w.torque_N_m = angular / in.duration_s;
                out.wrenches.push_back(w);
                out.work.push_back({w.body, work});
                series << in.end_s << ',' << w.body << ',' << w.force_N.x() << ',' << w.force_N.y()
                       << ',' << w.force_N.z() << ',' << w.torque_N_m.x() << ',' << w.torque_N_m.y()
                       << ',' << w.torque_N_m.z() << ',' << floors[b].touching() << ','
                       << floors[b].penetration_m() << '\n';
            }
            participant.writeOutputs(std::move(out));
            participant.advance();
            break;
        }
        case coupling::Command::Finish:
            participant.finalize();
            return 0;
        }
    }
}

} // namespace grainlink::apps
