#include "grainlink/lab/LabTest.hpp"

#include <algorithm>
#include <sstream>
#include <stdexcept>
#include <type_traits>

namespace grainlink::lab {

namespace {

/// Each scenario's test: its result, how it runs and how it reruns for the numerical checks.
template <class Scenario> struct TestOf;
template <> struct TestOf<BevameterScenario> {
    using Result = BevameterResult;
    static constexpr auto run = runBevameter;
    static constexpr auto check = checkBevameter;
};
template <> struct TestOf<ShearAnnulusScenario> {
    using Result = ShearAnnulusResult;
    static constexpr auto run = runShearAnnulus;
    static constexpr auto check = checkShearAnnulus;
};
template <> struct TestOf<DirectShearScenario> {
    using Result = DirectShearResult;
    static constexpr auto run = runDirectShear;
    static constexpr auto check = checkDirectShear;
};
template <> struct TestOf<ReposeScenario> {
    using Result = ReposeResult;
    static constexpr auto run = runRepose;
    static constexpr auto check = checkRepose;
};
template <> struct TestOf<WheelScenario> {
    using Result = WheelResult;
    static constexpr auto run = runWheel;
    static constexpr auto check = checkWheel;
};

template <class Scenario> using ResultOf = typename TestOf<std::decay_t<Scenario>>::Result;

std::invalid_argument unknownTest(const std::string &test) {
    std::string names;
    for (const auto &name : labTestNames())
        names += (names.empty() ? "" : ", ") + name;
    return std::invalid_argument("lab test '" + test + "' is not implemented; available: " + names);
}

std::vector<std::string> split(const std::string &list) {
    std::vector<std::string> items;
    std::stringstream in(list);
    for (std::string item; std::getline(in, item, ',');)
        items.push_back(item);
    return items;
}

} // namespace

std::vector<std::string> labTestNames() {
    return {BevameterResult::kTest, ShearAnnulusResult::kTest, DirectShearResult::kTest,
            ReposeResult::kTest, WheelResult::kTest};
}

std::string labTestName(const LabScenario &scenario) {
    return std::visit([](const auto &s) -> std::string { return ResultOf<decltype(s)>::kTest; },
                      scenario);
}

const std::string &labScenarioName(const LabScenario &scenario) {
    return std::visit([](const auto &s) -> const std::string & { return s.name; }, scenario);
}

const std::vector<config::KeyWarning> &labWarnings(const LabScenario &scenario) {
    return std::visit(
        [](const auto &s) -> const std::vector<config::KeyWarning> & { return s.warnings; },
        scenario);
}

void requireLabTest(const std::string &test) {
    const auto names = labTestNames();
    if (std::find(names.begin(), names.end(), test) == names.end())
        throw unknownTest(test);
}

LabScenario loadLabScenario(const std::string &test, const std::string &path) {
    requireLabTest(test); // before the file: a wrong test name is the likelier mistake
    return parseLabScenario(test, config::ConfigNode::loadFile(path));
}

LabScenario parseLabScenario(const std::string &test, const config::ConfigNode &root) {
    if (test == BevameterResult::kTest)
        return parseBevameter(root);
    if (test == ShearAnnulusResult::kTest)
        return parseShearAnnulus(root);
    if (test == DirectShearResult::kTest)
        return parseDirectShear(root);
    if (test == ReposeResult::kTest)
        return parseRepose(root);
    if (test == WheelResult::kTest)
        return parseWheel(root);
    throw unknownTest(test);
}

LabRun runLabTest(const LabScenario &scenario, const LabRunOptions &options,
                  const CheckRequest &checks) {
    return std::visit(
        [&](const auto &s) {
            using Test = TestOf<std::decay_t<decltype(s)>>;
            const auto result = Test::run(s, options);
            LabRun run{result.summary(), result.report(), {}, {}};
            const bool written = !options.output_directory.empty();
            if (written) {
                run.files = split(Test::Result::kCsvFiles);
                run.files.insert(run.files.end(), {"report.txt", "summary.json"});
            }
            if (checks.any()) {
                run.checks = Test::check(s, result, checks, options);
                if (written) {
                    writeNumericalChecks(run.checks, options.output_directory);
                    run.files.push_back("numerical_check.csv");
                }
            }
            return run;
        },
        scenario);
}

} // namespace grainlink::lab
