// The rocker-bogie rover (docs/physics.md §9) on a penalty ground that the test computes from
// the wheel states every window and hands over through applyWrenches — the interface the soil
// uses. Tolerances and their reasons are stated per check.
#include "grainlink/mbs/RockerBogie.hpp"
#include "Angles.hpp"

#include <catch2/catch.hpp>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <unistd.h>

using namespace grainlink::mbs;
using Part = RockerBogie::Part;

namespace {

/// Flat penalty ground: the plane z = height[i] under wheel i. At the wheel's lowest point c =
/// centre - r ẑ, depth δ = h - c_z: N = max(0, k δ - c_n v_z) upward; tangential either viscous
/// (-c_t v_t, which vanishes at rest) or regularized Coulomb (-μ N tanh(|v_t| / v_reg) v_t /
/// |v_t|).
struct PenaltyGround {
    double stiffness_N_m = 2e5;
    double damping_N_s_m = 2000.0;
    double tangential_damping_N_s_m = 2000.0; ///< used when friction_coefficient is 0
    double friction_coefficient = 0.0;
    double regularization_m_s = 0.02;
    std::array<double, 6> height_m{};
    std::array<double, 6> normal_N{}; ///< the last normal forces

    std::vector<Wrench> wrenches(const RockerBogie &rover) {
        const double r = rover.wheelRadius_m();
        const auto states = rover.bodyStates();
        std::vector<Wrench> out(states.size());
        for (std::size_t i = 0; i < states.size(); ++i) {
            const auto &s = states[i];
            const Vec3 arm(0, 0, -r);
            const Vec3 c = s.position_m + arm;
            const Vec3 v = s.linear_velocity_m_s + s.angular_velocity_rad_s.cross(arm);
            const double depth = height_m[i] - c.z();
            normal_N[i] =
                depth > 0 ? std::max(0.0, stiffness_N_m * depth - damping_N_s_m * v.z()) : 0.0;
            Vec3 f(0, 0, normal_N[i]);
            const Vec3 vt(v.x(), v.y(), 0.0);
            if (normal_N[i] > 0) {
                if (friction_coefficient > 0) {
                    const double speed = vt.norm();
                    if (speed > 0)
                        f -= friction_coefficient * normal_N[i] *
                             std::tanh(speed / regularization_m_s) / speed * vt;
                } else {
                    f -= tangential_damping_N_s_m * vt;
                }
            }
            out[i].force_N = f;
            out[i].torque_N_m = arm.cross(f);
        }
        return out;
    }

