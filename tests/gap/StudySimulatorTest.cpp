// Every variant the diagnosis can ask for is a scenario the lab's own reader accepts: each
// catalogue effect at its signature strengths and each numerical check, on every experiment of
// the CI design (docs/gap.md, "The base model"). A key an effect writes that no reader knows,
// or a value out of range, fails here rather than hours into a diagnosis.
#include "grainlink/gap/StudySimulator.hpp"
#include "grainlink/dem/Scenario.hpp"
#include "grainlink/gap/Effects.hpp"
#include "grainlink/gap/Twin.hpp"
#include "grainlink/lab/LabTest.hpp"

#include <catch2/catch.hpp>
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <set>
#include <tuple>
#include <variant>

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
        CHECK_NOTHROW(grainlink::lab::loadLabScenario(testSectionOf(e.type), file.string()));
    }
}

/// Calls `visit` with the base, each numerical check of `sim` and each applicable catalogue
/// effect at each of its signature strengths: every variant a diagnosis can ask for.
void forEveryVariant(const StudySimulator &sim,
                     const std::function<void(const VariantRequest &)> &visit) {
    const EffectCatalogue catalogue =
        loadEffects(std::string(GRAINLINK_SOURCE_DIR) + "/data/effects.yaml");
    const YAML::Node reference = sim.referenceScenario();
    VariantRequest base;
    base.label = "base";
    visit(base);
    for (const std::string &check : sim.checks()) {
        VariantRequest r;
        r.label = "check-" + check;
        r.check = check;
        visit(r);
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
            visit(r);
        }
    }
}

/// A 60 mm plate's sinkage curve to 10 mm with more `numbers` (a plate_diameter_m among them
/// replaces the 60 mm) and the text conditions `labels`.
Experiment plateExperiment(const std::string &id, const std::map<std::string, double> &numbers,
                           const std::map<std::string, std::string> &labels) {
    Experiment e;
    e.id = id;
    e.type = ExperimentType::PlateSinkage;
    e.x_name = "sinkage";
    e.observables = {"pressure_Pa"};
    e.numbers = {{"plate_diameter_m", 0.06}};
    for (const auto &[key, value] : numbers)
        e.numbers[key] = value;
    e.labels = labels;
    Trial t;
    t.curves["pressure_Pa"] = Curve{{0.0, 0.005, 0.01}, {0.0, 1e4, 2e4}};
    e.trials.push_back(t);
    return e;
}

/// A direct shear curve at 4 kPa to 2 mm with more `numbers` and the text conditions `labels`.
Experiment shearExperiment(const std::string &id, const std::map<std::string, double> &numbers,
                           const std::map<std::string, std::string> &labels) {
    Experiment e;
    e.id = id;
    e.type = ExperimentType::DirectShear;
    e.x_name = "shear_displacement";
    e.observables = {"shear_stress_Pa"};
    e.numbers = {{"normal_stress_Pa", 4000.0}};
    for (const auto &[key, value] : numbers)
        e.numbers[key] = value;
    e.labels = labels;
    e.trials.push_back(Trial{});
    e.trials[0].curves["shear_stress_Pa"] = Curve{{0.0, 0.001, 0.002}, {0.0, 2e3, 3e3}};
    return e;
}

/// The CMU base model's text, for a test to edit.
std::string cmuBaseText() {
    std::ifstream in(std::string(GRAINLINK_SOURCE_DIR) + "/scenarios/gap/cmu/base.yaml");
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

/// A fresh scratch folder under the temporary directory.
fs::path freshScratch(const std::string &name) {
    const fs::path scratch = fs::temp_directory_path() / name;
    fs::remove_all(scratch);
    fs::create_directories(scratch);
    return scratch;
}

/// The groups of experiments that share a test, as a set.
std::set<std::vector<std::string>> groupSet(const StudySimulator &sim, const ExperimentSet &set) {
    const auto groups = sim.groups(set);
    return {groups.begin(), groups.end()};
}

/// The soil of an experiment's base scenario as the lab reads it (written to `scratch`).
grainlink::dem::DemScenario labSoilOf(const StudySimulator &sim, const ExperimentSet &set,
                                      const std::string &id, const fs::path &scratch) {
    VariantRequest plain;
    plain.label = "base";
    const fs::path file = scratch / (id + ".yaml");
    std::ofstream(file) << sim.scenarioText(set, {id}, plain, 1);
    const auto scenario =
        grainlink::lab::loadLabScenario(testSectionOf(set.find(id).type), file.string());
    return std::visit([](const auto &s) { return s.soil; }, scenario);
}

} // namespace

TEST_CASE("every effect and numerical check on the self-tests' designs is a scenario the lab "
          "accepts",
          "[gap][simulator]") {
    const std::string kGap = std::string(GRAINLINK_SOURCE_DIR) + "/scenarios/gap";
    const std::string kDesign =
        GENERATE_COPY(kGap + "/selftest-ci/design.yaml", kGap + "/selftest-full/design.yaml",
                      kGap + "/selftest-full/three_boxes.yaml");
    const fs::path scratch = fs::temp_directory_path() / "grainlink-gap-simulator-test";
    fs::remove_all(scratch);
    fs::create_directories(scratch);
    const StudySimulator sim(
        loadBaseModel((fs::path(kDesign).parent_path() / "base.yaml").string()),
        (scratch / "sims").string(), {});
    const Design design = loadDesign(kDesign);
    forEveryVariant(sim,
                    [&](const VariantRequest &r) { acceptedByTheLab(sim, design, r, scratch); });
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
    CHECK_THROWS_WITH(simulable(only_wheels, base, all),
                      Catch::Contains("every experiment of") &&
                          Catch::Contains("smooth_wheel (wheel_steady_state: ") &&
                          Catch::Contains("has no tests.wheel_steady_state"));
    // Every one left out for its gravity: said with that, not blamed on the base's tests.
    ExperimentSet upside_down = set;
    for (Experiment &e : upside_down.experiments)
        e.numbers["gravity_m_s2"] = -9.81;
    std::vector<std::string> none;
    CHECK_THROWS_WITH(simulable(upside_down, base, none),
                      Catch::Contains("is left out, none is simulated: ") &&
                          Catch::Contains("gravity_m_s2 -9.81: the magnitude of a gravity") &&
                          !Catch::Contains("no test in"));
}

