// Fuzz target: a scenario file, read by every reader of one — the DEM run, each lab test, and a
// coupled run (the coupling sections, then every participant's section and its model); see
// docs/scenario.md. Every refusal must name the file.
#include "CouplingCommands.hpp"
#include "FuzzTarget.hpp"
#include "grainlink/config/ConfigNode.hpp"
#include "grainlink/dem/Scenario.hpp"
#include "grainlink/lab/LabTest.hpp"

#include <filesystem>

namespace fz = grainlink::fuzz;
using namespace grainlink;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
    const std::string path = fz::inputFile(data, size, "scenario.yaml");
    const std::string folder = std::filesystem::path(path).parent_path().string();
    fz::expectClearError(folder, [&] { dem::loadScenario(path); });
    for (const auto &test : lab::labTestNames())
        fz::expectClearError(folder, [&] { lab::loadLabScenario(test, path); });
    fz::expectClearError(folder, [&] {
        apps::checkedCoupledConfig(config::ConfigNode::loadFile(path));
    });
    return 0;
}
