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
    repose.files = {file("repose", "trial,angle\n1,29.5\n2,30.1\n3,\n4,NaN\n")};
    repose.id = "repose";
    repose.type = "angle_of_repose";
    repose.y["angle_deg"] = {"angle", "deg"};
    // Values missing: left out, and said (written inline, they could not be said later).
    const auto said = importCsv(repose, out.string());
    REQUIRE(said.size() == 1);
    CHECK_THAT(said[0], Catch::StartsWith(repose.files[0] + ": 2 of 4 rows miss a value in "
                                                            "'angle' (empty or NaN); those are "
                                                            "left out (lines 4, 5)"));
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

namespace {

std::string writeInput(const std::string &name, const std::string &text) {
    const fs::path p =
        fs::temp_directory_path() / (name + "-" + std::to_string(::getpid()) + ".csv");
    std::ofstream(p) << text;
    return p.string();
}

CsvImport plate(const std::string &file) {
    CsvImport csv;
    csv.files = {file};
    csv.id = "p40";
    csv.type = "plate_sinkage";
    csv.x_column = "Sinkage, mm";
    csv.x_unit = "mm";
    csv.y["pressure_Pa"] = {"Pressure, kPa", "kPa"};
    csv.units_row = true;
    return csv;
}

const char *kPlateRun = "\"Sinkage, mm\",\"Pressure, kPa\",\"Comment\"\nmm,kPa,-\n"
                        "0.5,7.3,ok\n1.0,12.0,ok\n1.5,18.5,ok\n";

} // namespace

TEST_CASE("import csv names a wrong observable with every observable of its type, and a "
          "missing column among its quoted columns",
          "[gap][import]") {
    const fs::path out = scratch("csv-names");
    CsvImport wrong = plate(writeInput("names", kPlateRun));
    wrong.y = {{"pressure", {"Pressure, kPa", "kPa"}}};
    // Not a unit error: the name is wrong, and a plate may give its pressure or its force.
    CHECK_THROWS_WITH(importCsv(wrong, out.string()),
                      "--y pressure=Pressure, kPa:kPa: 'pressure' is not an observable of "
                      "plate_sinkage (its observables: pressure_Pa, force_N)");
    // A scalar's one value too: its name was not checked, and any name became angle_deg.
    CsvImport repose;
    repose.files = {writeInput("names-repose", "trial,angle\n1,29.5\n2,30.1\n")};
    repose.id = "repose";
    repose.type = "angle_of_repose";
    repose.y["angle"] = {"angle", "deg"};
    CHECK_THROWS_WITH(importCsv(repose, out.string()),
                      Catch::Contains("'angle' is not an observable of angle_of_repose (its "
                                      "observables: angle_deg)"));
    CsvImport missing = plate(wrong.files[0]);
    missing.x_column = "Sinkage";
    CHECK_THROWS_WITH(importCsv(missing, out.string()),
                      Catch::Contains("column 'Sinkage' is not in " + wrong.files[0] +
                                      " (its columns: 'Sinkage, mm', 'Pressure, kPa', 'Comment')"));
    CHECK_FALSE(fs::exists(out));
}

TEST_CASE("import csv names the --condition or the input file of an error, never the folder it "
          "would have written",
          "[gap][import]") {
    const fs::path out = scratch("csv-cond");
    CsvImport csv = plate(writeInput("cond", kPlateRun));
    csv.conditions = {{"plate_diameter_m", "40mm"}};
    CHECK_THROWS_WITH(importCsv(csv, out.string()),
                      Catch::StartsWith("--condition plate_diameter_m=40mm: ") &&
                          Catch::Contains("(0.04 for 40mm)"));
    // Refused by the read-back of what the import wrote: said by the option all the same, and
    // the folder it made is gone.
    csv.conditions = {{"plate_diameter_m", "40"}};
    CHECK_THROWS_WITH(importCsv(csv, out.string()),
                      Catch::StartsWith("--condition plate_diameter_m=40: ") &&
                          Catch::Contains("given in mm?") && !Catch::Contains("experiments.yaml"));
    CHECK_FALSE(fs::exists(out));
    // A force needs the plate's size: the option to give, not the key of a file.
    csv.conditions.clear();
    csv.y = {{"force_N", {"Pressure, kPa", "N"}}};
    CHECK_THROWS_WITH(importCsv(csv, out.string()),
                      Catch::StartsWith("--y force_N=Pressure, kPa:N: ") &&
                          Catch::Contains("--condition plate_diameter_m") &&
                          !Catch::Contains("conditions."));
    // An error found in the copy names the input file and its own line: a slip in % under "-"
    // on the input's line 4 (a comment and the header above it; the copy's own line 4 is the
    // first row).
    CsvImport wheel;
    wheel.files = {writeInput("cond-wheel", "# tester\ns,dp\n0.1,1\n12,2\n30,3\n")};
    wheel.id = "w";
    wheel.type = "wheel_steady_state";
    wheel.x_column = "s";
    wheel.x_unit = "-";
    wheel.y["drawbar_pull_N"] = {"dp", "N"};
    wheel.scatter = true;
    CHECK_THROWS_WITH(importCsv(wheel, out.string()),
                      Catch::StartsWith("--x s:-: " + wheel.files[0] + ":4: column 's': slip 12") &&
                          Catch::Contains("give --x s:%") && !Catch::Contains("data/"));
    // One sample is no curve: said of the input file.
    CsvImport one =
        plate(writeInput("cond-one", "\"Sinkage, mm\",\"Pressure, kPa\"\nmm,kPa\n1,2\n"));
    CHECK_THROWS_WITH(importCsv(one, out.string()),
                      Catch::StartsWith(one.files[0] + ": 'pressure_Pa' has 1 sample(s)"));
    CHECK_FALSE(fs::exists(out));
}

