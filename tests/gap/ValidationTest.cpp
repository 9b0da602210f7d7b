#include "grainlink/gap/Validation.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <random>

using namespace grainlink::gap;

namespace {

Measured oneFeature(double value, double u_D, bool repeats) {
    Measured m;
    m.keys = {{"e1", "pressure_Pa", "plate/pressure_Pa", 0.0, 0.002}};
    m.value = Eigen::VectorXd::Constant(1, value);
    m.u_D = Eigen::VectorXd::Constant(1, u_D);
    m.trials = Eigen::VectorXi::Constant(1, 1);
    m.from_repeats = {repeats};
    return m;
}

/// Six bins of one experiment, each measured at 100 from three repeats.
Measured sixBinMeasurement() {
    Measured m;
    for (int b = 0; b < 6; ++b)
        m.keys.push_back({"e", "p", "k", 0.001 * b, 0.001 * (b + 1)});
    m.value = Eigen::VectorXd::Constant(6, 100.0);
    m.u_D = Eigen::VectorXd::Constant(6, 1.0);
    m.trials = Eigen::VectorXi::Constant(6, 3);
    m.from_repeats.assign(6, true);
    return m;
}

} // namespace

TEST_CASE("u_val combines the seeds, one bed's scatter, the checks and the measurement",
          "[gap][validation]") {
    // Hand calculation (docs/gap.md, V&V 20): seeds 1.0 1.2 0.8 1.0 -> mean 1, sd 0.1633,
    // u_seed = sd/2; no repeats -> u_bed = sd; a resolution check at 1.3 on seeds 1 and 2
    // -> paired differences 0.3 and 0.1, mean 0.2, the variance of that mean 0.02 / 2:
    // u_res = sqrt(0.04 - 0.01).
    Eigen::MatrixXd base(4, 1);
    base << 1.0, 1.2, 0.8, 1.0;
    Eigen::MatrixXd check(2, 1);
    check << 1.3, 1.3;
    const auto v = validate(oneFeature(1.5, 0.1, false), base, {{"resolution", check}});
    const double sd = std::sqrt(0.08 / 3.0);
    CHECK(v.seed_sd[0] == Approx(sd));
    CHECK(v.u_seed[0] == Approx(sd / 2.0));
    CHECK(v.u_bed[0] == Approx(sd));
    const double u_res = std::sqrt(0.04 - 0.01);
    CHECK(v.u_checks.at(0).second[0] == Approx(u_res));
    // One check seed: no pair to measure the difference's scatter; the pooled scatter of the
    // two means stands in, sd^2 (1 + 1/4): sqrt(0.09 - 1.25 sd^2).
    Eigen::MatrixXd one(1, 1);
    one << 1.3;
    CHECK(validate(oneFeature(1.5, 0.1, false), base, {{"resolution", one}})
              .u_checks.at(0)
              .second[0] == Approx(std::sqrt(0.09 - 1.25 * 0.08 / 3.0)));
    CHECK(v.u_num[0] == Approx(std::sqrt(sd * sd / 4.0 + u_res * u_res)));
    CHECK(v.u_val[0] == Approx(std::sqrt(sd * sd / 4.0 + u_res * u_res + sd * sd + 0.01)));
    CHECK(v.ratio[0] == Approx(1.0 / 1.5));
    // With repeats the measured scatter already holds the bed's: no u_bed.
    CHECK(validate(oneFeature(1.5, 0.1, true), base, {}).u_bed[0] == 0.0);
}

