// summary.json (lab/LabSummary.hpp, docs/lab.md): its layout read by an independent JSON parser,
// the round trip through the project's reader, and a real run's summary against its CSV.
#include "grainlink/lab/LabBed.hpp"
#include "grainlink/lab/LabTest.hpp"

#include "TinyRepose.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

using namespace grainlink;
using Catch::Matchers::Contains;

namespace {

const double kNaN = std::numeric_limits<double>::quiet_NaN();

/// A summary with a fit, a NaN, a run value and two curves; 0.1 and 1/3 need all 17 digits.
lab::LabSummary sample() {
    lab::LabSummary s;
    s.test = "bevameter";
    s.scenario = "sample";
    s.condition = "plate_radius_m";
    s.bed.grains = 2600;
    s.bed.surface_m = 0.1;
    s.bed.packing_fraction = 1.0 / 3.0;
    s.bed.seed = 12345678901234ULL;
    s.bed.from_cache = true;
    s.fits.push_back(
        {"bekker", 199, {{"k_c", "N/m^(n+1)", -8.3e3, 0.9e3}, {"n", "-", 0.591, kNaN}}});
    s.runs.push_back(
        {{{"plate_radius_m", 0.025}, {"steps", 10070}},
         {{"sinkage_m", {-0.001, 0.0, 1.0 / 3.0}}, {"pressure_Pa", {0.0, kNaN, 2e4}}}});
    s.wall_s = 12.5;
    return s;
}

std::string readText(const std::filesystem::path &path) {
    std::ifstream in(path);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

} // namespace

TEST_CASE("summary.json: the documented layout, NaN as null", "[lab][summary]") {
    // Read by nlohmann's parser directly, not by labSummaryFromJson: the keys docs/lab.md names.
    const auto j = nlohmann::json::parse(lab::toJson(sample()));
    CHECK(j["format"] == "grainlink-lab-summary");
    CHECK(j["version"] == 1);
    CHECK(j["test"] == "bevameter");
    CHECK(j["scenario"] == "sample");
    CHECK(j["bed"]["grains"] == 2600);
    CHECK(j["bed"]["seed"] == 12345678901234ULL);
    CHECK(j["bed"]["packing_fraction"].get<double>() == 1.0 / 3.0); // shortest round-trip digits
    CHECK(j["bed"]["from_cache"] == true);
    const auto &k_c = j["fits"]["bekker"]["parameters"]["k_c"];
    CHECK(k_c["value"].get<double>() == -8.3e3);
    CHECK(k_c["half_width_95"].get<double>() == 0.9e3);
    CHECK(k_c["unit"] == "N/m^(n+1)");
    CHECK(j["fits"]["bekker"]["degrees_of_freedom"] == 199);
    CHECK(j["fits"]["bekker"]["parameters"]["n"]["half_width_95"].is_null());
    CHECK(j["condition"] == "plate_radius_m");
    const auto &run = j["runs"][0];
    CHECK(run["plate_radius_m"].get<double>() == 0.025);
    CHECK(run["sinkage_m"].size() == 3);
    CHECK(run["sinkage_m"][2].get<double>() == 1.0 / 3.0);
    CHECK(run["pressure_Pa"][1].is_null());
    CHECK(j["wall_s"].get<double>() == 12.5);
}

TEST_CASE("summary.json: the reader gives back what was written", "[lab][summary]") {
    // Exact: the writer prints the shortest digits that read back to the same double.
    const lab::LabSummary a = sample();
    const lab::LabSummary b = lab::labSummaryFromJson(lab::toJson(a), "sample.json");
    CHECK(b.test == a.test);
    CHECK(b.bed.seed == a.bed.seed);
    CHECK(b.bed.packing_fraction == a.bed.packing_fraction);
    CHECK(b.bed.from_cache);
    CHECK(b.fitted("bekker", "k_c").value == -8.3e3);
    CHECK(b.fitted("bekker", "k_c").unit == "N/m^(n+1)");
    CHECK(std::isnan(b.fitted("bekker", "n").half_width_95));
    REQUIRE(b.runs.size() == 1);
    CHECK(b.runs[0].value("steps") == 10070);
    CHECK(b.runs[0].curve("sinkage_m") == a.runs[0].curve("sinkage_m"));
    CHECK(std::isnan(b.runs[0].curve("pressure_Pa")[1]));
    CHECK(lab::toJson(b) == lab::toJson(a));

    CHECK_THROWS_WITH(b.fitted("janosi", "c"), Contains("'c' of 'janosi'"));
    CHECK_THROWS_WITH(b.runs[0].curve("force_N"), Contains("no curve 'force_N'"));
    CHECK_THROWS_WITH(lab::labSummaryFromJson("{\"format\": \"x\"}", "other.json"),
                      Contains("other.json") && Contains("format"));
    std::string text = lab::toJson(a);
    text.replace(text.find("\"bed\""), 5, "\"bad\"");
    CHECK_THROWS_WITH(lab::labSummaryFromJson(text, "s.json"),
                      Contains("s.json") && Contains("no 'bed'"));
    CHECK_THROWS_WITH(lab::labSummaryFromJson("{", "broken.json"),
                      Contains("broken.json: not JSON"));
    // A run key given twice would hide one of them in the JSON object.
    lab::LabSummary twice = a;
    twice.runs[0].values.push_back({"sinkage_m", 1.0});
    CHECK_THROWS_WITH(lab::toJson(twice), Contains("'sinkage_m' given twice"));
}

TEST_CASE("Bed summary: a simple cubic packing has packing fraction pi / 6", "[lab][summary]") {
    // 10 x 10 x 5 grains of r = 1 mm on a cubic lattice of 2 r, floor z = 0: the top layer (20 %
    // of the grains) puts the 98th percentile of grain tops at 10 r, so the bed is 10 r high on a
    // 20 r x 20 r footprint and holds a sphere per cube of side 2 r: pi / 6 (1e-12 relative:
    // one sum and two divisions).
    const double r = 0.001;
    dem::DemScenario soil;
    soil.material = {"grains", 1e7, 0.2, 2500.0};
    soil.deposition.radius.min_m = soil.deposition.radius.max_m = r;
    soil.deposition.seed = 7;
    dem::DemSystem system(soil.law, {soil.material}, soil.settings);
    for (int i = 0; i < 10; ++i)
        for (int j = 0; j < 10; ++j)
            for (int k = 0; k < 5; ++k) {
                dem::ParticleSpec grain;
                grain.position_m = dem::Vec3((2 * i + 1) * r, (2 * j + 1) * r, (2 * k + 1) * r);
                grain.radius_m = r;
                grain.density_kg_m3 = soil.material.density_kg_m3;
                system.particles().add(grain);
            }
    const lab::LabBedSummary bed = lab::measureBed(system, soil, {400 * r * r, 0.0});
    CHECK(bed.grains == 500);
    CHECK(bed.surface_m == Approx(10 * r).epsilon(1e-12));
    CHECK(bed.packing_fraction == Approx(M_PI / 6.0).epsilon(1e-12));
    CHECK(bed.bulk_density_kg_m3 == Approx(2500.0 * M_PI / 6.0).epsilon(1e-12));
    CHECK(bed.seed == 7);
}

TEST_CASE("A lab run's summary.json holds what its CSV and report hold", "[lab][summary][dem][slow]") {
    // The tiny repose test through runLabTest, written to disk: summary.json's profile against
    // heap_profile.csv (10 significant digits there), its angle against the result's.
    const auto dir = std::filesystem::temp_directory_path() /
                     ("grainlink_lab_summary_test-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    std::ofstream(dir / "repose.yaml") << kTinyRepose;
    const lab::LabScenario scenario =
        lab::loadLabScenario("repose", (dir / "repose.yaml").string());
    CHECK(lab::labTestName(scenario) == "repose");
    CHECK(lab::labWarnings(scenario).empty());
    lab::LabRunOptions options;
    options.output_directory = (dir / "out").string();
    options.progress_interval_s = 1e9; // quiet
    const lab::LabRun run = lab::runLabTest(scenario, options);
    CHECK(run.files == std::vector<std::string>{"heap_profile.csv", "report.txt", "summary.json"});
    const lab::LabSummary s = lab::readLabSummary((dir / "out" / "summary.json").string());
    CHECK(s.test == "repose");
    CHECK(s.scenario == "tiny-repose");
    CHECK(s.bed.grains == 600);
    CHECK(s.bed.seed == 3);
    CHECK(s.bed.packing_fraction > 0.4); // a random fill in a tube: 0.4-0.64
    CHECK(s.bed.packing_fraction < 0.64);
    REQUIRE(s.runs.size() == 1);
    CHECK(s.runs[0].value("lift_speed_m_s") == 0.1);
    CHECK(s.fitted("repose", "angle").value == run.summary.fitted("repose", "angle").value);
    CHECK_THAT(readText(dir / "out" / "report.txt"), Contains("angle of repose"));

    std::ifstream csv(dir / "out" / "heap_profile.csv");
    std::string line;
    std::getline(csv, line);
    CHECK(line == "radius_m,height_m,grains");
    const auto &radius = s.runs[0].curve("radius_m"), &height = s.runs[0].curve("height_m");
    std::size_t rows = 0;
    for (; std::getline(csv, line); ++rows) {
        REQUIRE(rows < radius.size());
        double r = 0, h = 0;
        char comma;
        std::istringstream(line) >> r >> comma >> h;
        CHECK(r == Approx(radius[rows]).epsilon(1e-9));
        CHECK(h == Approx(height[rows]).epsilon(1e-9));
    }
    CHECK(rows == radius.size());
    std::filesystem::remove_all(dir);
}
