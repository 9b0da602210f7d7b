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
    csv.files = {src.string()};
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
    // Numbers are written as given, not as yaml-cpp's 17 digits (0.050000000000000003).
    std::ifstream written(out / "experiments.yaml");
    const std::string text((std::istreambuf_iterator<char>(written)),
                           std::istreambuf_iterator<char>());
    CHECK_THAT(text, Catch::Contains("plate_diameter_m: 0.05}") &&
                         !Catch::Contains("0.050000000000000003"));
}

TEST_CASE("import csv reads a file as the diagnosis does, and a failed import leaves the folder "
          "as it was",
          "[gap][import]") {
    const fs::path out = scratch("csv-eu");
    const auto file = [](const std::string &name, const std::string &text) {
        const fs::path p =
            fs::temp_directory_path() / (name + "-" + std::to_string(::getpid()) + ".csv");
        std::ofstream(p) << text;
        return p.string();
    };
    // A European spreadsheet's export: a byte-order mark, quoted names holding the delimiter,
    // ';' between cells, decimal commas.
    CsvImport csv;
    csv.files = {file("eu", "\xEF\xBB\xBF\"Sinkage; mm\";\"Pressure; kPa\"\n0,5;1,5\n1;3\n")};
    csv.id = "eu";
    csv.type = "plate_sinkage";
    csv.x_column = "Sinkage; mm";
    csv.x_unit = "mm";
    csv.y["pressure_Pa"] = {"Pressure; kPa", "kPa"};
    csv.delimiter = ";";
    csv.decimal = ",";
    importCsv(csv, out.string() + "/");
    const ExperimentSet set = loadExperiments(out.string());
    CHECK(set.name == out.filename().string());
    const Curve &c = set.find("eu").trials[0].curves.at("pressure_Pa");
    REQUIRE(c.y.size() == 2);
    CHECK(c.y[0] == Approx(1500.0));
    CHECK(c.x[1] == Approx(0.001));

    // A scalar: the column's values.
    CsvImport repose;
    repose.files = {file("repose", "trial,angle\n1,29.5\n2,30.1\n")};
    repose.id = "repose";
    repose.type = "angle_of_repose";
    repose.y["angle_deg"] = {"angle", "deg"};
    importCsv(repose, out.string());
    CHECK(loadExperiments(out.string()).find("repose").trials.size() == 2);

    // Refused before anything is written, naming the user's file and line: the folder reads as
    // before, no copy is left, and the same id imports once the file is fixed.
    std::ifstream before_in(out / "experiments.yaml");
    const std::string before((std::istreambuf_iterator<char>(before_in)),
                             std::istreambuf_iterator<char>());
    CsvImport bad = csv;
    bad.id = "units_row";
    bad.files = {file("unitsrow", "z;p\nmm;kPa\n1;2\n2;5\n")};
    bad.x_column = "z";
    bad.y = {{"pressure_Pa", {"p", "kPa"}}};
    // The reader's hint names the importer's option, not a key of experiments.yaml.
    CHECK_THROWS_WITH(
        importCsv(bad, out.string()),
        Catch::Contains(bad.files[0] + ":2: column 'z': 'mm' is not a finite number") &&
            Catch::Contains("give --units-row") && !Catch::Contains("data.units_row"));
    // A ';' file read with the default ',': the option that reads it, not a decimal comma.
    CsvImport no_delimiter = csv;
    no_delimiter.id = "no_delimiter";
    no_delimiter.delimiter = ",";
    CHECK_THROWS_WITH(importCsv(no_delimiter, out.string()),
                      Catch::Contains("give --delimiter \";\"") && !Catch::Contains("data."));
    // A unit of the wrong kind is named by its option, before any file is read or written.
    CsvImport wrong_unit = csv;
    wrong_unit.id = "wrong_unit";
    wrong_unit.y = {{"pressure_Pa", {"Pressure; kPa", "mm"}}};
    CHECK_THROWS_WITH(importCsv(wrong_unit, out.string()),
                      Catch::Contains("--y pressure_Pa=Pressure; kPa:mm: ") &&
                          Catch::Contains("not a pressure"));
    CsvImport bad_id = csv;
    bad_id.id = "../up";
    CHECK_THROWS_WITH(importCsv(bad_id, out.string()), Catch::Contains("one word"));
    std::ifstream after_in(out / "experiments.yaml");
    CHECK(std::string((std::istreambuf_iterator<char>(after_in)),
                      std::istreambuf_iterator<char>()) == before);
    CHECK_FALSE(fs::exists(out / "data" / "units_row.csv"));
    CHECK_FALSE(fs::exists(out / "data" / "wrong_unit.csv"));
    bad.units_row = true; // the units row skipped, as the copy's reader needs no such flag
    importCsv(bad, out.string());
    CHECK(loadExperiments(out.string()).find("units_row").trials[0].curves.at("pressure_Pa").y ==
          (std::vector<double>{2000.0, 5000.0}));

    // Repeats of one test: one experiment, a trial per file, a copy per file.
    CsvImport repeats = csv;
    repeats.id = "repeats";
    repeats.files = {file("rep1", "\"Sinkage; mm\";\"Pressure; kPa\"\n0,5;1,5\n1;3\n"),
                     file("rep2", "\"Sinkage; mm\";\"Pressure; kPa\"\n0,5;1,7\n1;3,2\n")};
    importCsv(repeats, out.string());
    const ExperimentSet with_repeats = loadExperiments(out.string());
    const Experiment &r = with_repeats.find("repeats");
    REQUIRE(r.trials.size() == 2);
    CHECK(r.trials[1].curves.at("pressure_Pa").y[0] == Approx(1700.0));
    CHECK(fs::exists(out / "data" / "repeats_1.csv"));
    CHECK(fs::exists(out / "data" / "repeats_2.csv"));
}