TEST_CASE("a numerical check's systematic part: found when it shifts or reshapes the curve, "
          "near zero when it does not",
          "[gap][validation]") {
    // Six bins of one experiment, beds moving the whole curve (level sd 10 %), three base seeds
    // and two check seeds. A check that lowers everything by 30 % is found at about 30 %, as is
    // one that raises the first three bins by 30 % and lowers the last three by 30 % (a signed
    // mean of the differences saw none of it); one that changes nothing contributes about half
    // the noise of the difference on average (the positive part of d^2 - var d), not the noise.
    const Measured m = sixBinMeasurement();
    std::mt19937 rng(5);
    std::normal_distribution<double> z;
    double shifted = 0.0, still = 0.0, reshaped = 0.0;
    const int draws = 400;
    for (int d = 0; d < draws; ++d) {
        Eigen::MatrixXd base(3, 6), same(2, 6), lower(2, 6), tilted(2, 6);
        for (int s = 0; s < 3; ++s) {
            const double level = 1.0 + 0.1 * z(rng);
            for (int b = 0; b < 6; ++b)
                base(s, b) = 100.0 * level * (1.0 + 0.02 * z(rng));
        }
        for (int s = 0; s < 2; ++s) {
            const double level = 1.0 + 0.1 * z(rng);
            for (int b = 0; b < 6; ++b) {
                same(s, b) = 100.0 * level * (1.0 + 0.02 * z(rng));
                lower(s, b) = 0.7 * same(s, b);
                tilted(s, b) = (b < 3 ? 1.3 : 0.7) * same(s, b);
            }
        }
        still += validate(m, base, {{"time_step", same}}).u_checks[0].second[2] / draws;
        shifted += validate(m, base, {{"time_step", lower}}).u_checks[0].second[2] / draws;
        reshaped += validate(m, base, {{"time_step", tilted}}).u_checks[0].second[2] / draws;
    }
    // The seed noise of a 3-vs-2 mean difference of one level is 10 % x sqrt(1/3 + 1/2) = 9 %.
    CHECK(still < 7.0);
    CHECK(shifted == Approx(30.0).margin(6.0));
    CHECK(reshaped == Approx(30.0).margin(6.0));
}

TEST_CASE("one measured bed against three simulated: the residual's z holds its level",
          "[gap][validation]") {
    // One trial (no repeats) and three seeds, all of one soil: the residual over u_val is
    // Student's t of 2 degrees of freedom, the seeds' sd counted once though it gives both
    // u_seed and u_bed. Counted as two estimates (3.2 degrees of freedom), |z| > 1.96 came out
    // in about 9 % of draws instead of 5 %.
    std::mt19937 rng(3);
    std::normal_distribution<double> z;
    int beyond = 0;
    const int draws = 4000;
    for (int d = 0; d < draws; ++d) {
        Eigen::MatrixXd base(3, 1);
        base << 10.0 + z(rng), 10.0 + z(rng), 10.0 + z(rng);
        const auto v = validate(oneFeature(10.0 + z(rng), 0.0, false), base, {});
        beyond += std::abs(v.z[0]) > 1.96;
    }
    INFO("share beyond 1.96: " << double(beyond) / draws);
    CHECK(double(beyond) / draws == Approx(0.05).margin(0.012));
}

TEST_CASE("a check on the base's own beds (the loading rate) is measured by its paired "
          "differences, not lost in the beds' scatter",
          "[gap][validation]") {
    // The rate check leaves the packing as it is: check seed j runs on base seed j's bed. Beds
    // move the curve by 10 %, the slower loading lowers it by 5 % (and a run's own noise is
    // 0.5 %). Taken as independent beds, 9 % of noise was subtracted from a 5 % shift, and the
    // check read 0 in most draws.
    const Measured m = sixBinMeasurement();
    std::mt19937 rng(7);
    std::normal_distribution<double> z;
    double found = 0.0;
    const int draws = 200;
    for (int d = 0; d < draws; ++d) {
        Eigen::MatrixXd base(3, 6), rate(2, 6);
        for (int s = 0; s < 3; ++s) {
            const double level = 1.0 + 0.1 * z(rng);
            for (int b = 0; b < 6; ++b) {
                base(s, b) = 100.0 * level * (1.0 + 0.005 * z(rng));
                if (s < 2)
                    rate(s, b) = 0.95 * 100.0 * level * (1.0 + 0.005 * z(rng));
            }
        }
        found += validate(m, base, {{"rate", rate}}).u_checks[0].second[2] / draws;
    }
    CHECK(found == Approx(5.0).margin(0.6));
}

