// Fuzz target: a user's effect catalogue (`--effects FILE`, docs/gap.md "The effect
// catalogue"): every expression is parsed when the file is read, so a typo stops there.
#include "FuzzTarget.hpp"
#include "grainlink/gap/Effects.hpp"

namespace fz = grainlink::fuzz;
using namespace grainlink;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
    const std::string path = fz::inputFile(data, size, "effects.yaml");
    fz::expectClearError(path, [&] { gap::loadEffects(path); });
    return 0;
}
