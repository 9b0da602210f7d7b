#pragma once
// A six-wheel rocker-bogie rover (docs/physics.md §9): a chassis free in space (6 DOF), a rocker
// on each side on a pin about the chassis' lateral axis, a differential between the two rockers
// (the chassis pitch is the mean of the rocker pitches), a bogie on each rocker (pin), the front
// wheel on the rocker, the middle and rear wheels on the bogie. Every wheel is on a pin about its
// carrier's y axis, driven at a commanded speed (Constraint::ConstantSpeed; the motor torque is
// minus its multiplier) or by a torque, and is a coupled body.
//
// Frames: x forward, y to the left, z up; at zero joint angles every body frame is parallel to
// the chassis frame. Angles about +y are positive nose-down (right-hand rule), so a wheel turning
// at a positive speed rolls towards +x. Geometry is given for the left side in the chassis frame
// at zero joint angles; the right side is its mirror image (y -> -y).
// Coupled bodies, in this order: wheel_lf, wheel_lm, wheel_lr, wheel_rf, wheel_rm, wheel_rr
// (left/right; front, middle, rear).
#include "grainlink/config/ConfigNode.hpp"
#include "grainlink/mbs/SimbodyModel.hpp"

#include <array>

namespace grainlink::mbs {

/// Positions in the chassis frame at zero joint angles (left side; the right is mirrored).
/// The defaults are documented with their source in docs/physics.md §9.
struct RockerBogieSettings {
    std::string name_prefix = "wheel_"; ///< coupled body names: prefix + lf, lm, lr, rf, rm, rr
    WheelShape wheel = defaultWheel();  ///< every wheel's geometry (the DEM side builds it too)
    double wheel_mass_kg = 3.0;         ///< [kg] each wheel
    Vec3 wheel_inertia_kg_m2 = Vec3::Zero(); ///< [kg m^2] about its centre; zero: thin ring
    double chassis_mass_kg = 256.0;          ///< [kg] body, mast, payload
    Vec3 chassis_com_m = Vec3(0, 0, 0.1);    ///< [m] chassis centre of mass
    Vec3 chassis_inertia_kg_m2 = Vec3(15.57, 23.25, 34.99); ///< [kg m^2] about its CoM
    double rocker_mass_kg = 8.0;                            ///< [kg] each rocker
    Vec3 rocker_com_m = Vec3(0.1, 0.55, -0.15);             ///< [m]
    Vec3 rocker_inertia_kg_m2 = Vec3(0.05, 0.6, 0.6);       ///< [kg m^2] about its CoM
    double bogie_mass_kg = 5.0;                             ///< [kg] each bogie
    Vec3 bogie_com_m = Vec3(-0.325, 0.6, -0.2);             ///< [m]
    Vec3 bogie_inertia_kg_m2 = Vec3(0.02, 0.18, 0.18);      ///< [kg m^2] about its CoM
    Vec3 rocker_pivot_m = Vec3(0, 0.45, 0);                 ///< [m] rocker pin on the chassis
    Vec3 bogie_pivot_m = Vec3(-0.325, 0.6, -0.15);          ///< [m] bogie pin on the rocker
    Vec3 front_wheel_m = Vec3(0.65, 0.6, -0.3075);          ///< [m] front wheel centre (rocker)
    Vec3 middle_wheel_m = Vec3(0.0, 0.6, -0.3075);          ///< [m] middle wheel centre (bogie)
    Vec3 rear_wheel_m = Vec3(-0.65, 0.6, -0.3075);          ///< [m] rear wheel centre (bogie)
    Vec3 start_position_m = Vec3(0, 0, 0.45); ///< [m] chassis origin at t = 0 (wheels touch z=0)
    double start_yaw_deg = 0.0;               ///< [deg] heading at t = 0 (about +z from +x)
    /// [rad/s] commanded speed of each wheel relative to its carrier, coupled-body order.
    std::array<double, 6> wheel_speeds_rad_s{0.35, 0.35, 0.35, 0.35, 0.35, 0.35};
    /// [N m] torque drive of each wheel instead of the speed drive, when set.
    std::optional<std::array<double, 6>> drive_torques_N_m;
    bool rotation_locked = false;          ///< start with every wheel held at zero speed
    /// [s] The drop: every wheel locked until this time, then driven.
    std::optional<double> release_time_s;
    /// In the drop, hold the chassis' horizontal velocity at zero: it comes down onto a slope
    /// without sliding down it (the rig's hold_carriage_in_drop).
    bool hold_chassis_in_drop = false;
    /// With the DEM soil, `grainlink run` refuses a run in which a strip's end walls took more
    /// than this share of its wheels' push over the run's second half (dem::endWallShare).
    double end_wall_limit = 0.5;
    Vec3 gravity_m_s2 = Vec3(0, 0, -3.71); ///< [m/s^2] Mars
    IntegratorSettings integrator;