TEST_CASE("a numerical check's systematic part is not set by a bin near zero",
          "[gap][validation]") {
    // Six bins, the first at 1 (a plate's first millimetre), the rest at 100; the check moves
    // the first by 1 (100 % of it) and nothing else. Its part is sqrt(1 / (1 + 5 * 100^2)) of
    // each bin's value: 0.45 at 100 (a mean of relative differences gave 41 %, 41 at 100).
    const Measured m = sixBinMeasurement();
    Eigen::MatrixXd base = Eigen::MatrixXd::Constant(3, 6, 100.0), check(2, 6);
    base.col(0).setConstant(1.0);
    check = base.topRows(2);
    check.col(0).setConstant(2.0);
    const auto u = validate(m, base, {{"resolution", check}}).u_checks[0].second;
    CHECK(u[3] == Approx(100.0 / std::sqrt(1.0 + 5.0 * 1e4)).epsilon(1e-9));
    CHECK(u[0] == Approx(1.0 / std::sqrt(1.0 + 5.0 * 1e4)).epsilon(1e-9));
}

TEST_CASE("standardised residuals of a matching model are about unit normal",
          "[gap][validation]") {
    // Monte Carlo: the truth and the simulation are the same process (bed scatter 1), the
    // simulation has 4 seeds, the measurement one bed plus instrument noise 0.5 (stated).
    // If u_val is right, |e| <= 2 about 92-95 % of the time (a little less than the normal's
    // 95.4 % because the scatter is estimated from 4 seeds).
    std::mt19937 rng(7);
    std::normal_distribution<double> bed(10.0, 1.0), instrument(0.0, 0.5);
    int within = 0;
    const int draws = 4000;
    for (int d = 0; d < draws; ++d) {
        Eigen::MatrixXd base(4, 1);
        for (int s = 0; s < 4; ++s)
            base(s, 0) = bed(rng);
        const double meas = bed(rng) + instrument(rng);
        const auto v = validate(oneFeature(meas, 0.5, false), base, {});
        within += std::abs(v.standardised[0]) <= 2.0;
    }
    const double share = double(within) / draws;
    CHECK(share > 0.88);
    CHECK(share < 0.97);
}

TEST_CASE("the gap test holds its false-alarm rate with independent or fully correlated features",
          "[gap][validation]") {
    std::vector<FeatureKey> keys;
    for (int e = 0; e < 6; ++e)
        for (int b = 0; b < 5; ++b)
            keys.push_back({"exp" + std::to_string(e), "p", "plate/p", 0.002 * b, 0.002 * (b + 1)});
    std::mt19937 rng(11);
    std::normal_distribution<double> z;
    int alarms_independent = 0, alarms_correlated = 0;
    const int draws = 3000;
    for (int d = 0; d < draws; ++d) {
        Eigen::VectorXd ind(30), cor(30);
        for (int e = 0; e < 6; ++e) {
            const double shared = z(rng);
            for (int b = 0; b < 5; ++b) {
                ind[5 * e + b] = z(rng);
                cor[5 * e + b] = shared;
            }
        }
        alarms_independent += testGap(keys, ind).gap;
        alarms_correlated += testGap(keys, cor).gap;
    }
    // Family-wise level 5 %: Bonferroni is conservative, so the rate is at most about that.
    CHECK(double(alarms_independent) / draws < 0.06);
    CHECK(double(alarms_correlated) / draws < 0.06);

    // Many features moderately off (half of them at 2.5 u_val): (a) and (b) miss it, (c) not.
    Eigen::VectorXd half = Eigen::VectorXd::Zero(30);
    for (int k = 0; k < 30; k += 2)
        half[k] = 2.5;
    const GapVerdict h = testGap(keys, half);
    CHECK(h.max_abs < h.feature_bound);
    CHECK(h.worst_rms < h.experiment_bound);
    CHECK(h.gap);

    // A consistent 3 u_val gap on every feature, and one feature 6 u_val out, are gaps; a
    // consistent 1.5 is not.
    CHECK(testGap(keys, Eigen::VectorXd::Constant(30, 3.0)).gap);
    Eigen::VectorXd one = Eigen::VectorXd::Zero(30);
    one[7] = 6.0;
    CHECK(testGap(keys, one).gap);
    CHECK_FALSE(testGap(keys, Eigen::VectorXd::Constant(30, 1.5)).gap);
}