    void run(RockerBogie &rover, double until_s, double window_s = 5e-4) {
        while (rover.time() < until_s - 1e-12) {
            rover.applyWrenches(wrenches(rover));
            rover.advanceTo(rover.time() + window_s);
        }
    }
};

Vec3 mirror(const Vec3 &v, int side) {
    return side == 0 ? v : Vec3(v.x(), -v.y(), v.z());
}

/// The hand calculation of docs/physics.md §9.2: six vertical wheel loads from statics with the
/// settled positions (levers measured horizontally, across each pin axis).
std::array<double, 6> handLoads(const RockerBogie &rover) {
    const auto &s = rover.settings();
    const double g = s.gravity_m_s2.norm();
    const auto wheels = rover.bodyStates();
    const auto chassis = rover.partState(Part::Chassis);
    const Vec3 chassis_com = chassis.position_m + chassis.orientation * s.chassis_com_m;
    Eigen::Matrix<double, 6, 6> a = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
    // Row 0: Σ N = M g. Row 1: moments about the world x axis, Σ N y = g Σ m y.
    b(0) = rover.totalMass_kg() * g;
    b(1) = s.chassis_mass_kg * g * chassis_com.y();
    for (int i = 0; i < 6; ++i) {
        a(0, i) = 1.0;
        a(1, i) = wheels[i].position_m.y();
        b(1) += s.wheel_mass_kg * g * wheels[i].position_m.y();
    }
    for (int side = 0; side < 2; ++side) {
        const auto rocker = rover.partState(side == 0 ? Part::LeftRocker : Part::RightRocker);
        const auto bogie = rover.partState(side == 0 ? Part::LeftBogie : Part::RightBogie);
        const Vec3 pivot = mirror(s.rocker_pivot_m, side),
                   bogie_pivot = mirror(s.bogie_pivot_m, side);
        const Vec3 rocker_com =
            rocker.position_m + rocker.orientation * (mirror(s.rocker_com_m, side) - pivot);
        const Vec3 bogie_com =
            bogie.position_m + bogie.orientation * (mirror(s.bogie_com_m, side) - bogie_pivot);
        b(1) += g * (s.rocker_mass_kg * rocker_com.y() + s.bogie_mass_kg * bogie_com.y());
        // Horizontal direction across the pin axis: e = (axis × ẑ) / |axis × ẑ|.
        const Vec3 e = (rocker.orientation * Vec3::UnitY()).cross(Vec3::UnitZ()).normalized();
        auto lever = [&](const Vec3 &x, const Vec3 &p) { return (x - p).dot(e); };
        const int f = 3 * side, m = f + 1, r = f + 2;
        // Bogie about its pivot: N_m l_m + N_r l_r = g (m_w l_m + m_w l_r + m_b l_b).
        const Vec3 &pb = bogie.position_m;
        for (int i : {m, r}) {
            a(2 + side, i) = lever(wheels[i].position_m, pb);
            b(2 + side) += g * s.wheel_mass_kg * lever(wheels[i].position_m, pb);
        }
        b(2 + side) += g * s.bogie_mass_kg * lever(bogie_com, pb);
        // Rocker side about its pivot, with half the chassis' moment through the differential.
        const Vec3 &pr = rocker.position_m;
        for (int i : {f, m, r}) {
            a(4 + side, i) = lever(wheels[i].position_m, pr);
            b(4 + side) += g * s.wheel_mass_kg * lever(wheels[i].position_m, pr);
        }
        b(4 + side) +=
            g * (s.rocker_mass_kg * lever(rocker_com, pr) + s.bogie_mass_kg * lever(bogie_com, pr) +
                 0.5 * s.chassis_mass_kg * lever(chassis_com, pr));
    }
    const Eigen::Matrix<double, 6, 1> n = a.fullPivLu().solve(b);
    std::array<double, 6> out{};
    for (int i = 0; i < 6; ++i)
        out[i] = n(i);
    return out;
}

/// The paper calculation of docs/physics.md §9.2 with the nominal geometry (zero joint angles,
/// all wheel centres at one height and the left ones at one y): per side, the bogie about its
/// pivot, the side about the rocker pivot with half the chassis' moment, and the side total
/// from the roll balance.
std::array<double, 6> paperLoads(const RockerBogieSettings &s) {
    const double g = s.gravity_m_s2.norm();
    const double weight =
        g * (s.chassis_mass_kg + 2 * (s.rocker_mass_kg + s.bogie_mass_kg) + 6 * s.wheel_mass_kg);
    const double yw = s.front_wheel_m.y();
    // (T_L - T_R) y_w = m_c g y_c; the rockers, bogies and wheels are mirrored and cancel.
    const double imbalance = s.chassis_mass_kg * g * s.chassis_com_m.y() / yw;
    std::array<double, 6> out{};
    for (int side = 0; side < 2; ++side) {
        const double total = 0.5 * (weight + (side == 0 ? imbalance : -imbalance));
        const double xp = s.rocker_pivot_m.x(), xb = s.bogie_pivot_m.x();
        const double ef = s.front_wheel_m.x() - xp, em = s.middle_wheel_m.x() - xp,
                     er = s.rear_wheel_m.x() - xp;
        const double dm = s.middle_wheel_m.x() - xb, dr = s.rear_wheel_m.x() - xb;
        Eigen::Matrix3d a;
        a << 1, 1, 1,  //
            0, dm, dr, //
            ef, em, er;
        const Eigen::Vector3d b(
            total, g * (s.wheel_mass_kg * (dm + dr) + s.bogie_mass_kg * (s.bogie_com_m.x() - xb)),
            g * (s.wheel_mass_kg * (ef + em + er) + s.rocker_mass_kg * (s.rocker_com_m.x() - xp) +
                 s.bogie_mass_kg * (s.bogie_com_m.x() - xp) +
                 0.5 * s.chassis_mass_kg * (s.chassis_com_m.x() - xp)));
        const Eigen::Vector3d n = a.fullPivLu().solve(b);
        for (int k = 0; k < 3; ++k)
            out[3 * side + k] = n(k);
    }
    return out;
}

RockerBogieSettings resting() {
    RockerBogieSettings s; // the defaults: ExoMars-class, Mars gravity, wheels touching z = 0
    s.rotation_locked = true;
    return s;
}

double pitchOf(const Quat &q) { // body-fixed z-y-x pitch (nose-down positive)
    const Vec3 x = q * Vec3::UnitX();
    return std::asin(std::clamp(-x.z(), -1.0, 1.0));
}

/// Angle about y of a rotation that is a pure rotation about y.
std::vector<double> flatten(const RockerBogie &rover) {
    std::vector<double> out{rover.time()};
    auto add = [&](const RigidState &s) {
        for (int k = 0; k < 3; ++k)
            out.insert(out.end(), {s.position_m[k], s.linear_velocity_m_s[k],
                                   s.angular_velocity_rad_s[k], s.orientation.coeffs()[k]});
        out.push_back(s.orientation.w());
    };
    for (const auto &s : rover.bodyStates())
        add(s);
    add(rover.chassisState());
    for (const auto &[name, value] : rover.observables())
        out.push_back(value);
    return out;
}

} // namespace

