// Run-to-run reproducibility: the same input and thread count give bit-identical trajectories
// (docs/physics.md §4: deterministic force summation). Different thread counts may differ.
#include "Fixtures.hpp"

#include <catch2/catch.hpp>

using namespace grainlink::dem;
using namespace grainlink::dem::testing;

namespace {

/// 300 grains poured into a box of planes while a cylinder (mesh body) sinks into them: pair,
/// plane and mesh contacts, friction with history, rolling resistance, re-sorts and rebuilds.
ParticleStore pour(int threads) {
    DemSettings settings;
    settings.time_step_s = 2e-5;
    settings.threads = threads;
    settings.resort_every_builds = 2;
    settings.skin_m = 2e-4; // frequent rebuilds and re-sorts within a short run
    ContactLaw law = hertzRestitution(0.3, 0.5);
    law.rolling = RollingEpsd{0.05};
    DemSystem sys(law, {kMaterial}, settings);
    const Vec3 lower(-0.02, -0.02, 0.0), upper(0.02, 0.02, 0.096);
    addBoxPlanes(sys, lower, Vec3(0.02, 0.02, 0.2));
    addLattice(sys, lower, upper, 0.008, 0.0025, 0.0035, kMaterial.density_kg_m3, 0.3, 300);
    RigidBodyState start;
    start.position_m = Vec3(0, 0, 0.11);
    start.linear_velocity_m_s = Vec3(0, 0, -0.5);
    start.angular_velocity_rad_s = Vec3(0, 5, 0);
    MeshBody wheel("wheel", makeCylinder(0.01, 0.03, 24), start);
    sys.addBody(wheel, constantVelocity(start));
    sys.run(2000);
    REQUIRE(sys.neighbourBuilds() > 20);
    REQUIRE(sys.body(0).force_N.norm() > 0.0); // the wheel is in the bed
    return sys.particles();
}

void requireIdentical(const ParticleStore& a, const ParticleStore& b) {
    REQUIRE(a.size() == b.size());
    std::size_t differing = 0;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (a.id[i] != b.id[i] || a.position[i] != b.position[i] ||
            a.velocity[i] != b.velocity[i] || a.angular_velocity[i] != b.angular_velocity[i] ||
            a.orientation[i].coeffs() != b.orientation[i].coeffs())
            ++differing;
    CHECK(differing == 0); // bitwise: no tolerance
}

} // namespace

TEST_CASE("Two identical runs give bit-identical particles, one and two threads",
          "[dem][determinism]") {
    SECTION("threads = 1") {
        requireIdentical(pour(1), pour(1));
    }
    SECTION("threads = 2") {
        requireIdentical(pour(2), pour(2));
    }
}
