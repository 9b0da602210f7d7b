#include "grainlink/gap/Effects.hpp"
#include "ShippedEffects.hpp"
#include "grainlink/gap/Twin.hpp"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

using namespace grainlink::gap;

namespace {

const char *kScenario = R"(name: plates
soil:
  simulation: {time_step_s: 4.0e-5, threads: 1}
  material: {youngs_modulus_Pa: 1.0e7, poisson_ratio: 0.2, density_kg_m3: 2400}
  contact:
    damping: {model: viscous, coefficient_N_s_m: 0.1}
    rolling: {model: epsd, coefficient: 0.3}
    tangential: {model: linear, stiffness_N_m: 200, stick_angle_deg: 32, slip_angle_deg: 30}
  walls:
    - {name: bin, type: box, lower_m: [0, 0, 0], upper_m: [0.1, 0.08, 0.2]}
  deposition:
    region: {lower_m: [0, 0, 0], upper_m: [0.1, 0.08, 0.05]}
    count: 2000
    radius: {distribution: uniform, min_m: 0.0018, max_m: 0.0022}
    seed: 3
bevameter:
  plate_radii_m: [0.02]
  speed_m_s: 0.05
  max_sinkage_m: 0.01
)";

} // namespace

TEST_CASE("the default catalogue holds the issue's effects, each with a prior and a signature",
          "[gap][effects]") {
    const EffectCatalogue c = shippedEffects();
    for (const char *name :
         {"rolling_resistance", "grain_shape", "cohesion", "polydispersity", "grain_stiffness",
          "grain_density", "wall_friction", "domain_size", "tool_friction", "rig_compliance",
          "sensor_zero_offset", "packing_density", "soft_surface_layer"}) {
        INFO(name);
        const Effect &e = c.find(name);
        CHECK(e.signature.size() >= 2);
        CHECK(e.prior.lo < e.prior.hi);
        CHECK_FALSE(e.description.empty());
    }
    CHECK_THROWS_WITH(c.find("gravity"), Catch::Contains("unknown effect 'gravity'"));
}

TEST_CASE("effects resolve their off value against the base", "[gap][effects]") {
    const YAML::Node base = YAML::Load(kScenario);
    const EffectCatalogue c = shippedEffects();
    CHECK(resolveAgainst(c.find("rolling_resistance"), base).prior.off == Approx(0.3));
    CHECK(resolveAgainst(c.find("cohesion"), base).prior.off == 0.0);
    // Walls without their own friction use the grains': tan 32 deg.
    CHECK(resolveAgainst(c.find("wall_friction"), base).prior.off ==
          Approx(std::tan(32.0 * M_PI / 180.0)));
    // A base whose walls and tool have laws of their own: those are the effects' off values,
    // not the grains' (the base's runs were made with them).
    YAML::Node own = YAML::Clone(base);
    own["soil"]["contact_wall"]["tangential"]["stick_angle_deg"] = 20.0;
    own["soil"]["contact_tool"]["tangential"]["friction_coefficient"] = 0.4;
    CHECK(resolveAgainst(c.find("wall_friction"), own).prior.off ==
          Approx(std::tan(20.0 * M_PI / 180.0)));
    CHECK(resolveAgainst(c.find("tool_friction"), own).prior.off == Approx(0.4));
    CHECK(resolveAgainst(c.find("polydispersity"), base).prior.off == Approx(0.1));
    CHECK(resolveAgainst(c.find("grain_stiffness"), base).prior.off == 1.0);
    CHECK(inapplicable(c.find("grain_shape"), base).find("the base has 'epsd'") !=
          std::string::npos);
    CHECK(inapplicable(c.find("rolling_resistance"), base).empty());
}

