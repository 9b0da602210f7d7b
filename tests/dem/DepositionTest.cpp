// Particle generation and settling (docs/physics.md §6).
#include "Fixtures.hpp"

#include "grainlink/dem/Deposition.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

using namespace grainlink::dem;
using namespace grainlink::dem::testing;

namespace {

std::unique_ptr<DemSystem> depositionBox(const Vec3 &upper) {
    DemSettings settings;
    settings.time_step_s = 1e-4;
    auto sys = std::make_unique<DemSystem>(hertzRestitution(0.3, 0.5),
                                           std::vector<Material>{soil(3e6, 0.2, 2400)}, settings);
    addBoxPlanes(*sys, Vec3::Zero(), upper); // the top is far above every grain
    return sys;
}

double largestOverlap(const ParticleStore &p) {
    double worst = 0.0;
    for (std::size_t i = 0; i < p.size(); ++i)
        for (std::size_t j = i + 1; j < p.size(); ++j)
            worst =
                std::max(worst, p.radius[i] + p.radius[j] - (p.position[i] - p.position[j]).norm());
    return worst;
}

} // namespace

TEST_CASE("random insertion places non-overlapping grains of the requested sizes inside the "
          "region, the same for the same seed",
          "[dem][deposition]") {
    DepositionSpec spec;
    spec.region_lower_m = Vec3(0.01, 0.0, 0.02);
    spec.region_upper_m = Vec3(0.06, 0.05, 0.07);
    spec.count = 400;
    spec.radius.kind = RadiusDistribution::Kind::Discrete;
    spec.radius.radii_m = {0.002, 0.003};
    spec.radius.fractions = {3.0, 1.0};
    spec.seed = 11;
    auto a = depositionBox(Vec3(0.07, 0.05, 0.2));
    Random random(spec.seed);
    REQUIRE(insertRandom(*a, spec, random, spec.count, spec.region_lower_m, spec.region_upper_m) ==
            400);
    const ParticleStore &p = a->particles();
    std::size_t small = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        const double r = p.radius[i];
        CHECK((r == 0.002 || r == 0.003));
        small += r == 0.002 ? 1 : 0;
        CHECK((p.position[i].array() - r >= spec.region_lower_m.array()).all());
        CHECK((p.position[i].array() + r <= spec.region_upper_m.array()).all());
    }
    // Number fraction 3:1 -> 300 small expected; binomial sd ~ 8.7, so +-4 sd.
    CHECK(small == Approx(300).margin(35));
    CHECK(largestOverlap(p) <= 0.0);

    auto b = depositionBox(Vec3(0.07, 0.05, 0.2));
    Random again(spec.seed);
    insertRandom(*b, spec, again, spec.count, spec.region_lower_m, spec.region_upper_m);
    CHECK(b->particles().position == p.position);
}

TEST_CASE("a distribution's mean cubed radius is the mean of r^3 over the grains it draws",
          "[dem][deposition]") {
    // The mean grain volume sizes a bed to a depth (docs/gap.md, bed_depth_m): checked against
    // the grains the insertion actually draws, 12000 of each distribution in a roomy region
    // (the sample mean's relative sd: 0.7 % uniform, 1.1 % discrete; 4 %: at least 3.5 sd).
    RadiusDistribution uniform;
    uniform.kind = RadiusDistribution::Kind::Uniform;
    uniform.min_m = 0.001;
    uniform.max_m = 0.003;
    RadiusDistribution discrete;
    discrete.kind = RadiusDistribution::Kind::Discrete;
    discrete.radii_m = {0.001, 0.002, 0.003};
    discrete.fractions = {2.0, 1.0, 1.0};
    RadiusDistribution constant;
    constant.min_m = constant.max_m = 0.002;
    // Hand values: uniform (3^4 - 1^4) / (4 * 2) mm^3 = 10 mm^3; discrete (2 + 8 + 27) / 4.
    CHECK(uniform.meanCubedRadius() == Approx(10e-9));
    CHECK(discrete.meanCubedRadius() == Approx(9.25e-9));
    CHECK(constant.meanCubedRadius() == Approx(8e-9));
    for (const RadiusDistribution &d : {uniform, discrete}) {
        DepositionSpec spec;
        spec.region_lower_m = Vec3::Zero();
        spec.region_upper_m = Vec3(0.2, 0.2, 0.2);
        spec.count = 12000;
        spec.radius = d;
        auto sys = depositionBox(Vec3(0.2, 0.2, 0.4));
        Random random(5);
        REQUIRE(insertRandom(*sys, spec, random, spec.count, spec.region_lower_m,
                             spec.region_upper_m) == 12000);
        double sum = 0.0;
        for (double r : sys->particles().radius)
            sum += r * r * r;
        CHECK(sum / 12000.0 == Approx(d.meanCubedRadius()).epsilon(0.04));
    }
}