    static WheelShape defaultWheel() {
        WheelShape w;
        w.diameter_m = 0.285;
        w.width_m = 0.12;
        return w;
    }
};

class RockerBogie final : public SimbodyModel {
public:
    enum Wheel { LeftFront, LeftMiddle, LeftRear, RightFront, RightMiddle, RightRear };
    static constexpr int kWheels = 6;
    /// The suffixes of the wheel names (lf, lm, lr, rf, rm, rr), in coupled-body order.
    static const std::array<std::string, 6> &wheelSuffixes();

    explicit RockerBogie(const RockerBogieSettings &settings);

    /// chassis_{x,y,z}_m, chassis_{vx,vy,vz}_m_s, chassis_{roll,pitch,yaw}_rad (yaw about z,
    /// then pitch about y, then roll about x; pitch positive nose-down), rocker_{left,right}_rad
    /// (relative to the chassis), bogie_{left,right}_rad (relative to the rocker),
    /// differential_torque_N_m (on the left rocker about +y; the right gets the same), and per
    /// wheel <name>_omega_rad_s (relative to its carrier) and <name>_motor_torque_N_m.
    std::map<std::string, double> observables() const override;
    /// Ends the drop at release_time_s, then integrates (SimbodyModel).
    std::vector<double> advanceTo(double time_s) override;

    /// Speed drive on every wheel at these speeds [rad/s] (coupled-body order).
    void setWheelSpeeds(const std::array<double, 6> &speeds_rad_s);
    /// Torque drive on every wheel with these torques [N m] (coupled-body order).
    void setDriveTorques(const std::array<double, 6> &torques_N_m);
    /// Holds every wheel at zero speed (e.g. while the rover settles) or releases it to the drive.
    void setRotationLocked(bool locked);
    bool rotationLocked() const { return locked_; }

    const RockerBogieSettings &settings() const { return settings_; }
    double wheelRadius_m() const { return 0.5 * settings_.wheel.diameter_m; }
    double totalMass_kg() const;
    /// Chassis pose and velocity (origin of the chassis frame), world frame.
    RigidState chassisState() const;
    /// The suspension's parts; a rocker's and a bogie's frame origin is at its pivot.
    enum class Part { Chassis, LeftRocker, RightRocker, LeftBogie, RightBogie };
    /// Pose and velocity of a part's frame origin, world frame.
    RigidState partState(Part part) const;

protected:
    std::string checkpointExtras() const override;
    void readCheckpointExtras(const std::string &line) override;

private:
    void applyDrive();

    RockerBogieSettings settings_;
    SimTK::MobilizedBody::Free chassis_;
    std::array<SimTK::MobilizedBody::Pin, 2> rockers_, bogies_; ///< left, right
    std::array<SimTK::MobilizedBody::Pin, 6> wheels_;
    std::array<SimTK::Constraint::ConstantSpeed, 6> wheel_speed_;
    /// The drop's hold: the chassis' ground-frame velocity along x and y at zero.
    std::array<SimTK::Constraint::ConstantSpeed, 2> chassis_hold_;
    SimTK::Constraint::CoordinateCoupler differential_;
    // Drive state (in checkpoints): mode, speeds, torques, lock.
    bool torque_drive_ = false;
    std::array<double, 6> speeds_rad_s_{};
    std::array<double, 6> torques_N_m_{};
    bool locked_ = false;
};

/// The `rover:` block of a scenario (docs/scenario.md): strict, errors name the key and line.
RockerBogieSettings parseRockerBogie(const config::ConfigNode &node);

} // namespace grainlink::mbs
