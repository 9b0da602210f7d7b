// The seed's procedure on the rig: the phases switch on the detected conditions, not on time.
#include "grainlink/mbs/WheelTest.hpp"

#include <catch2/catch.hpp>

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