TEST_CASE("wheel experiments become the lab's wheel test: one run per slip bin, the wheel and "
          "load from their conditions, every effect and check a scenario the lab accepts",
          "[gap][simulator][wheel]") {
    // The CMU base model's wheels, as `gap import cmu` describes them: straight runs of the
    // smooth and the grousered wheel, the smooth one steered by 30 deg, and one at a slip angle
    // the lab's wheel does not run.
    const BaseModel base =
        loadBaseModel(std::string(GRAINLINK_SOURCE_DIR) + "/scenarios/gap/cmu/base.yaml");
    ExperimentSet set;
    set.name = "wheels";
    for (const auto &[id, grouser, beta] :
         {std::tuple{"smooth_beta0", 0.0, 0.0}, std::tuple{"grouser_beta0", 0.005, 0.0},
          std::tuple{"smooth_beta30", 0.0, 30.0}, std::tuple{"smooth_beta120", 0.0, 120.0}}) {
        Experiment e;
        e.id = id;
        e.type = ExperimentType::WheelSteadyState;
        e.x_name = "slip";
        e.scatter = true;
        e.observables = {"traction_N", "vertical_load_N", "side_force_N"};
        e.numbers = {{"wheel_radius_m", 0.058},
                     {"wheel_width_m", 0.05},
                     {"grouser_height_m", grouser},
                     {"slip_angle_deg", beta},
                     {"load_N", 21.5}};
        for (double s : {-0.5, -0.2, 0.0, 0.2, 0.4, 0.6, 0.8}) {
            Trial t;
            for (const auto &o : e.observables)
                t.curves[o] = Curve{{s}, {1.0 + s}};
            e.trials.push_back(t);
        }
        set.experiments.push_back(e);
    }
    std::vector<std::string> left_out;
    const ExperimentSet kept = simulable(set, base, left_out);
    REQUIRE(kept.experiments.size() == 3);
    REQUIRE(left_out.size() == 1);
    CHECK(left_out[0].find("smooth_beta120 (wheel_steady_state: slip angle 120") == 0);
    CHECK(kept.notes.empty()); // every condition of these wheels sets up their test
    // A condition the simulation does not read is said, with the ones it does: a load under
    // another name left the base's load in its place without a word.
    ExperimentSet renamed = set;
    renamed.experiments = {set.experiments.front()};
    renamed.experiments[0].numbers.erase("load_N");
    renamed.experiments[0].numbers["wheel_load_N"] = 23.6;
    const ExperimentSet said = simulable(renamed, base, left_out);
    REQUIRE(said.notes.size() == 1);
    CHECK_THAT(said.notes[0], Catch::Contains("condition 'wheel_load_N' is not simulated") &&
                                  Catch::Contains("in smooth_beta0 (1 experiment") &&
                                  Catch::Contains("a wheel_steady_state test is set up from "
                                                  "wheel_radius_m, wheel_width_m"));

    const fs::path scratch = fs::temp_directory_path() / "grainlink-gap-wheel-test";
    fs::remove_all(scratch);
    fs::create_directories(scratch);
    const StudySimulator sim(base, (scratch / "sims").string(), {});
    // One test per wheel and slip angle: the two wheels differ in their grousers.
    CHECK(sim.groups(kept).size() == 3);
    const FeatureDesign fd = designFeatures(kept);
    const auto check = [&](const std::string &id, const VariantRequest &r) {
        const fs::path file = scratch / (r.label + "-" + id + ".yaml");
        std::ofstream(file) << sim.scenarioText(kept, {id}, r, 1);
        INFO(r.label << " on " << id);
        const auto scenario = grainlink::lab::loadLabScenario("wheel", file.string());
        return std::get<grainlink::lab::WheelScenario>(scenario);
    };
    VariantRequest plain;
    plain.label = "base";
    const auto smooth = check("smooth_beta0", plain), grouser = check("grouser_beta0", plain);
    CHECK(smooth.test.slip_angle_deg == 0.0);
    CHECK(check("smooth_beta30", plain).test.slip_angle_deg == 30.0);
    CHECK(smooth.test.shape.grouser_count == 0);
    CHECK(grouser.test.shape.grouser_count == 12);
    CHECK(grouser.test.shape.grouser_height_m == 0.005);
    CHECK(smooth.test.shape.diameter_m == Approx(0.116));
    CHECK(smooth.test.load_N == 21.5);
    // A run in every slip bin the measurements are compared in, at the mean measured slip in
    // it (not the bin's centre): the bins here are 0.2 wide and hold one run each, so the
    // runs are at the measured slips the bins cover.
    const std::vector<double> &edges = fd.edges.at("smooth_beta0/traction_N");
    CHECK(edges[1] - edges[0] == Approx(0.2));
    std::vector<double> measured;
    for (double s : {-0.5, -0.2, 0.0, 0.2, 0.4, 0.6, 0.8})
        if (s >= edges.front() && s <= edges.back())
            measured.push_back(s);
    REQUIRE(smooth.test.slips.size() == measured.size());
    for (std::size_t i = 0; i < measured.size(); ++i)
        CHECK(smooth.test.slips[i] == Approx(measured[i]).margin(1e-6));

    forEveryVariant(sim, [&](const VariantRequest &r) {
        for (const char *id : {"smooth_beta0", "grouser_beta0", "smooth_beta30"})
            CHECK_NOTHROW(check(id, r));
    });
    fs::remove_all(scratch);
}

TEST_CASE("data sets that reach nearly as far share their simulations", "[gap][simulator]") {
    // Plates measured to 9.90 and 9.93 mm: 1.1 times the reach rounded up to two significant
    // digits is 11 mm for both, plus the zero offset's 2 mm: one scenario, one cached run.
    const StudySimulator sim(loadBaseModel(kDir + "/base.yaml"), "", {});
    const ExperimentSet design = loadDesign(kDir + "/design.yaml").set;
    const auto reaching = [&](double reach) {
        ExperimentSet set = design;
        for (Experiment &e : set.experiments)
            for (Trial &t : e.trials)
                for (auto &[name, curve] : t.curves)
                    curve.x.back() = reach;
        return set;
    };
    const std::string id = design.experiments.front().id;
    const std::string a = sim.scenarioText(reaching(0.0099), {id}, {}, 1);
    CHECK(a == sim.scenarioText(reaching(0.00993), {id}, {}, 1));
    CHECK(YAML::Load(a)["bevameter"]["max_sinkage_m"].as<double>() == Approx(0.013));
    CHECK(a != sim.scenarioText(reaching(0.0105), {id}, {}, 1));
}

