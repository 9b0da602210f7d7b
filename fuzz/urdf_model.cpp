// Fuzz target: a user's multibody model (docs/user-models.md): its YAML file and the URDF it
// names, read and built into a Simbody system. Input: model.yaml, a line "%%%%", robot.urdf.
#include "FuzzTarget.hpp"
#include "grainlink/mbs/UrdfModel.hpp"

namespace fz = grainlink::fuzz;
using namespace grainlink;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
    const auto parts = fz::splitParts(data, size, 2);
    const std::string folder = fz::freshFolder();
    const std::string path = fz::writeFile(folder, "model.yaml", parts[0]);
    fz::writeFile(folder, "robot.urdf", parts[1]);
    fz::expectClearError(folder, [&] { mbs::UrdfModel model(mbs::parseUrdfModel(path)); });
    return 0;
}
