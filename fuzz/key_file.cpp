// Fuzz target: a CURVE key file (coupling/Security.hpp, docs/protocol.md): its text, read as a
// participant's or the coordinator's key. Needs a ZeroMQ built with CURVE.
#include "FuzzTarget.hpp"
#include "grainlink/coupling/Security.hpp"

#include <sys/stat.h>

namespace fz = grainlink::fuzz;
using namespace grainlink;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
    const std::string path = fz::inputFile(data, size, "soil.key");
    ::chmod(path.c_str(), 0600); // a secret key's mode: the reader refuses others
    fz::expectClearError(path, [&] { coupling::readKeyFile(path); });
    return 0;
}
