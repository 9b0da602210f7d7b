// The ParaView snapshots (dem/VtkWriter) are written whole or not at all: each file goes to
// <name>.partial and is renamed over <name> when complete, so a crash while writing leaves the
// previous file or none, never a cut .vtu (the fault soak found one after a SIGKILL).
#include "Fixtures.hpp"

#include "grainlink/dem/VtkWriter.hpp"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

using namespace grainlink::dem;
using namespace grainlink::dem::testing;
namespace fs = std::filesystem;

namespace {

std::string contents(const fs::path &path) {
    std::ifstream in(path);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

} // namespace

TEST_CASE("Snapshots: each file is renamed into place, never written in it", "[dem][output]") {
    const fs::path dir =
        fs::temp_directory_path() / ("grainlink-test-vtk-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    DemSystem sys(hertzRestitution(0.5, 0.3), {soil()}, quietSettings(1e-5));
    sys.particles().add(sphere({0, 0, 0}, 0.01, 2500));
    sys.particles().add(sphere({0.03, 0, 0}, 0.01, 2500));
    RigidBodyState above;
    above.position_m = Vec3(0, 0, 0.1);
    sys.addBody(MeshBody("wheel", makeCylinder(0.02, 0.03, 8), above));
    // Each file the snapshot writes already exists as a second name of a witness file. Written
    // in place, the file's data would change under both names; renamed into place, the name
    // moves to the new file and the witness keeps the old data.
    const std::vector<std::string> names = {"particles_000000.vtu", "body_wheel_000000.vtu",
                                            "particles.pvd", "body_wheel.pvd"};
    for (const auto &name : names) {
        std::ofstream(dir / ("witness_" + name)) << "old\n";
        fs::create_hard_link(dir / ("witness_" + name), dir / name);
    }
    VtkWriter vtk(dir.string());
    vtk.write(sys, 0.5);
    for (const auto &name : names) {
        INFO(name);
        CHECK(contents(dir / ("witness_" + name)) == "old\n");
        const std::string written = contents(dir / name);
        CHECK(written.rfind("<?xml", 0) == 0);
        CHECK(written.size() >= 11);
        CHECK(written.substr(written.size() - 11) == "</VTKFile>\n");
        CHECK_FALSE(fs::exists(dir / (name + ".partial")));
    }
    CHECK(contents(dir / "particles.pvd").find("file=\"particles_000000.vtu\"") !=
          std::string::npos);
    fs::remove_all(dir);
}
