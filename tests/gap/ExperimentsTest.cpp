#include "grainlink/gap/Comparison.hpp"
#include "grainlink/gap/Experiments.hpp"

#include "grainlink/config/ConfigNode.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <unistd.h>

using namespace grainlink::gap;
namespace fs = std::filesystem;

namespace {

/// A fresh folder for one test's measurements (the process id keeps parallel runs apart).
fs::path folder(const std::string &name) {
    const fs::path p = fs::temp_directory_path() /
                       ("grainlink-gap-" + name + "-" + std::to_string(::getpid()));
    fs::remove_all(p);
    fs::create_directories(p);
    return p;
}

void write(const fs::path &p, const std::string &text) { std::ofstream(p) << text; }

/// p = a z (kPa, z in mm) sampled every 0.5 mm to 12 mm.
void linearTrial(const fs::path &p, double a) {
    std::ofstream out(p);
    out << "# a comment line\nsinkage_mm,pressure_kPa\n";
    for (int i = 0; i <= 24; ++i)
        out << 0.5 * i << ',' << a * 0.5 * i << '\n';
}

std::string plateYaml(const std::string &extra = "") {
    return "name: test\nexperiments:\n"
           "  - id: p60\n    type: plate_sinkage\n"
           "    conditions: {plate_diameter_m: 0.06, box: large}\n"
           "    data:\n      files: [a1.csv, a2.csv, a3.csv]\n"
           "      x: {column: sinkage_mm, unit: mm}\n"
           "      y: {pressure_Pa: {column: pressure_kPa, unit: kPa}}\n" +
           extra;
}

/// Writes `yaml` as dir's experiments.yaml and requires it refused with a message holding `what`.
void checkRefused(const fs::path &dir, const std::string &yaml, const std::string &what) {
    write(dir / "experiments.yaml", yaml);
    try {
        loadExperiments(dir.string());
        FAIL("accepted: " << yaml);
    } catch (const grainlink::config::ConfigError &e) {
        INFO(e.what());
        CHECK(std::string(e.what()).find(what) != std::string::npos);
    }
}

} // namespace

TEST_CASE("experiments.yaml: repeats in SI, and their mean and scatter per bin",
          "[gap][experiments]") {
    const fs::path dir = folder("repeats");
    linearTrial(dir / "a1.csv", 1.0);
    linearTrial(dir / "a2.csv", 2.0);
    linearTrial(dir / "a3.csv", 3.0);
    write(dir / "experiments.yaml", plateYaml());
    const ExperimentSet set = loadExperiments(dir.string());
    REQUIRE(set.experiments.size() == 1);
    const Experiment &e = set.experiments[0];
    CHECK(e.trials.size() == 3);
    CHECK(e.trials[1].curves.at("pressure_Pa").y.back() == Approx(2.0 * 12.0 * 1000.0));
    CHECK(e.trials[1].curves.at("pressure_Pa").x.back() == Approx(0.012));
    CHECK(e.labels.at("box") == "large");
    CHECK(e.numbers.at("plate_diameter_m") == 0.06);

    const FeatureDesign d = designFeatures(set, 6); // 12 mm / 6 -> 2 mm bins
    REQUIRE(d.keys.size() == 6);
    CHECK(d.keys[0].x_hi == Approx(0.002));
    const Measured m = measure(set, d);
    // Bin [4, 6] mm: trial a gives a * 5 mm -> 5, 10, 15 kPa: mean 10 kPa, sd 5 kPa, u = sd/sqrt 3.
    CHECK(m.value[2] == Approx(10000.0));
    CHECK(m.u_D[2] == Approx(5000.0 / std::sqrt(3.0)));
    CHECK(m.from_repeats[2]);
    CHECK(m.trials[2] == 3);

    // A simulated curve equal to the mean trial gives the measured features exactly.
    Curve mean_trial;
    for (int i = 0; i <= 30; ++i) {
        mean_trial.x.push_back(0.0005 * i);
        mean_trial.y.push_back(2.0 * 0.5 * i * 1000.0);
    }
    const Eigen::VectorXd sim = simulatedFeatures(set, d, {{"p60", {{"pressure_Pa", mean_trial}}}});
    CHECK((sim - m.value).cwiseAbs().maxCoeff() < 1e-6);
}

TEST_CASE("experiments.yaml: trials written one after the other in a file are refused as one "
          "curve, and read apart by their trial column",
          "[gap][experiments]") {
    // The three trials of the test above, stacked in one file as another code exports them,
    // each with its run number; a comment line and the header come first (lines 1 and 2).
    const fs::path dir = folder("stacked");
    {
        std::ofstream out(dir / "all.csv");
        out << "# three runs\nrun,sinkage_mm,pressure_kPa\n";
        for (int run = 1; run <= 3; ++run)
            for (int i = 0; i <= 24; ++i)
                out << run << ',' << 0.5 * i << ',' << run * 0.5 * i << '\n';
    }
    const std::string yaml = "name: test\nexperiments:\n"
                             "  - id: p60\n    type: plate_sinkage\n"
                             "    conditions: {plate_diameter_m: 0.06, box: large}\n"
                             "    data:\n      files: [all.csv]\n"
                             "      x: {column: sinkage_mm, unit: mm}\n"
                             "      y: {pressure_Pa: {column: pressure_kPa, unit: kPa}}\n";
    // Read as one curve, each bin would hold the three runs' samples: refused where the second
    // run starts (file line 2 + 25 + 1 = 28), with the key that reads it apart.
    checkRefused(dir, yaml,
                 "all.csv:28: sinkage_m falls back to its start here and runs up "
                 "again (2 time(s) in the file): 3 trials one after the other? give "
                 "data.trial");
    // By its trial column: the three trials of three files, the same mean and scatter.
    write(dir / "experiments.yaml", yaml + "      trial: run\n");
    const ExperimentSet set = loadExperiments(dir.string());
    const Experiment &e = set.experiments.at(0);
    REQUIRE(e.trials.size() == 3);
    CHECK(e.trials[1].curves.at("pressure_Pa").y.back() == Approx(2.0 * 12.0 * 1000.0));
    CHECK(e.trials[2].source.find("(run 3)") != std::string::npos);
    const FeatureDesign d = designFeatures(set, 6);
    const Measured m = measure(set, d);
    CHECK(m.value[2] == Approx(10000.0)); // bin [4, 6] mm: 5, 10, 15 kPa, as above
    CHECK(m.u_D[2] == Approx(5000.0 / std::sqrt(3.0)));
    CHECK(m.trials[2] == 3);

    // One trial unloaded to its start at the end is one trial, its loading branch kept.
    {
        std::ofstream out(dir / "all.csv");
        out << "sinkage_mm,pressure_kPa\n";
        for (int i = 0; i <= 24; ++i)
            out << 0.5 * i << ',' << 0.5 * i << '\n';
        for (int i = 23; i >= 0; --i)
            out << 0.5 * i << ',' << 0.1 * i << '\n';
    }
    write(dir / "experiments.yaml", yaml);
    CHECK(loadExperiments(dir.string()).experiments.at(0).trials.size() == 1);
    // A trial column where each row is a trial already, or that is not in the file.
    checkRefused(dir,
                 "name: test\nexperiments:\n  - id: w\n    type: wheel_steady_state\n"
                 "    data:\n      files: [all.csv]\n      scatter: true\n      trial: run\n"
                 "      x: {column: sinkage_mm, unit: \"-\"}\n"
                 "      y: {traction_N: {column: pressure_kPa, unit: N}}\n",
                 "experiments.yaml:8: key 'experiments[0].data.trial': a scatter's rows are "
                 "its trials already");
    checkRefused(dir, yaml + "      trial: run\n", "'run'");
}

