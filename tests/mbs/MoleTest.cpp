// The HP3 mole's hammer mechanism without soil: stroke energy, momentum, impact speed against
// analytic values, stroke period, hull mesh, checkpoints (tolerances stated per check).
#include "grainlink/mbs/Mole.hpp"

#include <Eigen/Eigenvalues>
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <unistd.h>

using namespace grainlink::mbs;

namespace {

/// Strokes every 0.3 s (cocking 0.1 s, so the first release is at 0.1 s; 0.2 s for the impacts
/// and for the mechanism to settle) so a test sees several in a second and a half.
constexpr double kPeriod = 0.3, kRelease = 0.1;

MoleSettings quickMole() {
    MoleSettings s;
    s.stroke_period_s = kPeriod;
    s.cocking_duration_s = kRelease;
    s.start_tip_position_m = Vec3(0.0, 0.0, 0.5);
    return s;
}

MoleSettings benchMole() { // hull welded to Ground, no gravity, no losses
    MoleSettings s = quickMole();
    s.hull_fixed = true;
    s.gravity_m_s2 = Vec3::Zero();
    s.drive_damping_N_s_m = 0.0;
    s.brake_damping_N_s_m = 0.0;
    s.contact_dissipation_s_m = 0.0;
    return s;
}

std::string tempPath(const std::string &name) {
    return (std::filesystem::temp_directory_path() /
            (name + "-" + std::to_string(::getpid()) + ".txt"))
        .string();
}

/// The hammer (y_h) and suppressor (y_s) of the bench after the release while nothing touches:
/// a linear two-mass oscillator, M ÿ + K y = f, solved exactly by its modes from (y0, v0).
struct TwoMassRelease {
    Eigen::Matrix2d M, K;
    Eigen::Vector2d f, y_static, a, b;
    Eigen::Matrix2d modes;
    Eigen::Vector2d omega;

    TwoMassRelease(const Mole &mole, const Eigen::Vector2d &y0, const Eigen::Vector2d &v0) {
        const auto &s = mole.settings();
        const double k = mole.driveSpringStiffness_N_m(), kb = s.brake_spring_stiffness_N_m;
        const double d0 = s.drive_spring_preload_m, b0 = s.brake_spring_preload_N / kb;
        // Drive spring compression δ0 + y_h - y_s, brake spring compression δb0 + y_s.
        M << s.hammer_mass_kg, 0, 0, s.suppressor_mass_kg;
        K << k, -k, -k, k + kb;
        f << -k * d0, k * d0 - kb * b0;
        y_static = K.ldlt().solve(f);
        Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::Matrix2d> eig(K, M);
        modes = eig.eigenvectors(); // M-orthonormal
        omega = eig.eigenvalues().cwiseSqrt();
        a = modes.transpose() * M * (y0 - y_static);
        b = (modes.transpose() * M * v0).cwiseQuotient(omega);
    }
    Eigen::Vector2d y(double t) const {
        return y_static +
               modes *
                   Eigen::Vector2d(a[0] * std::cos(omega[0] * t) + b[0] * std::sin(omega[0] * t),
                                   a[1] * std::cos(omega[1] * t) + b[1] * std::sin(omega[1] * t));
    }
    Eigen::Vector2d v(double t) const {
        return modes *
               Eigen::Vector2d(
                   omega[0] * (b[0] * std::cos(omega[0] * t) - a[0] * std::sin(omega[0] * t)),
                   omega[1] * (b[1] * std::cos(omega[1] * t) - a[1] * std::sin(omega[1] * t)));
    }
    /// First time t > 0 at which g(t) reaches zero from above: scan, then bisect.
    template <class G> static double firstZero(G g) {
        double t0 = 0.0;
        const double dt = 1e-6;
        while (g(t0 + dt) > 0.0)
            t0 += dt;
        double lo = t0, hi = t0 + dt;
        for (int i = 0; i < 60; ++i) {
            const double mid = 0.5 * (lo + hi);
            (g(mid) > 0.0 ? lo : hi) = mid;
        }
        return 0.5 * (lo + hi);
    }
    /// The hammer's touch on the anvil (y_h = 0): (time, closing speed). The drive spring is
    /// a compression spring: if it goes slack (δ0 + y_h - y_s = 0) first, the hammer flies on
    /// at constant speed from then.
    std::pair<double, double> touch(double drive_preload_m) const {
        const double t_touch = firstZero([&](double t) { return y(t)[0]; });
        const double t_slack =
            firstZero([&](double t) { return drive_preload_m + y(t)[0] - y(t)[1]; });
        if (t_touch <= t_slack)
            return {t_touch, -v(t_touch)[0]};
        const double speed = -v(t_slack)[0];
        return {t_slack + y(t_slack)[0] / speed, speed};
    }
};

} // namespace

