// The single-wheel rig without soil against analytic motion (tolerances stated per check).
#include "grainlink/mbs/SingleWheelRig.hpp"
#include "Angles.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <unistd.h>

using namespace grainlink::mbs;

namespace {

SingleWheelRigSettings seedRig() {
    SingleWheelRigSettings s; // the seed's Table 1: 250 mm wheel, 8.33 kg, 3 rad/s
    s.wheel.diameter_m = 0.25;
    s.wheel.width_m = 0.1;
    s.start_position_m = Vec3(0.1, 0.05, 0.5);
    return s;
}

} // namespace

TEST_CASE("Rig without soil: free fall and driven rotation are analytic", "[mbs][rig]") {
    SingleWheelRig rig(seedRig());
    REQUIRE(rig.coupledBodies().size() == 1);
    rig.applyWrenches({Wrench{}});
    rig.advanceTo(0.3);
    const auto s = rig.bodyStates()[0];
    // z = z0 - g t² / 2 and v = -g t, to the integrator's accuracy (1e-8 relative): 1e-9 m.
    CHECK(s.position_m.z() == Approx(0.5 - 0.5 * 9.81 * 0.09).margin(1e-9));
    CHECK(s.linear_velocity_m_s.z() == Approx(-9.81 * 0.3).margin(1e-9));
    CHECK(s.position_m.x() == Approx(0.1).margin(1e-12));
    CHECK(s.position_m.y() == Approx(0.05).margin(1e-12));
    // Driven at 3 rad/s: angle 0.9 rad about +y.
    CHECK(s.angular_velocity_rad_s.y() == Approx(3.0).margin(1e-12));
    CHECK(angleAboutY(s.orientation) == Approx(0.9).margin(1e-9));
    const auto o = rig.observables();
    CHECK(o.at("motor_torque_N_m") == Approx(0.0).margin(1e-9));
}

TEST_CASE("Rig: the motor holds the speed against the soil's torque", "[mbs][rig]") {
    SingleWheelRig rig(seedRig());
    Wrench soil;
    soil.torque_N_m = Vec3(0, -5.0, 0); // resists the rolling direction
    rig.applyWrenches({soil});
    rig.advanceTo(0.1);
    const auto o = rig.observables();
    CHECK(o.at("wheel_omega_rad_s") == Approx(3.0).margin(1e-12));
    CHECK(o.at("motor_torque_N_m") == Approx(5.0).epsilon(1e-9));
}

TEST_CASE("Rig: drawbar force, locked rotation and slip control", "[mbs][rig]") {
    auto settings = seedRig();
    settings.drawbar_force_N = 10.0;
    SECTION("the drawbar force decelerates the whole horizontal mass") {
        SingleWheelRig rig(settings);
        rig.applyWrenches({Wrench{}});
        rig.advanceTo(0.2);
        CHECK(rig.bodyStates()[0].linear_velocity_m_s.x() ==
              Approx(-10.0 / 8.33 * 0.2).epsilon(1e-9));
    }
    SECTION("locked rotation keeps the wheel still; unlocking drives it") {
        settings.rotation_locked = true;
        SingleWheelRig rig(settings);
        rig.applyWrenches({Wrench{}});
        rig.advanceTo(0.1);
        CHECK(rig.bodyStates()[0].angular_velocity_rad_s.y() == 0.0);
        CHECK(angleAboutY(rig.bodyStates()[0].orientation) == Approx(0.0).margin(1e-12));
        rig.setRotationLocked(false);
        rig.advanceTo(0.2);
        CHECK(rig.bodyStates()[0].angular_velocity_rad_s.y() == Approx(3.0).margin(1e-12));
        CHECK(angleAboutY(rig.bodyStates()[0].orientation) == Approx(0.3).margin(1e-9));
    }
    SECTION("slip control holds v = ω r (1 - s) and measures the drawbar pull") {
        settings.slip = 0.2;
        SingleWheelRig rig(settings);
        rig.applyWrenches({Wrench{}});
        rig.advanceTo(0.1);
        const auto o = rig.observables();
        CHECK(o.at("carriage_vx_m_s") == Approx(3.0 * 0.125 * 0.8).epsilon(1e-12));
        CHECK(o.at("slip") == Approx(0.2).epsilon(1e-9));
        CHECK(o.at("carriage_drive_force_N") == Approx(10.0).epsilon(1e-9));
    }
}