TEST_CASE("effects edit the scenario: stiffness, cohesion, rolling switched off",
          "[gap][effects]") {
    const YAML::Node base = YAML::Load(kScenario);
    const EffectCatalogue c = shippedEffects();
    const YAML::Node stiff =
        applyEffect(c.find("grain_stiffness"), 4.0, base, ExperimentType::PlateSinkage);
    CHECK(stiff["soil"]["material"]["youngs_modulus_Pa"].as<double>() == Approx(4.0e7));
    CHECK(stiff["soil"]["contact"]["tangential"]["stiffness_N_m"].as<double>() == Approx(800.0));
    CHECK(stiff["soil"]["contact"]["damping"]["coefficient_N_s_m"].as<double>() == Approx(0.2));
    CHECK(stiff["soil"]["simulation"]["time_step_s"].as<double>() == Approx(2.0e-5));
    // The base itself is untouched (a deep copy).
    CHECK(base["soil"]["material"]["youngs_modulus_Pa"].as<double>() == Approx(1.0e7));

    const YAML::Node coh = applyEffect(c.find("cohesion"), 5e4, base, ExperimentType::PlateSinkage);
    CHECK(coh["soil"]["contact"]["cohesion"]["model"].as<std::string>() == "linear");
    CHECK(coh["soil"]["contact"]["cohesion"]["energy_density_J_m3"].as<double>() == Approx(5e4));
    // Grain-grain only: walls and tools get no cohesion (docs/scenario.md, contact_wall).
    CHECK(coh["soil"]["contact_wall"]["cohesion"]["energy_density_J_m3"].as<double>() == 0.0);
    CHECK(coh["soil"]["contact_tool"]["cohesion"]["energy_density_J_m3"].as<double>() == 0.0);
    // Off, the edits that only apply when on leave no empty keys behind.
    const YAML::Node coh_off =
        applyEffect(c.find("cohesion"), 0.0, base, ExperimentType::PlateSinkage);
    CHECK_FALSE(coh_off["soil"]["contact_wall"]);
    CHECK_FALSE(coh_off["soil"]["contact_tool"]);

    const YAML::Node none =
        applyEffect(c.find("rolling_resistance"), 0.0, base, ExperimentType::PlateSinkage);
    CHECK(none["soil"]["contact"]["rolling"]["model"].as<std::string>() == "none");
    CHECK_FALSE(none["soil"]["contact"]["rolling"]["coefficient"]);

    const YAML::Node wall =
        applyEffect(c.find("wall_friction"), 0.25, base, ExperimentType::PlateSinkage);
    CHECK(wall["soil"]["walls"][0]["friction_coefficient"].as<double>() == Approx(0.25));
    // The grain-wall law in its tangential model's terms: linear -> the stick angle atan(mu).
    CHECK(wall["soil"]["contact_wall"]["tangential"]["stick_angle_deg"].as<double>() ==
          Approx(14.036243).epsilon(1e-6));
    CHECK_FALSE(wall["soil"]["contact_tool"]);
    // A wildcard path edits the walls there are; a test without walls gets none.
    YAML::Node wall_less = YAML::Clone(base);
    wall_less["soil"].remove("walls");
    CHECK_FALSE(applyEffect(c.find("wall_friction"), 0.25, wall_less,
                            ExperimentType::DirectShear)["soil"]["walls"]);
    const YAML::Node tool =
        applyEffect(c.find("tool_friction"), 0.5, base, ExperimentType::DirectShear);
    CHECK_FALSE(tool["bevameter"]["plate_friction_coefficient"]); // only for plate tests
    CHECK(tool["soil"]["contact_tool"]["tangential"]["stick_angle_deg"].as<double>() ==
          Approx(26.565051).epsilon(1e-6));
    YAML::Node mindlin = YAML::Clone(base);
    mindlin["soil"]["contact"]["tangential"] =
        YAML::Load("{model: mindlin, friction_coefficient: 0.6}");
    const YAML::Node tool_m =
        applyEffect(c.find("tool_friction"), 0.5, mindlin, ExperimentType::DirectShear);
    CHECK(tool_m["soil"]["contact_tool"]["tangential"]["friction_coefficient"].as<double>() == 0.5);
    CHECK_FALSE(tool_m["soil"]["contact_tool"]["tangential"]["stick_angle_deg"]);
    CHECK_FALSE(tool["soil"]["contact_wall"]);
}