// The factors against NIST SP 811's table (B.9, to 7 digits) and by hand: a table entry
// mistyped, or a unit taken for one of another kind, fails here.
TEST_CASE("units as other tools and the older literature write them convert to SI",
          "[gap][experiments]") {
    CHECK(unitFactor("psi", "pressure") == Approx(6.894757e3).epsilon(1e-6));
    CHECK(unitFactor("lbf", "force") == Approx(4.448222).epsilon(1e-6));
    CHECK(unitFactor("kgf/cm2", "pressure") == Approx(9.806650e4).epsilon(1e-6));
    CHECK(unitFactor("lbf_in", "torque") == Approx(1.129848e-1).epsilon(1e-6));
    CHECK(unitFactor("ft", "length") == Approx(0.3048).epsilon(1e-12));
    CHECK(unitFactor("lb", "mass") == Approx(0.4535924).epsilon(1e-6));
    CHECK(unitFactor("kN/m^2", "pressure") == 1e3);
    CHECK(unitFactor("N/m2", "pressure") == 1.0);
    CHECK(unitFactor("mm/min", "speed") == Approx(1.0 / 60000.0));
    CHECK(unitFactor("g/cm3", "density") == 1e3);
    CHECK(unitFactor("\u00b5m", "length") == 1e-6); // the micro sign, as a spreadsheet writes it
    CHECK(unitFactor("\u03bcm", "length") == 1e-6); // the Greek mu
    CHECK(unitFactor("g0", "acceleration") == 9.80665);
    CHECK_THROWS_WITH(unitFactor("psi", "length"),
                      Catch::Contains("unit 'psi' is a pressure, not a length"));
    CHECK_THROWS_WITH(unitFactor("kN/mm2", "pressure"), Catch::Contains("unknown unit 'kN/mm2'"));

    // Read from a file: a plate curve in inches and psi is the same curve in SI.
    const fs::path dir = folder("customary");
    write(dir / "p.csv", "z_in,p_psi\n0,0\n0.1,2\n0.2,5\n");
    write(dir / "experiments.yaml", "experiments:\n  - id: p\n    type: plate_sinkage\n"
                                    "    conditions: {plate_diameter_m: 0.0508}\n"
                                    "    data: {files: [p.csv], x: {column: z_in, unit: in}, "
                                    "y: {pressure_Pa: {column: p_psi, unit: psi}}}\n");
    const Curve &c =
        loadExperiments(dir.string()).experiments.at(0).trials.at(0).curves.at("pressure_Pa");
    CHECK(c.x.back() == Approx(0.00508));
    CHECK(c.y.back() == Approx(5 * 6894.757).epsilon(1e-6));
}

TEST_CASE("experiments.yaml: a force-threshold zero moves x to the shallowest sample reaching "
          "it, an unloading branch is left out",
          "[gap][experiments]") {
    // p = 0 until 3 mm, then rises: with a 0.5 kPa threshold the zero is at 3.5 mm.
    Curve c{{0.0, 0.001, 0.002, 0.003, 0.0035, 0.004}, {0.0, 0.0, 0.0, 0.0, 600.0, 1200.0}};
    ZeroConvention z;
    z.method = ZeroConvention::Method::ForceThreshold;
    z.threshold = 500.0;
    const Curve zeroed = applyZero(c, z);
    CHECK(zeroed.x.front() == Approx(-0.0035));
    CHECK(zeroed.x[4] == Approx(0.0));
    // The same file written deepest first has the same zero (its first row reaching 0.5 kPa is
    // its deepest).
    const Curve reversed{{c.x.rbegin(), c.x.rend()}, {c.y.rbegin(), c.y.rend()}};
    CHECK(applyZero(reversed, z).x.front() == Approx(-0.0035));
    z.method = ZeroConvention::Method::FirstSample;
    const Curve shifted = applyZero(Curve{{0.002, 0.001, 0.003}, {2.0, 1.0, 3.0}}, z);
    CHECK(shifted.x.front() == 0.0);
    CHECK(shifted.y.front() == 1.0); // sorted by x

    // Loaded to 10 mm (p = z kPa/mm) and unloaded to 8 mm (p falling to 0).
    Curve cycle;
    for (int i = 0; i <= 20; ++i)
        cycle.x.push_back(0.0005 * i), cycle.y.push_back(500.0 * i);
    for (int i = 1; i <= 4; ++i)
        cycle.x.push_back(0.010 - 0.0005 * i), cycle.y.push_back(10000.0 * (1.0 - 0.25 * i));
    CHECK(loadingBranch(cycle) == 21);
    // A file sorted by x the other way round is no unloading: every sample stays.
    CHECK(loadingBranch(Curve{{0.003, 0.002, 0.001, 0.0}, {3.0, 2.0, 1.0, 0.0}}) == 4);

    // Read from a file: an encoder's x repeats (each value three times), loaded to 1 mm and
    // unloaded to 0.8 mm. The unloading samples interleaved with the loading ones would halve
    // the deepest bins; they are left out, and the reading says so.
    const fs::path dir = folder("unload");
    {
        std::ofstream f(dir / "enc.csv");
        f << "z_mm,p_kPa\n";
        for (int i = 0; i <= 10; ++i)
            for (int k = 0; k < 3; ++k)
                f << 0.1 * i << ',' << 10.0 * i << '\n';
        for (int i = 9; i >= 8; --i)
            for (int k = 0; k < 3; ++k)
                f << 0.1 * i << ',' << 10.0 * (i - 8) << '\n';
    }
    // A wheel's table of slips, braking rows last: no time series, every row stays.
    write(dir / "w.csv", "slip,F\n0,1\n0.1,2\n0.2,3\n0.3,4\n0.4,5\n-0.1,-1\n-0.2,-2\n");
    write(dir / "experiments.yaml", "experiments:\n  - id: enc\n    type: plate_sinkage\n"
                                    "    data: {files: [enc.csv], x: {column: z_mm, unit: mm}, "
                                    "y: {pressure_Pa: {column: p_kPa, unit: kPa}}}\n"
                                    "  - id: w\n    type: wheel_steady_state\n"
                                    "    data: {files: [w.csv], x: {column: slip, unit: '-'}, "
                                    "y: {traction_N: {column: F, unit: N}}}\n");
    const ExperimentSet set = loadExperiments(dir.string());
    const Curve &enc = set.find("enc").trials[0].curves.at("pressure_Pa");
    CHECK(enc.x.size() == 33);
    CHECK(*binMean(applyZero(enc, ZeroConvention{}), 0.00075, 0.00095) == Approx(85000.0));
    REQUIRE(set.notes.size() == 1);
    CHECK_THAT(set.notes[0], Catch::Contains("enc.csv: pressure_Pa: the 6 samples after the "
                                             "largest sinkage_m (an unloading) are left out"));
    CHECK(set.find("w").trials[0].curves.at("traction_N").x.size() == 7);
}