TEST_CASE("Rocker-bogie: static wheel loads on flat ground match the hand calculation",
          "[mbs][rover][slow]") {
    auto settings = resting();
    SECTION("default rover") {}
    SECTION("chassis centre of mass forward and to the left") {
        settings.chassis_com_m = Vec3(0.15, 0.05, 0.1);
    }
    RockerBogie rover(settings);
    REQUIRE(rover.coupledBodies().size() == 6);
    CHECK(rover.coupledBodies()[0].name == "wheel_lf");
    CHECK(rover.coupledBodies()[5].name == "wheel_rr");
    CHECK(rover.totalMass_kg() == Approx(300.0).epsilon(1e-12));
    PenaltyGround ground;
    ground.run(rover, 1.0);
    const auto paper = paperLoads(settings);
    const auto hand = handLoads(rover);
    const double weight = rover.totalMass_kg() * 3.71;
    double sum = 0.0;
    for (int i = 0; i < 6; ++i) {
        CAPTURE(i, ground.normal_N[i], paper[i], hand[i]);
        // Against the paper calculation with the nominal geometry: the ground's deflections
        // (N/k ≈ 0.7-1.3 mm, different per wheel) tilt the chassis and move the levers by about
        // 0.1 m × 1e-3 = 0.1 mm of 650 mm: 0.2 % leaves a margin over that.
        CHECK(ground.normal_N[i] == Approx(paper[i]).epsilon(2e-3));
        // The same statics with the settled positions are exact; what is left is the damped
        // residual motion after 1 s (damper forces ~1e-6 N): 1e-5.
        CHECK(ground.normal_N[i] == Approx(hand[i]).epsilon(1e-5));
        sum += ground.normal_N[i];
    }
    // Σ N = m g at rest (same residual): 1e-5.
    CHECK(sum == Approx(weight).epsilon(1e-5));
    // The differential carries half the chassis' weight moment to each rocker (about +y).
    const auto chassis = rover.partState(Part::Chassis);
    const auto rocker = rover.partState(Part::LeftRocker);
    const double lever =
        (chassis.position_m + chassis.orientation * settings.chassis_com_m - rocker.position_m)
            .dot(Vec3::UnitX());
    CHECK(rover.observables().at("differential_torque_N_m") ==
          Approx(0.5 * settings.chassis_mass_kg * 3.71 * lever).margin(0.01));
}

