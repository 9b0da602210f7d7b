// The seed's procedure on the rig: the phases switch on the detected conditions, not on time.
#include "grainlink/mbs/WheelTest.hpp"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <unistd.h>

using namespace grainlink::mbs;

TEST_CASE("Wheel test: drop until the height is steady, drive until the slip is steady",
          "[mbs][procedure]") {
    // No gravity and a slip-controlled carriage: the wheel keeps its height, so the drop phase
    // ends as soon as drop_min_s and drop_settle_time_s allow, and the slip is the imposed 0.25,
    // so the drive phase ends at the first chance: after max(drive_min_s, 2 steady windows).
    SingleWheelRigSettings rig_settings;
    rig_settings.wheel.diameter_m = 0.25;
    rig_settings.wheel.width_m = 0.1;
    rig_settings.gravity_m_s2 = Vec3::Zero();
    rig_settings.slip = 0.25;
    rig_settings.rotation_locked = true;
    SingleWheelRig rig(rig_settings);
    WheelTestSettings test_settings;
    test_settings.drop_min_s = 0.2;
    test_settings.drop_settle_time_s = 0.1;
    test_settings.drive_min_s = 0.3;
    test_settings.steady_window_s = 0.25;
    WheelTest test(test_settings);
    Wrench soil;
    soil.force_N = Vec3(-4.0, 0, 0);
    rig.applyWrenches({soil});
    double drive_started = -1.0, steady_at = -1.0;
    for (int window = 1; window <= 2000 && steady_at < 0.0; ++window) {
        rig.advanceTo(window * 1e-3);
        const bool done = test.afterWindow(rig, soil);
        if (drive_started < 0.0 && test.phase() == WheelTest::Phase::Drive)
            drive_started = rig.time();
        if (done)
            steady_at = rig.time();
    }
    CHECK(drive_started == Approx(0.2).margin(1.5e-3));
    CHECK(steady_at - drive_started == Approx(0.5).margin(1.5e-3)); // 2 x steady_window_s
    const auto &steady = test.steady();
    REQUIRE(steady.reached);
    CHECK(steady.slip.mean == Approx(0.25).epsilon(1e-9));
    CHECK(steady.slip.sd == Approx(0.0).margin(1e-9));
    CHECK(steady.slip.standard_error == Approx(0.0).margin(1e-9));
    CHECK(steady.drawbar_pull_N.mean == Approx(-4.0).epsilon(1e-12));
    CHECK(steady.slip_drift.per_span == Approx(0.0).margin(1e-9));
    CHECK(steady.span_start_s == Approx(steady_at - 0.5).margin(1.5e-3));
    CHECK(steady.revolutions == Approx(0.5 * 3.0 / (2 * M_PI)).margin(1e-3));
}

namespace {

/// The rig and procedure of the test above (no gravity, slip-controlled carriage, a constant
/// soil force), ready for its first window.
struct Procedure {
    Procedure() : rig(rigSettings()), test(testSettings()) { rig.applyWrenches({soil()}); }
    static SingleWheelRigSettings rigSettings() {
        SingleWheelRigSettings s;
        s.wheel.diameter_m = 0.25;
        s.wheel.width_m = 0.1;
        s.gravity_m_s2 = Vec3::Zero();
        s.slip = 0.25;
        s.rotation_locked = true;
        return s;
    }
    static WheelTestSettings testSettings() {
        WheelTestSettings s;
        s.drop_min_s = 0.2;
        s.drop_settle_time_s = 0.1;
        s.drive_min_s = 0.3;
        s.steady_window_s = 0.25;
        return s;
    }
    static Wrench soil() {
        Wrench w;
        w.force_N = Vec3(-4.0, 0, 0);
        return w;
    }
    /// Windows first..last (1 ms each); the phase after each, "done" once steady.
    std::vector<std::string> run(int first, int last) {
        std::vector<std::string> phases;
        for (int window = first; window <= last; ++window) {
            rig.advanceTo(window * 1e-3);
            phases.push_back(test.afterWindow(rig, soil()) ? "done" : test.phaseName());
        }
        return phases;
    }
    SingleWheelRig rig;
    WheelTest test;
};

} // namespace

