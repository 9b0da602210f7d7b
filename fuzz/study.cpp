// Fuzz target: a study file and the base scenario it names (docs/study.md), read and every
// point checked by its kind's reader as `grainlink study` does before anything runs. Input: the
// study file, a line "%%%%", the base scenario (base.yaml beside it).
#include "FuzzTarget.hpp"
#include "grainlink/study/Design.hpp"
#include "grainlink/study/Study.hpp"

namespace fz = grainlink::fuzz;
using namespace grainlink;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
    const auto parts = fz::splitParts(data, size, 2);
    const std::string folder = fz::freshFolder();
    const std::string path = fz::writeFile(folder, "study.yaml", parts[0]);
    fz::writeFile(folder, "base.yaml", parts[1]);
    fz::expectClearError(folder, [&] {
        const study::Study s = study::loadStudy(path, folder + "/out");
        study::validate(s);
    });
    return 0;
}