TEST_CASE("experiments.yaml: stated uncertainty and the zero's uncertainty enter u_D",
          "[gap][experiments]") {
    const fs::path dir = folder("stated");
    linearTrial(dir / "a1.csv", 2.0);
    write(dir / "experiments.yaml",
          "experiments:\n  - id: one\n    type: plate_sinkage\n"
          "    conditions: {plate_diameter_m: 0.06}\n"
          "    data:\n      files: [a1.csv]\n      x: {column: sinkage_mm, unit: mm}\n"
          "      y: {pressure_Pa: {column: pressure_kPa, unit: kPa}}\n"
          "    uncertainty: {y_sigma: 0.3, unit: kPa, x_zero_sigma: 0.5, x_unit: mm}\n");
    const ExperimentSet set = loadExperiments(dir.string());
    const Measured m = measure(set, designFeatures(set, 6));
    // One trial: sigma 300 Pa and the slope 2 kPa/mm x 0.5 mm = 1 kPa, in quadrature.
    CHECK_FALSE(m.from_repeats[2]);
    CHECK(m.u_D[2] == Approx(std::sqrt(300.0 * 300.0 + 1000.0 * 1000.0)));
    // Beds are shared within a box unless the experiment says its own.
    CHECK_FALSE(set.experiments[0].uncertainty.own_beds);
    write(dir / "experiments.yaml",
          "experiments:\n  - id: one\n    type: plate_sinkage\n"
          "    conditions: {plate_diameter_m: 0.06}\n"
          "    data:\n      files: [a1.csv]\n      x: {column: sinkage_mm, unit: mm}\n"
          "      y: {pressure_Pa: {column: pressure_kPa, unit: kPa}}\n"
          "    uncertainty: {y_sigma: 0.3, unit: kPa, beds: own}\n");
    CHECK(loadExperiments(dir.string()).experiments[0].uncertainty.own_beds);

    // Two observables of one experiment: every bin of each gets its own slope times the zero's
    // uncertainty, the first and last of each too (traction 10 N and torque 2 N m per unit slip).
    {
        std::ofstream f(dir / "wz.csv");
        f << "slip,F,T\n";
        for (int i = 0; i <= 12; ++i)
            f << 0.05 * i << ',' << 0.5 * i << ',' << 0.1 * i << '\n';
    }
    write(dir / "experiments.yaml",
          "experiments:\n  - id: w\n    type: wheel_steady_state\n"
          "    data: {files: [wz.csv], x: {column: slip, unit: '-'}, "
          "y: {traction_N: {column: F, unit: N}, torque_N_m: {column: T, unit: N_m}}}\n"
          "    uncertainty: {x_zero_sigma: 0.01, x_unit: '-'}\n");
    const ExperimentSet wheel = loadExperiments(dir.string());
    const FeatureDesign d = designFeatures(wheel, 6);
    const Measured mw = measure(wheel, d);
    int checked = 0;
    for (Eigen::Index k : d.by_experiment.at("w")) {
        const bool traction = d.keys[std::size_t(k)].observable == "traction_N";
        INFO(d.keys[std::size_t(k)].observable << " bin " << d.keys[std::size_t(k)].x_lo << "-"
                                               << d.keys[std::size_t(k)].x_hi << " value "
                                               << mw.value[k]);
        CHECK(mw.u_D[k] == Approx(traction ? 0.1 : 0.02).epsilon(1e-6));
        ++checked;
    }
    CHECK(checked >= 4);
}

TEST_CASE("experiments.yaml: scalars and scatters", "[gap][experiments]") {
    const fs::path dir = folder("scatter");
    write(dir / "wheel.csv", "slip,F,beta\n0.1,10,0\n0.12,12,0\n0.5,30,0\n0.1,99,45\n");
    write(dir / "experiments.yaml",
          "experiments:\n"
          "  - id: repose\n    type: angle_of_repose\n    data: {values: [29, 31], unit: deg}\n"
          "  - id: w0\n    type: wheel_steady_state\n    conditions: {slip_angle_deg: 0}\n"
          "    data:\n      files: [wheel.csv]\n      scatter: true\n      filter: {beta: 0}\n"
          "      x: {column: slip, unit: '-'}\n      y: {traction_N: {column: F, unit: N}}\n"
          "    bins: {edges: [0, 0.2, 0.4, 0.6], unit: '-'}\n");
    const ExperimentSet set = loadExperiments(dir.string());
    CHECK(set.experiments[1].trials.size() == 3); // the beta = 45 row filtered out
    const FeatureDesign d = designFeatures(set);
    REQUIRE(d.keys.size() == 3); // repose + two slip bins with points
    const Measured m = measure(set, d);
    CHECK(m.value[0] == Approx(30.0));
    CHECK(m.u_D[0] == Approx(1.0)); // sd sqrt 2 over sqrt 2
    CHECK(m.value[1] == Approx(11.0));
    CHECK(m.value[2] == Approx(30.0));

    // One y_sigma in newtons cannot be the sinkage's sigma too.
    write(dir / "wheel.csv", "slip,F,S\n0.1,10,5\n0.12,12,6\n0.5,30,9\n");
    write(dir / "experiments.yaml",
          "experiments:\n"
          "  - id: w0\n    type: wheel_steady_state\n    conditions: {slip_angle_deg: 0}\n"
          "    data:\n      files: [wheel.csv]\n      scatter: true\n"
          "      x: {column: slip, unit: '-'}\n"
          "      y: {traction_N: {column: F, unit: N}, sinkage_m: {column: S, unit: mm}}\n"
          "    bins: {edges: [0, 0.2, 0.4, 0.6], unit: '-'}\n"
          "    uncertainty: {y_sigma: 0.5, unit: N}\n");
    CHECK_THROWS_WITH(loadExperiments(dir.string()),
                      Catch::Matches(".*experiments.yaml:11: .*y_sigma.*'traction_N' \\(force\\) "
                                     "cannot serve 'sinkage_m' \\(length\\).*"));
}

TEST_CASE("wheel runs without bins: the last slip is binned, a run on an inner edge counts once, "
          "one slip is one bin",
          "[gap][experiments]") {
    // Runs at slips 0, 0.25, 0.45, 0.5 and 0.75 (traction 10 N per 0.25 of slip): raw bin 0.125 is
    // rounded to 0.1, and the bins must reach 0.75 (they stopped at 0.7: the 0.75 runs were
    // dropped). Edges fall on 0.5: its run belongs to [0.5, 0.6) alone, not to [0.4, 0.5] too.
    const fs::path dir = folder("slips");
    write(dir / "wheel.csv", "slip,F\n0,0\n0.25,10\n0.45,18\n0.5,20\n0.75,30\n0.5,22\n");
    write(dir / "experiments.yaml",
          "experiments:\n"
          "  - id: w\n    type: wheel_steady_state\n"
          "    data:\n      files: [wheel.csv]\n      scatter: true\n"
          "      x: {column: slip, unit: '-'}\n      y: {traction_N: {column: F, unit: N}}\n");
    const ExperimentSet set = loadExperiments(dir.string());
    const FeatureDesign d = designFeatures(set);
    const Measured m = measure(set, d);
    std::map<double, double> by_bin; // bin start -> mean traction
    int runs = 0;
    for (std::size_t k = 0; k < d.keys.size(); ++k) {
        by_bin[std::round(d.keys[k].x_lo * 10.0) / 10.0] = m.value[Eigen::Index(k)];
        runs += m.trials[Eigen::Index(k)];
    }
    CHECK(runs == 6); // every run counted, once
    REQUIRE(by_bin.count(0.7) == 1);
    CHECK(by_bin[0.7] == Approx(30.0));
    CHECK(by_bin[0.5] == Approx(21.0));
    CHECK(by_bin[0.4] == Approx(18.0));
    // The simulated side bins a run as the measured side does.
    SimulatedCurves sim;
    sim["w"]["traction_N"] = Curve{{0.0, 0.25, 0.45, 0.5, 0.75}, {1.0, 2.0, 2.8, 3.0, 4.0}};
    const Eigen::VectorXd row = simulatedFeatures(set, d, sim);
    for (std::size_t k = 0; k < d.keys.size(); ++k) {
        const double lo = std::round(d.keys[k].x_lo * 10.0) / 10.0;
        if (lo == 0.4)
            CHECK(row[Eigen::Index(k)] == Approx(2.8)); // not (2.8 + 3.0) / 2
        if (lo == 0.5)
            CHECK(row[Eigen::Index(k)] == Approx(3.0));
    }

    // Every run at one slip: that slip is the bin (there was none, and the wheel test stopped
    // with "no slip bin to simulate").
    write(dir / "wheel.csv", "slip,F\n0.2,10\n0.2,12\n");
    const ExperimentSet one = loadExperiments(dir.string());
    const FeatureDesign d1 = designFeatures(one);
    REQUIRE(d1.keys.size() == 1);
    CHECK(d1.keys[0].x_lo == Approx(0.2));
    CHECK(measure(one, d1).value[0] == Approx(11.0));
}

