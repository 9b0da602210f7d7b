// Angle of repose, lifted-cylinder test (docs/lab.md, physics.md §12.10).
#include "grainlink/lab/Repose.hpp"

#include "TextEdit.hpp"
#include "TinyRepose.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <string>

using namespace grainlink;
using Catch::Matchers::Contains;

namespace {

lab::ReposeScenario parseReposeText(const std::string &text) {
    return lab::parseRepose(config::ConfigNode::loadString(text, "repose.yaml"));
}

std::string editedRepose(const std::string &from, const std::string &to) {
    return replacedOnce(kTinyRepose, from, to);
}

} // namespace

TEST_CASE("Heap measurement recovers the angle of a packed cone", "[lab][repose]") {
    // Grains of r = 1 mm on a simple cubic lattice filling a cone of 30 deg, 40 mm high, on the
    // floor. The profile's bin maxima follow the cone to within a lattice step, so the fitted
    // angle must be 30 deg within 1.5 deg (lattice steps over a ~40 mm flank).
    const double r = 0.001, angle = 30.0 * M_PI / 180.0, height = 0.04;
    std::vector<Eigen::Vector3d> positions;
    std::vector<double> radii;
    for (double x = -0.08; x <= 0.08; x += 2 * r)
        for (double y = -0.08; y <= 0.08; y += 2 * r)
            for (double z = r; z + r <= height; z += 2 * r)
                if (z + r <= height - std::hypot(x, y) * std::tan(angle)) {
                    positions.emplace_back(x, y, z);
                    radii.push_back(r);
                }
    lab::ReposeResult result;
    lab::measureHeap(positions, radii, Eigen::Vector2d::Zero(), 2 * r, result);
    INFO(result.report());
    CHECK(result.angle_deg == Approx(30.0).margin(1.5));
    CHECK(result.heap_height_m == Approx(height).margin(2 * r));
    CHECK(result.flank_bins >= 10);
}

TEST_CASE("Grains spread flat are no heap: a result with its profile, not an error",
          "[lab][repose]") {
    // Two layers of r = 1 mm grains over a 60 mm disc: the top is 4 mm everywhere, so no bin
    // lies between 20 % and 80 % of it above 3 r_max. Frictionless spheres end like this; the
    // test must report it (angle NaN) and keep the profile instead of failing.
    const double r = 0.001;
    std::vector<Eigen::Vector3d> positions;
    std::vector<double> radii;
    for (double x = -0.03; x <= 0.03; x += 2 * r)
        for (double y = -0.03; y <= 0.03; y += 2 * r)
            for (double z : {r, 3 * r})
                if (std::hypot(x, y) <= 0.03) {
                    positions.emplace_back(x, y, z);
                    radii.push_back(r);
                }
    lab::ReposeResult result;
    lab::measureHeap(positions, radii, Eigen::Vector2d::Zero(), 2 * r, result);
    INFO(result.report());
    CHECK_FALSE(result.heapFormed());
    CHECK(std::isnan(result.angle_deg));
    CHECK(result.heap_height_m == Approx(4 * r));
    CHECK(result.profile.size() >= 15);
    CHECK_THAT(result.report(), Contains("no heap"));
}

TEST_CASE("Angle of repose: more rolling resistance builds a steeper heap", "[lab][repose][slow]") {
    // The same 600 grains with rolling resistance 0.3 and 0.1, each filled from three deposition
    // seeds. Grain shape (here its stand-in) is what holds a heap of spheres up, so the 0.3 heaps
    // must be steeper on average by more than the two 95 % intervals of the means together
    // (each mean's half width sqrt(sum w_i^2) / 3 from the seeds' slope-regression half widths
    // w_i: independent heaps). Equal rolling resistance (a law that does not act) gives a
    // difference around zero.
    // One heap of 600 grains is one realisation: seed 3 alone with 2 r_max bins gave 29.8 +- 2.1
    // against 10.1 +- 4.4 deg in the generic build and 22.3 +- 7.8 against 11.9 +- 3.5 deg with
    // -march=native, across the check. Measured with these settings over seeds 1, 2, 4-9, both
    // builds: 0.3 heaps 19.3-27.5 deg, 0.1 heaps 8.1-12.5 deg; a single seed failed the check
    // once in 16 (8.4 against 9.1 deg), three-seed means pass for every choice of three with a
    // margin of 2.1x or more. Seeds 1, 2, 4, generic / native build: 25.2 +- 2.0 against
    // 10.9 +- 1.3 deg / 23.7 +- 2.1 against 10.7 +- 1.8 deg; on two threads 22.9 +- 2.6 against
    // 10.0 +- 1.6 deg / 22.6 +- 2.5 against 9.8 +- 2.3 deg.
    struct Mean {
        double angle_deg = 0.0, half_width_sq = 0.0;
    };
    Mean steep, flat;
    const char *seeds[] = {"seed: 1", "seed: 2", "seed: 4"};
    for (const char *seed : seeds) {
        const std::string text = editedRepose("seed: 3", seed);
        const auto s = lab::runRepose(parseReposeText(text), {});
        const auto f = lab::runRepose(
            parseReposeText(replacedOnce(text, "rolling: {model: epsd, coefficient: 0.3}",
                                         "rolling: {model: epsd, coefficient: 0.1}")),
            {});
        WARN(seed << "\n" << s.report() << f.report());
        steep.angle_deg += s.angle_deg / 3.0;
        steep.half_width_sq += s.angle_half_width_95_deg * s.angle_half_width_95_deg / 9.0;
        flat.angle_deg += f.angle_deg / 3.0;
        flat.half_width_sq += f.angle_half_width_95_deg * f.angle_half_width_95_deg / 9.0;
    }
    INFO("mean angles " << steep.angle_deg << " +- " << std::sqrt(steep.half_width_sq) << " and "
                        << flat.angle_deg << " +- " << std::sqrt(flat.half_width_sq) << " deg");
    CHECK(steep.angle_deg - flat.angle_deg >
          std::sqrt(steep.half_width_sq) + std::sqrt(flat.half_width_sq));
    // Both are heaps of spheres: between 5 and 45 deg (beyond it the measurement is broken).
    CHECK(steep.angle_deg > 5.0);
    CHECK(steep.angle_deg < 45.0);
    CHECK(flat.angle_deg > 0.0);
}

TEST_CASE("Repose input errors name the key and the line", "[lab][repose]") {
    CHECK_THROWS_WITH(parseReposeText(editedRepose("tube_radius_m: 0.021", "tube_radius_m: 0.015")),
                      Contains("repose.yaml:19:") && Contains("repose.tube_radius_m") &&
                          Contains("inside the tube"));
    CHECK_THROWS_WITH(parseReposeText(editedRepose("lift_speed_m_s: 0.1", "lift_speed_m_s: 0")),
                      Contains("repose.lift_speed_m_s") && Contains("must be > 0"));
    CHECK_THROWS_WITH(parseReposeText(editedRepose("tube_height_m", "tube_height_mm")),
                      Contains("wrong unit"));
}
