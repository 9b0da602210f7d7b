// The lab tests' shared pieces (LabBed.hpp, LabConfig.hpp): the highest grain under a
// round tool, the test's centre and the `centre_m` key.
#include "grainlink/lab/LabBed.hpp"
#include "grainlink/lab/LabConfig.hpp"

#include <catch2/catch.hpp>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

using namespace grainlink;
using Catch::Matchers::Contains;

namespace {

void addGrain(dem::ParticleStore &grains, double x, double y, double z, double r) {
    dem::ParticleSpec spec;
    spec.position_m = dem::Vec3(x, y, z);
    spec.radius_m = r;
    spec.density_kg_m3 = 2500.0;
    grains.add(spec);
}

} // namespace

TEST_CASE("Highest grain under a round tool counts the grains its footprint touches",
          "[lab][lab_bed]") {
    dem::ParticleStore grains;
    addGrain(grains, 0.0, 0.0, 0.010, 0.001);    // on the axis: top 11 mm
    addGrain(grains, 0.0105, 0.0, 0.020, 0.001); // centre 0.5 mm outside R = 10 mm, touches it
    addGrain(grains, 0.0115, 0.0, 0.030, 0.001); // 0.5 mm clear of the rim: not under the tool
    const Eigen::Vector2d axis(0.0, 0.0);
    // Exact: the result is one grain's z + r or the floor, no arithmetic beyond that sum.
    CHECK(lab::highestGrainUnder(grains, axis, 0.010, 0.0) == 0.020 + 0.001);
    CHECK(lab::highestGrainUnder(grains, axis, 0.005, 0.0) == 0.010 + 0.001);
    CHECK(lab::highestGrainUnder(grains, axis, 0.005, 0.015) == 0.015); // the floor wins
    CHECK(lab::highestGrainUnder(grains, Eigen::Vector2d(1.0, 1.0), 0.010, -1.0) == -1.0);
}

TEST_CASE("Test centre: centre_m when given, else the middle of the deposition region",
          "[lab][lab_bed]") {
    dem::DemScenario soil;
    soil.deposition.region_lower_m = dem::Vec3(0.0, -0.02, 0.0);
    soil.deposition.region_upper_m = dem::Vec3(0.06, 0.04, 0.1);
    const Eigen::Vector2d middle = lab::testCentre(soil, std::nullopt);
    CHECK(middle.x() == 0.03); // exact: halves of sums of short binary fractions
    CHECK(middle.y() == 0.01);
    CHECK(lab::testCentre(soil, Eigen::Vector2d(0.1, 0.2)) == Eigen::Vector2d(0.1, 0.2));

    auto section = [](const std::string &text) {
        return config::ConfigNode::loadString(text, "lab.yaml")["test"];
    };
    CHECK_FALSE(lab::parseCentre(section("test: {speed_m_s: 1}\n")).has_value());
    CHECK(*lab::parseCentre(section("test: {centre_m: [0.1, -0.2]}\n")) ==
          Eigen::Vector2d(0.1, -0.2));
    CHECK_THROWS_WITH(lab::parseCentre(section("test:\n  centre_m: [0.1]\n")),
                      Contains("lab.yaml:2") && Contains("centre_m") &&
                          Contains("expected [x, y]"));
}

TEST_CASE("Lab CSV: header line, 10 significant digits, an unwritable file named",
          "[lab][lab_bed]") {
    const auto dir = std::filesystem::temp_directory_path() /
                     ("grainlink_lab_bed_test-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    {
        auto csv = lab::openCsv(dir, "t.csv", "x_m,y_m");
        csv << 1.0 / 3.0 << ',' << 2.0 << '\n';
    }
    std::ifstream in(dir / "t.csv");
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    CHECK(text == "x_m,y_m\n0.3333333333,2\n");
    std::filesystem::remove_all(dir);
    CHECK_THROWS_WITH(lab::openCsv(dir / "missing", "t.csv", "x_m"),
                      Contains("cannot write") && Contains("missing/t.csv"));
}