TEST_CASE("Rocker-bogie: the differential splits a raised front wheel between the rockers",
          "[mbs][rover][slow]") {
    RockerBogie rover(resting());
    PenaltyGround ground;
    // The ground under the left front wheel rises to a 60 mm step over 0.4 s, then holds.
    const double step = 0.06;
    while (rover.time() < 1.2 - 1e-12) {
        ground.height_m[RockerBogie::LeftFront] = step * std::min(1.0, rover.time() / 0.4);
        rover.applyWrenches(ground.wrenches(rover));
        rover.advanceTo(rover.time() + 5e-4);
    }
    const auto o = rover.observables();
    const double ql = o.at("rocker_left_rad"), qr = o.at("rocker_right_rad");
    // Simbody holds q_left + q_right = 0 to its accuracy (1e-8): 1e-7 rad.
    CHECK(ql + qr == Approx(0.0).margin(1e-7));
    // The left rocker turns nose-up about its bogie pivot (the bogie stays on the ground) by ψ,
    // 0.975 sin ψ + 0.1575 (1 - cos ψ) = 0.06 with the default lever arms (ψ = 0.06115 rad);
    // the differential gives half of it to each rocker relative to the chassis. Tolerance 2 %:
    // the wheels' deflections differ by up to 0.6 mm of the 60 mm step (1 %), and the chassis
    // roll (≈ 0.02 rad) shortens the step seen in the rocker plane by cos(roll) (2e-4).
    const double dx = 0.65 + 0.325, dz = 0.3075 - 0.15;
    double psi = step / dx;
    for (int it = 0; it < 50; ++it) // Newton on dx sin ψ + dz (1 - cos ψ) = step
        psi -= (dx * std::sin(psi) + dz * (1 - std::cos(psi)) - step) /
               (dx * std::cos(psi) + dz * std::sin(psi));
    CHECK(ql == Approx(-psi / 2).epsilon(0.02));
    CHECK(qr == Approx(psi / 2).epsilon(0.02));
    // The rocker bodies turned by exactly q about the chassis' y axis (1e-12: round-off).
    const auto chassis = rover.partState(Part::Chassis);
    const auto left = rover.partState(Part::LeftRocker), right = rover.partState(Part::RightRocker);
    CHECK(angleAboutY(chassis.orientation.conjugate() * left.orientation) ==
          Approx(ql).margin(1e-12));
    CHECK(angleAboutY(chassis.orientation.conjugate() * right.orientation) ==
          Approx(qr).margin(1e-12));
    // In the world the chassis pitch is the mean of the rocker pitches. With the chassis rolled
    // by φ ≈ 0.02 rad, each rocker's world pitch is θ ± q cos φ to first order, off by
    // q (1 - cos φ) ≈ 6e-6 rad, which cancels in the mean as q_left = -q_right: 1e-6 rad.
    CHECK(o.at("chassis_pitch_rad") ==
          Approx(0.5 * (pitchOf(left.orientation) + pitchOf(right.orientation))).margin(1e-6));
    CHECK(o.at("chassis_pitch_rad") == Approx(-psi / 2).epsilon(0.02));
    // The loads still sum to m g (1e-5, the residual motion) and still follow the statics with
    // the settled positions (1e-5).
    const auto hand = handLoads(rover);
    double sum = 0.0;
    for (int i = 0; i < 6; ++i) {
        CAPTURE(i, ground.normal_N[i], hand[i]);
        CHECK(ground.normal_N[i] == Approx(hand[i]).epsilon(1e-5));
        sum += ground.normal_N[i];
    }
    CHECK(sum == Approx(rover.totalMass_kg() * 3.71).epsilon(1e-5));
}

