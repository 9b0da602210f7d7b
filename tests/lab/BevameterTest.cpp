// Virtual bevameter on a tiny bed (docs/lab.md): the p(z) it measures and the input checks.
#include "grainlink/lab/Bevameter.hpp"

#include "TextEdit.hpp"
#include "TinyBed.hpp"

#include <catch2/catch.hpp>

#include <string>

using namespace grainlink;
using Catch::Matchers::Contains;

namespace {

/// A tiny bed: 2600 grains of 1.5 mm radius in a 50 mm box (~20 mm deep), two plates of 10 and
/// 13 mm radius: Gamma = 6.7 and 8.7 instead of the seed's 10 (min_resolution lowered) to keep
/// the test at a few seconds. Rolling resistance stands in for grain shape: frictional spheres
/// without it fail under the plate at ~2 kPa (bearing capacity of a bed of low bulk friction)
/// and p(z) then wanders on a plateau; with it p(z) rises throughout, as for real sand.
const std::string kTinyBevameter =
    "name: tiny-bevameter\n" + tinyBinSoil("0.05", "0.08", "2600") + R"(bevameter:
  plate_radii_m: [0.010, 0.013]
  speed_m_s: 0.1
  max_sinkage_m: 0.008
  start_clearance_m: 0.001
  sample_interval_s: 0.002
  min_resolution: 5
)";

lab::BevameterScenario parseBevameterText(const std::string &text) {
    return lab::parseBevameter(config::ConfigNode::loadString(text, "bevameter.yaml"));
}

std::string editedBevameter(const std::string &from, const std::string &to) {
    return replacedOnce(kTinyBevameter, from, to);
}

} // namespace

TEST_CASE("Bevameter on a tiny bed: pressure grows with sinkage for both plates, Bekker fits",
          "[lab][bevameter][slow]") {
    const auto result = lab::runBevameter(parseBevameterText(kTinyBevameter), {});
    INFO(result.report());
    REQUIRE(result.runs.size() == 2);
    for (const auto &plate : result.runs) {
        // A DEM p(z) rattles from sample to sample as grains jam and slip, so monotonic is
        // judged on the mean pressure over four equal sinkage spans of the loaded part
        // (z > 1 mm, past the surface's grain-scale roughness): each span's mean must be above
        // the previous one's. Any rise counts; no tolerance needed beyond the averaging.
        const double z_lo = 0.001, z_hi = plate.samples.back().sinkage_m;
        double sum[4] = {0, 0, 0, 0};
        int count[4] = {0, 0, 0, 0};
        for (const auto &s : plate.samples)
            if (s.sinkage_m > z_lo) {
                const int k = std::min(3, int(4.0 * (s.sinkage_m - z_lo) / (z_hi - z_lo)));
                sum[k] += s.pressure_Pa;
                ++count[k];
            }
        for (int k = 0; k < 4; ++k)
            REQUIRE(count[k] > 0);
        for (int k = 1; k < 4; ++k) {
            INFO("plate R = " << plate.plate_radius_m << ", span " << k);
            CHECK(sum[k] / count[k] > sum[k - 1] / count[k - 1]);
        }
        // The plate is loaded by the bed: the last pressure is positive and of the order a
        // 20 mm bed of 1.5 mm grains carries (> 100 Pa: the bed's own weight under the plate
        // is ~350 Pa, so a plate at 8 mm that carries less touches nothing).
        CHECK(plate.samples.back().pressure_Pa > 100.0);
    }
    REQUIRE(result.fit);
    WARN(result.report());
    // The fit describes the curves: rms residual below a quarter of the largest pressure.
    double p_max = 0.0;
    for (const auto &plate : result.runs)
        for (const auto &s : plate.samples)
            p_max = std::max(p_max, s.pressure_Pa);
    CHECK(result.fit->rms_residual_Pa < 0.25 * p_max);
}

TEST_CASE("Bevameter input errors name the key and the line", "[lab][bevameter]") {
    // Gamma = R / r_max below the required resolution.
    CHECK_THROWS_WITH(
        parseBevameterText(editedBevameter("min_resolution: 5", "min_resolution: 10")),
        Contains("bevameter.yaml:20:") && Contains("bevameter.plate_radii_m") &&
            Contains("Gamma = 6.66"));
    CHECK_THROWS_WITH(parseBevameterText(editedBevameter("speed_m_s: 0.1", "speed_m_s: -0.1")),
                      Contains("bevameter.speed_m_s") && Contains("must be > 0"));
    CHECK_THROWS_WITH(parseBevameterText(editedBevameter("  min_resolution: 5\n",
                                                         "  min_resolution: 5\n  depth_m: 1\n")),
                      Contains("unknown key 'bevameter.depth_m'"));
    CHECK_THROWS_WITH(parseBevameterText(editedBevameter("max_sinkage_m", "max_sinkage_mm")),
                      Contains("wrong unit"));
    // A plate wider than the 50 mm bed (a diameter given as a radius) presses on the walls.
    CHECK_THROWS_WITH(
        parseBevameterText(editedBevameter("[0.010, 0.013]", "[0.010, 0.026]")),
        Contains("bevameter.plate_radii_m") &&
            Contains("plate of radius 26 mm about (25, 25) mm reaches past the bed, whose "
                     "nearest side is 25 mm away"));
    CHECK_NOTHROW(parseBevameterText(editedBevameter("[0.010, 0.013]", "[0.010, 0.025]")));
}