// A design may hold wheels: a scatter over the slips it names, with the lab's wheel observables.
// Its twin folder holds one file per repeat with a row per slip run whose every observable
// settled, and reads back as the measurements it was written from.
TEST_CASE("a wheel design makes a twin folder the diagnosis reads", "[gap][twin][wheel]") {
    const fs::path scratch = fs::temp_directory_path() / "grainlink-gap-wheel-twin";
    fs::remove_all(scratch);
    fs::create_directories(scratch);
    std::ofstream(scratch / "design.yaml")
        << "name: wheel-design\nexperiments:\n"
           "  - {id: wheel, type: wheel_steady_state, slips: [0.1, 0.3, 0.6], repeats: 2,\n"
           "     conditions: {load_N: 20, grouser_count: 0}}\n"
           "  - {id: plate, type: plate_sinkage, conditions: {plate_diameter_m: 0.02}, "
           "reach: 0.004, repeats: 2}\n";
    const Design design = loadDesign((scratch / "design.yaml").string());
    const Experiment &wheel = design.set.find("wheel");
    CHECK(wheel.scatter);
    CHECK(wheel.observables == std::vector<std::string>{"traction_N", "sinkage_m", "torque_N_m"});
    REQUIRE(wheel.trials.size() == 3);
    CHECK(wheel.trials[2].curves.at("torque_N_m").x == std::vector<double>{0.6});

    // Two repeats; in the second the 0.6 slip's torque did not settle (no value).
    std::vector<SimulatedCurves> curves(2);
    for (int r = 0; r < 2; ++r) {
        const std::vector<double> slips = {0.1, 0.3, 0.6};
        curves[r]["wheel"]["traction_N"] = Curve{slips, {2.0 + r, 5.0 + r, 9.0 + r}};
        curves[r]["wheel"]["sinkage_m"] = Curve{slips, {0.010, 0.015, 0.030}};
        curves[r]["wheel"]["torque_N_m"] =
            r == 0 ? Curve{slips, {0.3, 0.5, 0.8}} : Curve{{0.1, 0.3}, {0.3, 0.5}};
        curves[r]["plate"]["pressure_Pa"] = Curve{{0.0, 0.002, 0.004, 0.006}, {0, 1e4, 2e4, 3e4}};
    }
    TwinKey key;
    key.seed = 3;
    key.noise = key.level_noise = 0.0;
    writeTwin(design, curves, key, (scratch / "twin").string(),
              (scratch / "twin.key.json").string());

    const ExperimentSet read = loadExperiments((scratch / "twin").string());
    const Experiment &w = read.find("wheel");
    CHECK(w.type == ExperimentType::WheelSteadyState);
    CHECK(w.scatter);
    REQUIRE(w.trials.size() == 5); // 3 runs of the first repeat, 2 of the second
    CHECK(w.trials[1].curves.at("traction_N").x[0] == Approx(0.3));
    CHECK(w.trials[1].curves.at("traction_N").y[0] == Approx(5.0));
    CHECK(w.trials[4].curves.at("torque_N_m").y[0] == Approx(0.5));
    CHECK(w.trials[4].curves.at("sinkage_m").y[0] == Approx(0.015));
    CHECK(w.numbers.at("load_N") == 20.0);
    // The plate's data stop at the design's reach.
    const Experiment &p = read.find("plate");
    REQUIRE(p.trials.size() == 2);
    CHECK(p.trials[0].curves.at("pressure_Pa").x.back() == Approx(0.004));
    fs::remove_all(scratch);
}

TEST_CASE("an experiment's gravity and a wheel's slope make its soil: tilted gravity, a level "
          "bed, one test per gravity and slope",
          "[gap][simulator]") {
    // The CMU base (Earth's gravity by default): a plate at Mars gravity, a plate and a
    // wheel with neither condition, the wheel on a 20 deg slope (the slope study's hand-written
    // vector: (-3.3552, 0, -9.2184)), and conditions no soil has.
    const BaseModel base =
        loadBaseModel(std::string(GRAINLINK_SOURCE_DIR) + "/scenarios/gap/cmu/base.yaml");
    const auto plate = [](const std::string &id, const std::map<std::string, double> &extra) {
        return plateExperiment(id, extra, {{"box", "small"}});
    };
    const auto wheel = [](const std::string &id, std::map<std::string, double> extra) {
        Experiment e;
        e.id = id;
        e.type = ExperimentType::WheelSteadyState;
        e.x_name = "slip";
        e.scatter = true;
        e.observables = {"traction_N"};
        e.numbers = {{"wheel_radius_m", 0.058}, {"wheel_width_m", 0.05}, {"load_N", 21.5}};
        e.numbers.insert(extra.begin(), extra.end());
        for (double s : {0.0, 0.3}) {
            Trial t;
            t.curves["traction_N"] = Curve{{s}, {1.0 + s}};
            e.trials.push_back(t);
        }
        return e;
    };
    ExperimentSet set;
    set.name = "gravity";
    set.experiments = {plate("earth_plate", {}),
                       plate("mars_plate", {{"gravity_m_s2", 3.71}}),
                       plate("mars_plate_again", {{"gravity_m_s2", 3.71}}),
                       plate("tilted_plate", {{"slope_deg", 10.0}}),
                       plate("no_gravity", {{"gravity_m_s2", 0.0}}),
                       wheel("level_wheel", {}),
                       wheel("slope_wheel", {{"slope_deg", 20.0}}),
                       wheel("cliff_wheel", {{"slope_deg", 75.0}})};
    std::vector<std::string> left_out;
    const ExperimentSet kept = simulable(set, base, left_out);
    REQUIRE(left_out.size() == 2);
    CHECK_THAT(left_out[0], Catch::StartsWith("no_gravity (plate_sinkage: gravity_m_s2 0"));
    CHECK_THAT(left_out[1], Catch::StartsWith("cliff_wheel (wheel_steady_state: slope 75 deg"));
    // A plate's slope is no condition its test reads, and is said so; gravity is.
    REQUIRE(kept.notes.size() == 1);
    CHECK_THAT(kept.notes[0], Catch::Contains("condition 'slope_deg' is not simulated") &&
                                  Catch::Contains("in tilted_plate (1 experiment"));

    const fs::path scratch = freshScratch("grainlink-gap-gravity-test");
    const StudySimulator sim(base, (scratch / "sims").string(), {});
    // Earth and tilted plates share a test (the slope is not theirs), the two Mars plates
    // another; each wheel its own.
    CHECK(groupSet(sim, kept) ==
          std::set<std::vector<std::string>>{{"earth_plate", "tilted_plate"},
                                             {"mars_plate", "mars_plate_again"},
                                             {"level_wheel"},
                                             {"slope_wheel"}});
    const auto soilOf = [&](const std::string &id) { return labSoilOf(sim, kept, id, scratch); };
    const auto earth = soilOf("earth_plate"), mars = soilOf("mars_plate");
    CHECK(earth.settings.gravity_m_s2.isApprox(grainlink::dem::Vec3(0, 0, -9.81)));
    CHECK_FALSE(earth.deposition.gravity_m_s2); // without the conditions, the base's soil as it is
    CHECK(mars.settings.gravity_m_s2.isApprox(grainlink::dem::Vec3(0, 0, -3.71)));
    REQUIRE(mars.deposition.gravity_m_s2);
    CHECK(mars.deposition.gravity_m_s2->isApprox(grainlink::dem::Vec3(0, 0, -3.71)));
    // A fall under Mars' gravity takes sqrt(9.81 / 3.71) = 1.626 times as long: so may settling.
    CHECK(mars.deposition.max_settle_time_s ==
          Approx(earth.deposition.max_settle_time_s * 1.6261).epsilon(1e-4));
    // Settled means the same fraction of a grain's m g d under either gravity: 3.71 / 9.81.
    CHECK(mars.deposition.settle_kinetic_energy_J ==
          Approx(earth.deposition.settle_kinetic_energy_J * 0.37819).epsilon(1e-4));
    const auto slope = soilOf("slope_wheel");
    CHECK(slope.settings.gravity_m_s2.x() == Approx(-3.3552).margin(1e-4));
    CHECK(slope.settings.gravity_m_s2.y() == 0.0);
    CHECK(slope.settings.gravity_m_s2.z() == Approx(-9.2184).margin(1e-4));
    REQUIRE(slope.deposition.gravity_m_s2);
    CHECK(slope.deposition.gravity_m_s2->isApprox(grainlink::dem::Vec3(0, 0, -9.81)));
    // Every slope shares the level bed's packing; another gravity settles its own.
    CHECK(grainlink::dem::packingKey(slope) == grainlink::dem::packingKey(soilOf("level_wheel")));
    CHECK(grainlink::dem::packingKey(mars) != grainlink::dem::packingKey(earth));
    fs::remove_all(scratch);
}

