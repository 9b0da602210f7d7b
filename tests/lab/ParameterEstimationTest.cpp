// grainlink params: the seed's parameter estimation (section 2.3), docs/physics.md §12.
#include "grainlink/lab/ParameterEstimation.hpp"
#include "grainlink/dem/DemSystem.hpp"
#include "grainlink/dem/Scenario.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <string>

using namespace grainlink;
using Catch::Matchers::Contains;

namespace {

/// The seed's Table 1 soil with its given E: wheel with 15 mm grousers at Gamma = 3; the
/// pressure is the normal load 8.33 kg over a 125 mm x 60 mm contact patch (~10.9 kPa).
const char *kTable1 = R"(soil:
  name: seed Table 1
  grain_density_kg_m3: 2400
  poisson_ratio: 0.2
  stick_angle_deg: 32
  slip_angle_deg: 30
test:
  expected_pressure_Pa: 10900
  tool_size_m: 0.015
  plate_radius_m: 0.03
  bed_height_m: 0.2
  expected_sinkage_m: 0.02
model:
  resolution: 3
  max_overlap_ratio: 0.05
  damping_fraction: 0.1
  youngs_modulus_Pa: 3.0e6
)";

lab::SoilTestDescription parseDescription(const std::string &text) {
    return lab::parseSoilTestDescription(config::ConfigNode::loadString(text, "params.yaml"));
}

/// kTable1 with one line replaced (`from` must occur).
std::string editedTable1(const std::string &from, const std::string &to) {
    std::string text = kTable1;
    const auto at = text.find(from);
    REQUIRE(at != std::string::npos);
    return text.replace(at, from.size(), to);
}

} // namespace

TEST_CASE("Seed Table 1: Gamma = 3 on 15 mm grousers gives r = 2.5 mm and a stable step above "
          "5e-5 s for E = 3e6 Pa, rho = 2400",
          "[lab][params]") {
    const auto m = lab::estimateParameters(parseDescription(kTable1));
    // Eq. 11: r_max = L_min / (2 Gamma) = 15 mm / 6; exact arithmetic, rounding only.
    CHECK(m.radius_max_m == Approx(2.5e-3).epsilon(1e-12));
    // Rayleigh time of a 2.5 mm grain of E = 3 MPa, nu = 0.2, rho = 2400 worked by hand
    // (G = 1.25 MPa): 3.7851e-4 s; 1e-4 relative covers the hand rounding.
    CHECK(m.rayleigh_time_s == Approx(3.7851e-4).epsilon(1e-4));
    // The seed ran Table 1 at 5e-5 s: every limit must allow it, and the recommended step with
    // the default safety factor 0.5 too. (T_R / 2 = 1.9e-4 s: margin 3.8.)
    CHECK(m.grainlink_limit_s >= 5e-5);
    CHECK(m.oscillator_limit_s >= 5e-5);
    CHECK(m.recommended_time_step_s >= 5e-5);
    WARN("Table 1: T_R/2 = " << 0.5 * m.rayleigh_time_s << " s, oscillator limit "
                             << m.oscillator_limit_s << " s, recommended "
                             << m.recommended_time_step_s
                             << " s; worst-case overlap with E = 3 MPa: "
                             << m.overlap_ratio_at_worst_force
                             << " r, E_min(a = 0.05) = " << m.minimum_youngs_modulus_Pa << " Pa");

    // The limit grainlink's DEM enforces for the same grains and dashpot must be the one
    // `params` reports (same formula in two places: catches drift). Relative 1e-9: round-off.
    dem::Material mat;
    mat.youngs_modulus_Pa = m.youngs_modulus_Pa;
    mat.poisson_ratio = m.input.poisson_ratio;
    mat.density_kg_m3 = m.input.grain_density_kg_m3;
    dem::ContactLaw law;
    law.damping = dem::DampingViscous{m.normal_damping_N_s_m};
    dem::TangentialLinear tangential;
    tangential.stiffness_N_m = m.tangential_stiffness_N_m;
    law.tangential = tangential;
    dem::DemSettings settings;
    settings.time_step_s = m.recommended_time_step_s;
    dem::DemSystem sys(law, {mat}, settings);
    dem::ParticleSpec grain;
    grain.radius_m = m.radius_min_m;
    grain.density_kg_m3 = mat.density_kg_m3;
    sys.particles().add(grain);
    CHECK(sys.stableTimeStepEstimate() == Approx(m.grainlink_limit_s).epsilon(1e-9));
}

