// Soil lookup table and its inversion (docs/lab.md, physics.md §12.16).
#include "grainlink/lab/SoilTable.hpp"

#include "grainlink/lab/DirectShear.hpp"

#include "TinyShearBox.hpp"

#include <catch2/catch.hpp>

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

using namespace grainlink;
using Catch::Matchers::Contains;

namespace {

/// A synthetic table on phi = 10..40 (step 10) x gamma = 0..30 (step 10), every quantity
/// bilinear in (phi, gamma) so the table's interpolation is exact:
///   psi    = 8 + 0.5 phi + 0.3 gamma + 0.004 phi gamma
///   repose = 12 + 0.2 phi + 0.6 gamma
std::vector<lab::SoilTableRow> syntheticRows() {
    std::vector<lab::SoilTableRow> rows;
    for (double phi : {10.0, 20.0, 30.0, 40.0})
        for (double gamma : {0.0, 10.0, 20.0, 30.0}) {
            lab::SoilTableRow r;
            r.phi_deg = phi;
            r.gamma_deg = gamma;
            r.psi_deg = 8 + 0.5 * phi + 0.3 * gamma + 0.004 * phi * gamma;
            r.psi_half_width_95_deg = 1.0;
            r.repose_deg = 12 + 0.2 * phi + 0.6 * gamma;
            r.repose_half_width_95_deg = 0.5;
            r.bulk_density_kg_m3 = 1500 - 2 * phi;
            r.packing_fraction = (1500 - 2 * phi) / 2400;
            rows.push_back(r);
        }
    return rows;
}

double psiOf(double phi, double gamma) {
    return 8 + 0.5 * phi + 0.3 * gamma + 0.004 * phi * gamma;
}
double reposeOf(double phi, double gamma) {
    return 12 + 0.2 * phi + 0.6 * gamma;
}

} // namespace

TEST_CASE("Soil table inversion recovers known (phi, gamma) from psi and repose",
          "[lab][soil_table]") {
    const auto table = lab::soilTableFromRows(syntheticRows(), "synthetic.csv");
    // The point (phi, gamma) = (27, 13) inside the grid: psi and repose computed from the same
    // bilinear laws. The inversion solves psi exactly per gamma and bisects the repose mismatch
    // (60 halvings), so it must return the point to 1e-6 deg.
    const double phi = 27.0, gamma = 13.0;
    const auto inv = lab::invertSoilTable(table, psiOf(phi, gamma), reposeOf(phi, gamma));
    CHECK(inv.chosen.phi_deg == Approx(phi).margin(1e-6));
    CHECK(inv.chosen.gamma_deg == Approx(gamma).margin(1e-6));
    CHECK(std::abs(inv.repose_mismatch_deg) < 1e-6);
    // Every point of the curve solves psi = target (interpolation is exact for bilinear data).
    for (const auto &p : inv.curve)
        CHECK(psiOf(p.phi_deg, p.gamma_deg) == Approx(inv.target_psi_deg).margin(1e-9));
    // Uncertainty: psi half width 1 deg over d psi / d phi = 0.5 + 0.004 gamma; the data are
    // linear in phi, so the resolution term (curvature) is zero.
    CHECK(inv.psi_slope_deg_per_deg == Approx(0.5 + 0.004 * gamma).epsilon(1e-9));
    CHECK(inv.phi_from_measurement_deg == Approx(1.0 / (0.5 + 0.004 * gamma)).epsilon(1e-9));
    REQUIRE(inv.phi_from_resolution_deg);
    CHECK(*inv.phi_from_resolution_deg == Approx(0.0).margin(1e-9));
    CHECK(inv.packing_fraction == Approx((1500 - 2 * phi) / 2400).epsilon(1e-9));
    CHECK_THAT(inv.contactBlock(),
               Contains("aspect_ratio_angle_deg: 13") && Contains("stick_angle_deg: 27"));
}

TEST_CASE("Soil table inversion with psi only picks the middle of the gamma range",
          "[lab][soil_table]") {
    const auto table = lab::soilTableFromRows(syntheticRows(), "synthetic.csv");
    // psi = 31 at gamma = 15 (the middle of 0..30): 8 + 0.5 phi + 4.5 + 0.06 phi = 31
    // -> phi = 18.5 / 0.56 (to 1e-9, the interpolation is exact).
    const auto inv = lab::invertSoilTable(table, 31.0);
    CHECK(inv.chosen.gamma_deg == Approx(15.0).margin(1e-12));
    CHECK(inv.chosen.phi_deg == Approx(18.5 / 0.56).epsilon(1e-9));
    // The curve spans gamma 0..30 where phi stays inside 10..40: phi(0) = 46 is outside, so
    // the curve starts where phi = 40 is reached.
    CHECK(inv.curve.front().phi_deg <= 40.0);
    CHECK(inv.curve.back().gamma_deg == Approx(30.0));
}

TEST_CASE("Soil table inversion: targets outside the table name the file and its range",
          "[lab][soil_table]") {
    const auto table = lab::soilTableFromRows(syntheticRows(), "data/synthetic.csv");
    // psi covers 8 + 5 = 13 (phi 10, gamma 0) to 8 + 20 + 9 + 4.8 = 41.8 deg.
    CHECK_THROWS_WITH(lab::invertSoilTable(table, 50.0),
                      Contains("data/synthetic.csv") && Contains("13") && Contains("41.8") &&
                          Contains("phi [10, 40]") && Contains("gamma [0, 30]"));
    CHECK_THROWS_WITH(lab::invertSoilTable(table, 5.0), Contains("outside the soil table"));
    CHECK_THROWS_WITH(lab::invertSoilTable(table, 31.0, 60.0),
                      Contains("angle of repose 60") && Contains("data/synthetic.csv"));
}