TEST_CASE("the gap test gives each kind of observable its share of the level: one heap angle is "
          "not held to the bound of 88 features",
          "[gap][validation]") {
    // 87 plate bins over 6 plates and one heap angle: two kinds.
    std::vector<FeatureKey> keys;
    for (int k = 0; k < 87; ++k)
        keys.push_back(
            {"plate" + std::to_string(k % 6), "p", "plate/p", 0.001 * k, 0.001 * (k + 1)});
    keys.push_back({"repose", "angle_deg", "repose/angle_deg", 0.0, 0.0});
    Eigen::VectorXd e = Eigen::VectorXd::Zero(88);
    e[87] = -3.0; // the heap 3 u_val off, everything else agreeing
    const GapVerdict g = testGap(keys, e);
    // Hand values: the heap's kind holds 0.05 / 3 / 2 kinds, two-sided, of one feature:
    // Phi^-1(1 - 0.05/12) = 2.638 (tables); the plates' bound Phi^-1(1 - 0.05/(12 * 87)) = 3.90.
    CHECK(g.feature_bound == Approx(2.638).margin(0.002));
    CHECK(g.worst_kind == "repose/angle_deg");
    CHECK(g.gap); // one bound over all 88 features, Phi^-1(1 - 0.05/(6 * 88)) = 3.73, let it pass
    e[87] = 0.0;
    e[5] = 3.8; // a plate bin under its kind's 3.90
    const GapVerdict plates = testGap(keys, e);
    CHECK(plates.feature_bound == Approx(3.90).margin(0.01));
    CHECK_FALSE(plates.gap);

    // The level holds over both kinds together (3000 draws of unit normal features).
    std::mt19937 rng(12);
    std::normal_distribution<double> z;
    int alarms = 0;
    const int draws = 3000;
    for (int d = 0; d < draws; ++d) {
        for (Eigen::Index k = 0; k < 88; ++k)
            e[k] = z(rng);
        alarms += testGap(keys, e).gap;
    }
    CHECK(double(alarms) / draws < 0.06);
}

TEST_CASE("localise says where the simulation is too high, on which experiments, and where it "
          "agrees",
          "[gap][validation]") {
    // Two boxes x two plates, four sinkage bins. Every plate 2.5x too high in the first two
    // bins; in the last two only the small box is 30 % too low.
    std::vector<FeatureKey> keys;
    std::map<std::string, Conditions> conditions;
    ValidationResult v;
    std::vector<double> e, ratio;
    for (const std::string box : {"large", "small"})
        for (const std::string plate : {"60", "100"}) {
            const std::string id = box + "_" + plate;
            conditions[id] = {{"box", box}, {"plate_diameter_mm", plate}};
            for (int b = 0; b < 4; ++b) {
                keys.push_back({id, "pressure_Pa", "plate_sinkage/pressure_Pa", 0.004 * b,
                                0.004 * (b + 1)});
                if (b < 2) {
                    e.push_back(-6.0), ratio.push_back(b == 0 ? 2.9 : 2.1);
                } else if (box == "small") {
                    e.push_back(4.0), ratio.push_back(0.7);
                } else {
                    e.push_back(0.5), ratio.push_back(1.02);
                }
            }
        }
    v.standardised = Eigen::Map<Eigen::VectorXd>(e.data(), Eigen::Index(e.size()));
    v.ratio = Eigen::Map<Eigen::VectorXd>(ratio.data(), Eigen::Index(ratio.size()));
    const auto findings =
        localise(keys, v, conditions, {{"plate_sinkage/pressure_Pa", {"sinkage", "mm", 1000.0}}});
    REQUIRE(findings.size() == 2);
    CHECK(findings[0].sign == +1);
    CHECK(findings[0].x_hi == Approx(0.008));
    CHECK(findings[0].experiments == 4);
    CHECK(findings[0].text == "pressure 2.1-2.9x too high at sinkage 0-8 mm on every experiment (4)");
    CHECK(findings[1].sign == -1);
    CHECK(findings[1].text.find("30 % too low at sinkage 8-16 mm") != std::string::npos);
    CHECK(findings[1].text.find("on 2 of 4 experiments (those with box small)") !=
          std::string::npos);
}

