// The multibody models a coupled scenario can name, one section each. A new built-in model is
// one more entry here; a user's own mechanism needs none (`model:`, a URDF + YAML pair).
#include "Nodes.hpp"
#include "grainlink/mbs/Mole.hpp"
#include "grainlink/mbs/RockerBogie.hpp"
#include "grainlink/mbs/UrdfModel.hpp"

#include <filesystem>
#include <memory>

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
    // A model checks the relations between its keys when it is built ("need 0 <
    // cocking_duration_s < stroke_period_s"): its section's file and line go with the message.
    const auto built = [](const config::ConfigNode &section, auto make) {
        try {
            return std::unique_ptr<mbs::MultibodyModel>(make());
        } catch (const mbs::ModelError &e) {
            section.fail(e.what());
        }
    };
    if (root.has("rover"))
        return built(root["rover"], [&] {
            return std::make_unique<mbs::RockerBogie>(mbs::parseRockerBogie(root["rover"]));
        });
    if (root.has("mole"))
        return built(root["mole"],
                     [&] { return std::make_unique<mbs::Mole>(mbs::parseMole(root["mole"])); });
    if (root.has("model"))
        return std::make_unique<mbs::UrdfModel>(
            mbs::parseUrdfModel(besideScenario(root["model"].text(), scenario_path)));
    root.fail("no multibody model in this scenario: give `rig:` (the single-wheel rig), `rover:` "
              "(the rocker-bogie), `mole:` (the HP3 mole) or `model:` (a URDF model's YAML file, docs/user-models.md)");
}

} // namespace grainlink::apps