TEST_CASE("Rig: the work of a constant soil force is force times displacement", "[mbs][rig]") {
    SingleWheelRig rig(seedRig());
    Wrench soil;
    soil.force_N = Vec3(0, 0, 40.0); // pushes up, against the fall
    rig.applyWrenches({soil});
    const double z0 = rig.bodyStates()[0].position_m.z();
    const double work = rig.advanceTo(0.2)[0];
    const double dz = rig.bodyStates()[0].position_m.z() - z0;
    CHECK(work == Approx(40.0 * dz).epsilon(1e-6)); // trapezoid rule on the integrator's steps
}

TEST_CASE("Rig: save/restore and checkpoints continue bit-identically", "[mbs][rig]") {
    auto settings = seedRig();
    settings.rotation_locked = true;
    SingleWheelRig a(settings);
    Wrench soil;
    soil.force_N = Vec3(1.0, 0, 60.0);
    soil.torque_N_m = Vec3(0, -2.0, 0);
    a.applyWrenches({soil});
    a.advanceTo(0.05);
    a.setRotationLocked(false);
    a.advanceTo(0.1);
    a.saveState();
    const std::string path = (std::filesystem::temp_directory_path() /
                              ("grainlink-rig-" + std::to_string(::getpid()) + ".txt"))
                                 .string();
    a.writeCheckpoint(path);
    a.advanceTo(0.2);
    const auto first = a.bodyStates()[0];
    a.restoreState();
    a.advanceTo(0.2);
    CHECK(a.bodyStates()[0].position_m == first.position_m);
    CHECK(a.bodyStates()[0].orientation.coeffs() == first.orientation.coeffs());

    settings.rotation_locked = true; // the checkpoint must restore the unlocked drive
    SingleWheelRig b(settings);
    b.readCheckpoint(path);
    CHECK_FALSE(b.rotationLocked());
    b.advanceTo(0.2);
    CHECK(b.bodyStates()[0].position_m == first.position_m);
    CHECK(b.bodyStates()[0].linear_velocity_m_s == first.linear_velocity_m_s);
    CHECK(b.observables().at("motor_torque_N_m") == a.observables().at("motor_torque_N_m"));
    std::filesystem::remove(path);
}

TEST_CASE("Rig on a slope: the drop holds the carriage where asked, and it slides back once "
          "the drive starts",
          "[mbs][rig]") {
    // Gravity tilted by 20 deg, no soil: a free carriage slides back at g sin 20 deg.
    auto settings = seedRig();
    const double a = 20.0 * M_PI / 180.0;
    settings.gravity_m_s2 = Vec3(-9.81 * std::sin(a), 0, -9.81 * std::cos(a));
    settings.rotation_locked = true;
    SECTION("free (the default): x = x0 - g sin a t^2 / 2 in the drop") {
        SingleWheelRig rig(settings);
        rig.applyWrenches({Wrench{}});
        rig.advanceTo(0.2);
        CHECK(rig.bodyStates()[0].position_m.x() ==
              Approx(0.1 - 0.5 * 9.81 * std::sin(a) * 0.04).margin(1e-9));
    }
    SECTION("held: x stays in the drop, the hold carries m g sin a, and the drive frees it") {
        settings.hold_carriage_in_drop = true;
        SingleWheelRig rig(settings);
        rig.applyWrenches({Wrench{}});
        rig.advanceTo(0.2);
        CHECK(rig.bodyStates()[0].position_m.x() == Approx(0.1).margin(1e-9));
        CHECK(std::abs(rig.observables().at("carriage_drive_force_N")) ==
              Approx(settings.horizontal_mass_kg * 9.81 * std::sin(a)).epsilon(1e-6));
        rig.setRotationLocked(false);
        rig.advanceTo(0.4);
        CHECK(rig.bodyStates()[0].position_m.x() ==
              Approx(0.1 - 0.5 * 9.81 * std::sin(a) * 0.04).margin(1e-9));
    }
}