TEST_CASE("a text condition the base describes gives its experiments their soil: a bed's "
          "preparation, a value it does not describe is said",
          "[gap][simulator]") {
    // The CMU base with a dense preparation (more grains in the same box) besides its own bed:
    // plates prepared dense, loose (which the base leaves to its own soil) and unsaid.
    const fs::path scratch = freshScratch("grainlink-gap-preparation-test");
    std::string text = cmuBaseText();
    text += "conditions:\n  preparation:\n    dense: {soil: {deposition: {count: 5000}}}\n";
    std::ofstream(scratch / "base.yaml") << text;
    const BaseModel base = loadBaseModel((scratch / "base.yaml").string());
    ExperimentSet set;
    set.name = "preparations";
    set.experiments = {plateExperiment("dense_plate", {}, {{"preparation", "dense"}}),
                       plateExperiment("loose_plate", {}, {{"preparation", "loose"}}),
                       plateExperiment("plain_plate", {}, {})};
    std::vector<std::string> left_out;
    const ExperimentSet kept = simulable(set, base, left_out);
    CHECK(left_out.empty());
    REQUIRE(kept.notes.size() == 1);
    CHECK_THAT(kept.notes[0], Catch::Contains("preparation 'loose' has no soil") &&
                                  Catch::Contains("(conditions.preparation: dense)") &&
                                  Catch::Contains("in loose_plate (1 experiment") &&
                                  !Catch::Contains("misspelt"));
    // A value that differs from one the base describes only by a typo says which.
    ExperimentSet typo = set;
    typo.experiments = {plateExperiment("typo_plate", {}, {{"preparation", "Dense"}})};
    CHECK_THAT(simulable(typo, base, left_out).notes.at(0),
               Catch::Contains("preparation 'Dense' has no soil") &&
                   Catch::Contains("(conditions.preparation: dense; 'dense' misspelt?)"));
    const StudySimulator sim(base, (scratch / "sims").string(), {});
    CHECK(groupSet(sim, kept) ==
          std::set<std::vector<std::string>>{{"dense_plate"}, {"loose_plate", "plain_plate"}});
    VariantRequest plain;
    plain.label = "base";
    const auto scenarioOf = [&](const std::string &id) {
        const fs::path file = scratch / (id + ".yaml");
        std::ofstream(file) << sim.scenarioText(kept, {id}, plain, 1);
        return std::get<grainlink::lab::BevameterScenario>(
            grainlink::lab::loadLabScenario("bevameter", file.string()));
    };
    const auto dense = scenarioOf("dense_plate"), loose = scenarioOf("loose_plate");
    CHECK(dense.soil.deposition.count == 5000);
    CHECK(loose.soil.deposition.count != 5000);
    CHECK(dense.name == loose.name + "-dense");

    // `box` is `boxes:`' to give.
    std::ofstream(scratch / "boxed.yaml")
        << text << "  box:\n    tiny: {soil: {deposition: {count: 100}}}\n";
    CHECK_THROWS_WITH(loadBaseModel((scratch / "boxed.yaml").string()),
                      Catch::Contains("conditions.box") && Catch::Contains("boxes:"));
    fs::remove_all(scratch);
}

