// What `grainlink run` adds to a single-wheel rig's steady report from the soil's series
// (apps/CouplingCommands.hpp, addSoilMeasures): the sinkage and the bin's end walls over the
// judged span, and the refusal of a steady state whose push went into the bin's end wall
// (docs/scenario.md, "wheel_test"). The series here are written by hand, so that every figure
// is known; the real soil node writes the same columns (wheel_resume.py checks them).
#include "CouplingCommands.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;

namespace {

const char *kScenario = R"(participants:
  - {name: rig, role: multibody, command: [grainlink, mbs-node]}
  - {name: soil, role: soil, command: [grainlink, dem-node]}
rig:
  wheel: {diameter_m: 0.08, width_m: 0.05}
  wheel_mass_kg: 0.5
  normal_load_kg: 1.0
  start_position_m: [0.1, 0.04, 0.095]
)";

/// A run folder: the rig judged [1.5, 2] s after driving from 1 s (spans of 0.5 s); the soil's
/// series every 10 ms with the wheel 20 mm deep and the end walls at rest (ahead 3 N, behind 2 N)
/// until the drive, then the wall ahead `rise_N` harder over the judged span.
fs::path runFolder(const std::string &name, double drawbar_pull_N, double rise_N,
                   const std::string &extra_scenario = "") {
    const fs::path dir = fs::temp_directory_path() / ("grainlink-rig-summary-" + name);
    fs::remove_all(dir);
    fs::create_directories(dir);
    std::ofstream(dir / "scenario.yaml") << kScenario << extra_scenario;
    nlohmann::json summary = {
        {"steady", true},        {"phase", "steady"},
        {"message", "steady"},   {"drive_start_s", 1.0},
        {"span_s", {1.5, 2.0}},  {"span_length_s", 0.5},
        {"normal_load_N", 9.81}, {"drawbar_pull_N", {{"mean", drawbar_pull_N}, {"sd", 0.5}}}};
    std::ofstream(dir / "rig_summary.json") << summary.dump(2);
    std::ofstream series(dir / "soil.csv");
    series << "time_s,body,sinkage_m,Fx_N,Fy_N,Fz_N,Tx_N_m,Ty_N_m,Tz_N_m,contacts,"
              "end_wall_ahead_N,end_wall_behind_N\n";
    for (int k = 1; k <= 200; ++k) {
        const double t = 0.01 * k;
        const double ahead = 3.0 + (t > 1.5 - 1e-9 ? rise_N : 0.0) + (k % 2 ? 0.1 : -0.1);
        series << t << ",wheel,0.02,0,0,9.81,0,0,0,12," << ahead << ",2\n";
    }
    return dir;
}

nlohmann::json summaryOf(const fs::path &dir) {
    return nlohmann::json::parse(std::ifstream(dir / "rig_summary.json"));
}

bool measures(const fs::path &dir) {
    return grainlink::apps::addSoilMeasures(
        grainlink::config::ConfigNode::loadFile((dir / "scenario.yaml").string()), dir.string());
}

} // namespace

