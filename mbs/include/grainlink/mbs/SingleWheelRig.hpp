#pragma once
// The single-wheel test rig of the seed (Table 1; DIGEST §5): a wheel on a carriage that is free
// to move horizontally and vertically (two prismatic joints), the normal load as mass, the wheel
// on a revolute joint driven at constant angular velocity or by a torque, an optional drawbar
// force on the carriage, a phase with the rotation locked, and a slip-controlled mode in which
// the carriage speed is imposed as well. Frames: x travel, z up, wheel axis y.
#include "grainlink/mbs/SimbodyModel.hpp"

#include <optional>

namespace grainlink::mbs {

struct SingleWheelRigSettings {
    std::string wheel_name = "wheel";
    WheelShape wheel;                        ///< geometry (the DEM side builds the same mesh)
    double wheel_mass_kg = 2.0;              ///< [kg]
    Vec3 wheel_inertia_kg_m2 = Vec3::Zero(); ///< [kg m^2] about the centre; zero: thin ring
    double normal_load_kg = 8.33;            ///< [kg] wheel + carriage mass carried vertically
    double horizontal_mass_kg = 8.33;        ///< [kg] everything that moves with the carriage in x
    Vec3 start_position_m = Vec3(0, 0, 0.5); ///< [m] wheel centre at t = 0
    /// [m] `clearance_above_bed_m`: the start height is set by the multibody node so that the
    /// wheel's lowest point is this far above the settled bed (or the rigid floor); it replaces
    /// the z of start_position_m.
    std::optional<double> clearance_above_bed_m;
    double angular_velocity_rad_s = 3.0;     ///< [rad/s] driven speed (positive rolls towards +x)
    std::optional<double> drive_torque_N_m;  ///< [N m] torque drive instead of a speed drive
    double drawbar_force_N = 0.0;            ///< [N] horizontal resistance F_R on the carriage
    std::optional<double> slip;              ///< slip-controlled mode: carriage at ω r (1 - slip)
    bool rotation_locked = false;            ///< start with the wheel rotation locked (drop phase)
    /// Hold the carriage in x while the rotation is locked (the drop), as a rig's brake does:
    /// on a slope (gravity tilted) it would slide back before the wheel touches down.
    bool hold_carriage_in_drop = false;
    Vec3 gravity_m_s2 = Vec3(0, 0, -9.81);
    IntegratorSettings integrator;
};

class SingleWheelRig final : public SimbodyModel {
public:
    explicit SingleWheelRig(const SingleWheelRigSettings &settings);

    std::map<std::string, double> observables() const override;

    /// Locks or frees the wheel rotation (the seed's drop phase keeps it locked).
    void setRotationLocked(bool locked);
    bool rotationLocked() const { return locked_; }
    const SingleWheelRigSettings &settings() const { return settings_; }
    double wheelRadius_m() const { return 0.5 * settings_.wheel.diameter_m; }

protected:
    std::string checkpointExtras() const override;
    void readCheckpointExtras(const std::string &line) override;

private:
    void applyDrive();

    SingleWheelRigSettings settings_;
    SimTK::MobilizedBody::Slider carriage_x_, carriage_z_;
    SimTK::MobilizedBody::Pin wheel_;
    SimTK::Constraint::ConstantSpeed wheel_speed_, carriage_speed_;
    bool locked_ = false;
};

} // namespace grainlink::mbs