TEST_CASE("data files as other tools write them: a byte-order mark, quoted names, another "
          "delimiter, empty rows, missing values and a box named by a number",
          "[gap][experiments]") {
    const fs::path dir = folder("tools");
    // A spreadsheet's export: BOM, quoted header, ';', a row of empty cells, a blank line, and a
    // sensor dropout (NaN) and an empty cell in the pressure column.
    write(dir / "a1.csv", "\xEF\xBB\xBF\"sinkage_mm\";\"pressure_kPa\"\n0;0\n1;1\n;\n\n"
                          "2;NaN\n3;\n4;4\n");
    linearTrial(dir / "a2.csv", 1.0);
    linearTrial(dir / "a3.csv", 1.0);
    std::string yaml = plateYaml();
    yaml.replace(yaml.find("      x:"), 0, "      delimiter: ;\n");
    // Only a1.csv is ';'-separated: read it alone.
    yaml.replace(yaml.find("[a1.csv, a2.csv, a3.csv]"), 24, "[a1.csv]");
    write(dir / "experiments.yaml", yaml);
    const ExperimentSet set = loadExperiments(dir.string());
    const Curve &c = set.experiments[0].trials[0].curves.at("pressure_Pa");
    CHECK(c.x == std::vector<double>{0.0, 0.001, 0.004});
    CHECK(c.y == std::vector<double>{0.0, 1000.0, 4000.0});
    REQUIRE(set.notes.size() == 1);
    CHECK_THAT(set.notes[0], Catch::Contains("a1.csv: 2 of 5 rows miss a value") &&
                                 Catch::Contains("lines 6, 7"));
    // A wheel run without its sinkage keeps its traction, whichever column comes first.
    write(dir / "w.csv", "slip,S,F\n0.1,,10\n0.3,9,20\n");
    write(dir / "experiments.yaml",
          "experiments:\n  - id: w\n    type: wheel_steady_state\n"
          "    data:\n      files: [w.csv]\n      scatter: true\n"
          "      x: {column: slip, unit: '-'}\n"
          "      y: {sinkage_m: {column: S, unit: mm}, traction_N: {column: F, unit: N}}\n");
    const ExperimentSet wheel = loadExperiments(dir.string());
    REQUIRE(wheel.experiments[0].trials.size() == 2);
    CHECK(wheel.experiments[0].trials[0].curves.count("traction_N") == 1);
    CHECK(wheel.experiments[0].trials[0].curves.count("sinkage_m") == 0);
    // A box named by a number is a name (the base's `boxes: {"1": ...}`, and a group of beds).
    write(dir / "experiments.yaml", yaml.replace(yaml.find("box: large"), 10, "box: 1"));
    const ExperimentSet numbered = loadExperiments(dir.string());
    CHECK(numbered.experiments[0].labels.at("box") == "1");
    CHECK(numbered.experiments[0].numbers.count("box") == 0);
    // A word where a number belongs is still refused, with its file and line.
    write(dir / "a1.csv", "sinkage_mm;pressure_kPa\n0;0\n1;high\n");
    CHECK_THROWS_WITH(
        loadExperiments(dir.string()),
        Catch::Contains("a1.csv:3: column 'pressure_kPa': 'high' is not a finite number"));
    // The wrong delimiter is named as the likely cause of a column not found.
    write(dir / "experiments.yaml",
          plateYaml().replace(plateYaml().find("[a1.csv, a2.csv, a3.csv]"), 24, "[a1.csv]"));
    CHECK_THROWS_WITH(loadExperiments(dir.string()), Catch::Contains("give data.delimiter"));
}