TEST_CASE("a rig's steady report gets the soil's sinkage and end walls, and a wall-bound steady "
          "state is refused",
          "[apps][rig]") {
    // A braked wheel: the soil holds it back with 10 N, so it pushes the soil forward with 10 N,
    // and the wall ahead rises by 8 N: share 8 / max(10, 0.981) = 0.8, over the default 0.5.
    const fs::path braked = runFolder("braked", -10.0, 8.0);
    CHECK_FALSE(measures(braked));
    const auto b = summaryOf(braked);
    CHECK(b["sinkage_m"]["mean"].get<double>() == Approx(0.02));
    CHECK(b["end_wall_ahead_N"]["mean"].get<double>() == Approx(8.0).margin(0.02));
    CHECK(b["end_wall_behind_N"]["mean"].get<double>() == Approx(0.0).margin(1e-9));
    CHECK(b["end_wall_share"].get<double>() == Approx(0.8).margin(0.002));
    CHECK(b["steady"] == false);
    CHECK_THAT(b["message"].get<std::string>(),
               Catch::Contains("took 80 % of the wheel's push") &&
                   Catch::Contains("wheel_test.end_wall_limit = 0.5") &&
                   Catch::Contains(braked.string()));

    // The same with a limit of 0.9 stands, its share reported.
    const fs::path lenient =
        runFolder("lenient", -10.0, 8.0, "wheel_test: {end_wall_limit: 0.9}\n");
    CHECK(measures(lenient));
    CHECK(summaryOf(lenient)["steady"] == true);
    CHECK(summaryOf(lenient)["end_wall_share"].get<double>() == Approx(0.8).margin(0.002));

    // A driven wheel pushes the soil backwards: the wall behind, which did not rise, is judged.
    const fs::path driven = runFolder("driven", 10.0, 8.0);
    CHECK(measures(driven));
    CHECK(summaryOf(driven)["end_wall_share"].get<double>() == Approx(0.0).margin(1e-9));
    CHECK(summaryOf(driven)["steady"] == true);
    for (const auto &dir : {braked, lenient, driven})
        fs::remove_all(dir);
}

TEST_CASE("a mole's strokes get the tip's depth below the bed surface at each stroke's end",
          "[apps][mole]") {
    // Three strokes ending at 0.5, 0.8 and 1.1 s; the soil's series every 10 ms has the tip 20 mm
    // above the surface until 0.2 s, then 100 mm deep plus 2 mm for every stroke begun. Each
    // stroke's depth is the last window that ended within it; penetration (from the start
    // height) stays as the model wrote it.
    const fs::path dir = fs::temp_directory_path() / "grainlink-mole-depths";
    fs::remove_all(dir);
    fs::create_directories(dir);
    std::ofstream(dir / "scenario.yaml")
        << "participants:\n"
           "  - {name: mole, role: multibody, command: [grainlink, mbs-node]}\n"
           "  - {name: soil, role: soil, command: [grainlink, dem-node]}\n"
           "mole: {start_tip_position_m: [0.04, 0.04, 0.17], hull_name: hull, stroke_period_s: "
           "0.3,\n"
           "       cocking_duration_s: 0.1, first_cocking_s: 0.1}\n";
    nlohmann::json strokes = nlohmann::json::array();
    for (int k = 1; k <= 3; ++k)
        strokes.push_back({{"stroke", k}, {"end_time_s", 0.2 + 0.3 * k}, {"penetration_m", 0.1}});
    std::ofstream(dir / "mbs_summary.json") << nlohmann::json{{"strokes", strokes}}.dump(2);
    std::ofstream series(dir / "soil.csv");
    series << "time_s,body,sinkage_m,Fx_N,Fy_N,Fz_N,Tx_N_m,Ty_N_m,Tz_N_m,contacts\n";
    for (int k = 1; k <= 110; ++k) {
        const double t = 0.01 * k;
        // a stroke is released at 0.2, 0.5 and 0.8 s; the window ending at a release is before it
        const int begun = t <= 0.2 + 1e-9 ? 0 : t <= 0.5 + 1e-9 ? 1 : t <= 0.8 + 1e-9 ? 2 : 3;
        series << t << ",hull," << (begun ? 0.1 + 0.002 * begun : -0.02) << ",0,0,1,0,0,0,5\n";
        series << t << ",other,0.5,0,0,1,0,0,0,5\n"; // another body's rows are not the hull's
    }
    series.close();
    CHECK(grainlink::apps::addSoilMeasures(
        grainlink::config::ConfigNode::loadFile((dir / "scenario.yaml").string()), dir.string()));
    const auto s = nlohmann::json::parse(std::ifstream(dir / "mbs_summary.json"));
    REQUIRE(s["strokes"].size() == 3);
    CHECK(s["strokes"][0]["depth_m"].get<double>() == Approx(0.102));
    CHECK(s["strokes"][1]["depth_m"].get<double>() == Approx(0.104));
    CHECK(s["strokes"][2]["depth_m"].get<double>() == Approx(0.106));
    CHECK(s["strokes"][2]["penetration_m"].get<double>() == Approx(0.1));
    CHECK(s["depth_m"].get<double>() == Approx(0.106));
    CHECK(s["depth_before_strokes_m"].get<double>() == Approx(-0.02)); // the first release: 0.2 s
    fs::remove_all(dir);
}

