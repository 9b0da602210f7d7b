// The seed's procedure on the rig: the phases switch on the detected conditions, not on time.
#include "grainlink/mbs/WheelTest.hpp"

#include <catch2/catch.hpp>

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
    CHECK(steady.slip_mean == Approx(0.25).epsilon(1e-9));
    CHECK(steady.slip_std == Approx(0.0).margin(1e-9));
    CHECK(steady.drawbar_pull_mean_N == Approx(-4.0).epsilon(1e-12));
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
    CHECK(after.test.summary() == straight.test.summary());
    CHECK(after.test.steady().slip_std == straight.test.steady().slip_std);
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