TEST_CASE("data files from other codes and European spreadsheets: names holding the delimiter, "
          "decimal commas, column names on a comment line, a folder named with a slash",
          "[gap][experiments]") {
    const fs::path dir = folder("codes");
    const std::string head = "experiments:\n  - id: p\n    type: plate_sinkage\n    data:\n";
    const std::string axes = "      x: {column: 'Sinkage, mm', unit: mm}\n"
                             "      y: {pressure_Pa: {column: 'Pressure, kPa', unit: kPa}}\n";
    // Quoted names that hold the delimiter, and a doubled quote.
    write(dir / "q.csv", "\"Sinkage, mm\",\"Pressure, kPa\",\"say \"\"hi\"\"\"\n1,2,x\n2,4,y\n");
    write(dir / "experiments.yaml", head + "      files: [q.csv]\n" + axes);
    const ExperimentSet quoted = loadExperiments(dir.string() + "/");
    CHECK(quoted.experiments[0].trials[0].curves.at("pressure_Pa").y ==
          std::vector<double>{2000.0, 4000.0});
    // The folder's name, given with a trailing slash, is still its name.
    CHECK(quoted.name == dir.filename().string());
    CHECK(folderName(dir.string() + "/.") == dir.filename().string());

    // A European spreadsheet: ';' between cells, a decimal comma.
    write(dir / "eu.csv", "z_mm;p_kPa\n0,5;1,25\n1,0;2,5e0\n");
    const std::string eu = head + "      files: [eu.csv]\n      delimiter: ';'\n" +
                           "      x: {column: z_mm, unit: mm}\n"
                           "      y: {pressure_Pa: {column: p_kPa, unit: kPa}}\n";
    write(dir / "experiments.yaml", eu);
    CHECK_THROWS_WITH(loadExperiments(dir.string()),
                      Catch::Contains("eu.csv:2: column 'z_mm': '0,5' is not a finite number") &&
                          Catch::Contains("data.decimal"));
    std::string with_decimal = eu;
    with_decimal.replace(with_decimal.find("      x:"), 0, "      decimal: ','\n");
    write(dir / "experiments.yaml", with_decimal);
    const ExperimentSet european = loadExperiments(dir.string());
    const Curve &c = european.experiments[0].trials[0].curves.at("pressure_Pa");
    REQUIRE(c.x.size() == 2);
    CHECK(c.x[0] == Approx(0.0005));
    CHECK(c.x[1] == Approx(0.001));
    CHECK(c.y[0] == Approx(1250.0));
    CHECK(c.y[1] == Approx(2500.0));
    // A decimal comma in a comma-separated file reads only quoted numbers: unquoted, a row has
    // more cells than the header names, and is refused rather than read under the wrong names.
    checkRefused(dir,
                 head + "      files: [eu.csv]\n      decimal: ','\n" +
                     "      x: {column: z_mm, unit: mm}\n"
                     "      y: {pressure_Pa: {column: p_kPa, unit: kPa}}\n",
                 "eu.csv:2: 3 cells where the header line names 1");
    const std::string zp = "      x: {column: z_mm, unit: mm}\n"
                           "      y: {pressure_Pa: {column: p_kPa, unit: kPa}}\n";
    write(dir / "quoted.csv", "z_mm,p_kPa\n\"0,5\",\"1,25\"\n\"1\",\"2,5\"\n");
    write(dir / "experiments.yaml", head + "      files: [quoted.csv]\n      decimal: ','\n" + zp);
    CHECK(loadExperiments(dir.string()).experiments[0].trials[0].curves.at("pressure_Pa").y ==
          std::vector<double>{1250.0, 2500.0});
    write(dir / "commas.csv", "z_mm,p_kPa\n0,5,1,25\n1,0,2,5\n");
    checkRefused(dir, head + "      files: [commas.csv]\n" + zp,
                 "commas.csv:2: 4 cells where the header line names 2 ('z_mm', 'p_kPa')");
    // A trailing delimiter is no extra cell.
    write(dir / "trailing.csv", "z_mm,p_kPa,\n1,2,\n2,4,\n");
    write(dir / "experiments.yaml", head + "      files: [trailing.csv]\n" + zp);
    CHECK(loadExperiments(dir.string()).experiments[0].trials[0].curves.at("pressure_Pa").y ==
          std::vector<double>{2000.0, 4000.0});
    // Beside a decimal comma a '.' is a thousands separator: refused, not read as 1 and 1.5.
    write(dir / "thousands.csv", "z_um;p_kPa\n750;0,6\n1.000;0,8\n1.500;1,3\n");
    checkRefused(dir,
                 head + "      files: [thousands.csv]\n      delimiter: ';'\n      decimal: ','\n" +
                     "      x: {column: z_um, unit: um}\n"
                     "      y: {pressure_Pa: {column: p_kPa, unit: kPa}}\n",
                 "thousands.csv:3: column 'z_um': '1.000' is not a finite number (data.decimal is "
                 "\",\": a '.' would be a thousands separator");
    // strtod's hexadecimal is no measurement.
    write(dir / "hex.csv", "z_mm,p_kPa\n1,2\n0x10,4\n");
    checkRefused(dir, head + "      files: [hex.csv]\n" + zp,
                 "hex.csv:3: column 'z_mm': '0x10' is not a finite number");
    // A units row under the header: named as the likely cause, and skipped on request.
    write(dir / "units.csv", "z_mm;p_kPa\nmm;kPa\n1;2\n2;-\n3;6\n");
    const std::string units = head + "      files: [units.csv]\n      delimiter: ';'\n";
    checkRefused(dir, units + zp, "give data.units_row: true");
    write(dir / "experiments.yaml", units + "      units_row: true\n" + zp);
    const ExperimentSet with_units = loadExperiments(dir.string());
    const Curve &after_units = with_units.experiments[0].trials[0].curves.at("pressure_Pa");
    CHECK(after_units.y == std::vector<double>{2000.0, 6000.0}); // "-" is a missing value

    // LIGGGHTS' fix ave/time file: its column names stand on a comment line.
    write(dir / "lig.txt", "# Time-averaged data for fix out\n# TimeStep v_z v_p\n"
                           "100 0.001 5.0\n200 0.002 10.0\n");
    write(dir / "experiments.yaml", head + "      files: [lig.txt]\n      delimiter: whitespace\n" +
                                        "      columns: [step, z_m, p_kPa]\n" +
                                        "      x: {column: z_m, unit: m}\n"
                                        "      y: {pressure_Pa: {column: p_kPa, unit: kPa}}\n");
    CHECK(loadExperiments(dir.string()).experiments[0].trials[0].curves.at("pressure_Pa").y ==
          std::vector<double>{5000.0, 10000.0});
    // Too few or too many names for its columns: refused, never read under the wrong names.
    const std::string lig_axes = "      x: {column: z_m, unit: m}\n"
                                 "      y: {pressure_Pa: {column: p_kPa, unit: kPa}}\n";
    checkRefused(dir,
                 head + "      files: [lig.txt]\n      delimiter: whitespace\n" +
                     "      columns: [z_m, p_kPa]\n" + lig_axes,
                 "lig.txt:3: 3 cells where data.columns names 2 ('z_m', 'p_kPa')");
    checkRefused(dir,
                 head + "      files: [lig.txt]\n      delimiter: whitespace\n" +
                     "      columns: [step, z_m, p_kPa, extra]\n" + lig_axes,
                 "lig.txt:3: 3 cells where data.columns names 4");
    // A tab given as the character itself.
    write(dir / "tab.txt", "z_m\tp_kPa\n0.001\t5\n0.002\t10\n");
    write(dir / "experiments.yaml",
          head + "      files: [tab.txt]\n      delimiter: \"\\t\"\n" + lig_axes);
    CHECK(loadExperiments(dir.string()).experiments[0].trials[0].curves.at("pressure_Pa").y ==
          std::vector<double>{5000.0, 10000.0});
    // `comment: ""` reads every line: a header starting with '#'.
    write(dir / "hash.csv", "#z_mm,p_kPa\n1,2\n2,4\n");
    write(dir / "experiments.yaml", head + "      files: [hash.csv]\n      comment: ''\n" +
                                        "      x: {column: '#z_mm', unit: mm}\n"
                                        "      y: {pressure_Pa: {column: p_kPa, unit: kPa}}\n");
    CHECK(loadExperiments(dir.string()).experiments[0].trials[0].curves.at("pressure_Pa").x ==
          std::vector<double>{0.001, 0.002});

    // Two columns of one name, bins with an empty bin, a wheel curve with z up: refused.
    write(dir / "dup.csv", "z_mm,p_kPa,p_kPa\n1,2,3\n");
    checkRefused(dir,
                 head + "      files: [dup.csv]\n      x: {column: z_mm, unit: mm}\n"
                        "      y: {pressure_Pa: {column: p_kPa, unit: kPa}}\n",
                 "two columns are named 'p_kPa'");
    write(dir / "ok.csv", "z_mm,p_kPa\n1,2\n2,3\n");
    checkRefused(dir,
                 head + "      files: [ok.csv]\n      x: {column: z_mm, unit: mm}\n"
                        "      y: {pressure_Pa: {column: p_kPa, unit: kPa}}\n"
                        "    bins: {edges: [0, 1, 1, 2], unit: mm}\n",
                 "increasing edges");
    write(dir / "ws.csv", "slip,Z_mm\n0.1,-5\n0.3,-9\n");
    checkRefused(dir,
                 "experiments:\n  - id: w\n    type: wheel_steady_state\n"
                 "    data: {files: [ws.csv], x: {column: slip, unit: '-'}, "
                 "y: {sinkage_m: {column: Z_mm, unit: mm}}}\n",
                 "every run's sinkage is negative");
}

TEST_CASE("experiments.yaml: bad input names the file, the key and the line",
          "[gap][experiments]") {
    const fs::path dir = folder("bad");
    linearTrial(dir / "a1.csv", 1.0);
    linearTrial(dir / "a2.csv", 1.0);
    linearTrial(dir / "a3.csv", 1.0);
    const auto fails = [&](const std::string &yaml, const std::string &what) {
        checkRefused(dir, yaml, what);
    };
    fails(plateYaml("    colour: red\n"), "experiments.yaml:");
    fails(plateYaml("    colour: red\n"), "colour");
    std::string wrong_unit = plateYaml();
    wrong_unit.replace(wrong_unit.find("unit: kPa"), 9, "unit: mm");
    fails(wrong_unit, "is a length, not a pressure");
    std::string wrong_column = plateYaml();
    wrong_column.replace(wrong_column.find("column: pressure_kPa"), 20, "column: pressure_Pa");
    fails(wrong_column, "column 'pressure_Pa' is not in");
    std::string wrong_type = plateYaml();
    wrong_type.replace(wrong_type.find("plate_sinkage"), 13, "plate_test");
    fails(wrong_type, "unknown experiment type 'plate_test'");
    fails(plateYaml() + "  - id: p60\n    type: angle_of_repose\n    data: {values: [1], unit: deg}\n",
          "used twice");
    fails(plateYaml("    uncertainty: {beds: separate}\n"), "experiments.yaml:10");
    fails(plateYaml("    uncertainty: {beds: separate}\n"), "'separate'");
    // A file of one row covers no bin: refused by name instead of dropping out of the diagnosis.
    write(dir / "a2.csv", "sinkage_mm,pressure_kPa\n3.0,12.0\n");
    fails(plateYaml(), "a2.csv: 'pressure_Pa' has 1 sample(s)");
    fails(plateYaml(), "experiments.yaml:7: key 'experiments[0].data.files[1]'");
    linearTrial(dir / "a2.csv", 1.0);
    // A plate's radius beside a diameter that is not twice it.
    std::string both = plateYaml();
    both.replace(both.find("box: large"), 10, "box: large, plate_radius_m: 0.02");
    fails(both, "plate_radius_m 0.02 and plate_diameter_m 0.06 disagree");
    fails(both, "experiments.yaml:5: key 'experiments[0].conditions.plate_radius_m'");
}