TEST_CASE("Mole: the drive spring releases the configured stroke energy", "[mbs][mole]") {
    Mole mole(benchMole());
    const double at_rest = mole.driveSpringEnergy_J();
    mole.advanceTo(kRelease); // the cam has lifted the hammer by cam_lift_m and released it
    REQUIRE(mole.strokeCount() == 1);
    const double cocked = mole.driveSpringEnergy_J();
    const double released = cocked - at_rest;
    std::printf("mole stroke energy: cocked %.6f J, rest %.6f J, released %.6f J (set 0.7)\n",
                cocked, at_rest, released);
    // The rest state differs from the nominal one by the hammer's Hertz indentation of the
    // anvil under the drive preload, (k δ0 / K)^{2/3} ≈ 8 µm, worth k δ0 × 8 µm ≈ 2e-4 J:
    // 1e-3 relative.
    CHECK(released == Approx(0.7).epsilon(1e-3));

    // From the release until the hammer touches the anvil there are no losses (dampers off):
    // the spring energy becomes kinetic energy and the mechanical energy stays constant, to the
    // integrator's accuracy (1e-8 relative per step): 1e-6 relative.
    const double e0 = mole.mechanicalEnergy_J();
    double e_max_error = 0.0;
    double t = kRelease;
    while (std::isnan(mole.lastImpacts().primary_time_s)) {
        t += 1e-4;
        mole.advanceTo(t);
        if (!std::isnan(mole.lastImpacts().primary_time_s))
            break; // the step that reached the anvil: contact losses begin
        e_max_error = std::max(e_max_error, std::abs(mole.mechanicalEnergy_J() - e0));
    }
    std::printf("mole release: energy %.9f J, max drift before touch %.3e J\n", e0, e_max_error);
    CHECK(e_max_error < 1e-6 * e0);
}

TEST_CASE("Mole in free space: momentum is conserved through a stroke, primary impact before "
          "secondary",
          "[mbs][mole]") {
    MoleSettings s = quickMole();
    s.gravity_m_s2 = Vec3::Zero();
    Mole mole(s);
    mole.applyWrenches({Wrench{}});
    // The whole mole starts at rest: its momentum must stay zero (internal forces only).
    double p_max = 0.0, hull_v_max = 0.0;
    for (int i = 1; i <= 300; ++i) { // one period: cocking, release, impacts, rest
        mole.advanceTo(1e-3 * i);
        p_max = std::max(p_max, mole.totalMomentum_kg_m_s().norm());
        hull_v_max = std::max(hull_v_max, std::abs(mole.observables().at("hull_vz_m_s")));
    }
    const auto impacts = mole.lastImpacts();
    std::printf("mole free space: |P| max %.3e kg m/s, hull |vz| max %.4f m/s; primary at "
                "%.6f s (%.4f m/s), secondary at %.6f s (%.4f m/s)\n",
                p_max, hull_v_max, impacts.primary_time_s, impacts.primary_speed_m_s,
                impacts.secondary_time_s, impacts.secondary_speed_m_s);
    // Scale: the hammer's momentum at impact, 0.1 kg × 3.5 m/s ≈ 0.35 kg m/s. Every force is
    // an internal pair and a Runge-Kutta step keeps linear invariants exactly, so only round-off
    // is left (≈ 1e-16 of the scale over ~1e4 steps): 1e-11 kg m/s.
    CHECK(p_max < 1e-11);
    CHECK(hull_v_max > 0.1); // the hull was really thrown about (not a vacuous check)
    CHECK(mole.strokeCount() == 1);
    REQUIRE_FALSE(std::isnan(impacts.primary_time_s));
    REQUIRE_FALSE(std::isnan(impacts.secondary_time_s));
    CHECK(impacts.primary_time_s > kRelease);
    CHECK(impacts.primary_time_s < impacts.secondary_time_s);
    CHECK(impacts.primary_speed_m_s > 1.0);
    CHECK(impacts.secondary_speed_m_s > 0.0);
}

