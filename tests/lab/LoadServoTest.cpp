// Force servo of a body pressed onto the soil, docs/physics.md §12.11.
#include "grainlink/lab/LoadServo.hpp"

#include <catch2/catch.hpp>

#include <cmath>

using namespace grainlink;
using Catch::Matchers::Contains;

namespace {

lab::LoadServo servo(double target_N, double gain, double max_speed, double deadband = 0.0) {
    lab::LoadServo s;
    s.target_force_N = target_N;
    s.gain_m_s_per_N = gain;
    s.max_speed_m_s = max_speed;
    s.deadband_N = deadband;
    s.validate();
    return s;
}

/// Closed loop against a linear soil F = k max(depth, 0): returns the force after each interval.
std::vector<double> pressOnSpring(const lab::LoadServo &s, double k_N_m, double dt_s, int steps,
                                  double start_depth_m = 0.0) {
    double depth = start_depth_m, force = k_N_m * std::max(depth, 0.0);
    std::vector<double> history;
    for (int n = 0; n < steps; ++n) {
        depth += s.approachSpeed(force) * dt_s;
        force = k_N_m * std::max(depth, 0.0);
        history.push_back(force);
    }
    return history;
}

} // namespace

TEST_CASE("Load servo law: proportional, deadband, clamp, sign", "[lab][servo]") {
    // Exact arithmetic on representable numbers: a 1e-12 relative margin is rounding only.
    const auto s = servo(10.0, 1e-3, 0.004, 0.5);
    CHECK(s.approachSpeed(10.0) == 0.0);
    CHECK(s.approachSpeed(10.4) == 0.0); // inside the deadband
    CHECK(s.approachSpeed(9.6) == 0.0);
    CHECK(s.approachSpeed(8.0) == Approx(1e-3 * 1.5).epsilon(1e-12));   // too light: press
    CHECK(s.approachSpeed(12.0) == Approx(-1e-3 * 1.5).epsilon(1e-12)); // too heavy: back off
    CHECK(s.approachSpeed(-100.0) == Approx(0.004).epsilon(1e-12));     // clamped
    CHECK(s.approachSpeed(100.0) == Approx(-0.004).epsilon(1e-12));
    CHECK(s.verticalVelocity(8.0) == Approx(-1.5e-3).epsilon(1e-12)); // pressing down: v_z < 0
    // Continuous at the deadband's edge: just outside it the speed is gain times the excess.
    CHECK(s.approachSpeed(10.0 - 0.5 - 1e-3) == Approx(1e-6).epsilon(1e-9));
}

TEST_CASE("Load servo on a linear spring settles on the target without overshoot", "[lab][servo]") {
    // k gain dt = 0.5: the error halves every interval (e_{n+1} = (1 - k g dt) e_n) once the
    // clamp is left, so 60 intervals leave 2^-50 of it; 1e-9 N is rounding.
    const double k = 2e4, dt = 0.005, target = 20.0;
    const auto s = servo(target, 0.5 / (k * dt), 0.01);
    const auto f = pressOnSpring(s, k, dt, 60);
    for (double x : f)
        CHECK(x <= target * (1.0 + 1e-12)); // monotone approach from below: never above target
    CHECK(f.back() == Approx(target).margin(1e-9));
    // The clamp limits the approach: the first interval moves at most max_speed dt.
    CHECK(f.front() <= k * 0.01 * dt * (1.0 + 1e-12));

    SECTION("with a deadband it stops within the band") {
        const auto banded = servo(target, 0.5 / (k * dt), 0.01, 0.3);
        const double last = pressOnSpring(banded, k, dt, 60).back();
        CHECK(std::abs(last - target) <= 0.3 + 1e-12);
        CHECK(std::abs(last - target) >= 0.3 * 0.5); // it stopped moving, not converged to 0
    }
}

TEST_CASE("Load servo gain beyond 2 / (k dt) oscillates with growing amplitude", "[lab][servo]") {
    // k gain dt = 2.5: e_{n+1} = (1 - 2.5) e_n = -1.5 e_n while the body stays in contact. Start
    // 1 N short of the target, clamp far away: the errors are -1.5^n exactly for five intervals
    // (then the body lifts off, the spring cannot pull). 1e-9 relative is rounding.
    const double k = 2e4, dt = 0.005, target = 20.0;
    const auto s = servo(target, 2.5 / (k * dt), 1e3);
    const auto f = pressOnSpring(s, k, dt, 5, 19.0 / k);
    double expected = 1.0;
    for (double x : f) {
        expected *= -1.5;
        CHECK(target - x == Approx(expected).epsilon(1e-9));
    }
}

TEST_CASE("Load servo against a receding soil: proportional lags by v / gain, the integral "
          "term removes the lag",
          "[lab][servo]") {
    // The soil gives way at v = 5 mm/s: F = k (depth - v t). Proportional control settles at
    // the error v / gain exactly (u = v): 0.005 / 1e-3 = 5 N. With the integral term
    // (k g dt = 0.1, integral time gain / integral_gain = 0.1 s = 20 intervals) the error
    // decays to zero; after 400 intervals 1e-6 N is rounding.
    const double k = 2e4, dt = 0.005, target = 20.0, v = 0.005;
    auto run = [&](lab::LoadServo s, bool integral) {
        double depth = 0.0, force = 0.0;
        for (int n = 1; n <= 400; ++n) {
            depth += (integral ? s.update(force, dt) : s.approachSpeed(force)) * dt;
            force = k * std::max(depth - v * n * dt, 0.0);
        }
        return force;
    };
    auto s = servo(target, 1e-3, 0.05);
    CHECK(target - run(s, false) == Approx(v / 1e-3).epsilon(1e-9));
    s.integral_gain_m_s2_per_N = 1e-3 / 0.1;
    s.validate();
    CHECK(run(s, true) == Approx(target).margin(1e-6));
    // Anti-windup: while clamped (far from the target) the integral does not grow.
    auto clamped = servo(target, 1e-3, 0.001);
    clamped.integral_gain_m_s2_per_N = 1.0;
    CHECK(clamped.update(0.0, dt) == Approx(0.001).epsilon(1e-12));
    CHECK(clamped.integral_m_s == 0.0);
}

TEST_CASE("Load servo input errors name the member", "[lab][servo]") {
    lab::LoadServo s;
    s.target_force_N = 1.0;
    s.gain_m_s_per_N = 0.0;
    s.max_speed_m_s = 0.01;
    CHECK_THROWS_WITH(s.validate(), Contains("gain_m_s_per_N"));
    s.gain_m_s_per_N = 1e-3;
    s.max_speed_m_s = -1.0;
    CHECK_THROWS_WITH(s.validate(), Contains("max_speed_m_s"));
    s.max_speed_m_s = 0.01;
    s.deadband_N = -0.1;
    CHECK_THROWS_WITH(s.validate(), Contains("deadband_N"));
    s.deadband_N = 0.0;
    s.integral_gain_m_s2_per_N = -1.0;
    CHECK_THROWS_WITH(s.validate(), Contains("integral_gain_m_s2_per_N"));
    s.integral_gain_m_s2_per_N = 0.0;
    CHECK_NOTHROW(s.validate());
}
