// Fuzz target: a DEM checkpoint (dem/Checkpoint.hpp) restored into the system it was written
// from: a few grains on a floor with a drum ploughing through them, so that every part of the
// state (particles, pair, plane and mesh histories, the body) is in the file. Set
// GRAINLINK_FUZZ_WRITE_SEED=FILE to write such a checkpoint (the seed in fuzz/corpus/).
#include "FuzzTarget.hpp"
#include "grainlink/dem/Checkpoint.hpp"
#include "grainlink/dem/Deposition.hpp"
#include "grainlink/dem/TriangleMesh.hpp"

#include <cstdlib>
#include <memory>

namespace fz = grainlink::fuzz;
using namespace grainlink::dem;

namespace {

std::unique_ptr<DemSystem> busySystem() {
    DemSettings settings;
    settings.time_step_s = 5e-5;
    settings.threads = 1;
    ContactLaw law;
    law.damping = DampingViscous{0.02};
    law.rolling = RollingEpsd{0.2};
    Material soil;
    soil.name = "soil";
    soil.youngs_modulus_Pa = 3e6;
    soil.poisson_ratio = 0.2;
    soil.density_kg_m3 = 2400;
    auto sys = std::make_unique<DemSystem>(law, std::vector<Material>{soil}, settings);
    PlaneWall floor;
    floor.name = "floor";
    floor.point_m = Vec3::Zero();
    floor.normal = Vec3::UnitZ();
    sys->addPlane(floor);
    DepositionSpec spec;
    spec.region_lower_m = Vec3(0, 0, 0);
    spec.region_upper_m = Vec3(0.03, 0.03, 0.03);
    spec.count = 20;
    spec.radius.kind = RadiusDistribution::Kind::Uniform;
    spec.radius.min_m = 0.0025;
    spec.radius.max_m = 0.0035;
    Random random(1);
    insertRandom(*sys, spec, random, spec.count, spec.region_lower_m, spec.region_upper_m);
    RigidBodyState start;
    start.position_m = Vec3(-0.012, 0.015, 0.008);
    start.linear_velocity_m_s = Vec3(0.2, 0, 0);
    sys->addBody(MeshBody("drum", makeCylinder(0.01, 0.02, 12), start), constantVelocity(start));
    return sys;
}

} // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t *data, std::size_t size) {
    if (const char *seed = std::getenv("GRAINLINK_FUZZ_WRITE_SEED")) {
        auto sys = busySystem();
        sys->run(3000);
        writeCheckpoint(*sys, seed, {{"phase", 2.0}});
        std::exit(0);
    }
    const std::string path = fz::inputFile(data, size, "state.bin");
    auto sys = busySystem();
    bool restored = false;
    fz::expectClearError(path, [&] {
        readCheckpointExtras(path);
        readCheckpoint(*sys, path);
        restored = true;
    });
    if (restored) {
        // An accepted state must step, or stop with the step and the grain that went wrong, or
        // refuse the step it would need (std::invalid_argument, naming time_step_s).
        try {
            sys->run(2);
        } catch (const SimulationError &) {
        } catch (const std::invalid_argument &e) {
            if (std::string_view(e.what()).find("time_step_s") == std::string_view::npos)
                fz::finding(std::string("a restored state refused without naming the step: ") +
                            e.what());
        }
    }
    return 0;
}
