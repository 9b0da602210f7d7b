// A mesh body's motion as a value the DEM evaluates itself (dem/BodyMotion.hpp): the coupling
// window's Hermite path, the scenario's velocity segments, and the DEM applying them at every
// step's end time (docs/physics.md §7.2).
#include "Fixtures.hpp"

#include <catch2/catch.hpp>

using namespace grainlink::dem;
using namespace grainlink::dem::testing;

namespace {

/// Angle of the rotation taking q to r [rad] (q and -q are the same rotation).
double angleBetween(const Quat &q, const Quat &r) {
    return 2.0 * std::acos(std::min(1.0, std::abs(q.normalized().dot(r.normalized()))));
}

/// Two end states far enough apart that any wrong interpolation shows.
WindowMotion sampleWindow() {
    WindowMotion m;
    m.start_s = 1.25;
    m.duration_s = 0.013;
    m.a.position_m = Vec3(0.31, -0.07, 0.115);
    m.a.orientation = Quat(Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized()));
    m.a.linear_velocity_m_s = Vec3(0.2, 0.01, -0.05);
    m.a.angular_velocity_rad_s = Vec3(0.3, 3.1, -0.2);
    m.b.position_m = Vec3(0.3131, -0.0695, 0.1138);
    m.b.orientation = Quat(Eigen::AngleAxisd(1.9, Vec3(-1, 2, 0.5).normalized()));
    m.b.linear_velocity_m_s = Vec3(0.26, 0.03, -0.11);
    m.b.angular_velocity_rad_s = Vec3(0.1, 2.7, 0.4);
    return m;
}

} // namespace

TEST_CASE("window motion: both end states are reproduced exactly", "[dem][motion]") {
    const WindowMotion m = sampleWindow();
    const double end_s = m.start_s + m.duration_s;
    // At the ends and beyond them (held there): exactly the received states.
    for (double t : {m.start_s, m.start_s - 0.5}) {
        const RigidBodyState s = m.at(t);
        CHECK(s.position_m == m.a.position_m);
        CHECK(s.linear_velocity_m_s == m.a.linear_velocity_m_s);
        CHECK(s.angular_velocity_rad_s == m.a.angular_velocity_rad_s);
        CHECK(s.orientation.coeffs() == m.a.orientation.coeffs());
    }
    // Also a clock a rounding away from the end (the DEM's steps against the coupling's ticks).
    for (double t : {end_s, end_s + 0.5, end_s - 1e-12 * m.duration_s}) {
        const RigidBodyState s = m.at(t);
        CHECK(s.position_m == m.b.position_m);
        CHECK(s.linear_velocity_m_s == m.b.linear_velocity_m_s);
        CHECK(s.angular_velocity_rad_s == m.b.angular_velocity_rad_s);
        // slerp may land on -q_b, the same rotation: exact up to the sign.
        CHECK((s.orientation.coeffs() == m.b.orientation.coeffs() ||
               s.orientation.coeffs() == -m.b.orientation.coeffs()));
    }
}

TEST_CASE("window motion: the velocity is the derivative of the Hermite position",
          "[dem][motion]") {
    const WindowMotion m = sampleWindow();
    // Central differences of the position; for a cubic the truncation error is h^2/6 x''' and
    // with h = 1e-5 H both it and the round-off (1e-16 |x| / h) stay below 1e-8 m/s.
    const double h = 1e-5 * m.duration_s;
    double worst = 0.0;
    for (double s : {0.05, 0.2, 0.37, 0.5, 0.81, 0.95}) {
        const double t = m.start_s + s * m.duration_s;
        const Vec3 difference = (m.at(t + h).position_m - m.at(t - h).position_m) / (2.0 * h);
        worst = std::max(worst, (difference - m.at(t).linear_velocity_m_s).norm());
    }
    CHECK(worst < 1e-8);
    // And the path leaves the straight line between the ends (the test has a curve to check).
    const RigidBodyState mid = m.at(m.start_s + 0.5 * m.duration_s);
    CHECK((mid.position_m - 0.5 * (m.a.position_m + m.b.position_m)).norm() > 1e-6);
}

TEST_CASE("window motion: states at one constant velocity give exactly linear motion",
          "[dem][motion]") {
    // Exact but for the round-off of the positions (1e-16 |x|), which the velocity sees over
    // the window: 1e-16 |x| / H = 3e-15 m/s here.
    WindowMotion m = sampleWindow();
    m.b.linear_velocity_m_s = m.a.linear_velocity_m_s;
    m.b.position_m = m.a.position_m + m.duration_s * m.a.linear_velocity_m_s;
    for (double s : {0.1, 0.3, 0.5, 0.7, 0.9}) {
        const double t = m.start_s + s * m.duration_s;
        const RigidBodyState state = m.at(t);
        const Vec3 line = m.a.position_m + (t - m.start_s) * m.a.linear_velocity_m_s;
        CHECK((state.position_m - line).norm() < 1e-15);
        CHECK((state.linear_velocity_m_s - m.a.linear_velocity_m_s).norm() < 1e-13);
    }
}

