// Virtual bevameter, shear annulus (docs/lab.md, physics.md §12.12): the annulus mesh, the
// Janosi-Hanamoto fit, tau(j) on a tiny bed and the input checks.
#include "grainlink/lab/ShearAnnulus.hpp"

#include "TextEdit.hpp"
#include "TinyBed.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <random>
#include <string>

using namespace grainlink;
using Catch::Matchers::Contains;

namespace {

/// A tiny bed: 2300 grains of 1.5 mm radius in a 60 mm box (~15 mm deep); an annulus of 12 and
/// 22 mm radius with eight 3 mm grousers (Gamma = width / grain diameter = 3.3 instead of the
/// seed's 10, min_resolution lowered, to keep each run at a few seconds), turned at 4 rad/s to
/// j = 12 mm (0.7 rad). Rolling resistance stands in for grain shape, as in the bevameter test.
const std::string kTinyAnnulus =
    "name: tiny-shear\n" + tinyBinSoil("0.06", "0.04", "2300") + R"(bevameter_shear:
  inner_radius_m: 0.012
  outer_radius_m: 0.022
  grouser_count: 8
  grouser_height_m: 0.003
  normal_pressures_Pa: [1000, 2000]
  angular_speed_rad_s: 4
  max_shear_displacement_m: 0.012
  approach_speed_m_s: 0.05
  servo: {gain_m_s_per_N: 0.1, integral_gain_m_s2_per_N: 5, max_speed_m_s: 0.05}
  sample_interval_s: 0.001
  min_resolution: 3
)";

lab::ShearAnnulusScenario parseAnnulusText(const std::string &text) {
    return lab::parseShearAnnulus(config::ConfigNode::loadString(text, "shear.yaml"));
}

std::string editedAnnulus(const std::string &from, const std::string &to) {
    return replacedOnce(kTinyAnnulus, from, to);
}

/// Mean shear stress of the samples with j in [from, to) x j_max.
double meanStress(const lab::ShearRun &run, double from, double to, double j_max) {
    double sum = 0.0;
    int count = 0;
    for (const auto &s : run.samples)
        if (s.shear_displacement_m >= from * j_max && s.shear_displacement_m < to * j_max) {
            sum += s.shear_stress_Pa;
            ++count;
        }
    REQUIRE(count > 0);
    return sum / count;
}

/// tau(j) curves from known parameters, 60 points each to j = 10 mm, Gaussian noise.
std::vector<lab::ShearCurve> syntheticShearCurves(const lab::JanosiParameters &p,
                                                  const std::vector<double> &pressures,
                                                  double noise_Pa, unsigned seed) {
    std::mt19937 random(seed);
    std::normal_distribution<double> noise(0.0, noise_Pa);
    std::vector<lab::ShearCurve> curves;
    for (double sigma : pressures) {
        lab::ShearCurve c;
        c.normal_pressure_Pa = sigma;
        for (int i = 1; i <= 60; ++i) {
            const double j = 0.01 * i / 60.0;
            c.shear_displacement_m.push_back(j);
            c.shear_stress_Pa.push_back(p.shearStress(sigma, j) +
                                        (noise_Pa > 0.0 ? noise(random) : 0.0));
        }
        curves.push_back(c);
    }
    return curves;
}

} // namespace

TEST_CASE("Shear annulus mesh is closed, wound outward, with the expected volume",
          "[lab][shear_annulus]") {
    lab::AnnulusGeometry g;
    g.inner_radius_m = 0.03;
    g.outer_radius_m = 0.05;
    g.grouser_count = 6;
    g.grouser_height_m = 0.004;
    g.grouser_thickness_m = 0.002;
    g.ring_thickness_m = 0.005;
    g.ring_segments = 36;
    const auto mesh = lab::makeShearAnnulus(g);
    // Signed volume sum over triangles of a . (b x c) / 6: positive and equal to the parts'
    // volumes only if every part is closed and wound outward. The grousers overlap the ring by
    // half its thickness; a union of closed parts counts the overlap twice, so the expected
    // value is the sum of the parts: polygonal ring (n/2 sin(2 pi/n)(R_o^2 - R_i^2) t) plus
    // N boxes (R_o - R_i) w (h + t/2). Rounding only: 1e-12 relative.
    double volume = 0.0;
    for (const auto &t : mesh.triangles)
        volume +=
            mesh.vertices_m[t[0]].dot(mesh.vertices_m[t[1]].cross(mesh.vertices_m[t[2]])) / 6.0;
    const double n = g.ring_segments;
    const double ring = 0.5 * n * std::sin(2 * M_PI / n) * (0.05 * 0.05 - 0.03 * 0.03) * 0.005;
    const double grousers = 6 * 0.02 * 0.002 * (0.004 + 0.0025);
    CHECK(volume == Approx(ring + grousers).epsilon(1e-12));
    // The grouser tips are the lowest points, at -h; the ring's top at t.
    double z_min = 1.0, z_max = -1.0;
    for (const auto &v : mesh.vertices_m) {
        z_min = std::min(z_min, v.z());
        z_max = std::max(z_max, v.z());
    }
    CHECK(z_min == Approx(-0.004).epsilon(1e-12));
    CHECK(z_max == Approx(0.005).epsilon(1e-12));
    // Area and torque factor, closed forms (physics.md §12.12).
    CHECK(g.area_m2() == Approx(M_PI * (0.0025 - 0.0009)).epsilon(1e-14));
    CHECK(g.torqueFactor_m3() == Approx(2 * M_PI / 3 * (1.25e-4 - 2.7e-5)).epsilon(1e-14));
    CHECK(g.meanRadius_m() == Approx(0.04).epsilon(1e-14));
}

