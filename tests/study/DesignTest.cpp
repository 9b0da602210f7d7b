// A study file becomes its points: every combination of the varied values (or the zipped
// ones), each replicate a deposition seed, every value at its dotted path; a point is named by
// its scenario alone; a design point that is not a valid scenario stops everything before any
// run, naming the study file, the key and the value.
#include "StudyFixtures.hpp"

#include "grainlink/study/Design.hpp"
#include "grainlink/study/ScenarioEdit.hpp"

#include <catch2/catch.hpp>

#include <map>
#include <set>
#include <tuple>

using namespace grainlink::study;
using namespace grainlink::study::test;

namespace {

/// A study file in `folder` around the test scenario data/plate.yaml.
std::string studyFile(const TempFolder &folder, const std::string &name,
                      const std::string &design) {
    const std::string path = folder / (name + ".yaml");
    writeFile(path, "name: " + name + "\nbase: {kind: dem, scenario: " + kData + "/plate.yaml}\n" +
                        design + "observables: [bodies.plate.force_N.2]\n");
    return path;
}

std::string errorOf(const std::function<void()> &f) {
    try {
        f();
    } catch (const std::exception &e) {
        return e.what();
    }
    return "no error";
}

double at(const Point &p, const std::string &key) {
    return findAtPath(YAML::Load(p.scenario_yaml), key).as<double>();
}

} // namespace

TEST_CASE("a factorial design makes every combination of the values, each replicate a seed",
          "[study][design]") {
    TempFolder folder("factorial");
    const Study s =
        loadStudy(studyFile(folder, "factorial",
                            "design:\n"
                            "  vary:\n"
                            "    - {key: contact.tangential.stick_angle_deg, values: [32, 36]}\n"
                            "    - {key: contact.damping.coefficient_N_s_m,\n"
                            "       range: {from: 0.04, to: 0.06, step: 0.01}}\n"
                            "  replicates: 2\n"),
                  folder / "out");
    REQUIRE(s.points.size() == 2 * 3 * 2);
    std::set<std::tuple<double, double, double>> seen;
    for (const Point &p : s.points) {
        // Read back from the resolved scenario text, not from the design's own bookkeeping.
        seen.emplace(at(p, "contact.tangential.stick_angle_deg"),
                     at(p, "contact.damping.coefficient_N_s_m"), at(p, "deposition.seed"));
        CHECK(at(p, "contact.tangential.slip_angle_deg") == 30.0); // untouched keys stay
        CHECK(p.kind.name == "dem");
    }
    std::set<std::tuple<double, double, double>> expected;
    for (double stick : {32.0, 36.0})
        for (double damping : {0.04, 0.05, 0.06})
            for (double seed : {1.0, 2.0})
                expected.emplace(stick, damping, seed);
    CHECK(seen == expected);
    CHECK(s.varied_keys == std::vector<std::string>{"contact.tangential.stick_angle_deg",
                                                    "contact.damping.coefficient_N_s_m"});
    CHECK(s.replicate_key == "deposition.seed");
    CHECK(s.points[0].label == "stick_angle_deg=32 coefficient_N_s_m=0.04 seed=1");
}