TEST_CASE("Mole with the hull held: hammer impact speed is analytic", "[mbs][mole]") {
    SECTION("free suppressor: v = sqrt(2 E / m_eff), m_eff = m_h (1 + m_h / m_s)") {
        // No drive preload, so a brake spring of 0.01 N holds the suppressor: it moves freely
        // after the release, and the hammer and suppressor share the spring energy with zero
        // total momentum (hull welded, no gravity).
        MoleSettings s = benchMole();
        s.drive_spring_preload_m = 0.0;
        s.brake_spring_preload_N = 0.02;
        s.brake_spring_stiffness_N_m = 1.0;
        // A slow cam: its largest reaction on the suppressor, m_h s 2π / T² = 4.4 mN, stays
        // below the 0.02 N that holds it on its seat (so it is at rest at the release).
        s.cocking_duration_s = 1.0;
        s.stroke_period_s = 2.0;
        Mole mole(s);
        mole.advanceTo(1.01);
        const double mh = s.hammer_mass_kg, ms = s.suppressor_mass_kg;
        const double v = std::sqrt(2 * s.stroke_energy_J / (mh * (1 + mh / ms)));
        const double measured = mole.lastImpacts().primary_speed_m_s;
        std::printf("mole free suppressor: impact %.6f m/s, analytic %.6f m/s\n", measured, v);
        // The brake spring takes ≈ 0.02 N × 1.6 mm ≈ 3e-5 J (5e-5 of E): 1e-4 relative.
        CHECK(measured == Approx(v).epsilon(1e-4));
    }
    SECTION("default mechanism: the exact two-mass solution with drive and brake springs") {
        Mole mole(benchMole());
        mole.advanceTo(kRelease);
        REQUIRE(mole.strokeCount() == 1);
        // The suppressor is pressed ≈ 9 µm into its seat at the release; the seat's Hertz
        // contact pushes it off within ≈ 0.2 ms (an impulse that matters at the 0.2 % level).
        // From the moment it is off, only the two linear springs act: the reference starts there.
        double t0 = kRelease;
        while (mole.suppressorPosition_m() < 0.0) {
            t0 += 2e-6;
            mole.advanceTo(t0);
        }
        REQUIRE(std::isnan(mole.lastImpacts().primary_time_s));
        const Eigen::Vector2d y0(mole.hammerPosition_m(), mole.suppressorPosition_m());
        const Eigen::Vector2d v0(mole.hammerVelocity_m_s(), mole.suppressorVelocity_m_s());
        const TwoMassRelease exact(mole, y0, v0);
        const auto [t_touch, v] = exact.touch(mole.settings().drive_spring_preload_m);
        mole.advanceTo(kRelease + 0.01);
        const auto impacts = mole.lastImpacts();
        std::printf("mole default: suppressor off its seat %.4f ms after the release; impact "
                    "%.6f m/s at %.5f ms, exact %.6f m/s at %.5f ms; free-suppressor estimate "
                    "%.4f m/s\n",
                    1e3 * (t0 - kRelease), impacts.primary_speed_m_s,
                    1e3 * (impacts.primary_time_s - kRelease), v, 1e3 * (t0 + t_touch - kRelease),
                    std::sqrt(2 * 0.7 / (0.1 * (1 + 0.1 / 0.35))));
        // The integrator's accuracy (1e-8 relative) and the touch found from the step before
        // it at constant acceleration (the hammer flies free by then): 1e-5 relative on the
        // speed, 1e-6 s on the time.
        CHECK(impacts.primary_speed_m_s == Approx(v).epsilon(1e-5));
        CHECK(impacts.primary_time_s == Approx(t0 + t_touch).margin(1e-6));
    }
}

