#include "grainlink/mbs/SingleWheelRig.hpp"

#include "JointFrames.hpp"

#include <cmath>
#include <sstream>

namespace grainlink::mbs {

namespace {

using SimTK::Pi;

SimTK::Body::Rigid massless() {
    return SimTK::Body::Rigid(SimTK::MassProperties(0, SimTK::Vec3(0), SimTK::Inertia(0)));
}

} // namespace

SingleWheelRig::SingleWheelRig(const SingleWheelRigSettings &settings)
    : SimbodyModel(settings.gravity_m_s2, settings.integrator), settings_(settings) {
    const auto &s = settings_;
    const double r = 0.5 * s.wheel.diameter_m;
    if (!(r > 0.0) || !(s.wheel.width_m > 0.0))
        throw ModelError("single-wheel rig: the wheel needs a positive diameter and width");
    if (!(s.wheel_mass_kg > 0.0) || s.normal_load_kg < s.wheel_mass_kg ||
        s.horizontal_mass_kg < s.normal_load_kg)
        throw ModelError("single-wheel rig: need 0 < wheel_mass_kg <= normal_load_kg <= "
                         "horizontal_mass_kg");
    if (s.slip && s.drive_torque_N_m)
        throw ModelError("single-wheel rig: slip control imposes the wheel speed; it cannot be "
                         "combined with a drive torque");
    Vec3 inertia = s.wheel_inertia_kg_m2;
    if (inertia.isZero()) { // a thin ring of the wheel's radius and width
        const double m = s.wheel_mass_kg, w = s.wheel.width_m;
        inertia = Vec3(m * r * r / 2 + m * w * w / 12, m * r * r, m * r * r / 2 + m * w * w / 12);
    }

    // Ground -> carriage (x) -> carriage (z) -> wheel (pin about y).
    SimTK::Body::Rigid carriage_x_body(SimTK::MassProperties(
        s.horizontal_mass_kg - s.normal_load_kg, SimTK::Vec3(0), SimTK::Inertia(0)));
    if (s.horizontal_mass_kg == s.normal_load_kg)
        carriage_x_body = massless();
    carriage_x_ = SimTK::MobilizedBody::Slider(
        matter_.Ground(), SimTK::Transform(SimTK::Vec3(0, s.start_position_m.y(), 0)),
        carriage_x_body, SimTK::Transform());
    SimTK::Body::Rigid carriage_z_body = massless();
    if (s.normal_load_kg > s.wheel_mass_kg)
        carriage_z_body = SimTK::Body::Rigid(SimTK::MassProperties(
            s.normal_load_kg - s.wheel_mass_kg, SimTK::Vec3(0), SimTK::Inertia(0)));
    carriage_z_ = SimTK::MobilizedBody::Slider(carriage_x_, SimTK::Transform(kXToZ),
                                               carriage_z_body, SimTK::Transform(kXToZ));
    const SimTK::Body::Rigid wheel_body(
        SimTK::MassProperties(s.wheel_mass_kg, SimTK::Vec3(0), SimTK::Inertia(toSimTK(inertia))));
    wheel_ = SimTK::MobilizedBody::Pin(carriage_z_, SimTK::Transform(kZToY), wheel_body,
                                       SimTK::Transform(kZToY));

    wheel_speed_ = SimTK::Constraint::ConstantSpeed(wheel_, s.angular_velocity_rad_s);
    carriage_speed_ = SimTK::Constraint::ConstantSpeed(carriage_x_, 0.0);
    carriage_speed_.setDisabledByDefault(!s.slip.has_value());
    wheel_speed_.setDisabledByDefault(s.drive_torque_N_m.has_value() && !s.rotation_locked);

    BodyDescription wheel;
    wheel.name = s.wheel_name;
    wheel.mass.mass_kg = s.wheel_mass_kg;
    wheel.mass.inertia_diagonal_kg_m2 = inertia;
    wheel.geometry = s.wheel;
    addCoupled(wheel, wheel_);
    finishBuilding();

    carriage_x_.setOneQ(state(), SimTK::MobilizerQIndex(0), s.start_position_m.x());
    carriage_z_.setOneQ(state(), SimTK::MobilizerQIndex(0), s.start_position_m.z());
    locked_ = s.rotation_locked;
    applyDrive();
    saveState();
}

void SingleWheelRig::applyDrive() {
    const auto &s = settings_;
    SimTK::State &st = state();
    const double omega = locked_ ? 0.0 : s.angular_velocity_rad_s;
    const bool speed_drive = locked_ || !s.drive_torque_N_m;
    if (speed_drive) {
        if (wheel_speed_.isDisabled(st))
            wheel_speed_.enable(st);
        wheel_speed_.setSpeed(st, omega);
        wheel_.setOneU(st, SimTK::MobilizerUIndex(0), omega);
        discrete_.setOneMobilityForce(st, wheel_, SimTK::MobilizerUIndex(0), 0.0);
    } else {
        if (!wheel_speed_.isDisabled(st))
            wheel_speed_.disable(st);
        discrete_.setOneMobilityForce(st, wheel_, SimTK::MobilizerUIndex(0), *s.drive_torque_N_m);
    }
    if (s.slip || (locked_ && s.hold_carriage_in_drop)) {
        // Slip s = 1 - v / (ω r): the carriage is held at v = ω r (1 - s) while driving (at
        // rest while locked: ω = 0).
        const double v = omega * wheelRadius_m() * (1.0 - s.slip.value_or(0.0));
        if (carriage_speed_.isDisabled(st))
            carriage_speed_.enable(st);
        carriage_speed_.setSpeed(st, v);
        carriage_x_.setOneU(st, SimTK::MobilizerUIndex(0), v);
    } else if (!carriage_speed_.isDisabled(st)) {
        carriage_speed_.disable(st); // the drop's hold released: the carriage is free
    }
    discrete_.setOneMobilityForce(st, carriage_x_, SimTK::MobilizerUIndex(0), -s.drawbar_force_N);
    system_.realize(st, SimTK::Stage::Velocity);
}

void SingleWheelRig::setRotationLocked(bool locked) {
    if (locked == locked_)
        return;
    locked_ = locked;
    applyDrive();
}

std::map<std::string, double> SingleWheelRig::observables() const {
    const SimTK::State &st = state();
    system_.realize(st, SimTK::Stage::Acceleration);
    std::map<std::string, double> o;
    const double v = carriage_x_.getOneU(st, SimTK::MobilizerUIndex(0));
    const double omega = wheel_.getOneU(st, SimTK::MobilizerUIndex(0));
    o["carriage_x_m"] = carriage_x_.getOneQ(st, SimTK::MobilizerQIndex(0));
    o["carriage_z_m"] = carriage_z_.getOneQ(st, SimTK::MobilizerQIndex(0));
    o["carriage_vx_m_s"] = v;
    o["carriage_vz_m_s"] = carriage_z_.getOneU(st, SimTK::MobilizerUIndex(0));
    o["wheel_omega_rad_s"] = omega;
    // Slip s = 1 - v / (ω r); undefined while the wheel does not turn.
    o["slip"] = std::abs(omega) > 1e-9 ? 1.0 - v / (omega * wheelRadius_m()) : 0.0;
    // Lagrange multipliers carry the opposite sign of the force the drive applies.
    o["motor_torque_N_m"] = !wheel_speed_.isDisabled(st) ? -wheel_speed_.getMultiplier(st)
                            : settings_.drive_torque_N_m ? *settings_.drive_torque_N_m
                                                         : 0.0;
    o["carriage_drive_force_N"] =
        !carriage_speed_.isDisabled(st) ? -carriage_speed_.getMultiplier(st) : 0.0;
    o["rotation_locked"] = locked_ ? 1.0 : 0.0;
    return o;
}

std::string SingleWheelRig::checkpointExtras() const {
    return locked_ ? "locked 1" : "locked 0";
}

void SingleWheelRig::readCheckpointExtras(const std::string &line) {
    std::istringstream in(line);
    std::string tag;
    int locked = 0;
    if (!(in >> tag >> locked) || tag != "locked")
        throw ModelError("single-wheel rig checkpoint: expected 'locked 0|1', got '" + line + "'");
    locked_ = locked != 0;
    // Re-impose the drive on the restored velocities without changing them.
    SimTK::State &st = state();
    const double omega = wheel_.getOneU(st, SimTK::MobilizerUIndex(0));
    const double v = carriage_x_.getOneU(st, SimTK::MobilizerUIndex(0));
    applyDrive();
    wheel_.setOneU(st, SimTK::MobilizerUIndex(0), omega);
    carriage_x_.setOneU(st, SimTK::MobilizerUIndex(0), v);
    system_.realize(st, SimTK::Stage::Velocity);
}

} // namespace grainlink::mbs