TEST_CASE("Eq. 10: the weight term is a cubic column's weight and Hertz at a_max carries F_max "
          "with the minimum Young's modulus",
          "[lab][params]") {
    auto d = parseDescription(kTable1);
    d.youngs_modulus_Pa.reset();

    SECTION("weight of a cubic-lattice column, no plate load") {
        d.expected_pressure_Pa = 0.0;
        const auto m = lab::estimateParameters(d);
        const double r = m.radius_min_m, z_h = d.bed_height_m - d.expected_sinkage_m;
        // z_h / (2 r) grains of (4/3) pi r^3 rho g stacked: independent arithmetic, 1e-12.
        const double column =
            z_h / (2.0 * r) * 4.0 / 3.0 * M_PI * r * r * r * d.grain_density_kg_m3 * d.gravity_m_s2;
        CHECK(m.worst_contact_force_N == Approx(column).epsilon(1e-12));
    }
    SECTION("Hertz at the allowed overlap carries the worst-case force") {
        const auto m = lab::estimateParameters(d);
        const double r = m.radius_min_m, a = d.max_overlap_ratio;
        // The E chosen from the equivalent linear stiffness: Hertz's F(a r) = F_max and the
        // secant stiffness F / (a r) = c_n. Round-off only: 1e-12.
        const double f = lab::hertzForceEqualGrains(m.youngs_modulus_Pa, d.poisson_ratio, r, a);
        CHECK(f == Approx(m.worst_contact_force_N).epsilon(1e-12));
        CHECK(f / (a * r) == Approx(m.normal_stiffness_N_m).epsilon(1e-12));
        CHECK(m.overlap_ratio_at_worst_force == Approx(a).epsilon(1e-12));
        // c_T = 0.03 c_n (seed's lower bound), damping as the asked fraction of critical.
        CHECK(m.tangential_stiffness_N_m == Approx(0.03 * m.normal_stiffness_N_m).epsilon(1e-12));
        CHECK(m.normal_damping_N_s_m / m.critical_damping_N_s_m ==
              Approx(d.damping_fraction).epsilon(1e-12));

        // Halving the allowed overlap: linear c_n doubles, Hertz E grows by 2^(3/2).
        auto tighter = d;
        tighter.max_overlap_ratio = 0.5 * a;
        const auto t = lab::estimateParameters(tighter);
        CHECK(t.normal_stiffness_N_m == Approx(2.0 * m.normal_stiffness_N_m).epsilon(1e-12));
        CHECK(t.youngs_modulus_Pa ==
              Approx(std::pow(2.0, 1.5) * m.youngs_modulus_Pa).epsilon(1e-12));
    }
    SECTION("the stiffest pair is the smallest grains: polydisperse beds need a larger E") {
        const auto mono = lab::estimateParameters(d);
        d.radius_ratio_min_max = 0.5;
        const auto poly = lab::estimateParameters(d);
        CHECK(poly.radius_min_m == Approx(0.5 * mono.radius_max_m).epsilon(1e-12));
        CHECK(poly.youngs_modulus_Pa > mono.youngs_modulus_Pa);
        CHECK(poly.stable_time_step_s < mono.stable_time_step_s);
    }
}

TEST_CASE("Eq. 12: inertia of the virtual grain", "[lab][params]") {
    auto d = parseDescription(kTable1);
    d.aspect_ratios = Eigen::Vector3d(1.0, 2.0, 0.5);
    const auto m = lab::estimateParameters(d);
    // J_i = (1/9) pi rho r^3 (r/A_i)^2: for A = 1 it is 15/72 of a solid sphere's (8/15) pi rho
    // r^5, and it scales as 1/A^2. Round-off only: 1e-12.
    CHECK(m.inertia_kg_m2.x() / m.solid_sphere_inertia_kg_m2 == Approx(15.0 / 72.0).epsilon(1e-12));
    CHECK(m.inertia_kg_m2.y() == Approx(m.inertia_kg_m2.x() / 4.0).epsilon(1e-12));
    CHECK(m.inertia_kg_m2.z() == Approx(m.inertia_kg_m2.x() * 4.0).epsilon(1e-12));
}

