// Direct shear box (docs/lab.md, physics.md §12.15).
#include "grainlink/lab/DirectShear.hpp"

#include "TextEdit.hpp"
#include "TinyShearBox.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <string>

using namespace grainlink;
using Catch::Matchers::Contains;

namespace {

constexpr double kPi = 3.14159265358979323846;

lab::DirectShearScenario parse(const std::string &text) {
    return lab::parseDirectShear(config::ConfigNode::loadString(text, "direct_shear.yaml"));
}

std::string edited(const std::string &from, const std::string &to) {
    return replacedOnce(kTinyShearBox, from, to);
}

std::string errorOf(const std::string &text) {
    try {
        parse(text);
    } catch (const std::exception &e) {
        return e.what();
    }
    return "";
}

} // namespace

TEST_CASE("Mohr-Coulomb fit recovers c and psi exactly from points on a line",
          "[lab][direct_shear]") {
    // Points exactly on tau = 1500 Pa + sigma tan 31 deg: least squares must return the line
    // to rounding (1e-9 relative) and zero standard errors (residuals ~1e-12 Pa).
    const double c = 1500.0, psi = 31.0, slope = std::tan(psi * kPi / 180.0);
    std::vector<double> sigma{5000, 10000, 15000, 20000}, tau;
    for (double s : sigma)
        tau.push_back(c + s * slope);
    const auto fit = lab::fitMohrCoulomb(sigma, tau, true);
    CHECK(fit.cohesion_Pa == Approx(c).epsilon(1e-9));
    CHECK(fit.friction_angle_deg == Approx(psi).epsilon(1e-9));
    CHECK(fit.degrees_of_freedom == 2);
    CHECK(fit.friction_angle_se_deg < 1e-9);
    CHECK(fit.cohesion_se_Pa < 1e-6);

    // Through the origin: c = 0 on the same slope.
    std::vector<double> tau0;
    for (double s : sigma)
        tau0.push_back(s * slope);
    const auto fit0 = lab::fitMohrCoulomb(sigma, tau0, false);
    CHECK(fit0.friction_angle_deg == Approx(psi).epsilon(1e-9));
    CHECK(fit0.cohesion_Pa == 0.0);
    CHECK(fit0.degrees_of_freedom == 3);
}

TEST_CASE("Mohr-Coulomb fit: standard errors as the textbook line fit", "[lab][direct_shear]") {
    // Residuals +e, -e, -e, +e about tau = 1000 + 0.5 sigma at sigma = 1, 2, 3, 4 kPa: the slope
    // stays 0.5 (the residuals are symmetric), s^2 = 4 e^2 / 2 and SE(slope) = s / sqrt(Sxx),
    // Sxx = 5e6 Pa^2; the 95 % half width is t(0.975, 2) = 4.303 times the SE (in degrees
    // through d(atan s)/ds = 1 / (1 + s^2)). Tolerance 1e-9 relative (closed form).
    const double e = 100.0;
    std::vector<double> sigma{1000, 2000, 3000, 4000};
    std::vector<double> tau{1000 + 500 + e, 1000 + 1000 - e, 1000 + 1500 - e, 1000 + 2000 + e};
    const auto fit = lab::fitMohrCoulomb(sigma, tau, true);
    const double se_slope = std::sqrt(4 * e * e / 2) / std::sqrt(5e6);
    CHECK(fit.friction_angle_deg == Approx(std::atan(0.5) * 180 / kPi).epsilon(1e-9));
    CHECK(fit.friction_angle_se_deg == Approx(se_slope / 1.25 * 180 / kPi).epsilon(1e-9));
    CHECK(fit.friction_angle_half_width_95_deg ==
          Approx(4.30265273 * fit.friction_angle_se_deg).epsilon(1e-9));
    CHECK(fit.cohesion_Pa == Approx(1000.0).epsilon(1e-9));

    CHECK_THROWS_WITH(lab::fitMohrCoulomb({1000, 2000}, {1, 2}, true), Contains("at least 3"));
    CHECK_THROWS_WITH(lab::fitMohrCoulomb({1000, 1000}, {1, 2}, false), Contains("all normal"));
}

TEST_CASE("Direct shear input errors name the key", "[lab][direct_shear]") {
    CHECK_NOTHROW(parse(kTinyShearBox));
    CHECK_THAT(errorOf(edited("  packing_cache_directory: \"\"\n",
                              "  packing_cache_directory: \"\"\n  walls: []\n")),
               Contains("remove soil.walls"));
    CHECK_THAT(errorOf(edited("max_displacement_m: 0.003", "max_displacement_m: 0.02")),
               Contains("max_displacement_m") && Contains("half the box length"));
    CHECK_THAT(errorOf(edited("upper_m: [0.03, 0.03, 0.1]", "upper_m: [0.04, 0.03, 0.1]")),
               Contains("deposition") && Contains("inside the box"));
    CHECK_THAT(errorOf(edited("max_speed_m_s: 0.05, ", "")), Contains("max_speed_m_s"));
    CHECK_THAT(errorOf(edited("fit_cohesion: false", "fit_cohesion: false\n  speed: 1")),
               Contains("speed"));
}

