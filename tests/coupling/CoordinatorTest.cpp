// Coordinator and participants in one test binary, talking over inproc:// and tcp://127.0.0.1:*.
#include "CheckpointFiles.hpp"
#include "CouplingFixtures.hpp"
#include "TwoMassDriver.hpp"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <future>
#include <sstream>
#include <thread>
#include <unistd.h>

using namespace grainlink::coupling;
using grainlink::testing::startSide;
using grainlink::testing::twoMassRun;

namespace {

struct Outcome {
    CoordinatorSummary summary;
    double x1 = 0.0;
};

/// Runs the coordinator here and the two sides on threads.
Outcome runTwoMassNetworked(const CoordinatorConfig &config) {
    Coordinator coordinator(config);
    const std::string endpoint = coordinator.boundEndpoint();
    auto mbs = startSide(Role::Multibody, endpoint);
    auto soil = startSide(Role::Soil, endpoint);
    Outcome out;
    out.summary = coordinator.run();
    out.x1 = mbs.get();
    soil.get();
    return out;
}

} // namespace

TEST_CASE("Networked two-mass runs equal the in-process scheme bit for bit",
          "[coupling][coordinator]") {
    // The transport must not change a single bit: same scheme, same participants' arithmetic.
    for (auto kind :
         {SchemeKind::ExplicitSerial, SchemeKind::ExplicitParallel, SchemeKind::Implicit}) {
        // In the test program's own temporary folder (catch_main.cpp), removed with it.
        const std::string ipc =
            "ipc://" + (std::filesystem::temp_directory_path() / "two-mass.ipc").string();
        for (const std::string &endpoint : {std::string("inproc://two-mass-") + schemeName(kind),
                                            std::string("tcp://127.0.0.1:*"), ipc}) {
            auto config = twoMassRun(kind, endpoint, 0.01, 0.5);
            const auto networked = runTwoMassNetworked(config);
            // The window as the participants see it: a whole number of ticks.
            const double window_s = static_cast<double>(Ticks(10'000'000)) * config.tick_s;
            const auto reference = grainlink::testing::runTwoMass(config.scheme, window_s, 0.5);
            INFO(schemeName(kind) << " over " << endpoint);
            CHECK(networked.summary.windows == 50);
            CHECK(networked.x1 == reference.final_x1_m);
            CHECK(networked.summary.final_states[0].position_m.x() == reference.final_x1_m);
            CHECK(networked.summary.cumulative_mismatch_J ==
                  Approx(reference.work_mismatch_J).margin(1e-15));
            if (kind == SchemeKind::Implicit)
                CHECK(networked.summary.iterations == reference.total_iterations);
        }
    }
}

namespace {

/// A two-mass run of nominal 10 ms windows to 0.5 s whose soil side asks for 2.5 ms steps while
/// 0.1 s <= t < 0.2 s (an impact, say), with adaptive stepping between `min_step_s` and 10 ms.
CoordinatorSummary runWithImpactHints(const std::string &endpoint, double min_step_s,
                                      const std::string &output_directory = "") {
    auto config = twoMassRun(SchemeKind::ExplicitSerial, endpoint, 0.01, 0.5);
    config.min_macro_step_s = min_step_s;
    config.max_macro_step_s = 0.01;
    config.output_directory = output_directory;
    Coordinator coordinator(config);
    grainlink::examples::SideHooks hooks;
    hooks.suggest_step_s = [](double t) { return t >= 0.1 - 1e-12 && t < 0.2 ? 0.0025 : 0.0; };
    auto mbs = startSide(Role::Multibody, coordinator.boundEndpoint());
    auto soil = startSide(Role::Soil, coordinator.boundEndpoint(), hooks);
    const auto summary = coordinator.run();
    mbs.get();
    soil.get();
    return summary;
}

} // namespace