TEST_CASE("Janosi fit recovers c, phi and K from syntheticShearCurves curves",
          "[lab][shear_annulus]") {
    lab::JanosiParameters truth;
    truth.cohesion_Pa = 800.0;
    truth.friction_angle_deg = 31.0;
    truth.shear_modulus_m = 0.0015;
    const std::vector<double> pressures{2000.0, 4000.0, 8000.0};

    SECTION("noise-free: exact to 1e-6 (Levenberg-Marquardt's tolerance, far below any use)") {
        const auto fit = lab::fitJanosi(syntheticShearCurves(truth, pressures, 0.0, 1));
        CHECK(fit.parameters.cohesion_Pa == Approx(800.0).epsilon(1e-6));
        CHECK(fit.parameters.friction_angle_deg == Approx(31.0).epsilon(1e-6));
        CHECK(fit.parameters.shear_modulus_m == Approx(0.0015).epsilon(1e-6));
        CHECK(fit.rms_residual_Pa < 1e-6);
        CHECK(fit.points == 180);
        CHECK(fit.degrees_of_freedom == 177);
    }
    SECTION("with noise the 95 % intervals cover the truth at their nominal rate") {
        // 100 data sets with 50 Pa noise: each parameter's interval misses the truth about 5
        // times; binomial(100, 0.05) gives 5 +- 2.2, so 0..12 passes (p < 0.001 outside) and a
        // covariance wrong by a factor 1.5 in SE (misses ~ 25) fails. The noise itself is
        // estimated: the rms residual must be 50 Pa within 20 % (180 points: its relative scatter
        // is 1 / sqrt(2 x 177) = 5.3 %, so 20 % is 3.8 standard deviations).
        int misses[3] = {0, 0, 0};
        for (unsigned seed = 1; seed <= 100; ++seed) {
            const auto fit = lab::fitJanosi(syntheticShearCurves(truth, pressures, 50.0, seed));
            const double est[3] = {fit.parameters.cohesion_Pa, fit.parameters.friction_angle_deg,
                                   fit.parameters.shear_modulus_m};
            const double tru[3] = {800.0, 31.0, 0.0015};
            for (int k = 0; k < 3; ++k)
                misses[k] += std::abs(est[k] - tru[k]) > fit.half_width_95[k];
            CHECK(fit.rms_residual_Pa == Approx(50.0).epsilon(0.2));
        }
        for (int k = 0; k < 3; ++k) {
            INFO("parameter " << k << ": " << misses[k] << " misses of 100");
            CHECK(misses[k] <= 12);
        }
    }
    SECTION("one normal pressure cannot separate c and phi: refused") {
        CHECK_THROWS_WITH(lab::fitJanosi(syntheticShearCurves(truth, {4000.0}, 0.0, 1)),
                          Contains("two or more normal pressures"));
    }
}