TEST_CASE("an experiment's bed depth makes its bed: poured deeper and struck off level at it, "
          "the shear box's depth is its own",
          "[gap][simulator]") {
    // The CI self-test's base (a 50 mm box, grains of 1.8-2 mm poured about 25 mm deep): plates
    // on beds of 30 and 15 mm and one without the condition, and a shear box given a depth.
    const BaseModel base = loadBaseModel(kDir + "/base.yaml");
    const Experiment shear = shearExperiment("shear", {{"bed_depth_m", 0.03}}, {});
    ExperimentSet set;
    set.name = "depths";
    const auto plate = [](const std::string &id, std::map<std::string, double> numbers) {
        numbers["plate_diameter_m"] = 0.04; // in the 50 mm box
        return plateExperiment(id, numbers, {});
    };
    set.experiments = {plate("deep", {{"bed_depth_m", 0.03}}),
                       plate("shallow", {{"bed_depth_m", 0.015}}), plate("as_base", {}),
                       plate("no_depth", {{"bed_depth_m", -0.01}}), shear};
    std::vector<std::string> left_out;
    const ExperimentSet kept = simulable(set, base, left_out);
    REQUIRE(left_out.size() == 1);
    CHECK_THAT(left_out[0], Catch::StartsWith("no_depth (plate_sinkage: bed_depth_m -0.01"));
    REQUIRE(kept.notes.size() == 1);
    CHECK_THAT(kept.notes[0], Catch::Contains("condition 'bed_depth_m' is not simulated") &&
                                  Catch::Contains("in shear (1 experiment"));

    const fs::path scratch = freshScratch("grainlink-gap-depth-test");
    const StudySimulator sim(base, (scratch / "sims").string(), {});
    CHECK(groupSet(sim, kept) ==
          std::set<std::vector<std::string>>{{"deep"}, {"shallow"}, {"as_base"}, {"shear"}});
    const auto soilOf = [&](const std::string &id) { return labSoilOf(sim, kept, id, scratch); };
    const auto deep = soilOf("deep"), shallow = soilOf("shallow"), as_base = soilOf("as_base");
    CHECK_FALSE(as_base.deposition.strike_off_height_m);
    CHECK(as_base.deposition.count == 1300);
    REQUIRE(deep.deposition.strike_off_height_m);
    CHECK(*deep.deposition.strike_off_height_m == Approx(0.03));
    REQUIRE(shallow.deposition.strike_off_height_m);
    CHECK(*shallow.deposition.strike_off_height_m == Approx(0.015));
    // Enough grains to stand 15 % above the depth at a packing of 0.64: by hand, a grain of
    // uniform radius in [1.8, 2] mm has E[r^3] = 3.8 * 7.24 / 4 = 6.878 mm^3, a volume of
    // 28.81 mm^3; 1.15 * 30 mm * 50 mm * 50 mm * 0.64 / 28.81 mm^3 = 1916 grains for 30 mm,
    // 958 for 15 mm.
    CHECK(double(deep.deposition.count) == Approx(1916).margin(1));
    CHECK(double(shallow.deposition.count) == Approx(958).margin(1));
    // The region grows with the count (1916 / 1300 of 80 mm), never shrinks.
    CHECK(deep.deposition.region_upper_m.z() == Approx(0.08 * 1916 / 1300).epsilon(1e-3));
    CHECK(shallow.deposition.region_upper_m.z() == Approx(0.08));
    CHECK(soilOf("shear").deposition.strike_off_height_m == std::nullopt);

    // The bed as the DEM makes it: poured above 30 mm, struck off within a grain diameter of it
    // (docs/physics.md §6.1's strike-off bound, |z_s - h| < 2 r_max).
    auto system = grainlink::dem::makeSystem(deep);
    const grainlink::dem::DepositionReport report =
        grainlink::dem::deposit(*system, deep.deposition);
    CHECK(report.settled);
    CHECK(report.struck_off > 0);
    CHECK(grainlink::dem::bedSurface(system->particles()) == Approx(0.03).margin(0.004));
    fs::remove_all(scratch);
}

TEST_CASE("a mole experiment becomes a coupled run of the base's mole in its column: as many "
          "strokes as measured, windows of whole DEM steps, its gravity and its column's depth",
          "[gap][simulator][mole]") {
    const std::string dir = std::string(GRAINLINK_SOURCE_DIR) + "/scenarios/gap/mole";
    const BaseModel base = loadBaseModel(dir + "/base.yaml");
    const Design design = loadDesign(dir + "/design.yaml");
    const StudySimulator sim(base, (freshScratch("grainlink-gap-mole-test") / "sims").string(), {});
    const auto runOf = [&](const ExperimentSet &set, const VariantRequest &r) {
        return YAML::Load(sim.scenarioText(set, {set.experiments.front().id}, r, 1));
    };
    VariantRequest plain;
    plain.label = "base";
    const YAML::Node run = runOf(design.set, plain);
    // Two strokes measured: 0.1 s of settling plus two periods of 0.3 s (docs/gap.md, "The mole").
    CHECK(run["coupling"]["end_time_s"].as<double>() == Approx(0.7));
    CHECK(run["coupling"]["adaptive"]["min_macro_step_s"].as<double>() == Approx(5e-5));
    CHECK(run["coupling"]["adaptive"]["max_macro_step_s"].as<double>() == Approx(1e-3));
    CHECK(run["participants"].size() == 2);
    CHECK(run["participants"][1]["command"][1].as<std::string>() == "dem-node");
    CHECK_FALSE(run["name"]); // a coupled scenario has none
    const auto gravity = run["mole"]["gravity_m_s2"].as<std::vector<double>>();
    CHECK(gravity == std::vector<double>{0.0, 0.0, -3.71});
    CHECK(run["mole"]["start_tip_position_m"][2].as<double>() == Approx(0.22)); // 20 mm above 0.2

    // Every variant: windows of whole DEM steps and an end on one (the soil node refuses a
    // window of a fractional step); the soil, the mole and the coupling each read by their own
    // readers is the run's validation in `grainlink gap` (test `gap:mole-twin-is-diagnosed`).
    forEveryVariant(sim, [&](const VariantRequest &r) {
        const YAML::Node v = runOf(design.set, r);
        INFO(r.label << ":\n" << YAML::Dump(v));
        const double dt = v["soil"]["simulation"]["time_step_s"].as<double>();
        for (const double t :
             {v["coupling"]["adaptive"]["min_macro_step_s"].as<double>(),
              v["coupling"]["adaptive"]["max_macro_step_s"].as<double>(),
              v["coupling"]["macro_step_s"].as<double>(), v["coupling"]["end_time_s"].as<double>()})
            CHECK(std::abs(t / dt - std::round(t / dt)) < 1e-6);
        CHECK(std::abs(dt / 1e-9 - std::round(dt / 1e-9)) < 1e-6); // whole coupling ticks
    });

    // The rate check (f = 0.5) runs the strokes at half the rate: periods of 0.6 s.
    VariantRequest rate;
    rate.label = "check-rate";
    rate.check = "rate";
    const YAML::Node slow = runOf(design.set, rate);
    CHECK(slow["mole"]["stroke_period_s"].as<double>() == Approx(0.6));
    CHECK(slow["coupling"]["end_time_s"].as<double>() == Approx(1.3));

    // A deeper column (bed_depth_m 0.25) starts the tip 20 mm above its struck surface.
    ExperimentSet deeper = design.set;
    deeper.experiments.front().numbers["bed_depth_m"] = 0.25;
    deeper.experiments.front().numbers["gravity_m_s2"] = 1.62;
    const YAML::Node deep = runOf(deeper, plain);
    CHECK(deep["soil"]["deposition"]["strike_off_height_m"].as<double>() == Approx(0.25));
    CHECK(deep["mole"]["start_tip_position_m"][2].as<double>() == Approx(0.27));
    CHECK(deep["mole"]["gravity_m_s2"][2].as<double>() == Approx(-1.62));
    // Without the experiment's gravity the mole falls under the soil's (the base's `mars`), its
    // own default never standing apart from the soil's.
    ExperimentSet unstated = design.set;
    unstated.experiments.front().numbers.erase("gravity_m_s2");
    CHECK(runOf(unstated, plain)["mole"]["gravity_m_s2"][2].as<double>() == Approx(-3.71));
}