TEST_CASE("Wheel test: a resumed procedure goes on as if never stopped", "[mbs][procedure]") {
    // The uninterrupted procedure: drive from about 0.2 s, steady at about 0.7 s.
    Procedure straight;
    const auto expected = straight.run(1, 800);
    REQUIRE(expected[149] == "drop");  // after window 150
    REQUIRE(expected[349] == "drive"); // after window 350
    REQUIRE(expected.back() == "done");
    const std::string dir = (std::filesystem::temp_directory_path() /
                             ("grainlink-test-wheel-" + std::to_string(::getpid())))
                                .string();
    std::filesystem::create_directories(dir);
    // Stopped in the drop (its heights decide when driving begins) or while driving (its
    // phase, start and samples decide when the slip is steady), resumed from a checkpoint of
    // the rig and the procedure in fresh objects: every later window's phase and the report
    // are the uninterrupted run's.
    const int stop = GENERATE(150, 350);
    INFO("stopped after window " << stop);
    Procedure before;
    before.run(1, stop);
    before.rig.writeCheckpoint(dir + "/rig.txt");
    before.test.writeCheckpoint(dir + "/wheel_test.txt");
    Procedure after;
    after.rig.readCheckpoint(dir + "/rig.txt");
    after.test.readCheckpoint(dir + "/wheel_test.txt");
    const auto resumed = after.run(stop + 1, 800);
    CHECK(resumed == std::vector<std::string>(expected.begin() + stop, expected.end()));
    CHECK(after.test.summary(0.8) == straight.test.summary(0.8));
    CHECK(after.test.steady().slip.sd == straight.test.steady().slip.sd);
    CHECK(after.test.steady().time_s == straight.test.steady().time_s);

    // A damaged checkpoint names the file and the line.
    std::ifstream in(dir + "/wheel_test.txt");
    std::vector<std::string> lines;
    for (std::string line; std::getline(in, line);)
        lines.push_back(line);
    REQUIRE(lines.size() == 5);
    const auto error = [&](const std::vector<std::string> &damaged) {
        std::ofstream out(dir + "/bad.txt");
        for (const auto &line : damaged)
            out << line << '\n';
        out.close();
        try {
            WheelTest(Procedure::testSettings()).readCheckpoint(dir + "/bad.txt");
        } catch (const ModelError &e) {
            return std::string(e.what());
        }
        return std::string("no error");
    };
    CHECK(error({lines[0], lines[1], lines[2]}) ==
          dir + "/bad.txt:4: missing the line 'drive_samples ...' (the drive's samples (time "
                "[s], slip, torque [N m], force x [N], force z [N], height [m])): truncated "
                "wheel test checkpoint");
    CHECK(error({"phase coast", lines[1], lines[2], lines[3], lines[4]}) ==
          dir + "/bad.txt:1: unknown phase 'coast' (drop, drive or steady)");
    CHECK(error({"t 0.1", lines[1]}) == dir + "/bad.txt:1: expected 'phase drop|drive|steady', "
                                              "got 't 0.1': not a wheel test checkpoint");
    CHECK(error({lines[0], lines[1], lines[2], lines[3] + " 0.5", lines[4]}).find("bad.txt:4: ") !=
          std::string::npos);
    std::filesystem::remove_all(dir);
}

TEST_CASE("Wheel test: a phase past its maximum fails", "[mbs][procedure]") {
    // Without gravity, a constant upward soil force F accelerates the carriage (normal_load_kg
    // m) at a = F/m: the wheel never settles, so the drop fails at drop_max_s, or, pushed only
    // once driving, its height keeps a trend and the drive fails at drive_max_s. Each report
    // names the phase, how long it ran and what was still changing, by how much: the height
    // moved a/2 (t² - (t - 0.1 s)²) over the last 0.1 s of the drop; the drive's height drift
    // per span is the speed at the judged span's middle times the span, a (t_mid - t_drive) T.
    const std::string dir = (std::filesystem::temp_directory_path() /
                             ("grainlink-test-wheel-max-" + std::to_string(::getpid())))
                                .string();
    std::filesystem::create_directories(dir);
    auto settings = Procedure::testSettings();
    settings.drop_max_s = 0.5;
    settings.drive_max_s = 1.0;
    SingleWheelRig rig(Procedure::rigSettings());
    WheelTest test(settings);
    const double mass = rig.settings().normal_load_kg;
    const bool in_drop = GENERATE(true, false);
    const double force = in_drop ? 2.0 : 0.5;
    Wrench soil = Procedure::soil();
    double end = 0.0, drive_start = 0.0;
    for (int window = 1; window <= 3000; ++window) {
        if (in_drop || test.phase() == WheelTest::Phase::Drive)
            soil.force_N.z() = force;
        rig.applyWrenches({soil});
        rig.advanceTo(window * 1e-3);
        if (test.afterWindow(rig, soil)) {
            end = rig.time();
            break;
        }
        if (drive_start == 0.0 && test.phase() == WheelTest::Phase::Drive)
            drive_start = rig.time();
    }
    REQUIRE(test.failed());
    REQUIRE_FALSE(test.steady().reached);
    const double a = force / mass;
    const std::string summary = test.summary(end);
    INFO(summary);
    if (in_drop) {
        CHECK(end == Approx(0.501).margin(1e-9));
        CHECK(test.phaseName() == "drop");
        char expected[200];
        std::snprintf(expected, sizeof expected, "%.3g mm over the last 0.1 s",
                      1e3 * 0.5 * a * (end * end - (end - 0.1) * (end - 0.1)));
        CHECK(summary.rfind("wheel test: no steady state: the drop phase ran 0.501 s "
                            "(wheel_test.drop_max_s = 0.5 s) and the wheel still moved ",
                            0) == 0);
        CHECK(summary.find(expected) != std::string::npos);
    } else {
        CHECK(end - drive_start == Approx(1.001).margin(1e-9));
        CHECK(test.phaseName() == "drive");
        CHECK(summary.rfind("wheel test: no steady state: the drive phase ran 1 s "
                            "(wheel_test.drive_max_s = 1 s) without a steady state; still "
                            "changing: slip by +0 +- ",
                            0) == 0);
        CHECK(summary.find(" per 0.25 s (tolerance 0.02), height by +") != std::string::npos);
        CHECK(summary.find("(tolerance 2 mm, a trend unlike zero)") != std::string::npos);
        const auto &drift = test.steady().height_drift_m;
        const double middle = 0.5 * (test.steady().span_start_s + end);
        CHECK(drift.per_span == Approx(a * (middle - drive_start) * 0.25).epsilon(0.02));
        CHECK_FALSE(drift.consistent_with_zero);
    }
    // The JSON summary says the same for a script: not steady, the phase, the message.
    test.writeSummaryJson(dir + "/rig_summary.json", end, 0.0);
    const auto json = nlohmann::json::parse(std::ifstream(dir + "/rig_summary.json"));
    CHECK(json["steady"] == false);
    CHECK(json["phase"] == test.phaseName());
    CHECK(json["message"] == summary);
    CHECK(json.contains("slip") == !in_drop);
    std::filesystem::remove_all(dir);
}