TEST_CASE("Mole: the hammer's rebound from the anvil follows Hunt-Crossley", "[mbs][mole]") {
    // Hull held, default losses in the contacts only. The drive spring has gone slack before
    // the hammer reaches the anvil (the suppressor has recoiled by more than the preload), so
    // during the contact only the contact force acts on the hammer. For F = K δ^{3/2}
    // (1 + α δ̇), m δ̈ = -F integrates over a whole contact (δ from 0 back to 0) to
    //   α v_out + ln(1 - α v_out) = -α v_in + ln(1 + α v_in),   α = 3/2 c,
    // whatever K and m are; e = v_out / v_in ≈ 1 - c v_in for small c v_in.
    MoleSettings s = benchMole();
    s.contact_dissipation_s_m = 0.15;
    Mole mole(s);
    mole.advanceTo(kRelease + 0.0031); // just before the touch at ≈ 3.15 ms
    REQUIRE(std::isnan(mole.lastImpacts().primary_time_s));
    double t = mole.time();
    bool touched = false;
    for (int i = 0; i < 5000; ++i) { // step through the contact in 1 µs windows
        t += 1e-6;
        mole.advanceTo(t);
        touched = touched || mole.hammerPosition_m() <= 0.0;
        if (touched && mole.hammerPosition_m() > 0.0)
            break;
    }
    REQUIRE(touched);
    REQUIRE(mole.hammerPosition_m() > 0.0);
    const double v_in = mole.lastImpacts().primary_speed_m_s;
    const double v_out = mole.hammerVelocity_m_s();
    const double alpha = 1.5 * s.contact_dissipation_s_m;
    const double rhs = -alpha * v_in + std::log(1 + alpha * v_in);
    double lo = 0.0, hi = v_in; // solve for v_out: the left side falls monotonically in v_out
    for (int i = 0; i < 80; ++i) {
        const double mid = 0.5 * (lo + hi);
        (alpha * mid + std::log(1 - alpha * mid) > rhs ? lo : hi) = mid;
    }
    const double v_exact = 0.5 * (lo + hi);
    std::printf("mole rebound: v_in %.5f m/s, v_out %.5f m/s (Hunt-Crossley %.5f), e = %.4f "
                "(1 - c v_in = %.4f)\n",
                v_in, v_out, v_exact, v_out / v_in, 1 - s.contact_dissipation_s_m * v_in);
    // After the separation the hammer flies free, so the 1 µs windows do not matter; left are
    // the integrator's accuracy and v_in found from the step before the touch: 1e-4 relative.
    CHECK(v_out == Approx(v_exact).epsilon(1e-4));
}