TEST_CASE("a soft surface layer is a crust of softer grains in the prepared beds only",
          "[gap][effects]") {
    const YAML::Node base = YAML::Load(kScenario);
    const EffectCatalogue c = shippedEffects();
    const Effect &layer = c.find("soft_surface_layer");
    CHECK(resolveAgainst(layer, base).prior.off == 1.0);
    const YAML::Node soft = applyEffect(layer, 0.2, base, ExperimentType::PlateSinkage);
    CHECK(soft["soil"]["deposition"]["crust"]["thickness_m"].as<double>() == 0.015);
    CHECK(soft["soil"]["deposition"]["crust"]["youngs_modulus_factor"].as<double>() == Approx(0.2));
    // Off is the bed itself (a crust of factor 1 is refused by the scenario), and the repose
    // test's fill is poured into its tube, never prepared.
    const YAML::Node off = applyEffect(layer, 1.0, base, ExperimentType::PlateSinkage);
    CHECK_FALSE(off["soil"]["deposition"]["crust"]);
    const YAML::Node poured = applyEffect(layer, 0.2, base, ExperimentType::AngleOfRepose);
    CHECK_FALSE(poured["soil"]["deposition"]["crust"]);
}

// The full self-test's second effect outside the catalogue. The angles by hand:
// atan(0.6 tan 32 deg) = atan(0.374922) = 20.553 deg, atan(0.6 tan 30 deg) = atan(0.346410) =
// 19.107 deg.
TEST_CASE("sliding friction scales the tangents of the stick and slip angles, outside the "
          "catalogue",
          "[gap][effects]") {
    const YAML::Node base = YAML::Load(kScenario);
    const EffectCatalogue c = shippedEffects();
    const Effect &friction = c.find("sliding_friction");
    CHECK_FALSE(friction.in_catalogue);
    const YAML::Node low = applyEffect(friction, 0.6, base, ExperimentType::DirectShear);
    const YAML::Node t = low["soil"]["contact"]["tangential"];
    CHECK(t["stick_angle_deg"].as<double>() == Approx(20.553).margin(1e-3));
    CHECK(t["slip_angle_deg"].as<double>() == Approx(19.107).margin(1e-3));
    CHECK(t["stiffness_N_m"].as<double>() == 200.0);
    // Between grains only: walls and tools keep the angles they took from the grains.
    for (const char *type : {"contact_wall", "contact_tool"}) {
        INFO(type);
        CHECK(low["soil"][type]["tangential"]["stick_angle_deg"].as<double>() == 32.0);
        CHECK(low["soil"][type]["tangential"]["slip_angle_deg"].as<double>() == 30.0);
    }
    CHECK(base["soil"]["contact"]["tangential"]["stick_angle_deg"].as<double>() == 32.0);
    // A wall of its own keeps its own.
    YAML::Node own = YAML::Clone(base);
    own["soil"]["contact_wall"]["tangential"]["stick_angle_deg"] = 20.0;
    const YAML::Node kept = applyEffect(friction, 0.6, own, ExperimentType::DirectShear);
    CHECK(kept["soil"]["contact_wall"]["tangential"]["stick_angle_deg"].as<double>() == 20.0);
    CHECK_FALSE(kept["soil"]["contact_wall"]["tangential"]["slip_angle_deg"]);
    CHECK(kept["soil"]["contact_tool"]["tangential"]["stick_angle_deg"].as<double>() == 32.0);
    const YAML::Node off = applyEffect(friction, 1.0, base, ExperimentType::DirectShear);
    CHECK(off["soil"]["contact"]["tangential"]["stick_angle_deg"].as<double>() == Approx(32.0));

    // A source the scenario lacks (a typo in a user's catalogue) would let the walls inherit
    // the grains' new friction unnoticed: it stops, naming the edit's line, the effect, the keys.
    Effect typo = friction;
    typo.edits[0].source = "soil.contact.tangentail";
    CHECK_THROWS_WITH(applyEffect(typo, 0.6, base, ExperimentType::DirectShear),
                      Catch::Contains("effects.yaml:") && Catch::Contains("'sliding_friction'") &&
                          Catch::Contains("'soil.contact.tangentail': the scenario has no such "
                                          "key, so 'soil.contact_wall.tangential'"));
}

