// The multibody models a coupled scenario can name, one section each. A new built-in model is
// one more entry here; a user's own mechanism needs none (`model:`, a URDF + YAML pair).
#include "Nodes.hpp"
#include "grainlink/mbs/Mole.hpp"
#include "grainlink/mbs/RockerBogie.hpp"
#include "grainlink/mbs/UrdfModel.hpp"

#include <filesystem>

namespace grainlink::apps {

namespace {

/// A path in a scenario, relative to the scenario file's folder unless absolute.
std::string besideScenario(const std::string &path, const std::string &scenario_path) {
    const std::filesystem::path p(path);
    return p.is_absolute() ? path : (std::filesystem::path(scenario_path).parent_path() / p).string();
}

} // namespace

std::unique_ptr<mbs::MultibodyModel> makeModel(const config::ConfigNode &root,
                                               const std::string &scenario_path) {
    if (root.has("rover"))
        return std::make_unique<mbs::RockerBogie>(mbs::parseRockerBogie(root["rover"]));
    if (root.has("mole"))
        return std::make_unique<mbs::Mole>(mbs::parseMole(root["mole"]));
    if (root.has("model"))
        return std::make_unique<mbs::UrdfModel>(
            mbs::parseUrdfModel(besideScenario(root["model"].text(), scenario_path)));
    root.fail("no multibody model in this scenario: give `rig:` (the single-wheel rig), `rover:` "
              "(the rocker-bogie), `mole:` (the HP3 mole) or `model:` (a URDF model's YAML file, docs/user-models.md)");
}

} // namespace grainlink::apps
