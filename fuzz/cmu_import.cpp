// Fuzz target: the CMU 3d-terramechanics importer (`grainlink gap import cmu`, docs/gap.md) on
// a folder of one plate trial (its CSV and JSON) and one wheel table, and the measurements
// folder it writes read back. Input: the plate CSV, "%%%%", its JSON, "%%%%", the wheel CSV.
#include "FuzzTarget.hpp"
#include "grainlink/gap/Experiments.hpp"
#include "grainlink/gap/Importers.hpp"

namespace fz = grainlink::fuzz;
using namespace grainlink;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
    const auto parts = fz::splitParts(data, size, 3);
    const std::string folder = fz::freshFolder();
    const std::string trial = "cmu/plates/plate_large_d060mm_force-displacement_1";
    fz::writeFile(folder, trial + ".csv", parts[0]);
    fz::writeFile(folder, trial + ".json", parts[1]);
    fz::writeFile(folder, "cmu/steady_state_wheel/smooth.csv", parts[2]);
    fz::expectClearError(folder, [&] {
        gap::importCmu(folder + "/cmu", folder + "/measurements");
        gap::loadExperiments(folder + "/measurements");
    });
    return 0;
}