TEST_CASE("polydispersity keeps the mean radius and the solid volume, domain size the depth",
          "[gap][effects]") {
    const YAML::Node base = YAML::Load(kScenario);
    const EffectCatalogue c = shippedEffects();
    const YAML::Node wide =
        applyEffect(c.find("polydispersity"), 0.3, base, ExperimentType::PlateSinkage);
    const YAML::Node r = wide["soil"]["deposition"]["radius"];
    const double lo = r["min_m"].as<double>(), hi = r["max_m"].as<double>();
    CHECK(0.5 * (lo + hi) == Approx(0.002));
    CHECK((hi - lo) / (hi + lo) == Approx(0.3));
    // Solid volume: count x E[r^3]; E[r^3] of a uniform r on [a, b] is (b^4 - a^4) / (4 (b - a)).
    const auto volume = [](const YAML::Node &s) {
        const YAML::Node rr = s["soil"]["deposition"]["radius"];
        const double a = rr["min_m"].as<double>(), b = rr["max_m"].as<double>();
        return s["soil"]["deposition"]["count"].as<double>() * (std::pow(b, 4) - std::pow(a, 4)) /
               (4.0 * (b - a));
    };
    CHECK(volume(wide) == Approx(volume(base)).epsilon(1e-3));
    CHECK(wide["soil"]["simulation"]["time_step_s"].as<double>() == Approx(4.0e-5 * 0.7 / 0.9));

    const YAML::Node big =
        applyEffect(c.find("domain_size"), 1.5, base, ExperimentType::PlateSinkage);
    const auto upper = big["soil"]["walls"][0]["upper_m"].as<std::vector<double>>();
    const auto lower = big["soil"]["walls"][0]["lower_m"].as<std::vector<double>>();
    CHECK(upper[0] - lower[0] == Approx(0.15));
    CHECK(upper[1] - lower[1] == Approx(0.12));
    CHECK(upper[2] == Approx(0.2)); // height unchanged
    CHECK(big["soil"]["deposition"]["count"].as<double>() == Approx(4500));
}

TEST_CASE("a narrower wheel bin keeps the wheel's footprint: the clearance to the walls is what "
          "shrinks, a steered wheel's footprint being wider",
          "[gap][effects][wheel]") {
    const EffectCatalogue c = shippedEffects();
    // A 160 mm wide bin around a smooth wheel 116 mm across and 50 mm wide.
    const YAML::Node base = YAML::Load(R"(
soil:
  walls: [{name: bin, type: box, lower_m: [0, 0, 0], upper_m: [0.4, 0.16, 0.4]}]
  deposition: {region: {lower_m: [0, 0, 0], upper_m: [0.4, 0.16, 0.2]}, count: 4000}
wheel: {shape: {diameter_m: 0.116, width_m: 0.05}}
)");
    const auto width = [&](const YAML::Node &scenario, double s) {
        const YAML::Node out =
            applyEffect(c.find("domain_size"), s, scenario, ExperimentType::WheelSteadyState);
        const auto lo = out["soil"]["walls"][0]["lower_m"].as<std::vector<double>>();
        const auto hi = out["soil"]["walls"][0]["upper_m"].as<std::vector<double>>();
        CHECK(hi[0] - lo[0] == Approx(0.4)); // the travel's length stays
        CHECK(0.5 * (lo[1] + hi[1]) == Approx(0.08));
        return hi[1] - lo[1];
    };
    // Straight, the footprint is the 50 mm width: 55 mm each side, times 0.6 is 33 mm.
    CHECK(width(base, 0.6) == Approx(0.05 + 0.6 * 0.11));
    CHECK(width(base, 1.5) == Approx(0.05 + 1.5 * 0.11));
    // Steered across the travel it is the 116 mm diameter: 22 mm each side, times 0.6 is 13.2 mm.
    YAML::Node steered = YAML::Clone(base);
    steered["wheel"]["slip_angle_deg"] = 90.0;
    CHECK(width(steered, 0.6) == Approx(0.116 + 0.6 * 0.044));
    // At 30 deg with 5 mm grousers: 2 (63 sin 30 + 25 cos 30) mm = 106.3 mm.
    steered["wheel"]["slip_angle_deg"] = 30.0;
    steered["wheel"]["shape"]["grouser_height_m"] = 0.005;
    const double footprint = 2.0 * (0.063 * 0.5 + 0.025 * std::sqrt(3.0) / 2.0);
    CHECK(width(steered, 0.75) == Approx(footprint + 0.75 * (0.16 - footprint)));
}

