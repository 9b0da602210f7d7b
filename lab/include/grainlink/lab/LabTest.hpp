#pragma once
// Every lab test behind one call (docs/lab.md): `grainlink lab`, a study runner or the sim-to-real
// diagnosis holds a test's scenario as a value, runs it, and gets back what summary.json holds.
//
//     lab::LabScenario plate = lab::loadLabScenario("bevameter", "scenarios/lab/bevameter.yaml");
//     std::get<lab::BevameterScenario>(plate).test.plate_radii_m = {0.03};   // the condition
//     const lab::LabRun run = lab::runLabTest(plate, {});                    // nothing written
//     const auto &p = run.summary.runs[0].curve("pressure_Pa");
#include "grainlink/lab/Bevameter.hpp"
#include "grainlink/lab/DirectShear.hpp"
#include "grainlink/lab/LabExperiment.hpp"
#include "grainlink/lab/LabSummary.hpp"
#include "grainlink/lab/NumericalChecks.hpp"
#include "grainlink/lab/Repose.hpp"
#include "grainlink/lab/ShearAnnulus.hpp"
#include "grainlink/lab/Wheel.hpp"

#include <string>
#include <variant>
#include <vector>

namespace grainlink::lab {

/// The scenario of any lab test.
using LabScenario = std::variant<BevameterScenario, ShearAnnulusScenario, DirectShearScenario,
                                 ReposeScenario, WheelScenario>;

/// The tests' names as `grainlink lab TEST` and summary.json spell them: bevameter,
/// bevameter_shear, direct_shear, repose, wheel.
std::vector<std::string> labTestNames();
std::string labTestName(const LabScenario &scenario);
/// Throws std::invalid_argument naming the tests unless `test` is one of them.
void requireLabTest(const std::string &test);
/// The scenario's `name` (the default output directory is out/<name>).
const std::string &labScenarioName(const LabScenario &scenario);
/// What its file is warned about (deprecated spellings, a direct shear box too narrow), to print.
const std::vector<config::KeyWarning> &labWarnings(const LabScenario &scenario);

/// Reads `path` as a scenario of `test`; throws std::invalid_argument naming the tests for an
/// unknown one, config::ConfigError for a bad file.
LabScenario loadLabScenario(const std::string &test, const std::string &path);
/// The same for a scenario already read (a study checks its points so, in-process).
LabScenario parseLabScenario(const std::string &test, const config::ConfigNode &root);

/// What a lab test gave.
struct LabRun {
    LabSummary summary;                 ///< summary.json's content
    std::string report;                 ///< report.txt's (before the checks' table)
    std::vector<std::string> files;     ///< written into the output directory (empty: none)
    std::vector<NumericalCheck> checks; ///< the reruns `checks` asked for
};

/// Runs the test (runLabExperiment); with `checks`, reruns it on a wider box or finer grains
/// (NumericalChecks.hpp) and, with an output directory, writes numerical_check.csv and appends
/// the checks' table to report.txt.
LabRun runLabTest(const LabScenario &scenario, const LabRunOptions &options,
                  const CheckRequest &checks = {});

} // namespace grainlink::lab