TEST_CASE("Mole: strokes repeat with the configured period", "[mbs][mole][slow]") {
    MoleSettings s = quickMole();
    s.hull_fixed = true; // Mars gravity, losses on: the mechanism settles between strokes
    Mole mole(s);
    std::vector<double> primary, secondary;
    std::map<Mole::Phase, int> phases;
    bool hint_ok = true;
    for (int i = 1; i <= 1500; ++i) { // five strokes
        mole.advanceTo(1e-3 * i);
        const auto &impacts = mole.lastImpacts();
        if (!std::isnan(impacts.primary_time_s) &&
            (primary.empty() || impacts.primary_time_s != primary.back()))
            primary.push_back(impacts.primary_time_s);
        if (!std::isnan(impacts.secondary_time_s) &&
            (secondary.empty() || impacts.secondary_time_s != secondary.back()))
            secondary.push_back(impacts.secondary_time_s);
        ++phases[mole.phase()];
        // The hint: small in the impact window; otherwise never past the next release.
        const double t = mole.time(), hint = mole.suggestedMacroStep_s();
        const double period_time = std::fmod(t, kPeriod);
        if (mole.phase() == Mole::Phase::Released)
            hint_ok = hint_ok && hint == s.impact_macro_step_s;
        else if (period_time < kRelease)
            hint_ok =
                hint_ok && hint <= std::max(kRelease - period_time, s.impact_macro_step_s) + 1e-12;
    }
    CHECK(mole.strokeCount() == 5);
    REQUIRE(primary.size() == 5);
    REQUIRE(secondary.size() == 5);
    double worst_primary = 0.0, worst_secondary = 0.0;
    for (std::size_t k = 1; k < primary.size(); ++k) {
        worst_primary = std::max(worst_primary, std::abs(primary[k] - primary[k - 1] - kPeriod));
        worst_secondary =
            std::max(worst_secondary, std::abs(secondary[k] - secondary[k - 1] - kPeriod));
    }
    std::printf("mole period: primary at %.6f %.6f %.6f %.6f %.6f s, secondary %.6f ... %.6f s; "
                "worst period error %.3e s (primary), %.3e s (secondary)\n",
                primary[0], primary[1], primary[2], primary[3], primary[4], secondary[0],
                secondary[4], worst_primary, worst_secondary);
    // Releases are at fixed times; the impacts follow them by flight times that vary only with
    // what is left of the previous stroke's motion (the suppressor still bouncing on its seat
    // by micrometres): 2e-5 s for the primary (hammer flight ≈ 3.2 ms) and 2e-4 s for the
    // secondary (suppressor flight ≈ 30 ms), i.e. 1e-4 and 1e-3 of the period.
    CHECK(worst_primary < 2e-5);
    CHECK(worst_secondary < 2e-4);
    CHECK(primary[0] > kRelease);
    CHECK(phases[Mole::Phase::Cocking] > 0);
    CHECK(phases[Mole::Phase::Released] > 0);
    CHECK(phases[Mole::Phase::Resting] > 0);
    CHECK(hint_ok);
}

TEST_CASE("Mole strokes from a run's windows: span, advance, peak and mean hull force by hand",
          "[mbs][mole]") {
    // Two windows resting, then stroke 1 over two windows, stroke 2 over two. Stroke 1 spans
    // 0.2-0.4 s and advances from the rest penetration 20 mm; its impulse is 10 N x 0.1 s +
    // 2 N x 0.1 s = 1.2 N s, its mean force 1.2 N s / 0.2 s = 6 N.
    const std::vector<double> t{0.1, 0.2, 0.3, 0.4, 0.5, 0.6};
    const std::vector<double> count{0, 0, 1, 1, 2, 2};
    const std::vector<double> penetration{0.010, 0.020, 0.025, 0.030, 0.031, 0.035};
    const std::vector<double> force{3, 3, 10, 2, 8, 4};
    const auto strokes = moleStrokes(t, count, penetration, force);
    REQUIRE(strokes.size() == 2);
    CHECK(strokes[0].stroke == 1);
    CHECK(strokes[0].end_time_s == Approx(0.4));
    CHECK(strokes[0].penetration_m == Approx(0.030));
    CHECK(strokes[0].advance_m == Approx(0.010));
    CHECK(strokes[0].peak_hull_force_N == Approx(10.0));
    CHECK(strokes[0].hull_impulse_N_s == Approx(1.2));
    CHECK(strokes[0].mean_hull_force_N == Approx(6.0));
    CHECK(strokes[1].stroke == 2);
    CHECK(strokes[1].advance_m == Approx(0.005));
    CHECK(strokes[1].peak_hull_force_N == Approx(8.0));
    CHECK(strokes[1].hull_impulse_N_s == Approx(1.2));
    CHECK(strokes[1].mean_hull_force_N == Approx(6.0));
    CHECK_THROWS_AS(moleStrokes(t, count, penetration, {1.0}), ModelError);
    CHECK(moleStrokes({0.1}, {0}, {0.01}, {3}).empty());
}