TEST_CASE("an experiment loaded at another speed than its test is simulated at adds the loading "
          "rate check",
          "[gap][simulator]") {
    // The CI base presses its plates at 0.05 m/s and has no rate check: a plate measured at the
    // same speed (within 10 %) adds nothing; one pressed at 3 mm/s, as the CMU test bed does,
    // adds the check at its default factor and says so.
    const auto setWith = [](double speed) {
        ExperimentSet set;
        set.experiments = {
            plateExperiment("p", {{"plate_diameter_m", 0.02}, {"speed_m_s", speed}}, {})};
        return set;
    };
    BaseModel base = loadBaseModel(kDir + "/base.yaml");
    REQUIRE_FALSE(base.checks.count("rate"));
    CHECK(addRateCheckWhereSpeedDiffers(base, setWith(0.047)).empty());
    CHECK_FALSE(base.checks.count("rate"));
    const std::string note = addRateCheckWhereSpeedDiffers(base, setWith(0.003));
    CHECK_THAT(note, Catch::Contains("p: 0.003 m/s measured, 0.05 m/s simulated") &&
                         Catch::Contains("rate check (x 0.5) is added"));
    REQUIRE(base.checks.count("rate"));
    CHECK(base.checks.at("rate") == 0.5);
    // A base that has its own rate check keeps its factor.
    base.checks["rate"] = 0.25;
    CHECK(addRateCheckWhereSpeedDiffers(base, setWith(0.003)).empty());
    CHECK(base.checks.at("rate") == 0.25);
}

TEST_CASE("a condition the test needs, given under another name, is named as likely misspelt",
          "[gap][simulator]") {
    // The reading says `plate_diam_m` is not simulated; the error that follows must not leave
    // the user to connect it with the plate_diameter_m it lacks.
    const BaseModel base = loadBaseModel(kDir + "/base.yaml");
    // speed_m_s describes the experiment (the rate check reads it): no misspelling.
    Experiment plate = plateExperiment("p", {{"plate_diam_m", 0.02}, {"speed_m_s", 0.01}}, {});
    plate.numbers.erase("plate_diameter_m");
    ExperimentSet set;
    set.name = "misspelt";
    set.experiments = {plate};
    const StudySimulator sim(base, (freshScratch("grainlink-gap-misspelt") / "sims").string(), {});
    VariantRequest plain;
    plain.label = "base";
    CHECK_THROWS_WITH(sim.plan(set, {plain}),
                      Catch::Contains("experiment 'p' (plate_sinkage) needs the condition "
                                      "'plate_diameter_m' (it gives 'plate_diam_m', which nothing "
                                      "reads: misspelt?)"));
}

TEST_CASE("the plan names an effect that changes none of the base's runs and a proposed "
          "experiment the base cannot run",
          "[gap][simulator]") {
    // A user's catalogue entry whose every key is misspelt would be fitted as an effect that
    // changes nothing; a probe whose condition is misspelt stopped a finished diagnosis at its
    // very end, when it proposed the next experiment.
    const fs::path scratch = freshScratch("grainlink-gap-plan-refusals");
    std::string text = cmuBaseText();
    const std::string probe = "{normal_stress_Pa: 10000}";
    REQUIRE(text.find(probe) != std::string::npos);
    text.replace(text.find(probe), probe.size(), "{normal_stres_Pa: 10000}");
    std::ofstream(scratch / "base.yaml") << text;
    std::ofstream(scratch / "effects.yaml")
        << "effects:\n"
           "  - name: wet_density\n"
           "    description: pore water adds to the bulk weight\n"
           "    acts_on: grain-grain\n"
           "    strength: {parameter: f, unit: \"-\", prior: [1, 1.3], off: 1, signature: [1.1, "
           "1.25]}\n"
           "    edits:\n"
           "      - {key: soil.material.density_kg_m, scale: s}\n";
    const EffectCatalogue c =
        mergeEffects(loadEffects(std::string(GRAINLINK_SOURCE_DIR) + "/data/effects.yaml"),
                     loadEffects((scratch / "effects.yaml").string()));
    const BaseModel base = loadBaseModel((scratch / "base.yaml").string());
    ExperimentSet set;
    set.name = "plan";
    set.experiments = {plateExperiment("a", {}, {{"box", "small"}}),
                       plateExperiment("b", {{"plate_diameter_m", 0.08}}, {{"box", "small"}})};
    const StudySimulator sim(base, (scratch / "sims").string(), {});
    DiagnosisOptions o;
    const DiagnosisPlan plan =
        planDiagnosis(set, {&c.find("wet_density"), &c.find("grain_density")}, sim, o);
    REQUIRE(plan.inapplicable.size() == 1);
    CHECK(plan.inapplicable[0].first == "wet_density");
    CHECK_THAT(plan.inapplicable[0].second,
               Catch::Contains("its edits change nothing in this base's runs") &&
                   Catch::Contains("soil.material.density_kg_m (") &&
                   Catch::Contains("effects.yaml:7)"));
    CHECK(plan.applicable == std::vector<std::string>{"grain_density"});
    REQUIRE(plan.probes_refused.size() == 1);
    CHECK_THAT(plan.probes_refused[0].second,
               Catch::Contains("needs the condition 'normal_stress_Pa' (it gives "
                               "'normal_stres_Pa'"));
    fs::remove_all(scratch);
}