TEST_CASE("localise names an observable in words, without its unit", "[gap][validation]") {
    for (const auto &[observable, words] :
         std::vector<std::pair<std::string, std::string>>{{"vertical_load_N", "vertical load"},
                                                          {"torque_N_m", "torque"},
                                                          {"shear_stress_Pa", "shear stress"},
                                                          {"angle_deg", "angle"}}) {
        const std::vector<FeatureKey> keys{{"w", observable, "wheel_steady_state/" + observable, 0.0, 0.1}};
        ValidationResult v;
        v.standardised = Eigen::VectorXd::Constant(1, -5.0);
        v.ratio = Eigen::VectorXd::Constant(1, 2.0);
        const auto findings = localise(keys, v, {{"w", {}}}, {});
        REQUIRE(findings.size() == 1);
        INFO(findings[0].text);
        CHECK(findings[0].text.rfind(words + " 2x too high", 0) == 0);
    }
}

TEST_CASE("localise gives a simulated value of the other sign as its ratio, not as 'Nx too low'",
          "[gap][validation]") {
    // A heap that spread flat (-1.06 deg) against a measured 22.6 deg: the ratio -0.047
    // once read "-21x too low". A side force of the other sign than the measured -0.54 N
    // (+1.0 N, ratio -1.85) once read "-0.54x too low".
    const std::vector<FeatureKey> keys{{"repose", "angle_deg", "angle_of_repose/angle_deg", 0, 0},
                                       {"w", "side_force_N", "wheel/side_force_N", 0.35, 0.6}};
    ValidationResult v;
    v.standardised = Eigen::Vector2d(3.1, -2.7);
    v.ratio = Eigen::Vector2d(-1.06 / 22.6, 1.0 / -0.54);
    const auto findings = localise(keys, v, {{"repose", {}}, {"w", {}}}, {});
    REQUIRE(findings.size() == 2);
    CHECK(findings[0].text == "angle too low, simulated -0.047x the measured (the other sign, or "
                              "zero) on every experiment (1)");
    CHECK(findings[1].text == "side force too high, simulated -1.9x the measured (the other "
                              "sign, or zero) at x 0.35-0.6 on every experiment (1)");
}

TEST_CASE("a check that moves the base by over half its value makes the base unresolved",
          "[gap][validation]") {
    // Seeds 1.0 1.2 0.8 1.0 (mean 1). A time-step check at 10 on the first two seeds (the
    // Mindlin soil at twice its step, docs/gap.md) moves the feature by 890 % (paired
    // differences 9.0 and 8.8): named, with its figure. A resolution check
    // at 1.05 moves it by about 5 %, far below half: no warning.
    Eigen::MatrixXd base(4, 1);
    base << 1.0, 1.2, 0.8, 1.0;
    Eigen::MatrixXd stiff(2, 1), close(2, 1);
    stiff << 10.0, 10.0;
    close << 1.05, 1.05;
    const auto bad = validate(oneFeature(1.5, 0.1, true), base,
                              {{"resolution", close}, {"time_step", stiff}});
    const std::string w = unresolvedCheck(bad);
    CHECK(w.find("time_step check") != std::string::npos);
    CHECK(w.find("890 %") != std::string::npos);
    CHECK(numericalWarning(validate(oneFeature(1.5, 0.1, true), base, {{"resolution", close}}))
              .empty());
}