TEST_CASE("Mole hull mesh: closed, outward, volume of cylinder plus cone", "[mbs][mole]") {
    const MoleSettings s; // 400 mm × 27 mm, 40 mm tip, 24 facets around
    const MeshShape mesh = moleHullMesh(s);
    std::printf("mole mesh: %zu vertices, %zu triangles\n", mesh.vertices_m.size(),
                mesh.triangles.size());
    CHECK(mesh.triangles.size() >= 200);
    CHECK(mesh.triangles.size() <= 1000);
    // Closed and consistently wound: every directed edge once, its reverse once.
    std::map<std::pair<int, int>, int> edges;
    for (const auto &t : mesh.triangles)
        for (int e = 0; e < 3; ++e)
            ++edges[{t[e], t[(e + 1) % 3]}];
    bool closed = true;
    for (const auto &[edge, count] : edges)
        closed = closed && count == 1 && edges.count({edge.second, edge.first}) == 1;
    CHECK(closed);
    // Outward: side faces point away from the axis, the back cap along +z.
    double volume = 0.0;
    bool outward = true;
    for (const auto &t : mesh.triangles) {
        const Vec3 &a = mesh.vertices_m[t[0]], &b = mesh.vertices_m[t[1]],
                   &c = mesh.vertices_m[t[2]];
        const Vec3 n = (b - a).cross(c - a);
        const Vec3 centre = (a + b + c) / 3.0;
        const bool cap = std::abs(a.z() - s.hull_length_m) < 1e-12 &&
                         std::abs(b.z() - s.hull_length_m) < 1e-12 &&
                         std::abs(c.z() - s.hull_length_m) < 1e-12;
        outward = outward && (cap ? n.z() > 0 : n.dot(Vec3(centre.x(), centre.y(), 0)) > 0);
        volume += a.dot(b.cross(c)) / 6.0;
    }
    CHECK(outward);
    const double R = 0.5 * s.hull_diameter_m, L = s.hull_length_m, tip = s.tip_length_m;
    const int n = static_cast<int>(s.mesh_segments);
    // The polygon's area replaces the circle's: exact for the faceted solid (round-off, 1e-12)
    // and within the faceting error 1 - sin(2π/n) n / 2π (1.1 % at n = 24) of the round one.
    const double polygon = 0.5 * n * R * R * std::sin(2 * M_PI / n);
    const double faceted = polygon * (L - tip) + polygon * tip / 3.0;
    const double round = M_PI * R * R * (L - tip) + M_PI * R * R * tip / 3.0;
    std::printf("mole mesh volume %.6e m^3, faceted %.6e, round %.6e\n", volume, faceted, round);
    CHECK(volume == Approx(faceted).epsilon(1e-12));
    CHECK(volume == Approx(round).epsilon(1.0 - std::sin(2 * M_PI / n) * n / (2 * M_PI) + 1e-6));
    const auto bodies = Mole(quickMole()).coupledBodies();
    REQUIRE(bodies.size() == 1);
    const auto *hull = std::get_if<MeshShape>(&bodies[0].geometry);
    REQUIRE(hull);
    CHECK(hull->triangles.size() == mesh.triangles.size());
}