TEST_CASE("Soil table file: written rows read back, a gap in the grid is an error",
          "[lab][soil_table]") {
    const auto dir = std::filesystem::temp_directory_path() /
                     ("grainlink_soil_table_test-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const auto path = (dir / "table.csv").string();
    auto rows = syntheticRows();
    {
        std::ofstream csv(path);
        csv << "# comment\nfriction_angle_deg,aspect_ratio_angle_deg,psi_deg,"
               "psi_half_width_95_deg,cohesion_Pa,cohesion_half_width_95_Pa,repose_deg,"
               "repose_half_width_95_deg,bulk_density_kg_m3,packing_fraction\n";
        for (const auto &r : rows)
            csv << r.phi_deg << ',' << r.gamma_deg << ',' << r.psi_deg << ','
                << r.psi_half_width_95_deg << ",0,0," << r.repose_deg << ','
                << r.repose_half_width_95_deg << ',' << r.bulk_density_kg_m3 << ','
                << r.packing_fraction << '\n';
    }
    const auto table = lab::readSoilTable(path);
    CHECK(table.phi_deg.size() == 4);
    CHECK(table.gamma_deg.size() == 4);
    CHECK(table.has_repose);
    CHECK(table.at(table.psi, 25.0, 5.0) == Approx(psiOf(25.0, 5.0)).epsilon(1e-9));

    rows.erase(rows.begin() + 5);
    CHECK_THROWS_WITH(lab::soilTableFromRows(rows, "gappy.csv"),
                      Contains("gappy.csv") && Contains("phi = 20") && Contains("gamma = 10"));
    std::filesystem::remove_all(dir);
}

TEST_CASE("Grain parameters of a table point: stick = slip = phi, gamma 0 is the sphere",
          "[lab][soil_table]") {
    const auto base =
        lab::parseDirectShear(config::ConfigNode::loadString(kTinyShearBox, "direct_shear.yaml"))
            .soil;
    const auto shaped = lab::soilWithGrainParameters(base, 12.0, 35.0);
    const auto &t = std::get<dem::TangentialLinear>(shaped.law.tangential);
    CHECK(t.stick_angle_deg == 12.0);
    CHECK(t.slip_angle_deg == 12.0);
    const auto &r = std::get<dem::RollingGrainShape>(shaped.law.rolling);
    CHECK(r.aspect_ratio_angle_deg == dem::Vec3::Constant(35.0));
    CHECK(std::holds_alternative<dem::RollingNone>(
        lab::soilWithGrainParameters(base, 12.0, 0.0).law.rolling));
    // A different law gives a different packing: the cache must not mix them up.
    CHECK(dem::packingKey(shaped) != dem::packingKey(base));
}

TEST_CASE("Soil table generated on the tiny box reads back and inverts", "[lab][soil_table][dem][slow]") {
    // Two friction angles (0 and 30 deg) at gamma 20 deg on the tiny direct-shear box, no
    // repose test. The run writes the table; it must read back with the regenerate command in
    // its header. psi must rise with phi by more than 5 deg: measured 17.5 deg at phi 0 (the same
    // as the frictionless spheres of DirectShearTest to 1e-10: without tangential forces the
    // grain-shape law has nothing to resist) and 36.9 deg at phi 30. The inversion of the
    // mean psi must land at the middle phi (psi is linear between two nodes).
    const auto dir = std::filesystem::temp_directory_path() /
                     ("grainlink_soil_table_run-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "shear.yaml") << kTinyShearBox;
    std::ofstream(dir / "spec.yaml") << "direct_shear: shear.yaml\n"
                                        "friction_angles_deg: [0, 30]\n"
                                        "aspect_ratio_angles_deg: [20]\n";
    const auto spec = lab::loadSoilTableSpec((dir / "spec.yaml").string());
    CHECK(spec.direct_shear_path == (dir / "shear.yaml").string());
    lab::SoilTableOptions options;
    options.output_csv = (dir / "table.csv").string();
    options.command_line = "grainlink soil-table spec.yaml --out table.csv";
    const auto rows = lab::generateSoilTable(spec, options);
    REQUIRE(rows.size() == 2);
    CHECK(rows[1].psi_deg > rows[0].psi_deg + 5.0);
    CHECK(std::isnan(rows[0].repose_deg));
    std::ifstream csv(options.output_csv);
    const std::string text((std::istreambuf_iterator<char>(csv)), {});
    CHECK_THAT(text, Contains("# regenerate: grainlink soil-table spec.yaml --out table.csv"));
    const auto table = lab::readSoilTable(options.output_csv);
    const double mid = 0.5 * (rows[0].psi_deg + rows[1].psi_deg);
    const auto inv = lab::invertSoilTable(table, mid);
    // psi is linear in phi between the two nodes: the middle psi sits at the middle phi.
    CHECK(inv.chosen.phi_deg == Approx(15.0).margin(1e-9));
    CHECK(inv.chosen.gamma_deg == 20.0);
    CHECK_FALSE(inv.phi_from_resolution_deg); // two phi nodes: no curvature estimate
    std::filesystem::remove_all(dir);
}