TEST_CASE("Shear annulus on a tiny bed: load held, tau(j) rises and saturates, higher sigma "
          "gives higher tau_max",
          "[lab][shear_annulus][slow]") {
    const auto scenario = parseAnnulusText(kTinyAnnulus);
    const auto result = lab::runShearAnnulus(scenario, {});
    INFO(result.report());
    REQUIRE(result.runs.size() == 2);
    const double j_max = scenario.test.max_shear_displacement_m;
    for (const auto &run : result.runs) {
        INFO("sigma = " << run.target_pressure_Pa << " Pa");
        // The servo is proportional-integral (physics.md §12.11): the integral term takes up
        // the steady sinkage of the shearing annulus, which a proportional servo would lag by
        // v / gain (~10 % of the load here). So: the mean normal pressure while shearing
        // within 5 % of the target, the rms deviation of the 1 ms means (grains rattle; the
        // rotation's start makes the bed yield) below 12 %. Written: 1000.3 and 2001.7 Pa,
        // rms 6.0 % and 2.4 %.
        CHECK(run.mean_pressure_Pa == Approx(run.target_pressure_Pa).epsilon(0.05));
        CHECK(run.rms_load_error < 0.12);
        // tau(j) rises: the mean over the first 10 % of j is below 3/4 of the mean over the
        // second half. It saturates: the third and fourth quarters' means agree within 20 %
        // of the second half's mean (the single 1 ms samples scatter by ~30 %).
        const double early = meanStress(run, 0.0, 0.1, j_max);
        const double late = meanStress(run, 0.5, 1.01, j_max);
        CHECK(early < 0.75 * late);
        const double q3 = meanStress(run, 0.5, 0.75, j_max),
                     q4 = meanStress(run, 0.75, 1.01, j_max);
        CHECK(std::abs(q4 - q3) < 0.2 * late);
    }
    // Twice the normal pressure, a clearly higher strength: tau_max at 2 kPa above 1.3 x that
    // at 1 kPa (written: 735 and 1256 Pa, 1.71 x; the fit c = 155 Pa, phi = 24.3 deg).
    CHECK(result.runs[1].max_shear_stress_Pa > 1.3 * result.runs[0].max_shear_stress_Pa);
    REQUIRE(result.fit);
    WARN(result.report());
    // The law describes the curves: K well inside the run (saturated by j_max) and the rms
    // residual below a third of the larger tau_max (single samples scatter ~30 %).
    CHECK(result.fit->parameters.shear_modulus_m < 0.25 * j_max);
    CHECK(result.fit->rms_residual_Pa < result.runs[1].max_shear_stress_Pa / 3.0);
}

TEST_CASE("Shear annulus: frictionless grains carry a much smaller tau_max than 30 degree ones",
          "[lab][shear_annulus][slow]") {
    // Same bed and load (1 kPa); frictionless grains without rolling resistance (the annulus
    // takes the grains' friction, so it is frictionless too) resist only through the grousers
    // pushing grains aside. Written: 195 Pa against 735 Pa (ratio 0.26); required below 0.6,
    // which a frictionless bed that still carried 60 % of the frictional strength would fail.
    auto one = [](const std::string &text) {
        auto scenario = parseAnnulusText(text);
        return lab::runShearAnnulus(scenario, {}).runs.at(0).max_shear_stress_Pa;
    };
    const std::string frictional = editedAnnulus("[1000, 2000]", "[1000]");
    const std::string frictionless =
        replacedOnce(replacedOnce(frictional, "stick_angle_deg: 32, slip_angle_deg: 30",
                                  "stick_angle_deg: 0, slip_angle_deg: 0"),
                     "{model: epsd, coefficient: 0.3}", "{model: none}");
    const double with_friction = one(frictional), without = one(frictionless);
    WARN("tau_max " << without << " Pa frictionless vs " << with_friction << " Pa at 30 deg");
    CHECK(without < 0.6 * with_friction);
}

TEST_CASE("Shear annulus input errors name the key and the line", "[lab][shear_annulus]") {
    CHECK_THROWS_WITH(parseAnnulusText(editedAnnulus("min_resolution: 3", "min_resolution: 5")),
                      Contains("shear.yaml:21:") && Contains("bevameter_shear.outer_radius_m") &&
                          Contains("Gamma = 3.33"));
    CHECK_THROWS_WITH(
        parseAnnulusText(editedAnnulus("outer_radius_m: 0.022", "outer_radius_m: 0.010")),
        Contains("bevameter_shear.outer_radius_m") && Contains("must exceed inner_radius_m"));
    // An annulus wider than the 60 mm bed.
    CHECK_THROWS_WITH(
        parseAnnulusText(editedAnnulus("outer_radius_m: 0.022", "outer_radius_m: 0.031")),
        Contains("bevameter_shear.outer_radius_m") &&
            Contains("annulus of radius 31 mm about (30, 30) mm reaches past the bed"));
    CHECK_THROWS_WITH(parseAnnulusText(editedAnnulus("[1000, 2000]", "[1000, -5]")),
                      Contains("bevameter_shear.normal_pressures_Pa") && Contains("> 0"));
    CHECK_THROWS_WITH(parseAnnulusText(editedAnnulus("gain_m_s_per_N: 0.1, ", "")),
                      Contains("missing key 'bevameter_shear.servo.gain_m_s_per_N'"));
    CHECK_THROWS_WITH(parseAnnulusText(editedAnnulus("  min_resolution: 3\n",
                                                     "  min_resolution: 3\n  torque: 1\n")),
                      Contains("unknown key 'bevameter_shear.torque'"));
}
