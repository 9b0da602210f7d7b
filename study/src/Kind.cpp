#include "grainlink/study/Kind.hpp"

#include "grainlink/dem/Scenario.hpp"
#include "grainlink/lab/LabTest.hpp"

#include <stdexcept>

#include <yaml-cpp/yaml.h>

namespace grainlink::study {

namespace {

std::function<void(const config::ConfigNode &)> &runScenarioCheck() {
    static std::function<void(const config::ConfigNode &)> check;
    return check;
}

} // namespace

void setRunScenarioCheck(std::function<void(const config::ConfigNode &root)> check) {
    runScenarioCheck() = std::move(check);
}

Kind standardKind(const std::string &kind, const std::string &test) {
    if (kind == "dem") {
        if (!test.empty())
            throw std::invalid_argument("kind 'dem' takes no test (got '" + test + "')");
        return {"dem",
                {"dem"},
                "summary.json",
                {},
                "simulation.threads",
                "deposition.seed",
                "checkpoint.bin",
                [](const config::ConfigNode &root) { dem::parseScenario(root); }};
    }
    if (kind == "run") {
        if (!test.empty())
            throw std::invalid_argument("kind 'run' takes no test (got '" + test + "')");
        // The single-wheel rig writes its steady state; every other model (the mole, the
        // rover, a URDF model) its observables at the end time (docs/study.md).
        return {"run",
                {"run"},
                "rig_summary.json",
                [](const YAML::Node &scenario) {
                    return scenario["rig"] ? "rig_summary.json" : "mbs_summary.json";
                },
                "soil.simulation.threads",
                "soil.deposition.seed",
                "checkpoints/latest",
                runScenarioCheck()};
    }
    if (kind == "lab") {
        lab::requireLabTest(test);
        // The study reads the summary and plots its table: no plot per point, which would
        // count as the machinery's cost (0.8 s a point; tools/plot_lab.py points/ID draws one).
        return {"lab " + test,
                {"lab", test, "--no-plot"},
                "summary.json",
                {},
                "soil.simulation.threads",
                "soil.deposition.seed",
                "", // a lab test has no checkpoint: an interrupted one starts again
                [test](const config::ConfigNode &root) { lab::parseLabScenario(test, root); }};
    }
    throw std::invalid_argument("kind '" + kind + "' is not one of: dem, run, lab");
}

} // namespace grainlink::study
