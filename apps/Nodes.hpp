#pragma once
// The participant processes of a coupled wheel run: the Simbody rig and the DEM soil, each a
// `grainlink` subcommand that `grainlink run` starts from the scenario's participant commands.
#include <string>
#include <vector>

namespace grainlink::apps {

struct NodeOptions {
    std::string scenario_path;
    std::string name;
    std::string endpoint;
    std::string output_directory;
    std::vector<std::string> bodies; ///< soil node: the bodies it consumes
    std::string keys_directory;      ///< CURVE keys (<name>.key, coordinator.pub)
    double progress_interval_s = 10.0;
};

/// `grainlink mbs-node`: the single-wheel rig (section `rig:`) and its test procedure
/// (`wheel_test:`) as the multibody participant.
int runMultibodyNode(const NodeOptions &options);
/// `grainlink dem-node`: the DEM soil (section `soil:`) as the soil participant.
int runSoilNode(const NodeOptions &options);
/// `grainlink wheel-stl`: the scenario's parametric wheel (`rig.wheel` or `rover.wheel`) as STL.
int exportWheelStl(const std::string &scenario_path, const std::string &stl_path, bool binary);

} // namespace grainlink::apps