TEST_CASE("replicates over several seed keys give each key a seed of its own, never another "
          "replicate's",
          "[study][design]") {
    // The rover's two soil strips (scenarios/rover.yaml, seeds 21 and 22 of its own): two
    // replicates from seed 21 give the pairs (21, 22) and (23, 24), one table row.
    TempFolder folder("seed-keys");
    const std::string replicates =
        "  replicates: {count: 2, keys: [soil_left.deposition.seed, soil_right.deposition.seed], "
        "first: 21}\n";
    const auto file = [&](const std::string &name, const std::string &design) {
        const std::string path = folder / (name + ".yaml");
        writeFile(path, "name: " + name + "\nbase: {kind: run, scenario: " + kSource +
                            "/scenarios/rover.yaml}\ndesign:\n" + design +
                            "observables: [second_half.wheel_lm_slip.mean]\n");
        return path;
    };
    const Study s =
        loadStudy(file("two_strips",
                       "  vary:\n    - {key: rover.release_time_s, values: [0.4]}\n" + replicates),
                  folder / "out");
    REQUIRE(s.points.size() == 2);
    std::set<std::pair<double, double>> seeds;
    for (const Point &p : s.points)
        seeds.emplace(at(p, "soil_left.deposition.seed"), at(p, "soil_right.deposition.seed"));
    CHECK(seeds == std::set<std::pair<double, double>>{{21, 22}, {23, 24}});
    CHECK(s.replicate_key == "soil_left.deposition.seed");
    CHECK(s.varied_keys == std::vector<std::string>{"rover.release_time_s"});
    CHECK_THAT(s.points[0].label, Catch::Contains("=21") && Catch::Contains("=22"));

    const std::string both =
        file("both", "  replicates: {count: 2, key: soil_left.deposition.seed, keys: "
                     "[soil_right.deposition.seed]}\n");
    CHECK_THAT(errorOf([&] { loadStudy(both, folder / "out"); }),
               Catch::Contains(both + ":4: key 'design.replicates.keys': give key or keys"));
    const std::string twice =
        file("twice", "  replicates: {count: 2, keys: [soil_left.deposition.seed, "
                      "soil_left.deposition.seed]}\n");
    CHECK_THAT(errorOf([&] { loadStudy(twice, folder / "out"); }),
               Catch::Contains(twice + ":4:") && Catch::Contains("is given twice"));
}

TEST_CASE("a base scenario that is a folder is refused naming the study file and the line",
          "[study][design]") {
    // An empty (or only tagged) `scenario:` names the study's own folder, which opens as a
    // stream and failed when read with the stream's words alone (the study fuzzer's finding).
    TempFolder folder("scenario-folder");
    const std::string path = folder / "folder.yaml";
    writeFile(path, "name: folder\nbase: {kind: dem, scenario: \"\"}\n"
                    "observables: [bodies.plate.force_N.2]\n");
    CHECK_THAT(errorOf([&] { loadStudy(path, folder / "out"); }),
               Catch::Contains(path + ":2: key 'base.scenario'") &&
                   Catch::Contains("it is a folder"));
}

TEST_CASE("a zipped design pairs the i-th values, and lists of unequal length are refused",
          "[study][design]") {
    TempFolder folder("zip");
    const Study s = loadStudy(
        studyFile(folder, "zip",
                  "design:\n"
                  "  combine: zip\n"
                  "  vary:\n"
                  "    - {key: contact.tangential.stick_angle_deg, values: [32, 34, 36]}\n"
                  "    - {key: contact.tangential.slip_angle_deg, values: [31, 33, 35]}\n"),
        folder / "out");
    REQUIRE(s.points.size() == 3);
    for (const Point &p : s.points)
        CHECK(at(p, "contact.tangential.slip_angle_deg") ==
              at(p, "contact.tangential.stick_angle_deg") - 1.0);
    CHECK(s.points[1].label == "stick_angle_deg=34 slip_angle_deg=33");
    const std::string bad = studyFile(folder, "bad_zip",
                                      "design:\n"
                                      "  combine: zip\n"
                                      "  vary:\n"
                                      "    - {key: contact.tangential.stick_angle_deg, "
                                      "values: [32, 34]}\n"
                                      "    - {key: deposition.seed, values: [1, 2, 3]}\n");
    CHECK_THAT(errorOf([&] { loadStudy(bad, folder / "out"); }),
               Catch::Contains(bad + ":6: key 'design.vary': zip needs lists of one length: "
                                     "'contact.tangential.stick_angle_deg' has 2 values, "
                                     "'deposition.seed' has 3"));
}

TEST_CASE("a varied or replicate key that is not a dotted path is refused with its line",
          "[study][design]") {
    TempFolder folder("not-a-path");
    // An empty key (the fuzzer's: a YAML tag where the key was) crashed the labels' naming.
    for (const std::string key : {"\"\"", "!odies.0.motion", ".seed", "deposition.", "a..b"}) {
        INFO(key);
        const std::string bad = studyFile(folder, "bad_key",
                                          "design:\n"
                                          "  vary:\n"
                                          "    - {key: " +
                                              key + ", values: [1, 2]}\n");
        CHECK_THAT(errorOf([&] { loadStudy(bad, folder / "out"); }),
                   Catch::Contains(bad + ":5: key 'design.vary[0].key': '") &&
                       Catch::Contains("' is not a dotted path of keys"));
    }
    const std::string seed = studyFile(folder, "bad_seed",
                                       "design:\n"
                                       "  replicates: {count: 2, key: \"\"}\n");
    CHECK_THAT(errorOf([&] { loadStudy(seed, folder / "out"); }),
               Catch::Contains(seed + ":4: key 'design.replicates.key': '' is not a dotted path"));
}

