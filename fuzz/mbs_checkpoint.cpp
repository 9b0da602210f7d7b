// Fuzz target: a multibody checkpoint (mbs/SimbodyModel.hpp) read into a user's URDF model (the
// project's single-wheel rig, scenarios/models/) and into the HP3 mole (scenarios/mole.yaml).
// Set GRAINLINK_FUZZ_WRITE_SEED=PREFIX to write both models' checkpoints (the seeds).
#include "FuzzTarget.hpp"
#include "grainlink/config/ConfigNode.hpp"
#include "grainlink/mbs/Mole.hpp"
#include "grainlink/mbs/UrdfModel.hpp"

#include <cstdlib>
#include <memory>

namespace fz = grainlink::fuzz;
using namespace grainlink;

namespace {

const std::string kSource = GRAINLINK_SOURCE_DIR;

std::vector<std::unique_ptr<mbs::MultibodyModel>> models() {
    std::vector<std::unique_ptr<mbs::MultibodyModel>> m;
    m.push_back(std::make_unique<mbs::UrdfModel>(
        mbs::parseUrdfModel(kSource + "/scenarios/models/single_wheel_rig.yaml")));
    const auto mole = config::ConfigNode::loadFile(kSource + "/scenarios/mole.yaml");
    m.push_back(std::make_unique<mbs::Mole>(mbs::parseMole(mole["mole"])));
    return m;
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
    if (const char *seed = std::getenv("GRAINLINK_FUZZ_WRITE_SEED")) {
        int k = 0;
        for (auto &model : models()) {
            model->advanceTo(0.01);
            model->writeCheckpoint(std::string(seed) + std::to_string(k++) + ".txt");
        }
        std::exit(0);
    }
    const std::string path = fz::inputFile(data, size, "model.txt");
    for (auto &model : models())
        fz::expectClearError(path, [&] { model->readCheckpoint(path); });
    return 0;
}