TEST_CASE("Rocker-bogie: driven wheels hold their speed and climb a slope", "[mbs][rover][slow]") {
    // A 10° slope: the ground stays z = 0 and gravity tilts backwards, g (-sin α, 0, -cos α).
    const double alpha = 10.0 * SimTK::Pi / 180.0, g = 3.71;
    auto settings = resting();
    settings.gravity_m_s2 = Vec3(-g * std::sin(alpha), 0.0, -g * std::cos(alpha));
    settings.wheel_speeds_rad_s.fill(1.0);
    RockerBogie rover(settings);
    PenaltyGround ground;
    ground.friction_coefficient = 0.6;
    // Every wheel moves with the chassis at one slip velocity v_s, so each carries the same
    // F_t / N = μ tanh(v_s / v_reg), and Σ F_t / Σ N = tan α: v_s = v_reg atanh(tan α / μ).
    const double creep = ground.regularization_m_s * std::atanh(std::tan(alpha) / 0.6);
    ground.run(rover, 0.5); // settle with the wheels locked: it creeps down the slope at v_s
    // Tolerance 1e-3: the steady state is reached at the rate (Σ μN / v_reg) / m ≈ 400 /s.
    CHECK(rover.chassisState().linear_velocity_m_s.x() == Approx(-creep).epsilon(1e-3));
    rover.setRotationLocked(false);
    ground.run(rover, 2.0);
    const auto o = rover.observables();
    double torque = 0.0;
    for (const auto &suffix : RockerBogie::wheelSuffixes()) {
        // The speed constraint holds ω to the integrator's accuracy: 1e-7 rad/s.
        CHECK(o.at("wheel_" + suffix + "_omega_rad_s") == Approx(1.0).margin(1e-7));
        torque += o.at("wheel_" + suffix + "_motor_torque_N_m");
    }
    // At steady climbing the wheels' traction carries the weight's slope component, and each
    // motor torque balances its traction times r: Σ τ = m g sin α r. Tolerance 1e-3: steady
    // state as above.
    const double r = rover.wheelRadius_m();
    CHECK(torque == Approx(rover.totalMass_kg() * g * std::sin(alpha) * r).epsilon(1e-3));
    // It climbs at ω r less the same slip velocity (0.0061 of 0.1425 m/s); 1e-3 as above.
    CHECK(rover.chassisState().linear_velocity_m_s.x() == Approx(r - creep).epsilon(1e-3));
    // So every wheel slips by v_s / (ω r) = 0.043; the margin is the velocity's 1e-3 over ω r.
    for (const auto &suffix : RockerBogie::wheelSuffixes())
        CHECK(o.at("wheel_" + suffix + "_slip") == Approx(creep / r).margin(1e-3));
}

TEST_CASE("Rocker-bogie: held in the drop, it comes down onto a slope without sliding, released, "
          "it climbs as a free one does",
          "[mbs][rover][slow]") {
    // The 10° slope of the test above; the chassis' horizontal velocity held while locked.
    const double alpha = 10.0 * SimTK::Pi / 180.0, g = 3.71;
    auto settings = resting();
    settings.gravity_m_s2 = Vec3(-g * std::sin(alpha), 0.0, -g * std::cos(alpha));
    settings.wheel_speeds_rad_s.fill(1.0);
    settings.rotation_locked = false;
    settings.release_time_s = 0.5;
    settings.hold_chassis_in_drop = true;
    settings.start_position_m.z() += 0.02; // dropped from 20 mm
    RockerBogie rover(settings);
    CHECK(rover.rotationLocked());
    PenaltyGround ground;
    ground.friction_coefficient = 0.6;
    const Vec3 start = rover.chassisState().position_m;
    ground.run(rover, 0.5);
    // Held, it neither creeps down the slope (free, it creeps at v_s, above) nor sideways; it
    // came down the 20 mm onto its wheels. 1e-9 m: the constraint holds the velocity to the
    // integrator's accuracy.
    const RigidState held = rover.chassisState();
    CHECK(held.linear_velocity_m_s.x() == Approx(0.0).margin(1e-9));
    CHECK(held.position_m.x() == Approx(start.x()).margin(1e-9));
    CHECK(held.position_m.y() == Approx(start.y()).margin(1e-9));
    CHECK(held.position_m.z() < start.z() - 0.015);
    // Released with the wheels at 0.5 s, it climbs at omega r less the slip velocity, as a
    // rover never held does (the test above); 1e-3 as there.
    ground.run(rover, 2.0);
    CHECK_FALSE(rover.rotationLocked());
    const double creep = ground.regularization_m_s * std::atanh(std::tan(alpha) / 0.6);
    CHECK(rover.chassisState().linear_velocity_m_s.x() ==
          Approx(rover.wheelRadius_m() - creep).epsilon(1e-3));
}