TEST_CASE("list items are reached by index, and a path the base lacks names the study file, the "
          "line and what is there",
          "[study][design]") {
    TempFolder folder("paths");
    const Study s = loadStudy(studyFile(folder, "walls",
                                        "design:\n  vary:\n    - {key: walls.0.upper_m, values: "
                                        "[[0.06, 0.06, 0.2], [0.07, 0.07, 0.2]]}\n"),
                              folder / "out");
    REQUIRE(s.points.size() == 2);
    CHECK(at(s.points[1], "walls.0.upper_m.0") == 0.07);
    CHECK(at(s.points[1], "walls.0.lower_m.0") == 0.0);
    CHECK(s.points[1].settings[0].second == "[0.07, 0.07, 0.2]");
    CHECK(s.points[1].label == "upper_m=[0.07, 0.07, 0.2]");

    // Labels name each key by the shortest tail no other key shares, never a bare index.
    const Study times = loadStudy(
        studyFile(folder, "times",
                  "design:\n  combine: zip\n  vary:\n"
                  "    - {key: bodies.0.motion.0.duration_s, values: [0.1]}\n"
                  "    - {key: run.duration_s, values: [0.1]}\n"),
        folder / "out");
    CHECK(times.points[0].label == "motion.0.duration_s=0.1 run.duration_s=0.1");

    const std::string typo =
        studyFile(folder, "typo",
                  "design:\n  vary:\n    - {key: contact.tangentail.stick_angle_deg, "
                  "values: [30]}\n");
    CHECK_THAT(errorOf([&] { loadStudy(typo, folder / "out"); }),
               Catch::Contains(typo + ":5: key 'design.vary[0].key': key "
                                      "'contact.tangentail.stick_angle_deg': 'contact' has no "
                                      "key 'tangentail' (there: damping, tangential, rolling)"));
    const std::string index = studyFile(
        folder, "index", "design:\n  vary:\n    - {key: walls.3.upper_m, values: [[1, 1, 1]]}\n");
    CHECK_THAT(errorOf([&] { loadStudy(index, folder / "out"); }),
               Catch::Contains("key 'walls.3.upper_m': 'walls' is a list of 1: no item '3'"));
}

TEST_CASE("a point is named by its kind and scenario: the same point whatever the study or "
          "order, another value another point",
          "[study][design]") {
    TempFolder folder("ids");
    const Study up = loadStudy(
        studyFile(folder, "up",
                  "design:\n  vary:\n    - {key: contact.tangential.stick_angle_deg, values: "
                  "[32, 36]}\n"),
        folder / "a");
    const Study down = loadStudy(
        studyFile(folder, "down",
                  "design:\n  vary:\n    - {key: contact.tangential.stick_angle_deg, values: "
                  "[36, 34, 32]}\n"),
        folder / "b");
    REQUIRE(up.points.size() == 2);
    REQUIRE(down.points.size() == 3);
    CHECK(up.points[0].id == down.points[2].id); // 32
    CHECK(up.points[1].id == down.points[0].id); // 36
    CHECK(down.points[1].id != up.points[0].id);
    CHECK(down.points[1].id != up.points[1].id);
    CHECK(up.points[0].id.size() == 12);

    // --threads is part of the scenario: another thread count, another point.
    DesignOptions two_threads;
    two_threads.threads = 2;
    const Study threaded = loadStudy(folder / "up.yaml", folder / "c", two_threads);
    CHECK(threaded.points[0].threads == 2);
    CHECK(at(threaded.points[0], "simulation.threads") == 2.0);
    CHECK(threaded.points[0].id != up.points[0].id);
    // Built in code from the same text: the same point again.
    CHECK(makePoint(standardKind("dem"), up.points[0].scenario_yaml, "x").id == up.points[0].id);
    CHECK(makePoint(standardKind("lab", "repose"), up.points[0].scenario_yaml, "x").id !=
          up.points[0].id);
}