TEST_CASE("Adaptive stepping follows the smallest hint and lands on the end tick exactly",
          "[coupling][coordinator]") {
    // A hint shapes the window after the one it came with, so: windows 0..10 at 10 ms
    // (0 .. 0.11 s; the hint of the window starting at 0.1 s applies from 0.11 s), then 2.5 ms
    // windows while the hints last: 0.11 .. 0.2025 s is 37 windows, then back to 10 ms. The
    // smallest step, 0.5 ms, divides 2.5 ms: the hint is taken as asked.
    const std::string out = (std::filesystem::temp_directory_path() /
                             ("grainlink-adaptive-" + std::to_string(::getpid())))
                                .string();
    const auto summary = runWithImpactHints("inproc://adaptive", 0.0005, out);
    CHECK(summary.end_time_s == 0.5);
    // 11 + 37 windows to 0.2025 s, then 10 ms windows to 0.4925 s (29) and a last 7.5 ms one.
    CHECK(summary.windows == 11 + 37 + 29 + 1);
    std::ifstream csv(out + "/coupling.csv");
    std::string line, last;
    int rows = -1;
    while (std::getline(csv, line)) {
        last = line;
        ++rows;
    }
    CHECK(rows == int(summary.windows));
    CHECK_THAT(last, Catch::StartsWith("77,0.4925"));
    CHECK_THAT(last, Catch::Contains(",0.5,0.0074999"));
    std::filesystem::remove_all(out);
}

TEST_CASE("Adaptive steps are whole multiples of the smallest step", "[coupling][coordinator]") {
    // As above with min_macro_step_s = 1 ms: the 2.5 ms hint becomes 2 ms windows, so that a
    // DEM participant stepping 1 ms (or any divisor) takes each window in whole steps. The
    // hinting windows start at 0.11 .. 0.198 s (45) plus the one they shape after them: 46
    // windows of 2 ms to 0.202 s, then 10 ms windows to 0.492 s (29) and a last 8 ms one.
    const auto summary = runWithImpactHints("inproc://adaptive-whole", 0.001);
    CHECK(summary.end_time_s == 0.5);
    CHECK(summary.windows == 11 + 46 + 29 + 1);
}

TEST_CASE("A failed run resumes from its last checkpoint and ends as if never stopped",
          "[coupling][coordinator][checkpoint]") {
    const std::string base = (std::filesystem::temp_directory_path() /
                              ("grainlink-resume-" + std::to_string(::getpid())))
                                 .string();
    int runs = 0;
    auto run = [&](const std::string &out, bool resume, long fail_at) {
        // A closed inproc endpoint is released asynchronously: a new name for each run.
        const std::string endpoint = "inproc://resume-" + std::to_string(++runs);
        auto config = twoMassRun(SchemeKind::Implicit, endpoint, 0.01, 0.5);
        config.output_directory = out;
        config.checkpoint_every_windows = 10;
        config.resume = resume;
        Coordinator coordinator(config);
        grainlink::examples::SideHooks hooks;
        hooks.fail_at_window = fail_at;
        auto mbs = startSide(Role::Multibody, coordinator.boundEndpoint());
        auto soil = startSide(Role::Soil, coordinator.boundEndpoint(), hooks);
        std::string failure;
        try {
            coordinator.run();
        } catch (const CouplingError &e) {
            failure = e.what();
        }
        for (auto *side : {&mbs, &soil})
            try {
                side->get();
            } catch (const CouplingError &) {
            }
        return failure;
    };
    // Every column but the wall time.
    auto rows = [](const std::string &out) {
        std::ifstream csv(out + "/coupling.csv");
        std::vector<std::string> lines;
        for (std::string line; std::getline(csv, line);) {
            std::vector<std::string> cells;
            std::stringstream ss(line);
            for (std::string cell; std::getline(ss, cell, ',');)
                cells.push_back(cell);
            cells.erase(cells.begin() + 10); // wall_s
            std::string joined;
            for (const auto &c : cells)
                joined += c + ",";
            lines.push_back(joined);
        }
        return lines;
    };
    CHECK(run(base + "/straight", false, -1).empty());
    CHECK_THAT(run(base + "/broken", false, 35),
               Catch::StartsWith("participant 'soil' failed in window 35"));
    std::ifstream latest(base + "/broken/checkpoints/latest");
    std::string name;
    latest >> name;
    CHECK(name == "window_000000030");
    CHECK(rows(base + "/broken").size() >= 31); // rows up to the failure stay readable
    CHECK(run(base + "/broken", true, -1).empty());
    const auto straight = rows(base + "/straight");
    const auto resumed = rows(base + "/broken");
    CHECK(straight.size() == 51);
    CHECK(resumed == straight); // bit-identical: same numbers printed with 17 digits
    std::filesystem::remove_all(base);
}