TEST_CASE("Rocker-bogie: torque-driven wheels accelerate the rover up the slope", "[mbs][rover][slow]") {
    // The slope of the test above, reached at steady speed with the speed drive; then torque
    // drive with each wheel's steady motor torque plus 10 % of the total shared equally.
    const double alpha = 10.0 * SimTK::Pi / 180.0, g = 3.71;
    auto settings = resting();
    settings.rotation_locked = false;
    settings.gravity_m_s2 = Vec3(-g * std::sin(alpha), 0.0, -g * std::cos(alpha));
    settings.wheel_speeds_rad_s.fill(1.0);
    RockerBogie rover(settings);
    PenaltyGround ground;
    ground.friction_coefficient = 0.6;
    ground.run(rover, 0.8);
    const double r = rover.wheelRadius_m();
    const double total = rover.totalMass_kg() * g * std::sin(alpha) * r;
    std::array<double, 6> torques{};
    auto o = rover.observables();
    for (int i = 0; i < 6; ++i)
        torques[i] = o.at("wheel_" + RockerBogie::wheelSuffixes()[i] + "_motor_torque_N_m") +
                     0.1 * total / 6;
    rover.setDriveTorques(torques);
    o = rover.observables();
    CHECK(o.at("wheel_lf_motor_torque_N_m") == torques[0]);
    ground.run(rover, 1.0); // let the slip settle at the new traction
    const double v0 = rover.chassisState().linear_velocity_m_s.x();
    const double w0 = rover.observables().at("wheel_rm_omega_rad_s");
    ground.run(rover, 1.3);
    // Wheel spin I ω̇ = τ - F_t r and M a = Σ F_t - M g sin α with ω̇ r = a (steady slip):
    // a = (Σ Δτ / r) / (M + 6 I / r²), the thin-ring wheels adding 6 m_w = 18 kg.
    // Tolerance 1e-3: the slip settles at the rate (Σ μ N / v_reg) / M ≈ 400 /s, long before.
    const double a = 0.1 * total / r / (rover.totalMass_kg() + 6 * settings.wheel_mass_kg);
    CHECK((rover.chassisState().linear_velocity_m_s.x() - v0) / 0.3 == Approx(a).epsilon(1e-3));
    CHECK((rover.observables().at("wheel_rm_omega_rad_s") - w0) / 0.3 ==
          Approx(a / r).epsilon(1e-3));
}

TEST_CASE("Rocker-bogie: save/restore and checkpoints continue identically", "[mbs][rover][slow]") {
    auto settings = resting();
    RockerBogie rover(settings);
    PenaltyGround ground;
    ground.friction_coefficient = 0.6;
    ground.run(rover, 0.2);
    rover.setRotationLocked(false);
    rover.setWheelSpeeds({0.5, 0.6, 0.7, 0.5, 0.6, 0.7}); // turns the rover: controller state
    ground.run(rover, 0.3);
    const auto path = std::filesystem::temp_directory_path() /
                      ("grainlink_rover_" + std::to_string(::getpid()) + ".txt");
    rover.saveState();
    rover.writeCheckpoint(path.string());
    ground.run(rover, 0.5);
    const auto reference = flatten(rover);

    SECTION("restoreState") {
        rover.restoreState();
        ground.run(rover, 0.5);
    }
    SECTION("a fresh rover from the checkpoint (built locked at other speeds)") {
        RockerBogie fresh(settings);
        fresh.readCheckpoint(path.string());
        ground.run(fresh, 0.5);
        const auto again = flatten(fresh);
        REQUIRE(again.size() == reference.size());
        for (std::size_t k = 0; k < again.size(); ++k)
            CHECK(again[k] == reference[k]); // bit-identical
    }
    const auto again = flatten(rover);
    REQUIRE(again.size() == reference.size());
    for (std::size_t k = 0; k < again.size(); ++k)
        CHECK(again[k] == reference[k]); // bit-identical (in the fresh section: nothing moved)
    std::filesystem::remove(path);
}