TEST_CASE("Wheel test: the JSON summary of a steady run", "[mbs][procedure]") {
    // The first test's run: slip 0.25 imposed, drawbar pull -4 N, steady at once; every value
    // with its fluctuation and standard error, the drift with its uncertainty.
    Procedure p;
    p.run(1, 800);
    REQUIRE(p.test.steady().reached);
    const std::string path = (std::filesystem::temp_directory_path() /
                              ("grainlink-rig-summary-" + std::to_string(::getpid()) + ".json"))
                                 .string();
    p.test.writeSummaryJson(path, 0.8, 81.7);
    const auto json = nlohmann::json::parse(std::ifstream(path));
    std::filesystem::remove(path);
    CHECK(json["steady"] == true);
    CHECK(json["phase"] == "steady");
    CHECK(json["normal_load_N"].get<double>() == 81.7);
    CHECK(json["slip"]["mean"].get<double>() == Approx(0.25));
    CHECK(json["drawbar_pull_N"]["mean"].get<double>() == Approx(-4.0));
    CHECK(json["drawbar_pull_N"]["standard_error"].get<double>() == Approx(0.0).margin(1e-12));
    for (const char *key : {"motor_torque_N_m", "vertical_force_N", "wheel_z_m"})
        CHECK(json[key].contains("sd"));
    CHECK(json["drift"]["slip"]["consistent_with_zero"] == true);
    CHECK(json["span_s"][1].get<double>() - json["span_s"][0].get<double>() ==
          Approx(0.5).margin(1.5e-3));
}

TEST_CASE("Wheel test: settings that cannot work are refused", "[mbs][procedure]") {
    using grainlink::config::ConfigNode;
    const auto message = [](const std::string &text) {
        try {
            parseWheelTest(ConfigNode::loadString(text, "w.yaml")["wheel_test"]);
        } catch (const std::exception &e) {
            return std::string(e.what());
        }
        return std::string("accepted");
    };
    CHECK(message("wheel_test:\n  drop_min_s: 1.0\n  drop_max_s: 0.5\n") ==
          "w.yaml:3: key 'wheel_test.drop_max_s': drop_max_s = 0.500000 s is not above "
          "drop_min_s = 1.000000 s");
    // The default maximum (20 s) below a long minimum: the minimum is named.
    CHECK(message("wheel_test:\n  drive_min_s: 30\n") ==
          "w.yaml:2: key 'wheel_test.drive_min_s': drive_max_s = 20.000000 s is not above "
          "drive_min_s = 30.000000 s");
    CHECK(message("wheel_test:\n  drive_min_s: 30\n  run_until: end_time\n") == "accepted");
    CHECK(message("wheel_test:\n  run_until: forever\n") ==
          "w.yaml:2: key 'wheel_test.run_until': 'forever' is not steady or end_time");
}