TEST_CASE("Direct shear on a tiny box: the servo holds sigma and strength grows with it",
          "[lab][direct_shear][dem]") {
    const auto scenario = parse(kTinyShearBox);
    const auto result = lab::runDirectShear(scenario, {});
    REQUIRE(result.runs.size() == 2);
    for (const auto &run : result.runs) {
        INFO("sigma " << run.target_normal_stress_Pa << " Pa: mean N " << run.mean_normal_force_N
                      << " N for " << run.target_force_N << " N, max error "
                      << run.max_normal_force_error);
        // The servo keeps the plate's load within 15 % of its target in every 2 ms sample while
        // the box shears, and within 5 % on average over the shearing: a proportional servo
        // lags a dilating bed by (dilation speed) / gain, measured here up to 0.4 N of 3.6 N.
        CHECK(run.max_normal_force_error < 0.15);
        CHECK(run.mean_normal_force_N == Approx(run.target_force_N).epsilon(0.05));
        CHECK(run.samples.size() == 75); // 3 mm at 20 mm/s in 2 ms samples
    }
    INFO(result.report());
    // Frictional strength: three times the normal stress must carry clearly more than twice
    // the peak shear stress (a Coulomb material gives three times; > 2x leaves room for the
    // scatter of a 400-grain box).
    CHECK(result.runs[1].peak_shear_stress_Pa > 2.0 * result.runs[0].peak_shear_stress_Pa);
    REQUIRE(result.peak_fit);
    // Friction grains with rolling resistance: a macroscopic angle between 15 and 45 deg.
    CHECK(result.peak_fit->friction_angle_deg > 15.0);
    CHECK(result.peak_fit->friction_angle_deg < 45.0);
    CHECK(result.packing_fraction > 0.45);
    CHECK(result.packing_fraction < 0.65);
}

TEST_CASE("Direct shear: the servo's integral term removes the dilation lag",
          "[lab][direct_shear][dem]") {
    // The tiny box at 4 kPa with the proportional servo trails the dilating bed (measured:
    // worst sample 11.5 % off, mean +4.3 %, in the test above). With an integral gain of
    // 0.5 m/(s^2 N) (integral time gain / integral gain = 20 ms, 80 control intervals) the lag
    // goes: measured worst sample 6.3 %, mean +0.9 %. Checked: worst below 8 %, mean within 2 %.
    auto text = edited("control_interval_s: 0.00025}",
                       "control_interval_s: 0.00025, integral_gain_m_s2_per_N: 0.5}");
    text = replacedOnce(text, "normal_stresses_Pa: [4000, 12000]", "normal_stresses_Pa: [4000]");
    const auto result = lab::runDirectShear(parse(text), {});
    REQUIRE(result.runs.size() == 1);
    const auto &run = result.runs[0];
    INFO("mean N " << run.mean_normal_force_N << " N, worst " << run.max_normal_force_error);
    CHECK(run.max_normal_force_error < 0.08);
    CHECK(run.mean_normal_force_N == Approx(run.target_force_N).epsilon(0.02));
}

TEST_CASE("Direct shear: frictionless spheres are much weaker than phi = 30 deg grains",
          "[lab][direct_shear][dem]") {
    // Same box, stresses and packing procedure; phi = 0 with no rolling resistance against
    // phi = 30 deg with grain-shape rolling resistance.
    const auto rough = lab::runDirectShear(parse(kTinyShearBox), {});
    const auto smooth = lab::runDirectShear(
        parse(edited("stick_angle_deg: 30, slip_angle_deg: 30}\n    rolling: {model: "
                     "grain_shape, aspect_ratio_angle_deg: 20}",
                     "stick_angle_deg: 0, slip_angle_deg: 0}")),
        {});
    REQUIRE(rough.peak_fit);
    REQUIRE(smooth.peak_fit);
    INFO("psi rough " << rough.peak_fit->friction_angle_deg << " deg, smooth "
                      << smooth.peak_fit->friction_angle_deg << " deg");
    // Frictionless spheres still interlock geometrically (literature: psi ~ 5-10 deg), so not
    // zero; "much smaller" here means at most half of the rough grains' angle.
    CHECK(smooth.peak_fit->friction_angle_deg < 0.5 * rough.peak_fit->friction_angle_deg);
}