// A size under the other name (a plate's radius, a wheel's diameter) sets up the test as the
// condition it is: read as it was, it would be "not simulated" and the base's size would stand.
TEST_CASE(
    "experiments.yaml: a plate's radius and a wheel's diameter are read as the sizes they are",
    "[gap][experiments]") {
    const fs::path dir = folder("sizes");
    linearTrial(dir / "a1.csv", 1.0);
    linearTrial(dir / "a2.csv", 1.0);
    linearTrial(dir / "a3.csv", 1.0);
    std::string radius = plateYaml();
    radius.replace(radius.find("plate_diameter_m: 0.06"), 22, "plate_radius_m: 0.03");
    write(dir / "experiments.yaml",
          radius + "  - id: w\n    type: wheel_steady_state\n"
                   "    conditions: {wheel_diameter_m: 0.116, load_N: 23}\n"
                   "    data: {files: [w.csv], scatter: true, x: {column: slip, unit: '-'}, "
                   "y: {traction_N: {column: F, unit: N}}}\n");
    write(dir / "w.csv", "slip,F\n0.1,1\n0.3,3\n");
    const ExperimentSet set = loadExperiments(dir.string());
    CHECK(set.experiments[0].numbers.at("plate_diameter_m") == Approx(0.06));
    CHECK(set.experiments[0].numbers.count("plate_radius_m") == 0);
    CHECK(set.experiments[1].numbers.at("wheel_radius_m") == Approx(0.058));
    CHECK(set.experiments[1].numbers.count("wheel_diameter_m") == 0);
}

// Another code's output: the plate's force in N with z up (force and sinkage negative). Read
// with `force_N` and `scale: -1`, it is the pressure F / (pi d^2 / 4) on a growing sinkage; read
// as it is, it is refused with the fix, not compared as an enormous gap.
TEST_CASE("experiments.yaml: a plate force with z up becomes its pressure", "[gap][experiments]") {
    const fs::path dir = folder("force");
    const double d = 0.06, area = M_PI * d * d / 4.0; // 2.827e-3 m^2
    for (const char *name : {"f1.csv", "f2.csv"}) {
        std::ofstream out(dir / name);
        out << "z_mm,Fz_N\n";
        for (int i = 0; i <= 20; ++i)
            out << -0.5 * i << ',' << -10.0 * i << '\n'; // 10 N per 0.5 mm, both negative
    }
    const std::string head = "name: other-code\nexperiments:\n"
                             "  - id: p60\n    type: plate_sinkage\n"
                             "    conditions: {plate_diameter_m: 0.06}\n"
                             "    data:\n      files: [f1.csv, f2.csv]\n";
    write(dir / "experiments.yaml",
          head + "      x: {column: z_mm, unit: mm, scale: -1}\n"
                 "      y: {force_N: {column: Fz_N, unit: N, scale: -1}}\n"
                 "    zero: {method: force_threshold, threshold: 5, unit: N}\n"
                 "    uncertainty: {y_sigma: 2, unit: N}\n");
    const ExperimentSet set = loadExperiments(dir.string());
    const Experiment &e = set.experiments.at(0);
    REQUIRE(e.observables == std::vector<std::string>{"pressure_Pa"});
    const Curve &c = e.trials.at(0).curves.at("pressure_Pa");
    CHECK(c.x.back() == Approx(0.010));
    CHECK(c.y.back() == Approx(200.0 / area)); // 70.7 kPa
    CHECK(e.zero.threshold == Approx(5.0 / area));
    CHECK(e.uncertainty.y_sigma == Approx(2.0 / area));
    // A threshold no trial reaches (500 N against 200 N at most) is said with the experiment.
    write(dir / "experiments.yaml",
          head + "      x: {column: z_mm, unit: mm, scale: -1}\n"
                 "      y: {force_N: {column: Fz_N, unit: N, scale: -1}}\n"
                 "    zero: {method: force_threshold, threshold: 500, unit: N}\n");
    CHECK_THROWS_WITH(designFeatures(loadExperiments(dir.string())),
                      Catch::Matches(".*experiments.yaml:[0-9]+: experiment 'p60': no trial of "
                                     "'pressure_Pa' has a sample from its zero on.*"));

    const auto refused = [&](const std::string &axes, const std::string &what) {
        checkRefused(dir, head + axes, what);
        checkRefused(dir, head + axes, "scale: -1");
    };
    refused("      x: {column: z_mm, unit: mm, scale: -1}\n"
            "      y: {force_N: {column: Fz_N, unit: N}}\n",
            "the largest pressure is negative");
    refused("      x: {column: z_mm, unit: mm}\n"
            "      y: {force_N: {column: Fz_N, unit: N, scale: -1}}\n",
            "the sinkage falls as the plate is loaded");

    write(dir / "experiments.yaml",
          "name: other-code\nexperiments:\n  - id: p60\n    type: plate_sinkage\n"
          "    data:\n      files: [f1.csv]\n      x: {column: z_mm, unit: mm, scale: -1}\n"
          "      y: {force_N: {column: Fz_N, unit: N, scale: -1}}\n");
    CHECK_THROWS_WITH(loadExperiments(dir.string()),
                      Catch::Contains("needs conditions.plate_diameter_m"));

    // A shear box and a wheel from a code whose axes point the other way: refused with the fix
    // (a shear curve of negative displacement had no bins and was silently not compared; a
    // negative wheel sinkage read as a gap no effect explains).
    write(dir / "s1.csv", "dx_mm,tau_kPa\n0,0\n-1,-2\n-2,-3\n-3,-3.2\n");
    checkRefused(dir,
                 "experiments:\n  - id: s4\n    type: direct_shear\n"
                 "    conditions: {normal_stress_Pa: 4000}\n"
                 "    data:\n      files: [s1.csv]\n      x: {column: dx_mm, unit: mm}\n"
                 "      y: {shear_stress_Pa: {column: tau_kPa, unit: kPa}}\n",
                 "the largest shear stress is negative");
    checkRefused(dir,
                 "experiments:\n  - id: s4\n    type: direct_shear\n"
                 "    conditions: {normal_stress_Pa: 4000}\n"
                 "    data:\n      files: [s1.csv]\n      x: {column: dx_mm, unit: mm}\n"
                 "      y: {shear_stress_Pa: {column: tau_kPa, unit: kPa, scale: -1}}\n",
                 "the shear displacement falls");
    write(dir / "w.csv", "slip,F,z_mm\n0.1,10,-5\n0.3,20,-9\n");
    checkRefused(
        dir,
        "experiments:\n  - id: w\n    type: wheel_steady_state\n"
        "    data:\n      files: [w.csv]\n      scatter: true\n"
        "      x: {column: slip, unit: '-'}\n"
        "      y: {traction_N: {column: F, unit: N}, sinkage_m: {column: z_mm, unit: mm}}\n",
        "every run's sinkage is negative");
}

// An experiment that gives no bin was accepted and named "not compared" only after the
// simulations had run: z-up data without `scale: -1`, or its own bins beyond its data.
TEST_CASE("experiments.yaml: an experiment with no bin to compare is refused where it is read",
          "[gap][experiments]") {
    const fs::path dir = folder("nobin");
    // z up, written from the deepest sample on: the most loaded sample is the first, so the
    // curve reads as loading, but every sinkage lies below its recorded zero.
    write(dir / "up.csv", "z_mm,p_kPa\n-8,100\n-6,70\n-4,40\n-2,15\n0,0\n");
    const std::string head = "experiments:\n  - id: up\n    type: plate_sinkage\n"
                             "    conditions: {plate_diameter_m: 0.04}\n"
                             "    data:\n      files: [up.csv]\n";
    const std::string y = "      y: {pressure_Pa: {column: p_kPa, unit: kPa}}\n";
    checkRefused(dir, head + "      x: {column: z_mm, unit: mm}\n" + y,
                 "experiments.yaml:7: key 'experiments[0].data.x': experiment 'up' has no bin to "
                 "compare: its sinkage_m (zeroed by its zero method) runs from -0.008 to 0");
    checkRefused(dir, head + "      x: {column: z_mm, unit: mm}\n" + y, "add `scale: -1`");
    // With the fix it reads, and gives bins.
    write(dir / "experiments.yaml", head + "      x: {column: z_mm, unit: mm, scale: -1}\n" + y);
    CHECK(designFeatures(loadExperiments(dir.string())).keys.size() >= 4);
    // Its own bins beyond the data's 8 mm.
    checkRefused(dir,
                 head + "      x: {column: z_mm, unit: mm, scale: -1}\n" + y +
                     "    bins: {edges: [20, 30, 40], unit: mm}\n",
                 "experiments.yaml:9: key 'experiments[0].bins.edges': experiment 'up' has no bin "
                 "to compare");
    // A wheel whose runs all lie outside its own bins.
    write(dir / "w.csv", "slip,F\n0.1,10\n0.3,20\n");
    checkRefused(dir,
                 "experiments:\n  - id: w\n    type: wheel_steady_state\n"
                 "    data: {files: [w.csv], scatter: true, x: {column: slip, unit: '-'}, "
                 "y: {traction_N: {column: F, unit: N}}}\n"
                 "    bins: {edges: [0.5, 0.7, 0.9], unit: '-'}\n",
                 "experiment 'w' has no bin to compare: its slip runs from 0.1 to 0.3");
}