TEST_CASE("Mole: save/restore and a checkpoint continue identically", "[mbs][mole][slow]") {
    MoleSettings s = quickMole(); // Mars gravity, free hull, a constant soil force
    Wrench soil;
    soil.force_N = Vec3(0.1, 0.0, 2.0);
    Mole a(s);
    a.applyWrenches({soil});
    a.advanceTo(kRelease + 0.0023); // just after the release, hammer in flight
    const std::string path = tempPath("mole-checkpoint");
    a.writeCheckpoint(path);
    a.saveState();
    a.advanceTo(kPeriod + 0.03); // through the impacts into the next cocking
    const auto end_a = a.bodyStates()[0];
    const auto obs_a = a.observables();

    a.restoreState();
    a.advanceTo(kPeriod + 0.03);
    const auto end_restored = a.bodyStates()[0];

    Mole b(s);
    b.readCheckpoint(path);
    std::filesystem::remove(path);
    b.advanceTo(kPeriod + 0.03);
    const auto end_b = b.bodyStates()[0];
    const auto obs_b = b.observables();
    // Same State, same controller, same integrator steps: identical to the last bit.
    CHECK(end_restored.position_m == end_a.position_m);
    CHECK(end_restored.linear_velocity_m_s == end_a.linear_velocity_m_s);
    CHECK(end_b.position_m == end_a.position_m);
    CHECK(end_b.linear_velocity_m_s == end_a.linear_velocity_m_s);
    CHECK(end_b.angular_velocity_rad_s == end_a.angular_velocity_rad_s);
    for (const char *key :
         {"stroke_count", "cam_engaged", "hammer_position_m", "suppressor_position_m",
          "primary_impact_time_s", "primary_impact_speed_m_s", "secondary_impact_speed_m_s"})
        CHECK(obs_b.at(key) == obs_a.at(key));
    CHECK(obs_a.at("stroke_count") == 1.0);
    CHECK(obs_a.at("cam_engaged") == 1.0);
    CHECK(std::abs(obs_a.at("penetration_m")) > 0.0);
}

TEST_CASE("Mole settings: strict parsing names the key and the line", "[mbs][mole]") {
    using grainlink::config::ConfigError;
    using grainlink::config::ConfigNode;
    const auto ok = ConfigNode::loadString("mole:\n"
                                           "  start_tip_position_m: [0, 0, 0.3]\n"
                                           "  stroke_energy_J: 0.5\n"
                                           "  stroke_period_s: 2.0\n"
                                           "  hull_fixed: true\n",
                                           "mole.yaml");
    const MoleSettings s = parseMole(ok["mole"]);
    CHECK(s.stroke_energy_J == 0.5);
    CHECK(s.stroke_period_s == 2.0);
    CHECK(s.hull_fixed);
    CHECK(s.start_tip_position_m.z() == 0.3);
    CHECK(s.gravity_m_s2.z() == -3.71);
    const auto unknown = ConfigNode::loadString(
        "mole:\n  start_tip_position_m: [0, 0, 0.3]\n  stroke_energy_kJ: 0.5\n", "bad.yaml");
    CHECK_THROWS_WITH(parseMole(unknown["mole"]),
                      Catch::Contains("bad.yaml:3") && Catch::Contains("stroke_energy_kJ"));
    const auto negative = ConfigNode::loadString(
        "mole:\n  start_tip_position_m: [0, 0, 0.3]\n  cam_lift_m: -1\n", "neg.yaml");
    CHECK_THROWS_WITH(parseMole(negative["mole"]),
                      Catch::Contains("neg.yaml:3") && Catch::Contains("cam_lift_m"));
    const auto missing = ConfigNode::loadString("mole:\n  stroke_energy_J: 0.5\n", "miss.yaml");
    CHECK_THROWS_WITH(parseMole(missing["mole"]), Catch::Contains("start_tip_position_m"));
    MoleSettings weak = quickMole();
    weak.brake_spring_preload_N = 1.0;
    CHECK_THROWS_WITH(Mole(weak), Catch::Contains("brake_spring_preload_N"));
}