TEST_CASE(
    "measurement effects shift the simulated sinkage: a constant offset, or compliance x force",
    "[gap][effects]") {
    const EffectCatalogue c = shippedEffects();
    Experiment e;
    e.type = ExperimentType::PlateSinkage;
    e.numbers["plate_diameter_m"] = 0.1;
    const Curve curve{{0.0, 0.01}, {0.0, 40000.0}};
    const Curve zero =
        applyMeasurementEffect(c.find("sensor_zero_offset"), 0.001, e, "pressure_Pa", curve);
    CHECK(zero.x[1] == Approx(0.011));
    // 40 kPa on a 100 mm plate is 314 N; at 1e-5 m/N the rig adds 3.14 mm.
    const Curve rig =
        applyMeasurementEffect(c.find("rig_compliance"), 1e-5, e, "pressure_Pa", curve);
    CHECK(rig.x[1] == Approx(0.01 + 1e-5 * 40000.0 * M_PI * 0.0025));
    CHECK(rig.x[0] == 0.0);
    // Both at once, in either order (a pair of them reads one on the other's reads): the
    // sinkage plus the offset plus the rig's deflection, 10 + 1 + 3.14 mm.
    for (const auto &[first, second] : {std::pair{"sensor_zero_offset", "rig_compliance"},
                                        std::pair{"rig_compliance", "sensor_zero_offset"}}) {
        const auto strength = [](const std::string &name) {
            return name == "rig_compliance" ? 1e-5 : 0.001;
        };
        const Curve once =
            applyMeasurementEffect(c.find(first), strength(first), e, "pressure_Pa", curve);
        const Curve both =
            applyMeasurementEffect(c.find(second), strength(second), e, "pressure_Pa", once);
        CHECK(both.x[0] == Approx(0.001));
        CHECK(both.x[1] == Approx(0.01 + 0.001 + 1e-5 * 40000.0 * M_PI * 0.0025));
        CHECK(both.y == curve.y);
    }
}

TEST_CASE("an effects file with a bad expression or no signature is refused with its line",
          "[gap][effects]") {
    CHECK_THROWS_WITH(evaluate("2 * s +", 1.0, 0.0), Catch::Contains("expression '2 * s +'"));
    CHECK(evaluate("min(1, 1 / sqrt(s))", 4.0, 0.0) == Approx(0.5));
}

TEST_CASE("a twin's strength drawn from the far half of its prior lies there and fills it",
          "[gap][effects][twin]") {
    // The reference is the rule in words: on each side of off, the half of that side farther
    // from off, on the prior's own scale; both sides drawn in proportion to their length.
    struct Case {
        Prior prior;
        double far_lo_below, far_hi_above; ///< the far halves: s <= below, s >= above
    };
    const std::vector<Case> cases{
        {{0.2, 5.0, 1.0, true}, std::sqrt(0.2), std::sqrt(5.0)}, // log, off in the middle
        {{0.0, 4.0e5, 0.0, false}, -1.0, 2.0e5},                 // off at the low end
        {{-0.002, 0.002, 0.0, false}, -0.001, 0.001},            // symmetric
        {{3.0, 20.0, 1.0, true}, -1.0, std::sqrt(60.0)},         // off below the prior
    };
    for (const Case &c : cases) {
        Effect e;
        e.name = "x";
        e.prior = c.prior;
        int below = 0, above = 0;
        double lowest = c.prior.hi, highest = c.prior.lo;
        for (unsigned seed = 1; seed <= 2000; ++seed) {
            const double s = drawStrength(e, seed, StrengthDraw::FarHalf);
            INFO("prior [" << c.prior.lo << ", " << c.prior.hi << "] off " << c.prior.off
                           << ": drew " << s);
            REQUIRE(s >= c.prior.lo - 1e-9 * std::abs(c.prior.lo));
            REQUIRE(s <= c.prior.hi + 1e-9 * std::abs(c.prior.hi));
            const bool in_low = s <= c.far_lo_below * (1 + 1e-9),
                       in_high = s >= c.far_hi_above * (1 - 1e-9);
            REQUIRE((in_low || in_high));
            below += in_low;
            above += in_high;
            lowest = std::min(lowest, s);
            highest = std::max(highest, s);
        }
        // Sides in proportion to their length (2000 draws: sd of a share about 0.011).
        const double t_lo = c.prior.toScale(c.prior.lo), t_hi = c.prior.toScale(c.prior.hi);
        const double t_off = std::clamp(c.prior.toScale(c.prior.off), t_lo, t_hi);
        CHECK(double(below) / 2000.0 == Approx((t_off - t_lo) / (t_hi - t_lo)).margin(0.04));
        CHECK(highest == Approx(c.prior.hi).epsilon(0.01));
        if (below > 0)
            CHECK(lowest == Approx(c.prior.lo).epsilon(0.01).margin(1e-5));
    }
}