TEST_CASE("deposition by rain fills layer by layer and settles below the energy threshold",
          "[dem][deposition]") {
    DepositionSpec spec;
    spec.method = DepositionSpec::Method::Rain;
    spec.region_lower_m = Vec3(0.0, 0.0, 0.0);
    spec.region_upper_m = Vec3(0.05, 0.05, 0.12);
    spec.count = 300;
    spec.radius.kind = RadiusDistribution::Kind::Uniform;
    spec.radius.min_m = 0.0025;
    spec.radius.max_m = 0.0035;
    spec.layers = 3;
    spec.layer_interval_s = 0.08;
    spec.settle_kinetic_energy_J = 1e-8;
    spec.max_settle_time_s = 2.0;
    auto sys = depositionBox(Vec3(0.05, 0.05, 0.3));
    std::vector<std::size_t> counts;
    const DepositionReport report = deposit(*sys, spec, [&](const DepositionReport &r) {
        if (counts.empty() || counts.back() != r.inserted)
            counts.push_back(r.inserted);
    });
    CHECK(report.inserted == 300);
    CHECK(counts == std::vector<std::size_t>{100, 200, 300});
    CHECK(report.settled);
    const Energies e = sys->energies();
    CHECK((e.translational_J + e.rotational_J) / 300.0 < 1e-8);
    // Settled means resting on the floor: every grain is below the slab it was rained from.
    for (const Vec3 &x : sys->particles().position)
        CHECK(x.z() < 0.08);
}

TEST_CASE("under the Moon's gravity a bed in free fall is not settled: every grain has landed",
          "[dem][deposition]") {
    // 150 grains placed at rest through an 80 mm region under 1.62 m/s^2: 0.01 s in, the first
    // check, they fall at 16 mm/s, a mean kinetic energy of ~1e-8 J below the 1e-7 threshold, and
    // the bed counted as settled in free fall. The top grain needs sqrt(2 h / g) = 0.31 s to
    // reach the floor; settled, every grain rests in the bottom layers (150 grains of 3.5-4.5 mm
    // in 60 x 60 mm pack about 20 mm deep).
    DepositionSpec spec;
    spec.region_lower_m = Vec3(0.0, 0.0, 0.0);
    spec.region_upper_m = Vec3(0.06, 0.06, 0.08);
    spec.count = 150;
    spec.radius.kind = RadiusDistribution::Kind::Uniform;
    spec.radius.min_m = 0.0035;
    spec.radius.max_m = 0.0045;
    spec.settle_kinetic_energy_J = 1e-7;
    spec.max_settle_time_s = 2.0;
    auto sys = depositionBox(Vec3(0.06, 0.06, 0.3));
    sys->setGravity(Vec3(0.0, 0.0, -1.62));
    const DepositionReport report = deposit(*sys, spec);
    CHECK(report.settled);
    CHECK(report.settle_time_s >= std::sqrt(2.0 * 0.08 / 1.62));
    double highest = 0.0;
    for (const Vec3 &x : sys->particles().position)
        highest = std::max(highest, x.z());
    CHECK(highest < 0.04);
}

TEST_CASE("a region too small for the grains is an error that says what to change",
          "[dem][deposition]") {
    DepositionSpec spec;
    spec.region_lower_m = Vec3::Zero();
    spec.region_upper_m = Vec3(0.02, 0.02, 0.02);
    spec.count = 500;
    spec.radius.kind = RadiusDistribution::Kind::Constant;
    spec.radius.min_m = spec.radius.max_m = 0.003;
    auto sys = depositionBox(Vec3(0.02, 0.02, 0.2));
    CHECK_THROWS_WITH(deposit(*sys, spec),
                      Catch::Contains("particles fit into the insertion region"));
}