TEST_CASE("The printed soil block is a valid grainlink soil section with the derived values",
          "[lab][params]") {
    auto d = parseDescription(kTable1);
    d.youngs_modulus_Pa.reset();
    const auto m = lab::estimateParameters(d);
    // The user adds bed geometry; the block must parseDescription as it is printed.
    const std::string text = lab::soilBlock(m) + R"(  deposition:
    region: {lower_m: [0, 0, 0], upper_m: [0.05, 0.05, 0.05]}
    count: 10
    radius: {distribution: constant, value_m: 0.0025}
  packing_cache_directory: ""
)";
    const auto root = config::ConfigNode::loadString(text, "block.yaml");
    const auto scenario = dem::parseScenario(root["soil"], true);
    // Printed with 6 significant digits: 1e-5 relative.
    CHECK(scenario.material.youngs_modulus_Pa == Approx(m.youngs_modulus_Pa).epsilon(1e-5));
    CHECK(scenario.settings.time_step_s == Approx(m.recommended_time_step_s).epsilon(1e-5));
    const auto *viscous = std::get_if<dem::DampingViscous>(&scenario.law.damping);
    REQUIRE(viscous);
    CHECK(viscous->coefficient_N_s_m == Approx(m.normal_damping_N_s_m).epsilon(1e-5));
    const auto *tangential = std::get_if<dem::TangentialLinear>(&scenario.law.tangential);
    REQUIRE(tangential);
    CHECK(tangential->stiffness_N_m == Approx(m.tangential_stiffness_N_m).epsilon(1e-5));
    CHECK(tangential->damping_N_s_m == Approx(m.tangential_damping_N_s_m).epsilon(1e-5));
    CHECK(tangential->slip_angle_deg == Approx(30.0));
}

TEST_CASE("Bad params input: errors name the key and the line", "[lab][params]") {
    CHECK_THROWS_WITH(parseDescription(editedTable1("  tool_size_m: 0.015\n", "")),
                      Contains("missing key 'test.tool_size_m'"));
    CHECK_THROWS_WITH(
        parseDescription(editedTable1("expected_pressure_Pa", "expected_pressure_kPa")),
        Contains("params.yaml:8:") && Contains("wrong unit"));
    CHECK_THROWS_WITH(
        parseDescription(editedTable1("  damping_fraction: 0.1\n",
                                      "  damping_fraction: 0.1\n  dampnig_ratio: 2\n")),
        Contains("params.yaml:17:") && Contains("unknown key 'model.dampnig_ratio'"));
    CHECK_THROWS_WITH(
        parseDescription(editedTable1("max_overlap_ratio: 0.05", "max_overlap_ratio: 1.5")),
        Contains("params.yaml:15:") && Contains("model.max_overlap_ratio") && Contains("(0, 1)"));
    CHECK_THROWS_WITH(parseDescription(editedTable1("slip_angle_deg: 30", "slip_angle_deg: 35")),
                      Contains("soil.slip_angle_deg") && Contains("[0, 32]"));
    CHECK_THROWS_WITH(
        parseDescription(editedTable1("expected_sinkage_m: 0.02", "expected_sinkage_m: 0.3")),
        Contains("test.expected_sinkage_m"));
    CHECK_THROWS_WITH(
        parseDescription(editedTable1("grain_density_kg_m3: 2400", "grain_density_kg_m3: -1")),
        Contains("soil.grain_density_kg_m3"));
    CHECK_THROWS_WITH(parseDescription(editedTable1("resolution: 3", "resolution: three")),
                      Contains("model.resolution") && Contains("expected a number"));
    // Programmatic use is checked too.
    auto d = parseDescription(kTable1);
    d.poisson_ratio = 0.5;
    CHECK_THROWS_WITH(lab::estimateParameters(d), Contains("poisson_ratio"));
}