TEST_CASE("import csv checks condition names as the diagnosis reads them", "[gap][import]") {
    const fs::path out = scratch("csv-condname");
    CsvImport csv = plate(writeInput("condname", kPlateRun));
    // A decimal comma in an option (--decimal reads the files only).
    csv.conditions = {{"plate_diameter_m", "0,04"}};
    CHECK_THROWS_WITH(importCsv(csv, out.string()),
                      Catch::Contains("(0.04 for 0,04: a decimal point in options)"));
    // The plate's size misspelt: its test could not be set up, so it is refused.
    csv.conditions = {{"plate_diam", "0.04"}};
    CHECK_THROWS_WITH(importCsv(csv, out.string()),
                      Catch::StartsWith("--condition plate_diam=0.04: 'plate_diam' is not a "
                                        "condition of plate_sinkage (misspelt?") &&
                          Catch::Contains("plate_diameter_m, gravity_m_s2, bed_depth_m"));
    // With the size given, an unknown one is kept, but said.
    csv.conditions = {{"plate_diameter_m", "0.04"}, {"gravty_m_s2", "1.62"}, {"box", "large"}};
    const auto warnings = importCsv(csv, out.string());
    REQUIRE(warnings.size() == 1);
    CHECK_THAT(warnings[0], Catch::StartsWith("--condition gravty_m_s2=1.62: 'gravty_m_s2' is "
                                              "not a condition of plate_sinkage (misspelt?"));
    CHECK(loadExperiments(out.string()).find("p40").numbers.at("plate_diameter_m") == 0.04);
}

TEST_CASE("import csv reads another code's z-up output: skipped lines, scales and a zero",
          "[gap][import]") {
    const fs::path out = scratch("csv-zup");
    // A title line, z up: the plate goes down (z < 0) and the soil pushes it up, its force on
    // the soil negative.
    CsvImport csv;
    csv.files = {writeInput("zup", "LIGGGHTS plate run 1\nstep,z_m,fz_N\n0,0.0,0\n"
                                   "1,-0.001,-2\n2,-0.002,-5\n")};
    csv.id = "lig";
    csv.type = "plate_sinkage";
    csv.x_column = "z_m";
    csv.x_unit = "m";
    csv.y["force_N"] = {"fz_N", "N"};
    csv.conditions = {{"plate_diameter_m", "0.02"}};
    CHECK_THROWS_WITH(importCsv(csv, out.string()), Catch::Contains("--skip-lines"));
    csv.skip_lines = 1;
    // The other sign: refused, with the options that turn it.
    CHECK_THROWS_WITH(importCsv(csv, out.string()),
                      Catch::Contains("give --x-scale -1 or --y-scale OBS=-1"));
    csv.x_scale = -1.0;
    csv.y_scale["force_N"] = -1.0;
    csv.zero_method = "force_threshold";
    csv.zero_threshold = 1.0;
    csv.zero_unit = "N";
    CsvImport bad_scale = csv;
    bad_scale.y_scale = {{"pressure_Pa", -1.0}};
    CHECK_THROWS_WITH(importCsv(bad_scale, out.string()),
                      Catch::StartsWith("--y-scale pressure_Pa=-1: no --y pressure_Pa"));
    CsvImport bad_zero = csv;
    bad_zero.zero_unit = "mm";
    CHECK_THROWS_WITH(importCsv(bad_zero, out.string()),
                      Catch::StartsWith("--zero force_threshold=1:mm: ") &&
                          Catch::Contains("not a force"));
    // A threshold no sample reaches: said by the option, not at a line of the folder's
    // experiments.yaml, which the failed import leaves as it was.
    CsvImport high_zero = csv;
    high_zero.zero_threshold = 500.0;
    CHECK_THROWS_WITH(importCsv(high_zero, out.string()),
                      Catch::StartsWith("--zero force_threshold=500:N: ") &&
                          Catch::Contains("check its threshold") &&
                          !Catch::Contains("experiments.yaml"));
    importCsv(csv, out.string());
    const ExperimentSet set = loadExperiments(out.string());
    const Experiment &e = set.find("lig");
    const double area = M_PI * 0.01 * 0.01;
    CHECK(e.zero.method == ZeroConvention::Method::ForceThreshold);
    CHECK(e.zero.threshold == Approx(1.0 / area));
    // 2 N (the first force over 1 N) at 1 mm down is the zero: 5 N at 1 mm below it.
    const Curve c = applyZero(e.trials[0].curves.at("pressure_Pa"), e.zero);
    CHECK(c.x.back() == Approx(0.001));
    CHECK(c.y.back() == Approx(5.0 / area));
}