TEST_CASE("experiments.yaml: a slip in % given as unit '-' is refused where it is read",
          "[gap][experiments]") {
    const fs::path dir = folder("slip");
    write(dir / "w.csv", "run,slip_pct,F\n1,0.5,2\n2,10,8\n3,75,20\n");
    const std::string yaml = "experiments:\n  - id: w\n    type: wheel_steady_state\n"
                             "    data:\n      files: [w.csv]\n      scatter: true\n"
                             "      x: {column: slip_pct, unit: UNIT}\n"
                             "      y: {traction_N: {column: F, unit: N}}\n";
    std::string dash = yaml;
    dash.replace(dash.find("UNIT"), 4, "'-'");
    checkRefused(
        dir, dash,
        "experiments.yaml:7: key 'experiments[0].data.x.unit': " + (dir / "w.csv").string() +
            ":3: column 'slip_pct': slip 10 lies outside [-1, 1): a slip in %? give "
            "unit: \"%\"");
    std::string percent = yaml;
    percent.replace(percent.find("UNIT"), 4, "'%'");
    write(dir / "experiments.yaml", percent);
    const ExperimentSet set = loadExperiments(dir.string());
    REQUIRE(set.experiments[0].trials.size() == 3);
    CHECK(set.experiments[0].trials[2].curves.at("traction_N").x[0] == Approx(0.75));
}

TEST_CASE("experiments.yaml: a size condition in mm is refused with its experiment and line",
          "[gap][experiments]") {
    const fs::path dir = folder("size");
    linearTrial(dir / "a1.csv", 1.0);
    linearTrial(dir / "a2.csv", 1.0);
    linearTrial(dir / "a3.csv", 1.0);
    // The second experiment's diameter in mm: named as its own, not as the first's of its box.
    std::string second = plateYaml();
    second.replace(second.find("id: p60"), 7, "id: p80");
    second.replace(second.find("plate_diameter_m: 0.06"), 22, "plate_diameter_m: 80");
    checkRefused(dir, plateYaml() + second.substr(second.find("  - id: p80")),
                 "experiments.yaml:12: key 'experiments[1].conditions.plate_diameter_m': "
                 "experiment 'p80': plate_diameter_m 80 m is larger than a lab test's 2 m: given "
                 "in mm?");
    std::string depth = plateYaml();
    depth.replace(depth.find("box: large"), 10, "box: large, bed_depth_m: -0.1");
    checkRefused(dir, depth, "experiment 'p60': bed_depth_m -0.1: a length, >= 0");
    // A travel may be longer than a lab bin (a long test bed, a field run): read as given.
    std::string travel = plateYaml();
    travel.replace(travel.find("box: large"), 10, "box: large, travel_m: 5");
    write(dir / "experiments.yaml", travel);
    CHECK(loadExperiments(dir.string()).experiments[0].numbers.at("travel_m") == 5.0);
}

TEST_CASE("data files: an unknown key is named before a file fails to read, and lines before the "
          "header are skipped with skip_lines",
          "[gap][experiments]") {
    const fs::path dir = folder("preamble");
    // An instrument's export: a title, a line about the sample, a blank line, then the header.
    write(dir / "s.txt", "Direct shear test ASTM D3080\nSample: sand A  10 kPa\n\n"
                         "disp_mm\tshear_kPa\tvert_mm\n0\t0\t0\n0.5\t3\t-0.01\n1\t5\t-0.02\n");
    const std::string head = "experiments:\n  - id: s\n    type: direct_shear\n"
                             "    conditions: {normal_stress_Pa: 10000}\n"
                             "    data:\n      files: [s.txt]\n      delimiter: tab\n";
    const std::string axes = "      x: {column: disp_mm, unit: mm}\n"
                             "      y: {shear_stress_Pa: {column: shear_kPa, unit: kPa}}\n";
    // Read as it is, the title is the header: named as such, not as a decimal comma.
    checkRefused(dir, head + axes,
                 "s.txt:4: 3 cells where the header line names 1 ('Direct shear test ASTM "
                 "D3080'): a title above the header? give data.skip_lines");
    // A misspelt key is said first, not the file it would have read.
    checkRefused(dir, head + "      skip_line: 3\n" + axes,
                 "experiments.yaml:8: unknown key 'experiments[0].data.skip_line'");
    write(dir / "experiments.yaml", head + "      skip_lines: 3\n" + axes);
    const Curve &c =
        loadExperiments(dir.string()).experiments[0].trials[0].curves.at("shear_stress_Pa");
    REQUIRE(c.x.size() == 3);
    CHECK(c.x[1] == Approx(0.0005));
    CHECK(c.y[2] == Approx(5000.0));
    checkRefused(dir, head + "      skip_lines: 9\n" + axes, "none after the 9 of data.skip_lines");
}

TEST_CASE("data files: the hints name the option that reads the file", "[gap][experiments]") {
    const fs::path dir = folder("hints");
    const std::string head = "experiments:\n  - id: p\n    type: plate_sinkage\n    data:\n";
    const std::string zp = "      x: {column: z_mm, unit: mm}\n"
                           "      y: {pressure_Pa: {column: p_kPa, unit: kPa}}\n";
    // ';' between cells and decimal commas, with only the decimal mark given.
    write(dir / "eu.csv", "\"z_mm\";\"p_kPa\"\n0,5;1,25\n1,0;2,5\n");
    checkRefused(dir, head + "      files: [eu.csv]\n      decimal: ','\n" + zp,
                 "the header reads as one column holding \";\": give data.delimiter: \";\"");
    // A LIGGGHTS file read without columns: its names on the comment line, to copy.
    write(dir / "lig.txt", "# Time-averaged data\n# TimeStep z_mm p_kPa\n100 1 5\n200 2 10\n");
    checkRefused(dir, head + "      files: [lig.txt]\n      delimiter: whitespace\n" + zp,
                 "give data.columns: [TimeStep, z_mm, p_kPa]");
    // An empty file, and one of comments only.
    write(dir / "empty.csv", "");
    checkRefused(dir, head + "      files: [empty.csv]\n" + zp, "empty.csv is empty");
    write(dir / "comments.csv", "# nothing yet\n");
    checkRefused(dir, head + "      files: [comments.csv]\n" + zp,
                 "comments.csv has no header line (its 1 line(s) are comments or blank)");
    // A delimiter that is none of the four, said readably.
    checkRefused(dir, head + "      files: [eu.csv]\n      delimiter: '|'\n" + zp,
                 "'|' is no delimiter: give \",\", \";\", tab or whitespace");
}

TEST_CASE("an unknown experiment id is named with the set's ids", "[gap][experiments]") {
    const fs::path dir = folder("ids");
    linearTrial(dir / "a1.csv", 1.0);
    linearTrial(dir / "a2.csv", 1.0);
    linearTrial(dir / "a3.csv", 1.0);
    write(dir / "experiments.yaml", plateYaml());
    const ExperimentSet set = loadExperiments(dir.string());
    CHECK_THROWS_WITH(set.find("p6"), Catch::Contains("no experiment 'p6'") &&
                                          Catch::Contains("(its experiments: p60)"));
}