TEST_CASE("the uncertainty budget gives each part of u_val as its median share of the value",
          "[gap][validation]") {
    // By hand, on the first test's numbers: seeds 1.0 1.2 0.8 1.0 (mean 1, sd 0.1633), no
    // repeats, u_D 0.1, a resolution check at 1.3: measurement 0.1, beds sd = 0.1633, seeds
    // sd/2, resolution sqrt(0.04 - 0.01) = 0.1732, u_val their root sum of squares 0.2708.
    // A feature the check could not reach (NaN) is left out of that part's median.
    Eigen::MatrixXd base(4, 2);
    base << 1.0, 2.0, 1.2, 2.4, 0.8, 1.6, 1.0, 2.0;
    Eigen::MatrixXd check(2, 2);
    check << 1.3, std::nan(""), 1.3, std::nan("");
    Measured m = oneFeature(1.5, 0.1, false);
    m.keys.push_back({"e1", "pressure_Pa", "plate/pressure_Pa", 0.002, 0.004});
    m.value = Eigen::Vector2d(1.5, 3.0);
    m.u_D = Eigen::Vector2d(0.1, 0.1); // 5 % of the second feature's value 2
    m.trials = Eigen::Vector2i(1, 1);
    m.from_repeats = {false, false};
    const auto budget = uncertaintyBudget(validate(m, base, {{"resolution", check}}));
    const double sd = std::sqrt(0.08 / 3.0);
    REQUIRE(budget.size() == 5);
    CHECK(budget[0].first == "measurement");
    CHECK(budget[0].second == Approx(0.1)); // median of 0.1 and 0.05: the upper middle
    CHECK(budget[1].first == "beds");
    CHECK(budget[1].second == Approx(sd)); // relative sd is the same on both features
    CHECK(budget[2].first == "seeds");
    CHECK(budget[2].second == Approx(sd / 2.0));
    CHECK(budget[3].first == "resolution");
    CHECK(budget[3].second == Approx(std::sqrt(0.04 - 0.01)));
    CHECK(budget[4].first == "u_val");
    // u_val relative: feature 1 sqrt(0.01 + sd^2 + sd^2/4 + 0.03) = 0.2708; feature 2 has no
    // resolution part: sqrt(0.0025 + 1.25 sd^2) = 0.1896; the upper middle of two is 0.2708.
    CHECK(budget[4].second == Approx(std::sqrt(0.01 + 1.25 * sd * sd + 0.03)));
}

TEST_CASE("a check whose runs all failed is named as unknown and not read as none",
          "[gap][validation]") {
    // Its contribution to u_val stays 0 (u_val can only be too small, so a 'no gap' stands),
    // but the warning names the check and the experiment, and it is no reason for 'unresolved'.
    Eigen::MatrixXd base(4, 1);
    base << 1.0, 1.2, 0.8, 1.0;
    Eigen::MatrixXd failed(2, 1);
    failed << std::nan(""), std::nan("");
    const auto v = validate(oneFeature(1.5, 0.1, true), base, {{"time_step", failed}});
    REQUIRE(v.check_failures.size() == 1);
    CHECK(v.check_failures[0] == std::pair<std::string, std::string>{"time_step", "e1"});
    CHECK(v.u_checks[0].second[0] == 0.0);
    CHECK(unresolvedCheck(v).empty());
    CHECK(numericalWarning(v).find("every run of the time_step check failed on e1") !=
          std::string::npos);
}