TEST_CASE("a strength drawn again after twins that could not be simulated lies nearer off than "
          "each of them, on its side, and fills the far half of what is left",
          "[gap][selftest]") {
    // The reference is the rule in words: the prior cut at each failed strength (it and all
    // beyond it on its side of off left out), then the far half of each side of what is left.
    struct Case {
        Prior prior;
        std::vector<double> failed;
        double lo, hi;                     ///< the prior after the cuts
        double far_lo_below, far_hi_above; ///< its far halves: s <= below, s >= above
    };
    const std::vector<Case> cases{
        // the soft surface layer (off at the top): after 0.2, [0.2, sqrt 0.2]
        {{0.1, 1.0, 1.0, true}, {0.2}, 0.2, 1.0, std::sqrt(0.2), 2.0},
        // two failures on one side: the nearer cut holds
        {{0.1, 1.0, 1.0, true}, {0.15, 0.3}, 0.3, 1.0, std::sqrt(0.3), 2.0},
        // symmetric, one side cut: that side [-1.5, -0.75] mm, the other [1, 2] mm
        {{-0.002, 0.002, 0.0, false}, {-0.0015}, -0.0015, 0.002, -0.00075, 0.001},
        // both sides cut
        {{-0.002, 0.002, 0.0, false}, {0.0015, -0.001}, -0.001, 0.0015, -0.0005, 0.00075},
        // off below the prior: the failure cuts the top, [sqrt 30, 10]
        {{3.0, 20.0, 1.0, true}, {10.0}, 3.0, 10.0, -1.0, std::sqrt(30.0)},
    };
    for (const Case &c : cases) {
        Effect e;
        e.name = "x";
        e.prior = c.prior;
        double lowest = c.hi, highest = c.lo;
        int below = 0;
        for (unsigned seed = 1; seed <= 2000; ++seed) {
            const double s = drawStrength(e, seed, StrengthDraw::FarHalf, c.failed);
            INFO("prior [" << c.prior.lo << ", " << c.prior.hi << "] cut to [" << c.lo << ", "
                           << c.hi << "]: drew " << s);
            REQUIRE(s >= c.lo - 1e-9 * std::abs(c.lo));
            REQUIRE(s <= c.hi + 1e-9 * std::abs(c.hi));
            for (double f : c.failed)
                REQUIRE(s != f);
            const bool in_low = s <= c.far_lo_below + 1e-9 * std::abs(c.far_lo_below),
                       in_high = s >= c.far_hi_above - 1e-9 * std::abs(c.far_hi_above);
            REQUIRE((in_low || in_high));
            below += in_low;
            lowest = std::min(lowest, s);
            highest = std::max(highest, s);
        }
        const double t_lo = c.prior.toScale(c.lo), t_hi = c.prior.toScale(c.hi);
        const double t_off = std::clamp(c.prior.toScale(c.prior.off), t_lo, t_hi);
        CHECK(double(below) / 2000.0 == Approx((t_off - t_lo) / (t_hi - t_lo)).margin(0.04));
        // Filled: the draws reach both ends of what is left (2000 draws)
        if (below > 0)
            CHECK(lowest == Approx(c.lo).epsilon(0.01).margin(1e-5));
        if (below < 2000)
            CHECK(highest == Approx(c.hi).epsilon(0.01).margin(1e-5));
    }
}