TEST_CASE("Resume: no checkpoint, an unreadable one or one of other bodies is named",
          "[coupling][coordinator][checkpoint]") {
    namespace fs = std::filesystem;
    const std::string base =
        (fs::temp_directory_path() / ("grainlink-resume-refused-" + std::to_string(::getpid())))
            .string();
    fs::remove_all(base);
    int runs = 0;
    const auto config = [&] {
        auto c = twoMassRun(SchemeKind::ExplicitSerial,
                            "inproc://resume-refused-" + std::to_string(++runs), 0.01, 0.5);
        c.output_directory = base;
        c.checkpoint_every_windows = 10;
        c.resume = true;
        return c;
    };
    const std::string latest = base + "/checkpoints/latest";
    // Refused before anyone joins: no participant is started.
    const auto refusal = [&] {
        Coordinator coordinator(config());
        try {
            coordinator.run();
        } catch (const CouplingError &e) {
            return std::string(e.what());
        }
        return std::string("(ran)");
    };
    CHECK(refusal() == "cannot resume: no complete checkpoint (" + latest + " is missing)");
    const std::string folder = checkpointDirectory(base, 30);
    fs::create_directories(folder);
    std::ofstream(latest) << "window_000000030\n";
    const std::string none_whole = "cannot resume: every checkpoint in " + base +
                                   "/checkpoints is damaged; window_000000030: coordinator.pb is "
                                   "missing or unreadable";
    CHECK(refusal() == none_whole);
    std::ofstream(folder + "/coordinator.pb") << "\xff\xff\xff not protobuf";
    CHECK(refusal() == none_whole);

    // A complete checkpoint of another run, whose body is not this run's: the participants
    // join, are stopped, and the line names the checkpoint and the body.
    BodyState rock;
    rock.body = "rock";
    commitCheckpoint(base, folder, {"other-run", 30, 300'000'000, 10'000'000, {rock}, {}, 0.0});
    Coordinator coordinator(config());
    auto mbs = startSide(Role::Multibody, coordinator.boundEndpoint());
    auto soil = startSide(Role::Soil, coordinator.boundEndpoint());
    std::string failure = "(ran)";
    try {
        coordinator.run();
    } catch (const CouplingError &e) {
        failure = e.what();
    }
    CHECK(failure == "the checkpoint " + folder +
                         " failed during the handshake: state for unknown body 'rock'");
    for (auto *side : {&mbs, &soil})
        CHECK_THROWS_AS(side->get(), CouplingError); // told to stop, not left waiting
    fs::remove_all(base);
}

TEST_CASE("A participant that declares its experiment complete ends the run normally",
          "[coupling][coordinator]") {
    Coordinator coordinator(twoMassRun(SchemeKind::ExplicitSerial, "inproc://complete", 0.01, 1.0));
    grainlink::examples::SideHooks hooks;
    hooks.complete_at_window = 7;
    auto mbs = startSide(Role::Multibody, coordinator.boundEndpoint(), hooks);
    auto soil = startSide(Role::Soil, coordinator.boundEndpoint());
    const auto summary = coordinator.run();
    CHECK(summary.windows == 8);
    CHECK(summary.end_time_s == Approx(0.08).epsilon(1e-12));
    CHECK(summary.completed_by == "mbs");
    CHECK_NOTHROW(mbs.get());
    CHECK_NOTHROW(soil.get());
}

TEST_CASE("A coordinator runs once, a second run() says what to do instead",
          "[coupling][coordinator]") {
    Coordinator coordinator(twoMassRun(SchemeKind::ExplicitSerial, "inproc://once", 0.01, 0.05));
    CHECK(coordinator.state() == Coordinator::State::Bound);
    auto mbs = startSide(Role::Multibody, coordinator.boundEndpoint());
    auto soil = startSide(Role::Soil, coordinator.boundEndpoint());
    CHECK(coordinator.run().windows == 5);
    mbs.get();
    soil.get();
    CHECK(coordinator.state() == Coordinator::State::Finished);
    CHECK_THROWS_WITH(coordinator.run(),
                      "coordinator: run() called in state 'finished'; the run is over and a "
                      "coordinator runs once: construct a new Coordinator for another run");

    auto config = twoMassRun(SchemeKind::ExplicitSerial, "inproc://once-failed", 0.01, 0.05);
    config.handshake_timeout_s = 0.1;
    Coordinator failed(config);
    CHECK_THROWS_AS(failed.run(), CouplingError); // no one joins
    CHECK(failed.state() == Coordinator::State::Failed);
    CHECK_THROWS_AS(failed.run(), LifecycleError);
}
