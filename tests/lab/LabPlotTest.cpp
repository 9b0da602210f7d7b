// The lab run's plot (lab/LabPlot.hpp, tools/plot_lab.py): each test's summary.json plotted, and
// the one-line reasons when there is no interpreter or no matplotlib.
#include "grainlink/lab/LabPlot.hpp"
#include "grainlink/lab/LabSummary.hpp"

#include <catch2/catch.hpp>

#include <stdlib.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

using namespace grainlink;
using Catch::Matchers::Contains;

namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string &name) {
    const auto dir = fs::temp_directory_path() /
                     ("grainlink_lab_plot_test-" + std::to_string(::getpid())) / name;
    fs::create_directories(dir);
    return dir;
}

/// A run of `condition` with two samples of each curve.
lab::LabRunSummary run(const std::string &condition, double value,
                       std::vector<std::pair<std::string, double>> more,
                       const std::vector<std::string> &curves) {
    lab::LabRunSummary r;
    r.values = {{condition, value}};
    r.values.insert(r.values.end(), more.begin(), more.end());
    for (const auto &c : curves)
        r.curves.push_back({c, {0.001, 0.002}});
    return r;
}

/// A summary of `test` with the keys plot_lab.py reads (docs/lab.md, "summary.json").
lab::LabSummary summaryOf(const std::string &test) {
    lab::LabSummary s;
    s.test = test;
    s.scenario = "plot-" + test;
    if (test == "bevameter") {
        s.condition = "plate_radius_m";
        s.fits.push_back({"bekker",
                          1,
                          {{"k_c", "N/m^(n+1)", 1e3, 1e2},
                           {"k_phi", "N/m^(n+2)", 1e6, 1e5},
                           {"n", "-", 1.0, 0.1}}});
        s.runs.push_back(run("plate_radius_m", 0.025, {}, {"sinkage_m", "pressure_Pa"}));
    } else if (test == "bevameter_shear") {
        s.condition = "target_pressure_Pa";
        s.fits.push_back(
            {"janosi",
             1,
             {{"c", "Pa", 100, 10}, {"phi", "deg", 20, 1}, {"K", "m", 0.002, 0.0002}}});
        s.runs.push_back(run("target_pressure_Pa", 2000, {{"mean_pressure_Pa", 1900}},
                             {"shear_displacement_m", "shear_stress_Pa", "normal_pressure_Pa"}));
    } else if (test == "direct_shear") {
        s.condition = "target_normal_stress_Pa";
        s.fits.push_back({"mohr_coulomb_peak", 1, {{"psi", "deg", 30, 5}}});
        s.fit_note = "Mohr-Coulomb fit: all normal stresses are equal"; // no residual line
        for (double sigma : {4000.0, 8000.0})
            s.runs.push_back(run("target_normal_stress_Pa", sigma,
                                 {{"peak_normal_stress_Pa", sigma},
                                  {"peak_shear_stress_Pa", 0.6 * sigma},
                                  {"residual_normal_stress_Pa", sigma},
                                  {"residual_shear_stress_Pa", 0.5 * sigma}},
                                 {"displacement_m", "shear_stress_Pa"}));
    } else {
        s.condition = "lift_speed_m_s";
        s.fit_note = "no heap: the grains spread out (0 profile bins on a flank, 3 needed)";
        s.runs.push_back(run("lift_speed_m_s", 0.1, {{"flank_bins", 0}}, {"radius_m", "height_m"}));
    }
    return s;
}

bool hasMatplotlib() {
    return fs::exists("/usr/bin/python3") &&
           std::system("/usr/bin/python3 -c 'import matplotlib' 2>/dev/null") == 0;
}

} // namespace

TEST_CASE("Lab plot: every test's summary.json becomes <dir>/<test>.png", "[lab][plot][slow]") {
    if (!hasMatplotlib()) {
        WARN("skipped: no /usr/bin/python3 with matplotlib");
        return;
    }
    for (const std::string test : {"bevameter", "bevameter_shear", "direct_shear", "repose"}) {
        const fs::path dir = scratch(test);
        lab::writeLabSummary(summaryOf(test), (dir / "summary.json").string());
        const lab::PlotOutcome plot = lab::plotLabRun(dir.string(), test);
        INFO(test << ": " << plot.message);
        CHECK(plot.written);
        CHECK(plot.message == "plot: " + (dir / (test + ".png")).string());
        CHECK(fs::file_size(dir / (test + ".png")) > 1000);
    }
    fs::remove_all(scratch("").parent_path());
}

TEST_CASE("Lab plot: no interpreter, no matplotlib or no summary is one line, never a throw",
          "[lab][plot]") {
    const fs::path dir = scratch("missing");
    lab::writeLabSummary(summaryOf("repose"), (dir / "summary.json").string());
    const auto no_python = lab::plotLabRun(dir.string(), "repose", "/no/such/python3");
    CHECK_FALSE(no_python.written);
    CHECK_THAT(no_python.message, Contains("no plot: /no/such/python3 not found"));
    CHECK(no_python.message.find('\n') == std::string::npos);
    const auto no_tool = lab::plotLabRun(dir.string(), "repose", "/usr/bin/python3", "/no/tool.py");
    CHECK_THAT(no_tool.message, Contains("no plot: /no/tool.py not found"));
    if (!fs::exists("/usr/bin/python3")) {
        WARN("skipped the matplotlib case: no /usr/bin/python3");
        return;
    }
    // A matplotlib that fails to import, first on the module path: the tool's own reason.
    const fs::path fake = scratch("fake") / "matplotlib";
    fs::create_directories(fake);
    std::ofstream(fake / "__init__.py") << "raise ImportError('no matplotlib here')\n";
    const char *old = std::getenv("PYTHONPATH");
    const std::string saved = old ? old : "";
    ::setenv("PYTHONPATH", fake.parent_path().c_str(), 1);
    const auto no_matplotlib = lab::plotLabRun(dir.string(), "repose");
    old ? ::setenv("PYTHONPATH", saved.c_str(), 1) : ::unsetenv("PYTHONPATH");
    CHECK_FALSE(no_matplotlib.written);
    CHECK(no_matplotlib.message ==
          "no plot: plot_lab.py: python3-matplotlib is not installed (scripts/install-deps "
          "installs it)");
    CHECK_FALSE(fs::exists(dir / "repose.png"));
    // No summary.json: the tool's error, as the last line of what it printed.
    const auto no_summary = lab::plotLabRun(scratch("empty").string(), "repose");
    CHECK_FALSE(no_summary.written);
    CHECK_THAT(no_summary.message, Contains("no plot: ") && Contains("summary.json"));
    fs::remove_all(scratch("").parent_path());
}
