// Fuzz target: a measurements folder for `grainlink gap` (docs/gap.md, "The measurements
// folder"): experiments.yaml and one data file, read and turned into features as the diagnosis
// does. Input: experiments.yaml, a line "%%%%", data/a.csv.
#include "FuzzTarget.hpp"
#include "grainlink/gap/Experiments.hpp"
#include "grainlink/gap/Comparison.hpp"

namespace fz = grainlink::fuzz;
using namespace grainlink;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
    const auto parts = fz::splitParts(data, size, 2);
    const std::string folder = fz::freshFolder();
    fz::writeFile(folder, "experiments.yaml", parts[0]);
    fz::writeFile(folder, "data/a.csv", parts[1]);
    fz::expectClearError(folder, [&] {
        const gap::ExperimentSet set = gap::loadExperiments(folder);
        gap::measure(set, gap::designFeatures(set));
    });
    return 0;
}