TEST_CASE("a design point that is not a valid scenario is refused before anything runs, "
          "naming the study file, the key and the value",
          "[study][design]") {
    TempFolder folder("invalid");
    const std::string path =
        studyFile(folder, "invalid",
                  "design:\n  vary:\n    - {key: contact.tangential.stick_angle_deg,\n"
                  "       values: [32, 95]}\n  replicates: 2\n");
    const Study s = loadStudy(path, folder / "out");
    ExecutorOptions options;
    options.grainlink = kGrainlink;
    const std::string error = errorOf([&] { run(s, options); });
    CHECK_THAT(error, Catch::Contains(path + ":6: contact.tangential.stick_angle_deg = 95, " +
                                      path + ":7: deposition.seed = 1: not a valid dem scenario"));
    CHECK_THAT(error, Catch::Contains("stick_angle_deg"));
    CHECK_THAT(error, Catch::Contains("must be in [0, 90)"));
    // Nothing ran: no study file, no point folder; only the refused scenario the message
    // points into.
    CHECK_FALSE(fs::exists(folder / "out/study.json"));
    CHECK_FALSE(fs::exists(folder / "out/points"));
    const std::string refused = error.substr(error.find(folder / "out/scenarios/"));
    const std::string file = refused.substr(0, refused.find(".yaml:") + 5);
    REQUIRE(fs::exists(file));
    const int line = std::stoi(refused.substr(refused.find(".yaml:") + 6));
    std::istringstream text(readFile(file));
    std::string row;
    for (int k = 0; k < line; ++k)
        std::getline(text, row);
    CHECK_THAT(row, Catch::Contains("tangential:")); // the line the reader named

    // A key the base does not have is created, and the strict reader refuses it by name.
    const std::string unknown =
        studyFile(folder, "unknown",
                  "design:\n  vary:\n    - {key: contact.tangential.stick_angle,\n"
                  "       values: [32]}\n");
    CHECK_THAT(errorOf([&] { run(loadStudy(unknown, folder / "out"), options); }),
               Catch::Contains("unknown key 'contact.tangential.stick_angle'"));
}

TEST_CASE("relative file paths of the base become absolute, other values stay", "[study][design]") {
    TempFolder folder("files");
    writeFile(folder / "wheel.stl", "solid x\nendsolid x\n");
    YAML::Node tree = YAML::Load("bodies:\n  - mesh: {type: stl, file: wheel.stl}\n"
                                 "    other: {file: missing.stl}\n"
                                 "contact: {damping: {model: viscous}}\nmodel: wheel.stl\n");
    absolutizeFilePaths(tree, folder.path.string());
    CHECK(tree["bodies"][0]["mesh"]["file"].as<std::string>() == folder / "wheel.stl");
    CHECK(tree["model"].as<std::string>() == folder / "wheel.stl");
    CHECK(tree["bodies"][0]["other"]["file"].as<std::string>() == "missing.stl");
    CHECK(tree["contact"]["damping"]["model"].as<std::string>() == "viscous");
}

TEST_CASE("a coupled run's summary is the rig's steady state for the rig and the observables at "
          "the end for any other model",
          "[study][design]") {
    TempFolder folder("run_summary");
    const auto kindFor = [&](const std::string &name, const std::string &model_section) {
        writeFile(folder / (name + "_base.yaml"),
                  model_section + "soil: {deposition: {seed: 1}}\n");
        writeFile(folder / (name + ".yaml"), "name: " + name + "\nbase: {kind: run, scenario: " +
                                                 name + "_base.yaml}\nobservables: [a.b]\n");
        const Study s = loadStudy(folder / (name + ".yaml"), folder / ("out_" + name));
        REQUIRE(s.points.size() == 1);
        return s.points[0].kind.summary_file;
    };
    CHECK(kindFor("rig", "rig: {normal_load_kg: 2}\n") == "rig_summary.json");
    CHECK(kindFor("mole", "mole: {stroke_period_s: 0.3}\n") == "mbs_summary.json");
    CHECK(kindFor("rover", "rover: {}\n") == "mbs_summary.json");
}