TEST_CASE("experiments.yaml: a unit the file's units row contradicts, a sinkage beyond a lab's "
          "size and a shear stress 1000 times its normal stress are said",
          "[gap][experiments]") {
    const fs::path dir = folder("units-row");
    write(dir / "a.csv", "depth;p\n[mm];(kPa)\n0;0\n5;10\n10;21\n");
    const std::string plate = "name: test\nexperiments:\n"
                              "  - id: p20\n    type: plate_sinkage\n"
                              "    conditions: {plate_diameter_m: 0.02}\n"
                              "    data:\n      files: [a.csv]\n      delimiter: \";\"\n"
                              "      units_row: true\n";
    // The row says mm, the key m: 10 m of sinkage. Named at the units row's line (2).
    checkRefused(dir,
                 plate + "      x: {column: depth, unit: m}\n"
                         "      y: {pressure_Pa: {column: p, unit: kPa}}\n",
                 "a.csv:2: the units row gives column 'depth' in 'mm', but it is read in 'm'");
    checkRefused(dir,
                 plate + "      x: {column: depth, unit: mm}\n"
                         "      y: {pressure_Pa: {column: p, unit: Pa}}\n",
                 "column 'p' in 'kPa', but it is read in 'Pa'");
    write(dir / "experiments.yaml", plate + "      x: {column: depth, unit: mm}\n"
                                            "      y: {pressure_Pa: {column: p, unit: kPa}}\n");
    CHECK(loadExperiments(dir.string()).experiments.at(0).trials.size() == 1);
    // Without a units row to say so, a sinkage in mm read in m reaches 10 m: refused.
    write(dir / "b.csv", "depth,p\n0,0\n5,10\n10,21\n");
    checkRefused(dir,
                 "name: test\nexperiments:\n  - id: p20\n    type: plate_sinkage\n"
                 "    conditions: {plate_diameter_m: 0.02}\n"
                 "    data:\n      files: [b.csv]\n      x: {column: depth, unit: m}\n"
                 "      y: {pressure_Pa: {column: p, unit: kPa}}\n",
                 "b.csv: sinkage_m reaches 10 m, beyond a lab test's 2 m: is the column in mm?");

    // A shear box at "4" Pa (4 kPa meant) shearing at up to 2.9 kPa: said, and read on.
    write(dir / "s.csv", "d_mm,tau_kPa\n0,0\n1,2.1\n2,2.9\n");
    const auto shear = [&](const std::string &sigma) {
        write(dir / "experiments.yaml",
              "name: test\nexperiments:\n  - id: s4\n    type: direct_shear\n"
              "    conditions: {normal_stress_Pa: " +
                  sigma +
                  "}\n    data:\n      files: [s.csv]\n      x: {column: d_mm, unit: mm}\n"
                  "      y: {shear_stress_Pa: {column: tau_kPa, unit: kPa}}\n");
        return loadExperiments(dir.string()).notes;
    };
    const auto notes = shear("4");
    REQUIRE(notes.size() == 1);
    CHECK_THAT(notes[0], Catch::Contains("experiment 's4': shear stress up to 2900 Pa under "
                                         "normal_stress_Pa 4 (725 times it): normal_stress_Pa "
                                         "given in kPa? (conditions are in Pa: 4000 for 4 kPa)"));
    CHECK(shear("4000").empty());      // tan 36 deg
    CHECK(shear("100").empty());       // 29 times: a cohesive soil under a light load, maybe
    const auto low = shear("4000000"); // 1/1380 of it: the shear stress in Pa, read in kPa?
    REQUIRE(low.size() == 1);
    CHECK_THAT(low[0], Catch::Contains("is the shear stress column's unit right"));
}

TEST_CASE("experiments.yaml: an experiment 1000 times off the others of its kind is said",
          "[gap][experiments]") {
    const fs::path dir = folder("levels");
    linearTrial(dir / "a1.csv", 1.0);
    linearTrial(dir / "a2.csv", 2.0);
    linearTrial(dir / "a3.csv", 3.0);
    const auto plate = [](const std::string &id, const std::string &file, const std::string &unit) {
        return "  - id: " + id + "\n    type: plate_sinkage\n" +
               "    conditions: {plate_diameter_m: 0.06}\n    data:\n      files: [" + file +
               "]\n      x: {column: sinkage_mm, unit: mm}\n" +
               "      y: {pressure_Pa: {column: pressure_kPa, unit: " + unit + "}}\n";
    };
    const std::string head = "name: test\nexperiments:\n";
    // Three plates within three times of each other: nothing to say.
    write(dir / "experiments.yaml", head + plate("p1", "a1.csv", "kPa") +
                                        plate("p2", "a2.csv", "kPa") +
                                        plate("p3", "a3.csv", "kPa"));
    CHECK(loadExperiments(dir.string()).notes.empty());
    // The third's kPa column read as Pa: 36 Pa against the median 12 kPa (of 12 kPa, 24 kPa and
    // 36 Pa), said with its ratio.
    write(dir / "experiments.yaml", head + plate("p1", "a1.csv", "kPa") +
                                        plate("p2", "a2.csv", "kPa") + plate("p3", "a3.csv", "Pa"));
    const auto notes = loadExperiments(dir.string()).notes;
    REQUIRE(notes.size() == 1);
    CHECK_THAT(notes[0], Catch::Contains("experiment 'p3': plate_sinkage/pressure_Pa reaches 36, "
                                         "0.003 times the median of its kind's 3 experiments "
                                         "(1.2e+04): its unit?"));
}

TEST_CASE("experiments.yaml: a direct shear test's vertical displacement (dilation) is read as an "
          "observable of its own, in SI, with bins of its own kind",
          "[gap][experiments]") {
    const fs::path dir = folder("dilation");
    // A dense sand: the plate settles by 0.04 mm, then rises 0.1 mm per mm of shear.
    {
        std::ofstream out(dir / "s.csv");
        out << "d_mm,tau_kPa,dy_mm\n";
        for (int i = 0; i <= 12; ++i) {
            const double d = 0.5 * i;
            out << d << ',' << 5.0 + d << ',' << (d < 1.0 ? -0.04 * d : 0.1 * (d - 1.0) - 0.04)
                << '\n';
        }
    }
    const std::string head = "experiments:\n  - id: s4\n    type: direct_shear\n"
                             "    conditions: {normal_stress_Pa: 4000}\n"
                             "    data:\n      files: [s.csv]\n"
                             "      x: {column: d_mm, unit: mm}\n";
    write(dir / "experiments.yaml",
          head + "      y:\n        shear_stress_Pa: {column: tau_kPa, unit: kPa}\n"
                 "        vertical_displacement_m: {column: dy_mm, unit: mm}\n");
    const ExperimentSet set = loadExperiments(dir.string());
    const Experiment &e = set.experiments.at(0);
    REQUIRE(e.observables.size() == 2);
    const Curve &rise = e.trials.at(0).curves.at("vertical_displacement_m");
    CHECK(rise.x.back() == Approx(0.006));
    CHECK(rise.y.back() == Approx(0.46e-3)); // 0.1 x 5 mm - 0.04 mm
    CHECK(rise.y[1] == Approx(-0.02e-3));
    const FeatureDesign d = designFeatures(set, 6);
    int rises = 0;
    for (const FeatureKey &k : d.keys)
        rises += k.kind == "direct_shear/vertical_displacement_m";
    CHECK(rises == 6);
    CHECK(d.keys.size() == 12);
    // A rise given in a unit of stress is refused with its key.
    checkRefused(dir,
                 head + "      y:\n        vertical_displacement_m: {column: dy_mm, unit: kPa}\n",
                 "vertical_displacement_m");
}