TEST_CASE("window motion: slerp at constant angular velocity is the analytic rotation",
          "[dem][motion]") {
    // q(t) = exp((t - t0) w) q_a for a constant world-frame w; 1.5 rad over the window, where
    // interpolating the quaternions linearly (nlerp) would be off by about 1e-2 rad.
    WindowMotion m = sampleWindow();
    const Vec3 w = Vec3(0.3, -1.1, 0.6).normalized() * (1.5 / m.duration_s);
    m.a.angular_velocity_rad_s = m.b.angular_velocity_rad_s = w;
    m.b.orientation = rotationFromVector(m.duration_s * w) * m.a.orientation;
    double worst = 0.0;
    for (double s : {0.1, 0.25, 0.5, 0.75, 0.9}) {
        const double t = m.start_s + s * m.duration_s;
        const Quat analytic =
            Quat(Eigen::AngleAxisd(w.norm() * (t - m.start_s), w.normalized())) * m.a.orientation;
        worst = std::max(worst, angleBetween(m.at(t).orientation, analytic));
        CHECK((m.at(t).angular_velocity_rad_s - w).norm() < 1e-12 * w.norm());
    }
    CHECK(worst < 1e-12);
}

TEST_CASE("segmented motion: the pose integrates the velocities, the body rests after the "
          "last segment",
          "[dem][motion]") {
    RigidBodyState start;
    start.position_m = Vec3(0.1, 0.2, 0.3);
    const std::vector<MotionSegment> segments{
        {0.5, Vec3(0.0, 0.0, -0.1), Vec3::Zero()},
        {2.0, Vec3(0.2, 0.0, 0.0), Vec3(0.0, 3.0, 0.0)},
    };
    const SegmentedMotion m{start, 10.0, segments};
    const RigidBodyState first = m.at(10.25);
    CHECK((first.position_m - Vec3(0.1, 0.2, 0.3 - 0.025)).norm() < 1e-15);
    CHECK(first.linear_velocity_m_s == Vec3(0.0, 0.0, -0.1));
    const RigidBodyState second = m.at(11.5);
    CHECK((second.position_m - Vec3(0.1 + 0.2, 0.2, 0.25)).norm() < 1e-15);
    CHECK(angleBetween(second.orientation, Quat(Eigen::AngleAxisd(3.0, Vec3::UnitY()))) < 1e-12);
    CHECK(second.angular_velocity_rad_s == Vec3(0.0, 3.0, 0.0));
    const RigidBodyState after = m.at(20.0);
    CHECK((after.position_m - Vec3(0.1 + 0.4, 0.2, 0.25)).norm() < 1e-15);
    CHECK(after.linear_velocity_m_s == Vec3::Zero());
    CHECK(after.angular_velocity_rad_s == Vec3::Zero());
    // One endless segment is constant velocity.
    start.linear_velocity_m_s = Vec3(1.0, -2.0, 0.5);
    const SegmentedMotion steady = constantVelocity(start, 10.0);
    CHECK(
        (steady.at(13.0).position_m - (start.position_m + 3.0 * start.linear_velocity_m_s)).norm() <
        1e-15);
}

TEST_CASE("the DEM moves a body along its motion at every step's end time", "[dem][motion]") {
    DemSystem sys(hertzRestitution(0.5, 0.5), {soil()}, quietSettings(1e-4));
    sys.particles().add(sphere(Vec3(5, 5, 5), 0.005, 2500.0)); // far away: nothing touches
    const int k = sys.addBody(MeshBody("plate", makeRectangle(0.1, 0.1, 2, 2), {}));
    sys.run(3);
    WindowMotion window = sampleWindow();
    window.start_s = sys.time();
    window.duration_s = 20 * sys.settings().time_step_s;
    sys.setBodyMotion(k, window);
    // Taken at once, then followed step by step (the DEM moves a body to the motion at its
    // time before the step plus dt, which may differ from time() after it by a rounding).
    CHECK(sys.body(k).state().position_m == window.a.position_m);
    for (int step = 0; step < 25; ++step) {
        sys.step();
        const RigidBodyState expected = window.at(sys.time());
        CHECK((sys.body(k).state().position_m - expected.position_m).norm() < 1e-15);
        CHECK((sys.body(k).state().linear_velocity_m_s - expected.linear_velocity_m_s).norm() <
              1e-12);
    }
    CHECK(sys.body(k).state().position_m == window.b.position_m); // held at the window's end
    CHECK_THROWS_WITH(sys.setBodyMotion(3, HeldMotion{}), Catch::Contains("no mesh body 3"));
}
