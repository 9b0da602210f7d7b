// Fuzz target: an STL file (ASCII or binary) as a body's mesh (dem/TriangleMesh.hpp).
#include "FuzzTarget.hpp"
#include "grainlink/dem/TriangleMesh.hpp"

namespace fz = grainlink::fuzz;
using namespace grainlink;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
    const std::string path = fz::inputFile(data, size, "body.stl");
    fz::expectClearError(path, [&] { dem::readStl(path); });
    return 0;
}
