// The multibody models a coupled scenario can name, one section each. A new built-in model is
// one more entry here; a user's own mechanism needs none (`model:`, a URDF + YAML pair).
#include "Nodes.hpp"

namespace grainlink::apps {

std::unique_ptr<mbs::MultibodyModel> makeModel(const config::ConfigNode &root,
                                               const std::string &scenario_path) {
    (void)scenario_path;
    root.fail("no multibody model in this scenario: give a `rig:` section (docs/scenario.md)");
}

} // namespace grainlink::apps