TEST_CASE("Rocker-bogie: the rover block is parsed strictly", "[mbs][rover]") {
    using grainlink::config::ConfigNode;
    const auto ok = ConfigNode::loadString("rover:\n"
                                           "  start_position_m: [1, 2, 0.5]\n"
                                           "  chassis_mass_kg: 200\n"
                                           "  chassis_com_m: [0.1, 0, 0.05]\n"
                                           "  front_wheel_m: [0.7, 0.62, -0.3]\n"
                                           "  wheel: {diameter_m: 0.3, width_m: 0.1}\n"
                                           "  wheel_speed_rad_s: [1, 2, 3, 4, 5, 6]\n"
                                           "  gravity_m_s2: [0, 0, -9.81]\n",
                                           "ok.yaml");
    const auto s = parseRockerBogie(ok["rover"]);
    CHECK(s.start_position_m == Vec3(1, 2, 0.5));
    CHECK(s.chassis_mass_kg == 200.0);
    CHECK(s.chassis_com_m == Vec3(0.1, 0, 0.05));
    CHECK(s.front_wheel_m == Vec3(0.7, 0.62, -0.3));
    CHECK(s.middle_wheel_m == RockerBogieSettings().middle_wheel_m);
    CHECK(s.wheel.diameter_m == 0.3);
    CHECK(s.wheel_speeds_rad_s[5] == 6.0);
    CHECK_FALSE(s.drive_torques_N_m.has_value());
    CHECK(s.gravity_m_s2.z() == -9.81);
    const auto common = ConfigNode::loadString(
        "rover:\n  start_position_m: [0, 0, 1]\n  drive_torque_N_m: 2.5\n", "c.yaml");
    const auto t = parseRockerBogie(common["rover"]);
    REQUIRE(t.drive_torques_N_m.has_value());
    CHECK((*t.drive_torques_N_m)[3] == 2.5);
    CHECK(t.gravity_m_s2.z() == -3.71); // Mars by default

    const auto unknown = ConfigNode::loadString(
        "rover:\n  start_position_m: [0, 0, 1]\n  chassis_mass_g: 3\n", "bad.yaml");
    CHECK_THROWS_WITH(parseRockerBogie(unknown["rover"]),
                      Catch::Contains("bad.yaml:3") && Catch::Contains("chassis_mass_g"));
    const auto five = ConfigNode::loadString(
        "rover:\n  start_position_m: [0, 0, 1]\n  wheel_speed_rad_s: [1, 2, 3, 4, 5]\n",
        "five.yaml");
    CHECK_THROWS_WITH(parseRockerBogie(five["rover"]),
                      Catch::Contains("five.yaml:3") && Catch::Contains("list of 6"));
    const auto drop = ConfigNode::loadString("rover:\n  start_position_m: [0, 0, 1]\n  "
                                             "release_time_s: 0.4\n  hold_chassis_in_drop: true\n",
                                             "drop.yaml");
    const auto d = parseRockerBogie(drop["rover"]);
    CHECK(d.release_time_s == 0.4);
    CHECK(d.hold_chassis_in_drop);
    const auto no_end = ConfigNode::loadString(
        "rover:\n  start_position_m: [0, 0, 1]\n  hold_chassis_in_drop: true\n", "h.yaml");
    CHECK_THROWS_WITH(parseRockerBogie(no_end["rover"]),
                      Catch::Contains("h.yaml:3") && Catch::Contains("release_time_s"));
    const auto both = ConfigNode::loadString("rover:\n  start_position_m: [0, 0, 1]\n  "
                                             "rotation_locked: true\n  release_time_s: 0.4\n",
                                             "b.yaml");
    CHECK_THROWS_WITH(parseRockerBogie(both["rover"]),
                      Catch::Contains("b.yaml:4") && Catch::Contains("rotation_locked"));
    const auto missing = ConfigNode::loadString("rover:\n  chassis_mass_kg: 200\n", "m.yaml");
    CHECK_THROWS_WITH(parseRockerBogie(missing["rover"]), Catch::Contains("start_position_m"));
    RockerBogieSettings bad;
    bad.rocker_inertia_kg_m2 = Vec3(0.1, 0.1, 0.5);
    CHECK_THROWS_WITH(RockerBogie(bad), Catch::Contains("rocker inertia"));
    bad = RockerBogieSettings();
    bad.middle_wheel_m.y() = 0.01;
    CHECK_THROWS_WITH(RockerBogie(bad), Catch::Contains("middle_wheel_m"));
}
