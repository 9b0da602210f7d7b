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

lab::DirectShearScenario parseShearBoxText(const std::string &text) {
    return lab::parseDirectShear(config::ConfigNode::loadString(text, "direct_shear.yaml"));
}

std::string editedShearBox(const std::string &from, const std::string &to) {
    return replacedOnce(kTinyShearBox, from, to);
}

std::string shearBoxError(const std::string &text) {
    try {
        parseShearBoxText(text);
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
    const double c = 1500.0, psi = 31.0, slope = std::tan(psi * M_PI / 180.0);
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
    CHECK(fit.friction_angle_deg == Approx(std::atan(0.5) * 180 / M_PI).epsilon(1e-9));
    CHECK(fit.friction_angle_se_deg == Approx(se_slope / 1.25 * 180 / M_PI).epsilon(1e-9));
    CHECK(fit.friction_angle_half_width_95_deg ==
          Approx(4.30265273 * fit.friction_angle_se_deg).epsilon(1e-9));
    CHECK(fit.cohesion_Pa == Approx(1000.0).epsilon(1e-9));

    CHECK_THROWS_WITH(lab::fitMohrCoulomb({1000, 2000}, {1, 2}, true), Contains("at least 3"));
    CHECK_THROWS_WITH(lab::fitMohrCoulomb({1000, 1000}, {1, 2}, false), Contains("all normal"));
}

TEST_CASE("Direct shear input errors name the key", "[lab][direct_shear]") {
    CHECK_NOTHROW(parseShearBoxText(kTinyShearBox));
    CHECK_THAT(shearBoxError(editedShearBox("  packing_cache_directory: \"\"\n",
                                            "  packing_cache_directory: \"\"\n  walls: []\n")),
               Contains("remove soil.walls"));
    CHECK_THAT(
        shearBoxError(editedShearBox("max_displacement_m: 0.003", "max_displacement_m: 0.02")),
        Contains("max_displacement_m") && Contains("half the box length"));
    CHECK_THAT(
        shearBoxError(editedShearBox("upper_m: [0.03, 0.03, 0.1]", "upper_m: [0.04, 0.03, 0.1]")),
        Contains("deposition") && Contains("inside the box"));
    CHECK_THAT(shearBoxError(editedShearBox("max_speed_m_s: 0.05, ", "")),
               Contains("max_speed_m_s"));
    CHECK_THAT(
        shearBoxError(editedShearBox("fit_cohesion: false", "fit_cohesion: false\n  speed: 1")),
        Contains("speed"));
}

TEST_CASE("Direct shear on a tiny box: the servo holds sigma and strength grows with it",
          "[lab][direct_shear][dem][slow]") {
    const auto scenario = parseShearBoxText(kTinyShearBox);
    const auto result = lab::runDirectShear(scenario, {});
    REQUIRE(result.runs.size() == 2);
    for (const auto &run : result.runs) {
        INFO("sigma " << run.target_normal_stress_Pa << " Pa: mean N " << run.mean_normal_force_N
                      << " N for " << run.target_force_N << " N, max error "
                      << run.max_normal_force_error);
        // The servo keeps the plate's load near its target while the box shears: the rms of
        // the 2 ms samples' relative errors below 15 % (it bounds the mean error, the lag
        // rise / (T g) of the test below, too). Not every single sample: force-chain collapses
        // put up to 30 % into one whatever the servo (measured worst sample 0.10-0.30 at 4 kPa
        // over seeds 1-6 and two threads, generic and -march=native builds; seed 3: 11.5 /
        // 10.2 %). Measured rms at 4 kPa 4.0-9.5 %, at 12 kPa 0.8-4.0 % over those 16 runs;
        // seed 3, generic / native: 6.0 / 5.7 % and 1.0 / 1.0 %. A plate that stopped following
        // the dilating bed (0.1-0.5 mm against a Hertz estimate of ~3e4 N/m) would be several N
        // off.
        double rms = 0.0;
        for (const auto &s : run.samples)
            rms += std::pow((s.normal_force_N - run.target_force_N) / run.target_force_N, 2) /
                   double(run.samples.size());
        rms = std::sqrt(rms);
        INFO("rms error " << rms);
        CHECK(rms < 0.15);
        CHECK(run.samples.size() == 75); // 3 mm at 20 mm/s in 2 ms samples
    }
    INFO(result.report());
    // Frictional strength grows with the normal stress: a Coulomb line through the origin gives
    // the peak tau at 12 kPa 2.9 times the one at 4 kPa (sigma_n with the grains' weight above
    // the shear plane), no growth 1. The tiny box's envelope curves (its residual angle falls
    // from ~40 deg at 4 kPa to ~32 deg at 12 kPa), so the ratio is ~2: measured 1.81-2.39 over
    // seeds 1-6 and two threads in the generic and -march=native builds (seed 3: 2.23 / 2.27;
    // the check "> 2" written for seed 3 failed in 7 of those 16). Checked: above 1.5.
    CHECK(result.runs[1].peak_shear_stress_Pa > 1.5 * result.runs[0].peak_shear_stress_Pa);
    REQUIRE(result.peak_fit);
    // Friction grains with rolling resistance: a macroscopic angle between 15 and 45 deg.
    CHECK(result.peak_fit->friction_angle_deg > 15.0);
    CHECK(result.peak_fit->friction_angle_deg < 45.0);
    CHECK(result.bed.packing_fraction > 0.45);
    CHECK(result.bed.packing_fraction < 0.65);
}

TEST_CASE("Direct shear: the servo's integral term removes the dilation lag",
          "[lab][direct_shear][dem][slow]") {
    // A proportional servo (u = g e) moves the plate at g times the load error, so over the
    // shearing its mean error is exactly the plate's rise / (T g): the lag behind the dilating
    // bed (physics.md §12.11). With the integral term the mean error is instead the integral's
    // change over the run / (g_I T): about (integral time g / g_I) / (dilation time) of that lag.
    // Both runs shear the tiny box at 4 kPa on a bed settled without rolling resistance: denser
    // than the test above's, it dilates in every realisation (measured over seeds 1-6 in the
    // generic and the -march=native builds: the proportional lag 6-14 %; the test above's looser
    // bed dilates in some realisations and contracts in others, leaving nothing to remove).
    // Measured, seed 3, generic / native build: proportional: mean error +7.0 / +10.6 %, lag
    // 7.0 / 10.6 %; integral gain 0.5 m/(s^2 N) (integral time 20 ms of a 150 ms run): mean
    // error +2.1 / +3.4 % against its own lag 15.2 / 18.7 % (ratio 0.14 / 0.18; 0.02-0.25 over
    // seeds 1-6 in both builds, 0.00 / 0.12 for seed 3 on two threads).
    // Single 2 ms samples are not checked: force-chain collapses put 5-23 % into one sample
    // whatever the servo (integral time 10 samples); the lag is the mean.
    auto text =
        replacedOnce(kTinyShearBox, "    seed: 3\n", "    seed: 3\n    rolling: {model: none}\n");
    text = replacedOnce(text, "normal_stresses_Pa: [4000, 12000]", "normal_stresses_Pa: [4000]");
    const auto scenario = parseShearBoxText(text);
    const auto proportional = lab::runDirectShear(scenario, {});
    const auto integral =
        lab::runDirectShear(parseShearBoxText(replacedOnce(
                                text, "control_interval_s: 0.00025}",
                                "control_interval_s: 0.00025, integral_gain_m_s2_per_N: 0.5}")),
                            {});
    REQUIRE(proportional.runs.size() == 1);
    REQUIRE(integral.runs.size() == 1);
    // Mean relative load error and the proportional lag rise / (T g N_target) of a run.
    const double gain = scenario.test.servo.gain_m_s_per_N;
    const double sample_s = scenario.test.sample_interval_s;
    auto meanError = [](const lab::BoxShearRun &run) {
        return (run.mean_normal_force_N - run.target_force_N) / run.target_force_N;
    };
    auto lag = [&](const lab::BoxShearRun &run) {
        const double duration = double(run.samples.size()) * sample_s;
        return run.samples.back().plate_height_m / (duration * gain * run.target_force_N);
    };
    const auto &p = proportional.runs[0], &pi = integral.runs[0];
    INFO("proportional: mean error " << meanError(p) << ", lag " << lag(p) << "; integral: mean "
                                     << "error " << meanError(pi) << ", lag " << lag(pi));
    // The beds dilate (a lag above 4 %: the plate rises more than 0.2 mm), else this test
    // would have nothing to show.
    CHECK(lag(p) > 0.04);
    CHECK(lag(pi) > 0.04);
    // Proportional: the mean error is the lag, exact but for the one control interval between a
    // measurement and the speed it sets (first and last of 600 intervals: below 1 % of the mean
    // for interval errors up to 4 times it). Measured ratio 0.98-1.01 over 26 runs, both builds.
    CHECK(meanError(p) == Approx(lag(p)).epsilon(0.05));
    // Integral: at most half the lag in either direction. Dilating steadily from the start the
    // ratio is 20 ms / 150 ms = 0.13, from half way 0.27; a servo whose integral term does not
    // act gives 1 (the identity above).
    CHECK(std::abs(meanError(pi)) < 0.5 * lag(pi));
}

TEST_CASE("Direct shear: frictionless spheres are much weaker than phi = 30 deg grains",
          "[lab][direct_shear][dem][slow]") {
    // Same box and packing procedure at 4 kPa; phi = 0 with no rolling resistance against
    // phi = 30 deg with grain-shape rolling resistance (gamma = 20 deg). Strength as the
    // residual (critical-state) friction angle atan(tau / sigma), tau and sigma averaged over the
    // last quarter of the displacement (19 samples), for two deposition seeds: the tiny box's
    // peak is the largest of 75 noisy samples and its two-stress line swung from 17.5 against
    // 36.9 deg (generic build) to 17.3 against 32.3 deg (-march=native), across the old check.
    // Measured at 4 kPa over seeds 1-6, both builds: rough 33.7-44.4 deg, smooth 10.7-16.4 deg,
    // smooth / rough 0.24-0.40 for one seed. Seeds 3 and 4, generic / native build: smooth
    // 13.3, 16.4 / 13.9, 12.9 deg; rough 39.7, 41.5 / 35.4, 39.3 deg; ratio of the means
    // 0.37 / 0.36.
    // Frictionless spheres still interlock geometrically (literature: critical-state
    // psi ~ 5-6 deg; the tiny box's frame edges add to both), so not zero; "much smaller" means
    // at most half the rough grains' angle. Grains whose friction does not act give equal angles.
    const std::string smooth_edit_from = "stick_angle_deg: 30, slip_angle_deg: 30}\n    rolling: "
                                         "{model: grain_shape, aspect_ratio_angle_deg: 20}";
    const std::string smooth_edit_to = "stick_angle_deg: 0, slip_angle_deg: 0}";
    auto residualAngle = [](const lab::DirectShearResult &result) {
        REQUIRE(result.runs.size() == 1);
        const auto &run = result.runs[0];
        return std::atan(run.residual_shear_stress_Pa / run.residual_normal_stress_Pa) * 180.0 /
               M_PI;
    };
    double rough = 0.0, smooth = 0.0;
    for (const char *seed : {"seed: 3", "seed: 4"}) {
        auto text = editedShearBox("seed: 3", seed);
        text =
            replacedOnce(text, "normal_stresses_Pa: [4000, 12000]", "normal_stresses_Pa: [4000]");
        const double r = residualAngle(lab::runDirectShear(parseShearBoxText(text), {}));
        const double s = residualAngle(lab::runDirectShear(
            parseShearBoxText(replacedOnce(text, smooth_edit_from, smooth_edit_to)), {}));
        WARN(seed << ": residual psi rough " << r << " deg, smooth " << s << " deg");
        rough += 0.5 * r;
        smooth += 0.5 * s;
    }
    CHECK(smooth < 0.5 * rough);
    // Both are friction angles of a cohesionless packing of spheres (a broken measurement reads
    // outside): rough 15-50 deg (single seeds measured up to 44.4 deg), smooth above 0.
    CHECK(rough > 15.0);
    CHECK(rough < 50.0);
    CHECK(smooth > 0.0);
}
