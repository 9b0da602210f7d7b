// Every variant the diagnosis can ask for is a scenario the lab's own reader accepts: each
// catalogue effect at its signature strengths and each numerical check, on every experiment of
// the CI design (docs/gap.md, "The base model"). A key an effect writes that no reader knows,
// or a value out of range, fails here rather than hours into a diagnosis.
#include "grainlink/gap/Effects.hpp"
#include "grainlink/gap/StudySimulator.hpp"
#include "grainlink/gap/Twin.hpp"
#include "grainlink/lab/LabTest.hpp"

#include <catch2/catch.hpp>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>

using namespace grainlink::gap;
namespace fs = std::filesystem;

namespace {

const std::string kDir = std::string(GRAINLINK_SOURCE_DIR) + "/scenarios/gap/selftest-ci";

void acceptedByTheLab(const StudySimulator &sim, const Design &design, const VariantRequest &r,
                      const fs::path &scratch) {
    for (const Experiment &e : design.set.experiments) {
        const std::string text = sim.scenarioText(design.set, {e.id}, r, 1);
        const fs::path file = scratch / (r.label + "-" + e.id + ".yaml");
        std::ofstream(file) << text;
        INFO(r.label << " on " << e.id << ":\n" << text);
        CHECK_NOTHROW(grainlink::lab::loadLabScenario(labTestOf(e.type), file.string()));
    }
}

} // namespace

TEST_CASE("every effect and numerical check on the self-tests' designs is a scenario the lab "
          "accepts",
          "[gap][simulator]") {
    const std::string kDir = GENERATE(std::string(GRAINLINK_SOURCE_DIR) + "/scenarios/gap/selftest-ci",
                                      std::string(GRAINLINK_SOURCE_DIR) + "/scenarios/gap/selftest-full");
    const fs::path scratch = fs::temp_directory_path() / "grainlink-gap-simulator-test";
    fs::remove_all(scratch);
    fs::create_directories(scratch);
    const StudySimulator sim(loadBaseModel(kDir + "/base.yaml"), (scratch / "sims").string(), {});
    const Design design = loadDesign(kDir + "/design.yaml");
    const EffectCatalogue catalogue = loadEffects(std::string(GRAINLINK_SOURCE_DIR) + "/data/effects.yaml");
    const YAML::Node reference = sim.referenceScenario();

    VariantRequest base;
    base.label = "base";
    acceptedByTheLab(sim, design, base, scratch);
    for (const std::string &check : sim.checks()) {
        VariantRequest r;
        r.label = "check-" + check;
        r.check = check;
        acceptedByTheLab(sim, design, r, scratch);
    }
    for (const Effect &raw : catalogue.effects) {
        if (!inapplicable(raw, reference).empty())
            continue;
        const Effect e = resolveAgainst(raw, reference);
        for (double s : e.signature) {
            VariantRequest r;
            r.label = e.name + "-" + std::to_string(s);
            r.effect = &e;
            r.strength = s;
            acceptedByTheLab(sim, design, r, scratch);
        }
    }
    fs::remove_all(scratch);
}

TEST_CASE("experiments of a type the base model does not simulate are left out, named",
          "[gap][simulator]") {
    const BaseModel base = loadBaseModel(kDir + "/base.yaml");
    ExperimentSet set = loadDesign(kDir + "/design.yaml").set;
    Experiment wheel = set.experiments.front();
    wheel.id = "smooth_wheel";
    wheel.type = ExperimentType::WheelSteadyState;
    set.experiments.push_back(wheel);
    std::vector<std::string> left_out;
    const ExperimentSet kept = simulable(set, base, left_out);
    CHECK(kept.experiments.size() == set.experiments.size() - 1);
    REQUIRE(left_out.size() == 1);
    CHECK(left_out[0].find("smooth_wheel (wheel_steady_state") == 0);

    ExperimentSet only_wheels = set;
    only_wheels.experiments = {wheel};
    std::vector<std::string> all;
    CHECK_THROWS_WITH(simulable(only_wheels, base, all), Catch::Contains("no test in `tests`"));
}