TEST_CASE("a rover's strips get their end walls' push over the run's second half, and a strip "
          "whose wall took the wheels' push refuses the run",
          "[apps][rover]") {
    // Two strips, three wheels each, every 10 ms to 2 s (the second half from 1 s), dropped
    // until 0.4 s. Left: the walls rest at 3 N ahead and 5 N behind and stay there, the wheels
    // pushing the soil 40 N back (Fx = +40 N on them) under 550 N: share 0. Right: its wall
    // ahead rises by 30 N over the second half while the wheels push 20 N forward (Fx = -20 N):
    // share 30 / max(20, 55) = 0.55, over the default limit 0.5.
    const fs::path dir = fs::temp_directory_path() / "grainlink-rover-walls";
    fs::remove_all(dir);
    fs::create_directories(dir);
    std::ofstream(dir / "scenario.yaml")
        << "participants:\n"
           "  - {name: rover, role: multibody, command: [grainlink, mbs-node]}\n"
           "  - {name: soil_left, role: soil, command: [grainlink, dem-node, --section, "
           "soil_left]}\n"
           "  - {name: soil_right, role: soil, command: [grainlink, dem-node, --section, "
           "soil_right]}\n"
           "rover: {start_position_m: [0, 0, 0.5], release_time_s: 0.4}\n";
    std::ofstream(dir / "mbs_summary.json")
        << nlohmann::json{{"time_s", 2.0}, {"second_half_from_s", 1.0}}.dump(2);
    for (const char *side : {"soil_left", "soil_right"}) {
        const bool right = std::string(side) == "soil_right";
        std::ofstream series(dir / (std::string(side) + ".csv"));
        series << "time_s,body,sinkage_m,Fx_N,Fy_N,Fz_N,Tx_N_m,Ty_N_m,Tz_N_m,contacts,"
                  "end_wall_ahead_N,end_wall_behind_N\n";
        for (int k = 1; k <= 200; ++k) {
            const double t = 0.01 * k;
            const double ahead = 3.0 + (right && t > 0.995 ? 30.0 : 0.0);
            for (const char *wheel : {"front", "middle", "rear"})
                series << t << ',' << wheel << ",0.05," << (right ? -20.0 : 40.0) / 3.0 << ",0,"
                       << 550.0 / 3.0 << ",0,0,0,9," << ahead << ",5\n";
        }
    }
    CHECK_FALSE(grainlink::apps::addSoilMeasures(
        grainlink::config::ConfigNode::loadFile((dir / "scenario.yaml").string()), dir.string()));
    const auto s = nlohmann::json::parse(std::ifstream(dir / "mbs_summary.json"));
    CHECK(s["end_walls"]["soil_left"]["share"].get<double>() == Approx(0.0).margin(1e-9));
    CHECK(s["end_walls"]["soil_left"]["push_N"].get<double>() == Approx(-40.0));
    CHECK(s["end_walls"]["soil_right"]["ahead_N"]["mean"].get<double>() == Approx(30.0));
    CHECK(s["end_walls"]["soil_right"]["share"].get<double>() == Approx(30.0 / 55.0));
    CHECK_THAT(s["end_walls_refused"].get<std::string>(),
               Catch::Contains("soil_right's end walls took 55 %") &&
                   Catch::Contains("rover.end_wall_limit = 0.5"));
    fs::remove_all(dir);
}
