#include "grainlink/mbs/RockerBogie.hpp"

#include "JointFrames.hpp"

#include "grainlink/mbs/WheelTest.hpp" // parseWheelShape

#include <cmath>
#include <sstream>

namespace grainlink::mbs {

namespace {

using SimTK::Pi;

Vec3 mirrored(const Vec3 &v, int side) {
    return side == 0 ? v : Vec3(v.x(), -v.y(), v.z());
}

void checkInertia(const Vec3 &i, const std::string &part) {
    const bool ok = i.minCoeff() >= 0.0 && i.x() <= i.y() + i.z() && i.y() <= i.x() + i.z() &&
                    i.z() <= i.x() + i.y();
    if (!ok)
        throw ModelError("rocker-bogie: " + part +
                         " inertia needs non-negative principal moments that obey the triangle "
                         "inequality (each at most the sum of the other two)");
}

/// A rigid body with mass m, centre of mass c (body frame) and central principal moments.
SimTK::Body::Rigid rigidBody(double m, const Vec3 &c, const Vec3 &central,
                             const std::string &part) {
    if (!(m > 0.0))
        throw ModelError("rocker-bogie: " + part + " mass must be positive");
    checkInertia(central, part);
    const SimTK::Inertia about_com(toSimTK(central));
    // Simbody wants the inertia about the body origin: I_o = I_c + m (|c|² E - c cᵀ).
    return SimTK::Body::Rigid(
        SimTK::MassProperties(m, toSimTK(c), about_com.shiftFromMassCenter(toSimTK(c), m)));
}

SimTK::MobilizerQIndex q0() {
    return SimTK::MobilizerQIndex(0);
}
SimTK::MobilizerUIndex u0() {
    return SimTK::MobilizerUIndex(0);
}

} // namespace

const std::array<std::string, 6> &RockerBogie::wheelSuffixes() {
    static const std::array<std::string, 6> names{"lf", "lm", "lr", "rf", "rm", "rr"};
    return names;
}

RockerBogie::RockerBogie(const RockerBogieSettings &settings)
    : SimbodyModel(settings.gravity_m_s2, settings.integrator), settings_(settings) {
    const auto &s = settings_;
    const double r = 0.5 * s.wheel.diameter_m;
    if (!(r > 0.0) || !(s.wheel.width_m > 0.0))
        throw ModelError("rocker-bogie: the wheel needs a positive diameter and width");
    if (!(s.rocker_pivot_m.y() > 0.0))
        throw ModelError("rocker-bogie: rocker_pivot_m is the left pivot and needs y > 0 (the "
                         "right one is its mirror image)");
    for (const auto &[key, p] :
         {std::pair{"front_wheel_m", s.front_wheel_m},
          std::pair{"middle_wheel_m", s.middle_wheel_m}, std::pair{"rear_wheel_m", s.rear_wheel_m}})
        if (!(p.y() >= 0.5 * s.wheel.width_m))
            throw ModelError(std::string("rocker-bogie: ") + key +
                             " is a left wheel and needs y >= half the wheel width, or it "
                             "overlaps its mirror image");
    for (double w : s.wheel_speeds_rad_s)
        if (!std::isfinite(w))
            throw ModelError("rocker-bogie: wheel speeds must be finite");

    Vec3 wheel_inertia = s.wheel_inertia_kg_m2;
    if (wheel_inertia.isZero()) { // a thin ring of the wheel's radius and width, as the rig
        const double m = s.wheel_mass_kg, w = s.wheel.width_m;
        wheel_inertia =
            Vec3(m * r * r / 2 + m * w * w / 12, m * r * r, m * r * r / 2 + m * w * w / 12);
    }
    const auto wheel_body = rigidBody(s.wheel_mass_kg, Vec3::Zero(), wheel_inertia, "wheel");

    // Ground -> chassis (free) -> rocker (pin y) -> bogie (pin y); wheels on pins about y.
    chassis_ = SimTK::MobilizedBody::Free(
        matter_.Ground(), SimTK::Transform(),
        rigidBody(s.chassis_mass_kg, s.chassis_com_m, s.chassis_inertia_kg_m2, "chassis"),
        SimTK::Transform());
    // A free mobilizer's speeds are its angular velocity, then its linear velocity, both in
    // the ground frame: u 3 and 4 are v_x and v_y.
    for (int k = 0; k < 2; ++k)
        chassis_hold_[k] =
            SimTK::Constraint::ConstantSpeed(chassis_, SimTK::MobilizerUIndex(3 + k), 0.0);
    std::array<SimTK::MobilizedBody, 6> carriers;
    std::array<Vec3, 6> wheel_in_carrier;
    for (int side = 0; side < 2; ++side) {
        const Vec3 pivot = mirrored(s.rocker_pivot_m, side);
        const Vec3 bogie_pivot = mirrored(s.bogie_pivot_m, side);
        // Body frames: the rocker's origin at its pivot, the bogie's at its pivot.
        rockers_[side] = SimTK::MobilizedBody::Pin(
            chassis_, SimTK::Transform(kZToY, toSimTK(pivot)),
            rigidBody(s.rocker_mass_kg, mirrored(s.rocker_com_m, side) - pivot,
                      s.rocker_inertia_kg_m2, "rocker"),
            SimTK::Transform(kZToY));
        bogies_[side] = SimTK::MobilizedBody::Pin(
            rockers_[side], SimTK::Transform(kZToY, toSimTK(bogie_pivot - pivot)),
            rigidBody(s.bogie_mass_kg, mirrored(s.bogie_com_m, side) - bogie_pivot,
                      s.bogie_inertia_kg_m2, "bogie"),
            SimTK::Transform(kZToY));
        const int first = 3 * side;
        carriers[first] = rockers_[side];
        wheel_in_carrier[first] = mirrored(s.front_wheel_m, side) - pivot;
        carriers[first + 1] = bogies_[side];
        wheel_in_carrier[first + 1] = mirrored(s.middle_wheel_m, side) - bogie_pivot;
        carriers[first + 2] = bogies_[side];
        wheel_in_carrier[first + 2] = mirrored(s.rear_wheel_m, side) - bogie_pivot;
    }
    for (int i = 0; i < kWheels; ++i) {
        wheels_[i] = SimTK::MobilizedBody::Pin(
            carriers[i], SimTK::Transform(kZToY, toSimTK(wheel_in_carrier[i])), wheel_body,
            SimTK::Transform(kZToY));
        wheel_speed_[i] = SimTK::Constraint::ConstantSpeed(wheels_[i], s.wheel_speeds_rad_s[i]);
    }

    // The differential: q_left + q_right = 0 for the rocker angles relative to the chassis, so
    // the chassis pitch is the mean of the two rocker pitches. A CoordinateCoupler holds it at
    // the position level (no drift, as a SpeedCoupler on q̇ would allow, and exact for any
    // angle, which a point constraint on a modelled differential bar would only be to first
    // order); its multiplier is the torque the differential passes to each rocker.
    SimTK::Vector coefficients(3);
    coefficients[0] = 1.0;
    coefficients[1] = 1.0;
    coefficients[2] = 0.0;
    differential_ = SimTK::Constraint::CoordinateCoupler(
        matter_, new SimTK::Function::Linear(coefficients),
        std::vector<SimTK::MobilizedBodyIndex>{rockers_[0].getMobilizedBodyIndex(),
                                               rockers_[1].getMobilizedBodyIndex()},
        std::vector<SimTK::MobilizerQIndex>{q0(), q0()});

    for (int i = 0; i < kWheels; ++i) {
        BodyDescription wheel;
        wheel.name = s.name_prefix + wheelSuffixes()[i];
        wheel.mass.mass_kg = s.wheel_mass_kg;
        wheel.mass.inertia_diagonal_kg_m2 = wheel_inertia;
        wheel.geometry = s.wheel;
        addCoupled(wheel, wheels_[i]);
    }
    finishBuilding();

    chassis_.setQToFitTransform(
        state(), SimTK::Transform(SimTK::Rotation(s.start_yaw_deg * Pi / 180.0, SimTK::ZAxis),
                                  toSimTK(s.start_position_m)));
    speeds_rad_s_ = s.wheel_speeds_rad_s;
    torque_drive_ = s.drive_torques_N_m.has_value();
    if (torque_drive_)
        torques_N_m_ = *s.drive_torques_N_m;
    locked_ = s.rotation_locked || s.release_time_s.has_value();
    applyDrive();
    saveState();
}

std::vector<double> RockerBogie::advanceTo(double time_s) {
    // Decided from the time, so that a restored window decides again. A window that straddles
    // the release ends the drop at its start.
    if (settings_.release_time_s) {
        const bool drop = time() < *settings_.release_time_s - 1e-9;
        if (drop != locked_)
            setRotationLocked(drop);
    }
    return SimbodyModel::advanceTo(time_s);
}

void RockerBogie::applyDrive() {
    SimTK::State &st = state();
    for (int i = 0; i < kWheels; ++i) {
        auto &c = wheel_speed_[i];
        if (locked_ || !torque_drive_) {
            const double omega = locked_ ? 0.0 : speeds_rad_s_[i];
            if (c.isDisabled(st))
                c.enable(st);
            c.setSpeed(st, omega);
            wheels_[i].setOneU(st, u0(), omega);
            discrete_.setOneMobilityForce(st, wheels_[i], u0(), 0.0);
        } else {
            if (!c.isDisabled(st))
                c.disable(st);
            discrete_.setOneMobilityForce(st, wheels_[i], u0(), torques_N_m_[i]);
        }
    }
    for (int k = 0; k < 2; ++k) {
        auto &c = chassis_hold_[k];
        if (locked_ && settings_.hold_chassis_in_drop) {
            if (c.isDisabled(st))
                c.enable(st);
            chassis_.setOneU(st, SimTK::MobilizerUIndex(3 + k), 0.0);
        } else if (!c.isDisabled(st)) {
            c.disable(st); // released with the wheels: the chassis is free
        }
    }
    system_.realize(st, SimTK::Stage::Velocity);
}

void RockerBogie::setWheelSpeeds(const std::array<double, 6> &speeds_rad_s) {
    for (double w : speeds_rad_s)
        if (!std::isfinite(w))
            throw ModelError("rocker-bogie: wheel speeds must be finite");
    speeds_rad_s_ = speeds_rad_s;
    torque_drive_ = false;
    applyDrive();
}

void RockerBogie::setDriveTorques(const std::array<double, 6> &torques_N_m) {
    for (double t : torques_N_m)
        if (!std::isfinite(t))
            throw ModelError("rocker-bogie: drive torques must be finite");
    torques_N_m_ = torques_N_m;
    torque_drive_ = true;
    applyDrive();
}

void RockerBogie::setRotationLocked(bool locked) {
    if (locked == locked_)
        return;
    locked_ = locked;
    applyDrive();
}

double RockerBogie::totalMass_kg() const {
    const auto &s = settings_;
    return s.chassis_mass_kg + 2 * (s.rocker_mass_kg + s.bogie_mass_kg) + kWheels * s.wheel_mass_kg;
}

RigidState RockerBogie::chassisState() const {
    return partState(Part::Chassis);
}

RigidState RockerBogie::partState(Part part) const {
    const SimTK::State &st = state();
    system_.realize(st, SimTK::Stage::Velocity);
    const SimTK::MobilizedBody *body = &chassis_;
    switch (part) {
    case Part::Chassis:
        break;
    case Part::LeftRocker:
        body = &rockers_[0];
        break;
    case Part::RightRocker:
        body = &rockers_[1];
        break;
    case Part::LeftBogie:
        body = &bogies_[0];
        break;
    case Part::RightBogie:
        body = &bogies_[1];
        break;
    }
    RigidState out;
    const SimTK::Transform &x = body->getBodyTransform(st);
    out.position_m = fromSimTK(x.p());
    const SimTK::Quaternion q = x.R().convertRotationToQuaternion();
    out.orientation = Quat(q[0], q[1], q[2], q[3]).normalized();
    out.linear_velocity_m_s = fromSimTK(body->getBodyOriginVelocity(st));
    out.angular_velocity_rad_s = fromSimTK(body->getBodyAngularVelocity(st));
    return out;
}

std::map<std::string, double> RockerBogie::observables() const {
    const SimTK::State &st = state();
    system_.realize(st, SimTK::Stage::Acceleration);
    std::map<std::string, double> o;
    const SimTK::Transform &x = chassis_.getBodyTransform(st);
    const SimTK::Vec3 v = chassis_.getBodyOriginVelocity(st);
    const char *axes[3] = {"x", "y", "z"};
    for (int k = 0; k < 3; ++k) {
        o[std::string("chassis_") + axes[k] + "_m"] = x.p()[k];
        o[std::string("chassis_v") + axes[k] + "_m_s"] = v[k];
    }
    // Body-fixed z-y-x: R = Rz(yaw) Ry(pitch) Rx(roll).
    const SimTK::Vec3 ypr = x.R().convertThreeAxesRotationToThreeAngles(
        SimTK::BodyRotationSequence, SimTK::ZAxis, SimTK::YAxis, SimTK::XAxis);
    o["chassis_yaw_rad"] = ypr[0];
    o["chassis_pitch_rad"] = ypr[1];
    o["chassis_roll_rad"] = ypr[2];
    o["rocker_left_rad"] = rockers_[0].getOneQ(st, q0());
    o["rocker_right_rad"] = rockers_[1].getOneQ(st, q0());
    o["bogie_left_rad"] = bogies_[0].getOneQ(st, q0());
    o["bogie_right_rad"] = bogies_[1].getOneQ(st, q0());
    // Constraint generalized forces are -Gᵀλ, with G = [1 1] for q_left + q_right.
    o["differential_torque_N_m"] = -differential_.getMultipliersAsVector(st)[0];
    // Each wheel's slip as the rig's (s = 1 - v / (ω r), 0 while it does not turn): v its
    // centre's speed along the chassis heading, ω its spin on its carrier (the drive's).
    const SimTK::UnitVec3 heading = x.R().x();
    for (int i = 0; i < kWheels; ++i) {
        const std::string name = settings_.name_prefix + wheelSuffixes()[i];
        const double omega = wheels_[i].getOneU(st, u0());
        const double v_wheel = ~wheels_[i].getBodyOriginVelocity(st) * heading;
        o[name + "_omega_rad_s"] = omega;
        o[name + "_slip"] =
            std::abs(omega) > 1e-9 ? 1.0 - v_wheel / (omega * wheelRadius_m()) : 0.0;
        o[name + "_motor_torque_N_m"] =
            !wheel_speed_[i].isDisabled(st) ? -wheel_speed_[i].getMultiplier(st) : torques_N_m_[i];
    }
    o["rotation_locked"] = locked_ ? 1.0 : 0.0;
    return o;
}

std::string RockerBogie::checkpointExtras() const {
    std::ostringstream os;
    os.precision(17);
    os << "drive " << (torque_drive_ ? "torque" : "speed") << " locked " << (locked_ ? 1 : 0)
       << " speeds";
    for (double w : speeds_rad_s_)
        os << ' ' << w;
    os << " torques";
    for (double t : torques_N_m_)
        os << ' ' << t;
    return os.str();
}

void RockerBogie::readCheckpointExtras(const std::string &line) {
    std::istringstream in(line);
    std::string tag, mode, tag_locked, tag_speeds, tag_torques;
    int locked = 0;
    std::array<double, 6> speeds{}, torques{};
    in >> tag >> mode >> tag_locked >> locked >> tag_speeds;
    for (double &w : speeds)
        in >> w;
    in >> tag_torques;
    for (double &t : torques)
        in >> t;
    if (!in || tag != "drive" || (mode != "speed" && mode != "torque") || tag_locked != "locked" ||
        tag_speeds != "speeds" || tag_torques != "torques")
        throw ModelError("rocker-bogie checkpoint: expected 'drive speed|torque locked 0|1 "
                         "speeds <6 values> torques <6 values>', got '" +
                         line + "'");
    torque_drive_ = mode == "torque";
    locked_ = locked != 0;
    speeds_rad_s_ = speeds;
    torques_N_m_ = torques;
    // Re-impose the drive on the restored velocities without changing them.
    SimTK::State &st = state();
    std::array<double, 6> omega{};
    for (int i = 0; i < kWheels; ++i)
        omega[i] = wheels_[i].getOneU(st, u0());
    applyDrive();
    for (int i = 0; i < kWheels; ++i)
        wheels_[i].setOneU(st, u0(), omega[i]);
    system_.realize(st, SimTK::Stage::Velocity);
}

namespace {

Vec3 vec3Or(const config::ConfigNode &node, const std::string &key, const Vec3 &fallback) {
    if (auto n = node.optional(key))
        return n->vec3();
    return fallback;
}

/// A number for all six wheels, or a list of six in coupled-body order.
std::array<double, 6> perWheel(const config::ConfigNode &n) {
    std::array<double, 6> out{};
    if (n.isSequence()) {
        const auto values = n.numbers();
        if (values.size() != out.size())
            n.fail("needs one number for all wheels or a list of 6 (lf, lm, lr, rf, rm, rr), "
                   "got " +
                   std::to_string(values.size()));
        for (std::size_t i = 0; i < out.size(); ++i)
            out[i] = values[i];
    } else {
        out.fill(n.number());
    }
    return out;
}

} // namespace

RockerBogieSettings parseRockerBogie(const config::ConfigNode &node) {
    RockerBogieSettings s;
    s.name_prefix = node.text("name_prefix", s.name_prefix);
    if (auto w = node.optional("wheel"))
        s.wheel = parseWheelShape(*w);
    s.wheel_mass_kg = node.number("wheel_mass_kg", s.wheel_mass_kg);
    s.wheel_inertia_kg_m2 = vec3Or(node, "wheel_inertia_kg_m2", s.wheel_inertia_kg_m2);
    s.chassis_mass_kg = node.number("chassis_mass_kg", s.chassis_mass_kg);
    s.chassis_com_m = vec3Or(node, "chassis_com_m", s.chassis_com_m);
    s.chassis_inertia_kg_m2 = vec3Or(node, "chassis_inertia_kg_m2", s.chassis_inertia_kg_m2);
    s.rocker_mass_kg = node.number("rocker_mass_kg", s.rocker_mass_kg);
    s.rocker_com_m = vec3Or(node, "rocker_com_m", s.rocker_com_m);
    s.rocker_inertia_kg_m2 = vec3Or(node, "rocker_inertia_kg_m2", s.rocker_inertia_kg_m2);
    s.bogie_mass_kg = node.number("bogie_mass_kg", s.bogie_mass_kg);
    s.bogie_com_m = vec3Or(node, "bogie_com_m", s.bogie_com_m);
    s.bogie_inertia_kg_m2 = vec3Or(node, "bogie_inertia_kg_m2", s.bogie_inertia_kg_m2);
    s.rocker_pivot_m = vec3Or(node, "rocker_pivot_m", s.rocker_pivot_m);
    s.bogie_pivot_m = vec3Or(node, "bogie_pivot_m", s.bogie_pivot_m);
    s.front_wheel_m = vec3Or(node, "front_wheel_m", s.front_wheel_m);
    s.middle_wheel_m = vec3Or(node, "middle_wheel_m", s.middle_wheel_m);
    s.rear_wheel_m = vec3Or(node, "rear_wheel_m", s.rear_wheel_m);
    s.start_position_m = node["start_position_m"].vec3();
    s.start_yaw_deg = node.number("start_yaw_deg", 0.0);
    if (auto n = node.optional("wheel_speed_rad_s"))
        s.wheel_speeds_rad_s = perWheel(*n);
    if (auto n = node.optional("drive_torque_N_m"))
        s.drive_torques_N_m = perWheel(*n);
    s.rotation_locked = node.boolean("rotation_locked", false);
    if (node.has("release_time_s")) {
        if (s.rotation_locked)
            node["release_time_s"].fail("the wheels are locked for the whole run "
                                        "(rotation_locked: true): remove one of the two");
        s.release_time_s = node["release_time_s"].positive();
    }
    s.hold_chassis_in_drop = node.boolean("hold_chassis_in_drop", false);
    if (node.has("end_wall_limit"))
        s.end_wall_limit = node["end_wall_limit"].number(0.01, 1.0);
    if (s.hold_chassis_in_drop && !s.release_time_s)
        node["hold_chassis_in_drop"].fail("a hold in the drop needs the drop's end: give "
                                          "release_time_s");
    // One drive, and none for wheels that stay locked (nothing unlocks them in a coupled run).
    for (const char *key : {"wheel_speed_rad_s", "drive_torque_N_m"}) {
        if (!node.has(key))
            continue;
        if (s.rotation_locked)
            node[key].fail("the wheels are locked (rotation_locked: true) and never driven: "
                           "remove the key or the lock");
        if (node.has("wheel_speed_rad_s") && node.has("drive_torque_N_m"))
            node[key].fail("give one drive: wheel_speed_rad_s (speed) or drive_torque_N_m "
                           "(torque)");
    }
    s.gravity_m_s2 = vec3Or(node, "gravity_m_s2", s.gravity_m_s2);
    node.finish();
    return s;
}

} // namespace grainlink::mbs
