#include "grainlink/gap/Comparison.hpp"
#include "grainlink/gap/Experiments.hpp"
#include "grainlink/gap/Importers.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

using namespace grainlink::gap;
namespace fs = std::filesystem;

namespace {

fs::path scratch(const std::string &name) {
    const fs::path p = fs::temp_directory_path() /
                       ("grainlink-import-" + name + "-" + std::to_string(::getpid()));
    fs::remove_all(p);
    return p;
}

const fs::path kCmu = fs::path(GRAINLINK_SOURCE_DIR) / ".." / "shared" / "data" / "cmu-3d-terramechanics";

} // namespace

// Hidden from the default run ([.]): registered on its own with ctest, which reports it as
// skipped when the data folder is absent (as on a user's clone).
TEST_CASE("the CMU importer reads every plate trial and wheel run, as the data's summary says",
          "[.][cmu]") {
    if (!fs::is_directory(kCmu)) {
        WARN("skipped: no CMU data at " << kCmu.string());
        return;
    }
    const fs::path out = scratch("cmu");
    const auto ids = importCmu(kCmu.string(), out.string());
    const ExperimentSet set = loadExperiments(out.string());
    int plates = 0, wheels = 0;
    for (const Experiment &e : set.experiments) {
        if (e.type == ExperimentType::PlateSinkage) {
            ++plates;
            CHECK(e.trials.size() == 3);
        } else {
            ++wheels;
            CHECK(e.trials.size() == 27); // 27 runs per slip angle and wheel
        }
    }
    CHECK(plates == 6);  // 3 sizes x 2 boxes
    CHECK(wheels == 14); // 2 wheels x 7 slip angles
    // Against summary.csv: the large-box 60 mm trial 1 peaks at 53.0 kPa and 38.3 mm
    // (max synced sinkage from its sidecar: 38.3 mm authors' / synced within 1 mm).
    const Experiment &e = set.find("large_d060");
    const Curve &c = e.trials[0].curves.at("pressure_Pa");
    CHECK(*std::max_element(c.y.begin(), c.y.end()) == Approx(53.0e3).epsilon(0.002));
    CHECK(e.numbers.at("plate_diameter_m") == Approx(0.06));
    CHECK(e.numbers.at("speed_m_s") > 0.0005); // the descent: 1.5-8.7 mm/s medians
    CHECK(e.numbers.at("speed_m_s") < 0.01);
    // The grousered wheel at slip angle 0: traction rises with slip.
    const Experiment &w = set.find("grouser_beta0");
    const FeatureDesign d = designFeatures(set);
    const Measured m = measure(set, d);
    double first = NAN, last = NAN;
    for (Eigen::Index k : d.by_experiment.at("grouser_beta0"))
        if (d.keys[std::size_t(k)].observable == "traction_N") {
            if (std::isnan(first))
                first = m.value[k];
            last = m.value[k];
        }
    CHECK(last > first);
    CHECK(w.numbers.at("grouser_height_m") == Approx(0.005));
}

TEST_CASE("a plain CSV becomes an experiment of a measurements folder", "[gap][import]") {
    const fs::path out = scratch("csv");
    const fs::path src = fs::temp_directory_path() / ("plate-" + std::to_string(::getpid()) + ".csv");
    {
        std::ofstream f(src);
        f << "z_mm,p_kPa,other\n0,0,1\n5,10,1\n10,25,1\n";
    }
    CsvImport csv;
    csv.file = src.string();
    csv.id = "p50";
    csv.type = "plate_sinkage";
    csv.x_column = "z_mm";
    csv.x_unit = "mm";
    csv.y["pressure_Pa"] = {"p_kPa", "kPa"};
    csv.conditions = {{"plate_diameter_m", "0.05"}, {"box", "bin"}};
    importCsv(csv, out.string());
    csv.id = "p50b";
    importCsv(csv, out.string()); // a second one is appended
    const ExperimentSet set = loadExperiments(out.string());
    REQUIRE(set.experiments.size() == 2);
    const Experiment &e = set.find("p50");
    CHECK(e.numbers.at("plate_diameter_m") == 0.05);
    CHECK(e.labels.at("box") == "bin");
    CHECK(e.trials[0].curves.at("pressure_Pa").y.back() == Approx(25000.0));
    CHECK(e.trials[0].curves.at("pressure_Pa").x.back() == Approx(0.01));
    CHECK_THROWS_WITH(importCsv(csv, out.string()), Catch::Contains("already in"));
}
