// The rigid-floor participant: a soil-role process whose ground is a flat rigid plane instead of
// grains (dem/RigidFloor.hpp). It verifies the coupled stack against exact answers: a body on a
// floor carries exactly its weight, a driven wheel rolls without slip.
#include "Nodes.hpp"
#include "SoilSide.hpp"
#include "grainlink/coupling/ParticipantNode.hpp"
#include "grainlink/coupling/WindowLoads.hpp"
#include "grainlink/dem/RigidFloor.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>

namespace grainlink::apps {

namespace {

class FloorNode final : public coupling::ParticipantNode {
public:
    FloorNode(const NodeOptions &options, const config::ConfigNode &root)
        : options_(options), floor_(dem::parseRigidFloor(root["floor"])), progress_(options) {}

    void start(const coupling::RunInfo &run) override {
        progress_.start(run);
        for (const auto &name : options_.bodies)
            floors_.emplace_back(floor_, meshOf(describedBody(run, name)));
        std::filesystem::create_directories(options_.output_directory);
        series_.open(options_.output_directory + "/floor.csv");
        series_ << "time_s,body,Fx_N,Fy_N,Fz_N,Tx_N_m,Ty_N_m,Tz_N_m,touching_vertices,"
                   "penetration_m\n";
        series_.precision(10);
    }

    coupling::WindowOutputs advance(const coupling::WindowInputs &in) override {
        const auto steps = std::max<long long>(1, std::llround(in.duration_s / floor_.time_step_s));
        const double dt = in.duration_s / double(steps);
        coupling::WindowLoads loads(options_.bodies);
        for (std::size_t b = 0; b < floors_.size(); ++b) {
            const dem::WindowMotion motion = windowMotion(in, b);
            // Sub-steps along the window's motion, each at its midpoint in time.
            dem::Vec3 force, torque;
            for (long long k = 0; k < steps; ++k) {
                const auto state = motion.at(in.start_s + (double(k) + 0.5) * dt);
                floors_[b].step(state, dt, force, torque);
                loads.add(b, force, torque, state.linear_velocity_m_s, state.angular_velocity_rad_s,
                          dt);
            }
        }
        coupling::WindowOutputs out = loads.outputs(in.duration_s);
        for (std::size_t b = 0; b < floors_.size(); ++b) {
            const auto &w = out.wrenches[b];
            series_ << in.end_s << ',' << w.body << ',' << w.force_N.x() << ',' << w.force_N.y()
                    << ',' << w.force_N.z() << ',' << w.torque_N_m.x() << ',' << w.torque_N_m.y()
                    << ',' << w.torque_N_m.z() << ',' << floors_[b].touching() << ','
                    << floors_[b].penetration_m() << '\n';
        }
        progress_.update(in.end_s);
        return out;
    }

    void finish() override { series_.flush(); }

private:
    NodeOptions options_;
    dem::RigidFloorSettings floor_;
    std::vector<dem::RigidFloor> floors_;
    std::ofstream series_;
    NodeProgress progress_;
};

} // namespace

int runFloorNode(const NodeOptions &options) {
    const auto root = config::ConfigNode::loadFile(options.scenario_path);
    FloorNode node(options, root);
    coupling::Participant participant(soilParticipantConfig(options, root));
    coupling::runParticipant(participant, node);
    return 0;
}

} // namespace grainlink::apps