TEST_CASE("a typo in the base model is named where the base wrote it, not only in the scenario "
          "generated from it",
          "[gap][simulator]") {
    const fs::path scratch = freshScratch("grainlink-gap-base-typo");
    std::ifstream in(kDir + "/base.yaml");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string key = "youngs_modulus_Pa";
    const std::size_t at = text.find(key);
    REQUIRE(at != std::string::npos);
    const int line = int(std::count(text.begin(), text.begin() + long(at), '\n')) + 1;
    text.replace(at, key.size(), "youngs_modulus_pa");
    const std::string path = (scratch / "base.yaml").string();
    std::ofstream(path) << text;
    const BaseModel base = loadBaseModel(path);
    ExperimentSet set;
    set.name = "typo";
    set.experiments = {plateExperiment("p", {{"plate_diameter_m", 0.02}}, {})};
    const StudySimulator sim(base, (scratch / "sims").string(), {});
    VariantRequest plain;
    plain.label = "base";
    CHECK_THROWS_WITH(
        sim.plan(set, {plain}),
        Catch::Contains("unknown key 'soil.material.youngs_modulus_pa'") &&
            Catch::Contains("(written in " + path + ":" + std::to_string(line) + ")"));
    fs::remove_all(scratch);
}

TEST_CASE("a direct shear box under ten grains across is said once, at the base's line, before "
          "anything runs",
          "[gap][simulator]") {
    // The CI base's box is 30 mm for grains up to 4 mm: 7.5 diameters against ASTM D3080's 10.
    const StudySimulator narrow(loadBaseModel(kDir + "/base.yaml"),
                                (freshScratch("grainlink-gap-narrow-box") / "sims").string(), {});
    REQUIRE(narrow.labWarnings().size() == 1);
    CHECK_THAT(narrow.labWarnings()[0],
               Catch::StartsWith(kDir + "/base.yaml:38: tests.direct_shear: ") &&
                   Catch::Contains("'direct_shear.width_m': the box is 7.5 largest grain "
                                   "diameters across") &&
                   Catch::Contains("ASTM D3080"));
    // 40 mm across is ten diameters: nothing to say.
    const fs::path scratch = freshScratch("grainlink-gap-wide-box");
    std::ifstream in(kDir + "/base.yaml");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    for (const std::string key : {"length_m: 0.03", "width_m: 0.03"}) {
        const std::size_t at = text.find(key);
        REQUIRE(at != std::string::npos);
        text.replace(at, key.size(), key.substr(0, key.size() - 4) + "0.04");
    }
    std::ofstream(scratch / "base.yaml") << text;
    const StudySimulator wide(loadBaseModel((scratch / "base.yaml").string()),
                              (scratch / "sims").string(), {});
    CHECK(wide.labWarnings().empty());
    fs::remove_all(scratch);
}

TEST_CASE("a bed deeper than the base's bin is high is named with its experiment",
          "[gap][simulator]") {
    // bed_depth_m: 60 (mm meant) became a grain count of 5e7, refused as that count.
    const BaseModel base = loadBaseModel(kDir + "/base.yaml");
    ExperimentSet set;
    set.name = "deep";
    set.experiments = {
        plateExperiment("p", {{"bed_depth_m", 60.0}, {"plate_diameter_m", 0.02}}, {})};
    const StudySimulator sim(base, (freshScratch("grainlink-gap-too-deep") / "sims").string(), {});
    VariantRequest plain;
    plain.label = "base";
    CHECK_THROWS_WITH(sim.plan(set, {plain}),
                      Catch::Contains("experiment 'p': bed_depth_m 60") &&
                          Catch::Contains("is deeper than the base's bin") &&
                          Catch::Contains("a depth in mm?"));
}

TEST_CASE("a direct shear test's box label gives it no container: the test builds its own",
          "[gap][simulator]") {
    // The CI base's `narrow` box has walls; merged into a shear test they were refused as
    // soil.walls, a key the user never wrote for it.
    const BaseModel base = loadBaseModel(kDir + "/base.yaml");
    ExperimentSet set;
    set.name = "shear-box";
    set.experiments = {shearExperiment("shear", {}, {{"box", "narrow"}})};
    std::vector<std::string> left_out;
    const ExperimentSet kept = simulable(set, base, left_out);
    REQUIRE(kept.notes.size() == 1);
    CHECK_THAT(kept.notes[0], Catch::Contains("condition 'box' is not simulated") &&
                                  Catch::Contains("in shear (1 experiment"));
    const StudySimulator sim(base, (freshScratch("grainlink-gap-shear-box") / "sims").string(), {});
    VariantRequest plain;
    plain.label = "base";
    CHECK_NOTHROW(sim.plan(kept, {plain}));
}

TEST_CASE("a twin's experiments on beds of their own are run alone, each on another packing",
          "[gap][simulator]") {
    // A test bed rebuilt for every trial: two plates of one box, even two alike, are two beds per
    // trial, not one bed pressed twice (the default, as grainlink's packing cache does).
    const StudySimulator sim(loadBaseModel(kDir + "/base.yaml"),
                             (fs::temp_directory_path() / "grainlink-gap-own-beds").string(), {});
    ExperimentSet set = loadDesign(kDir + "/design.yaml").set;
    Experiment again = set.find("wide_d20");
    again.id = "wide_d20_again";
    set.experiments = {set.find("wide_d20"), set.find("wide_d30"), again};
    VariantRequest twin;
    twin.label = "twin";
    twin.seeds = 2;
    twin.seed_offset = 1000;
    const auto distinct = [](std::vector<std::string> ids) {
        std::sort(ids.begin(), ids.end());
        return std::size_t(std::unique(ids.begin(), ids.end()) - ids.begin());
    };
    CHECK(distinct(sim.runIds(set, twin)) == 2); // one run of the box per trial
    twin.own_beds = true;
    CHECK(distinct(sim.runIds(set, twin)) == 6); // the alike plates too: another seed each
    CHECK(sim.groups(set, {twin}).size() == 3);
}