TEST_CASE("import csv says a column that varies within a scatter, and --filter takes one value",
          "[gap][import]") {
    const fs::path out = scratch("csv-filter");
    // Two slip angles in one file, the side force following the angle, a run counter.
    std::string text = "run,beta_deg,slip,dp_N,fy_N\n";
    for (int r = 0; r < 8; ++r)
        text += std::to_string(r + 1) + "," + (r < 4 ? "0" : "15") + ",0." + std::to_string(r + 1) +
                "," + std::to_string(r) + "," + (r < 4 ? "0" : "-0.75") + "\n";
    CsvImport csv;
    csv.files = {writeInput("filter", text)};
    csv.id = "w";
    csv.type = "wheel_steady_state";
    csv.x_column = "slip";
    csv.x_unit = "-";
    csv.y["drawbar_pull_N"] = {"dp_N", "N"};
    csv.scatter = true;
    const auto merged = importCsv(csv, out.string());
    REQUIRE(merged.size() == 1); // not the run counter, nor fy_N, which follows beta_deg
    CHECK_THAT(merged[0], Catch::Contains("column 'beta_deg' takes 2 values (0, 15)") &&
                              Catch::Contains("--filter beta_deg=0"));
    csv.id = "w15";
    csv.filter = {{"beta_deg", 15.0}};
    csv.conditions = {{"slip_angle_deg", "15"}};
    CHECK(importCsv(csv, out.string()).empty());
    const ExperimentSet set = loadExperiments(out.string());
    const Experiment &e = set.find("w15");
    REQUIRE(e.trials.size() == 4);
    CHECK(e.trials[0].curves.at("drawbar_pull_N").y[0] == 4.0); // run 5, the first at 15 deg
    csv.id = "w30";
    csv.filter = {{"beta_deg", 30.0}};
    CHECK_THROWS_WITH(importCsv(csv, out.string()),
                      "--filter beta_deg=30: no row of " + csv.files[0] + " holds it");
}

TEST_CASE("import csv reads trials written one after the other by their --trial column",
          "[gap][import]") {
    const fs::path out = scratch("csv-trial");
    // Two runs in one file, the second starting on input line 6 (title, units, three rows).
    CsvImport csv = plate(writeInput("trial", "\"Sinkage, mm\",\"Pressure, kPa\",Run\nmm,kPa,-\n"
                                              "0.0,0.0,A\n1.0,12.0,A\n2.0,20.0,A\n"
                                              "0.0,0.0,B\n1.0,14.0,B\n2.0,22.0,B\n"));
    // Without --trial the runs would be one curve: refused at the input's line, by the option.
    CHECK_THROWS_WITH(importCsv(csv, out.string()),
                      Catch::Contains(csv.files[0] + ":6: sinkage_m falls back to its start") &&
                          Catch::Contains("give --trial COLUMN") && !Catch::Contains("data/"));
    CHECK_FALSE(fs::exists(out));
    csv.trial_column = "Run";
    importCsv(csv, out.string());
    const Experiment &e = loadExperiments(out.string()).find("p40");
    REQUIRE(e.trials.size() == 2);
    CHECK(e.trials[1].curves.at("pressure_Pa").y.back() == Approx(22000.0));
    // A scatter's rows are its trials already; a trial column the file lacks is named.
    CsvImport scatter = csv;
    scatter.id = "w";
    scatter.scatter = true;
    CHECK_THROWS_WITH(importCsv(scatter, out.string()),
                      Catch::StartsWith("--trial Run: a scatter's rows are its trials already"));
    CsvImport missing = csv;
    missing.id = "p41";
    missing.trial_column = "run_no";
    CHECK_THROWS_WITH(importCsv(missing, out.string()), Catch::Contains("'run_no'"));
}

TEST_CASE("import csv holds the options' units to the file's own units row", "[gap][import]") {
    const fs::path out = scratch("csv-unitsrow");
    CsvImport csv = plate(writeInput("unitsrow", kPlateRun)); // its units row: mm, kPa
    csv.x_unit = "m";
    CHECK_THROWS_WITH(importCsv(csv, out.string()),
                      Catch::StartsWith("--x Sinkage, mm:m: " + csv.files[0] +
                                        ":2: the units row gives column 'Sinkage, mm' in 'mm', "
                                        "but it is read in 'm'"));
    csv.x_unit = "mm";
    csv.y["pressure_Pa"].second = "Pa";
    CHECK_THROWS_WITH(importCsv(csv, out.string()),
                      Catch::StartsWith("--y pressure_Pa=Pressure, kPa:Pa: "));
    CHECK_FALSE(fs::exists(out));
}
