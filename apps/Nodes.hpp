#pragma once
// The participant processes of a coupled run: the Simbody models, the DEM soil and the rigid
// floor, each a `grainlink` subcommand that `grainlink run` starts from the scenario's
// participant commands.
#include "grainlink/config/ConfigNode.hpp"
#include "grainlink/coupling/Participant.hpp"
#include "grainlink/dem/Progress.hpp"
#include "grainlink/mbs/MultibodyModel.hpp"

#include <memory>
#include <string>
#include <vector>

namespace grainlink::apps {

struct NodeOptions {
    std::string scenario_path;
    std::string name;
    std::string endpoint;
    std::string output_directory;
    std::vector<std::string> bodies; ///< soil node: the bodies it consumes
    std::string section = "soil";    ///< soil node: the scenario section of its bed
    std::string keys_directory;      ///< CURVE keys (<name>.key, coordinator.pub)
    double progress_interval_s = 10.0; ///< [s] wall time between progress lines; 0: none
};

/// A node's progress line over the coupled run, whose end the handshake gives (start()).
class NodeProgress {
public:
    explicit NodeProgress(const NodeOptions &options)
        : progress_(options.name, options.progress_interval_s) {}
    void start(const coupling::RunInfo &run) { end_s_ = double(run.end_tick) * run.tick_s; }
    /// Whether update() prints now: a node whose note costs something asks first.
    bool due() const { return progress_.due(); }
    void update(double time_s, std::uint64_t particle_steps = 0, const std::string &note = "") {
        progress_.update(time_s, end_s_ > 0.0 ? time_s / end_s_ : 0.0, particle_steps, note);
    }

private:
    dem::Progress progress_;
    double end_s_ = 0.0; ///< [s] the run's end
};

/// How long a node waits for the coordinator's Welcome: the scenario's
/// `coupling.handshake_timeout_s` (the coordinator waits as long for every node to join, e.g.
/// while the soil node deposits a large bed the first time), else the participant's default.
inline double handshakeTimeout(const config::ConfigNode &root) {
    const auto coupling = root.optional("coupling");
    return coupling && coupling->has("handshake_timeout_s")
               ? (*coupling)["handshake_timeout_s"].positive()
               : coupling::ParticipantConfig{}.handshake_timeout_s;
}

/// `grainlink mbs-node`: the multibody participant: the single-wheel rig (section `rig:`) with
/// its test procedure (`wheel_test:`), or the model `makeModel` finds in the scenario.
int runMultibodyNode(const NodeOptions &options);
/// The multibody model a scenario names (apps/Models.cpp); every section is checked strictly.
std::unique_ptr<mbs::MultibodyModel> makeModel(const config::ConfigNode &root,
                                               const std::string &scenario_path);
/// `grainlink dem-node`: the DEM soil (section `soil:`) as the soil participant.
int runSoilNode(const NodeOptions &options);
/// `grainlink floor-node`: a rigid flat floor (section `floor:`) as the soil participant, for
/// verifying the coupled stack against exact answers.
int runFloorNode(const NodeOptions &options);
/// `grainlink wheel-stl`: the scenario's parametric wheel (`rig.wheel` or `rover.wheel`) as STL.
int exportWheelStl(const std::string &scenario_path, const std::string &stl_path, bool binary);

} // namespace grainlink::apps