TEST_CASE("a heap that spreads flat is an angle of repose of zero, not a missing value",
          "[gap][simulator]") {
    // The full self-test's repose fill on a frictionless floor: the grains run out of the lifted
    // tube and leave no flank to fit (the lab's "no heap"). A missing value would drop that bed,
    // and a model whose beds mostly spread would be judged by the one that kept a heap (wall
    // friction 0.07 on the full self-test: two beds spread, one kept a heap of -1.06 deg).
    const std::string dir = std::string(GRAINLINK_SOURCE_DIR) + "/scenarios/gap/selftest-full";
    std::ifstream in(dir + "/base.yaml");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string floor = "normal: [0, 0, 1], friction_coefficient: 0.6}";
    REQUIRE(text.find(floor) != std::string::npos);
    text.replace(text.find(floor), floor.size(), "normal: [0, 0, 1], friction_coefficient: 0.0}");
    const fs::path scratch = freshScratch("grainlink-gap-no-heap");
    std::ofstream(scratch / "base.yaml") << text;

    grainlink::study::ExecutorOptions run;
    run.grainlink = GRAINLINK_EXECUTABLE;
    run.progress_interval_s = 1e9;
    StudySimulator sim(loadBaseModel((scratch / "base.yaml").string()), (scratch / "sims").string(),
                       run);
    ExperimentSet set = loadDesign(dir + "/design.yaml").set;
    set.experiments = {set.find("repose")};
    VariantRequest plain;
    plain.label = "base";
    std::vector<int> seeds_of;
    const auto curves = sim.curves(set, {plain}, seeds_of);
    REQUIRE(curves.size() == 1);
    const Curve &angle = curves[0].at("repose").at("angle_deg");
    REQUIRE(angle.scalar());
    CHECK(angle.y[0] == 0.0);
}

TEST_CASE("a lab test refused for one experiment of its group names every experiment of it",
          "[gap][simulator]") {
    // Plates in one box run as one lab test: a plate too large for the bin was named as the
    // group's first experiment, which was not the one at fault.
    const BaseModel base = loadBaseModel(kDir + "/base.yaml");
    ExperimentSet set;
    set.name = "group";
    set.experiments = {plateExperiment("small", {{"plate_diameter_m", 0.02}}, {}),
                       plateExperiment("huge", {{"plate_diameter_m", 0.5}}, {})};
    const StudySimulator sim(base, (freshScratch("grainlink-gap-group") / "sims").string(), {});
    VariantRequest plain;
    plain.label = "base";
    CHECK_THROWS_WITH(sim.plan(set, {plain}),
                      Catch::Contains("base seed 0 small, huge: not a valid lab bevameter "
                                      "scenario") &&
                          Catch::Contains("reaches past the bed"));
}

// The shear box's vertical gauge: the lab's plate rise is the direct shear experiment's
// vertical displacement, and a twin writes it beside the stress, sampled with it.
TEST_CASE("a direct shear test's vertical displacement is the lab's plate rise: the bed settles, "
          "then dilates, less under more normal stress, and a twin writes it beside the stress",
          "[gap][simulator][twin]") {
    const std::string dir = std::string(GRAINLINK_SOURCE_DIR) + "/scenarios/gap/selftest-ci";
    const fs::path scratch = freshScratch("grainlink-gap-dilation");
    std::ofstream(scratch / "design.yaml")
        << "experiments:\n"
           "  - {id: s4, type: direct_shear, conditions: {normal_stress_Pa: 4000}, reach: 0.005,\n"
           "     observables: [shear_stress_Pa, vertical_displacement_m], repeats: 1}\n"
           "  - {id: s12, type: direct_shear, conditions: {normal_stress_Pa: 12000}, reach: "
           "0.005,\n"
           "     observables: [shear_stress_Pa, vertical_displacement_m], repeats: 1}\n";
    const Design design = loadDesign((scratch / "design.yaml").string());
    grainlink::study::ExecutorOptions run;
    run.grainlink = GRAINLINK_EXECUTABLE;
    run.progress_interval_s = 1e9;
    StudySimulator sim(loadBaseModel(dir + "/base.yaml"), (scratch / "sims").string(), run);
    VariantRequest plain;
    plain.label = "base";
    std::vector<int> seeds_of;
    const auto curves = sim.curves(design.set, {plain}, seeds_of);
    REQUIRE(curves.size() == 1);
    const auto rise = [&](const std::string &id) -> const Curve & {
        return curves[0].at(id).at("vertical_displacement_m");
    };
    for (const std::string id : {"s4", "s12"}) {
        const Curve &tau = curves[0].at(id).at("shear_stress_Pa");
        REQUIRE(rise(id).x == tau.x);
        REQUIRE(rise(id).x.back() >= 0.005);
        INFO(id << ": the plate's lowest "
                << *std::min_element(rise(id).y.begin(), rise(id).y.end()) << " m, at the end "
                << rise(id).y.back() << " m");
        // A poured bed is first compacted by the shear, then dilates (Reynolds): by 5 mm of
        // shear a bed of 2 mm grains has risen by tens of micrometres at least.
        CHECK(*std::min_element(rise(id).y.begin(), rise(id).y.end()) < 0.0);
        CHECK(rise(id).y.back() > 2e-5);
    }
    // Stress-dilatancy (Bolton 1986): a higher normal stress suppresses dilation.
    CHECK(rise("s12").y.back() < rise("s4").y.back());

    TwinKey key;
    key.seed = 1;
    key.noise = key.level_noise = 0.0;
    writeTwin(design, curves, key, (scratch / "twin").string(),
              (scratch / "twin.key.json").string());
    const ExperimentSet twin = loadExperiments((scratch / "twin").string());
    const Experiment &read = twin.find("s4");
    REQUIRE(read.trials.size() == 1);
    const Curve &back = read.trials[0].curves.at("vertical_displacement_m");
    REQUIRE(!back.x.empty());
    CHECK(back.x.back() <= 0.005);
    const Curve &sim4 = rise("s4");
    const auto at = std::find(sim4.x.begin(), sim4.x.end(), back.x.back());
    REQUIRE(at != sim4.x.end());
    CHECK(back.y.back() == Approx(sim4.y[std::size_t(at - sim4.x.begin())]).epsilon(1e-8));
    // A rise sampled elsewhere than its stress (another run's samples) is refused, named:
    // a row of the twin's file would pair values of two instants.
    auto torn = curves;
    Curve &short_rise = torn[0].at("s4").at("vertical_displacement_m");
    short_rise.x.pop_back();
    short_rise.y.pop_back();
    CHECK_THROWS_WITH(writeTwin(design, torn, key, (scratch / "torn").string(),
                                (scratch / "torn.key.json").string()),
                      Catch::Contains("experiment 's4', repeat 1: its 'vertical_displacement_m' "
                                      "was not sampled with its 'shear_stress_Pa'"));
    fs::remove_all(scratch);
}
