#pragma once
// Virtual bevameter, shear: a grousered annulus pressed onto a settled bed to a normal load, then
// turned at constant angular speed while a force servo holds the load; tau(j) per normal
// pressure and the Janosi-Hanamoto law fitted over the pressures (docs/lab.md, physics.md §12.12).
#include "grainlink/dem/Scenario.hpp"
#include "grainlink/dem/TriangleMesh.hpp"
#include "grainlink/lab/LabConfig.hpp"
#include "grainlink/lab/LabExperiment.hpp"
#include "grainlink/lab/NumericalChecks.hpp"

#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

namespace grainlink::lab {

/// The annulus: a flat ring with `grouser_count` radial grousers on its underside.
struct AnnulusGeometry {
    double inner_radius_m = 0.0;      ///< [m] R_i
    double outer_radius_m = 0.0;      ///< [m] R_o
    int grouser_count = 8;            ///< radial grousers, evenly spaced; 0: a plain ring
    double grouser_height_m = 0.0;    ///< [m] below the ring's bottom face
    double grouser_thickness_m = 0.0; ///< [m] in the direction of rotation; 0: height / 2
    double ring_thickness_m = 0.0;    ///< [m] 0: (R_o - R_i) / 4
    int ring_segments = 48;           ///< facets around each rim

    double area_m2() const;         ///< [m^2] pi (R_o^2 - R_i^2)
    double torqueFactor_m3() const; ///< [m^3] 2 pi / 3 (R_o^3 - R_i^3): T = tau * this
    double meanRadius_m() const;    ///< [m] (R_i + R_o) / 2, the radius of j = theta R_mean
};

/// Closed mesh of the annulus, axis z, the grousers' tips at z = -grouser_height_m, the ring's
/// bottom face at z = 0 (the body origin, on the axis).
dem::TriangleMesh makeShearAnnulus(const AnnulusGeometry &geometry);

/// The `bevameter_shear:` section.
struct ShearAnnulusSpec {
    AnnulusGeometry annulus;
    std::vector<double> normal_pressures_Pa; ///< [Pa] one run per normal pressure
    double angular_speed_rad_s = 0.0;        ///< [rad/s] during the shear phase
    double max_shear_displacement_m = 0.0;   ///< [m] the shear phase ends at j = theta R_mean
    double approach_speed_m_s = 0.05;        ///< [m/s] downward until the load is first reached
    /// The load servo (LabConfig.hpp): hold_s before the rotation starts, max_load_time_s for the
    /// approach to first reach the load.
    ServoSpec servo{0.0, 0.0, 0.0, 0.0, 0.02, 1.0}; // hold 0.02 s, 1 s to load
    double start_clearance_m = 0.001;               ///< [m] grouser tips above the highest grain
    double sample_interval_s = 0.002;               ///< [s] servo update and CSV row
    std::optional<double> friction_coefficient;     ///< annulus-grain; unset: the grains' angles
    double min_resolution = 3.0;                    ///< [-] required (R_o - R_i) / (2 r_max)
    std::optional<Eigen::Vector2d> centre_m;        ///< [m] axis (x, y); unset: region centre
};

struct ShearAnnulusScenario {
    std::string name = "bevameter_shear";
    dem::DemScenario soil;
    ShearAnnulusSpec test;
    std::vector<config::KeyWarning> warnings; ///< deprecated spellings read
};

/// Reads `name`, `soil:` (the DEM soil keys of docs/scenario.md) and `bevameter_shear:`. The
/// servo's keys before the `servo:` block (servo_gain_m_s_per_N, servo_max_speed_m_s,
/// servo_integral_gain_m_s2_per_N, servo_deadband_N, load_hold_s, max_load_time_s) still read,
/// each with a line in `warnings`.
ShearAnnulusScenario parseShearAnnulus(const config::ConfigNode &root);
ShearAnnulusScenario loadShearAnnulus(const std::string &path);

struct ShearSample {
    double time_s = 0.0;               ///< [s] since the rotation started, interval middle
    double rotation_rad = 0.0;         ///< [rad] theta, interval middle
    double shear_displacement_m = 0.0; ///< [m] j = theta R_mean
    double normal_force_N = 0.0;       ///< [N] vertical soil reaction, interval mean
    double normal_pressure_Pa = 0.0;   ///< [Pa] sigma = F_N / (pi (R_o^2 - R_i^2))
    double torque_N_m = 0.0;           ///< [N m] soil torque resisting the rotation (> 0)
    double shear_stress_Pa = 0.0;      ///< [Pa] tau = T / (2 pi / 3 (R_o^3 - R_i^3))
    double sinkage_m = 0.0;            ///< [m] grouser tips below the bed surface
};

/// One tau(j) curve at one normal pressure, as the fit takes it.
struct ShearCurve {
    double normal_pressure_Pa = 0.0; ///< [Pa] sigma of the curve
    std::vector<double> shear_displacement_m;
    std::vector<double> shear_stress_Pa;
};

struct JanosiParameters {
    double cohesion_Pa = 0.0;        ///< [Pa] c
    double friction_angle_deg = 0.0; ///< [deg] phi
    double shear_modulus_m = 0.0;    ///< [m] K, Janosi's shear deformation modulus
    /// tau(j) at normal pressure sigma [Pa]: (c + sigma tan phi)(1 - exp(-j / K)).
    double shearStress(double normal_pressure_Pa, double shear_displacement_m) const;
};

struct JanosiFit {
    JanosiParameters parameters;
    Eigen::Vector3d standard_error; ///< of (c, phi [deg], K)
    Eigen::Vector3d half_width_95;  ///< t(0.975, dof) * SE
    Eigen::Matrix3d covariance;     ///< of (c, phi [deg], K)
    double rms_residual_Pa = 0.0;
    std::size_t points = 0;
    int degrees_of_freedom = 0;
    int iterations = 0;
    std::string describe() const;
};

/// Fits the Janosi-Hanamoto law jointly over all curves' points with j > 0. Throws
/// std::invalid_argument with fewer than two distinct normal pressures (c and phi are then not
/// separable) or fewer than four points.
JanosiFit fitJanosi(const std::vector<ShearCurve> &curves);

struct ShearRun {
    double target_pressure_Pa = 0.0;  ///< [Pa]
    double target_force_N = 0.0;      ///< [N]
    double surface_m = 0.0;           ///< [m] settled bed surface
    double wall_gap_m = 0.0;          ///< [m] outer rim to the nearest side of the region
    double load_time_s = 0.0;         ///< [s] approach and hold before the rotation
    double sinkage_at_load_m = 0.0;   ///< [m] grouser tips below the surface when it started
    std::vector<ShearSample> samples; ///< shear phase only
    double mean_pressure_Pa = 0.0;    ///< [Pa] sigma over the shear phase
    double max_load_error = 0.0;      ///< [-] largest |F - F_target| / F_target, shear phase
    double rms_load_error = 0.0;      ///< [-] rms of the same
    double max_shear_stress_Pa = 0.0; ///< [Pa] tau_max
    std::uint64_t steps = 0;
    double wall_s = 0.0;
    ShearCurve curve() const; ///< at the mean measured pressure
};

struct ShearAnnulusResult : LabResult {
    static constexpr const char *kTest = "bevameter_shear";
    static constexpr const char *kCsvFiles = "shear_displacement.csv,janosi_fit.csv";
    AnnulusGeometry annulus;
    double resolution = 0.0;    ///< (R_o - R_i) / (2 r_max)
    std::vector<ShearRun> runs; ///< one per normal pressure, in the scenario's order
    std::optional<JanosiFit> fit;
    std::string report() const;
    LabSummary summary() const;
    /// shear_displacement.csv and janosi_fit.csv.
    void writeCsvs(const std::string &directory) const;
};

/// Settles (or reads) the bed once, runs every normal pressure on a copy of it, fits Janosi
/// (runLabExperiment); writes its outputs into options.output_directory unless empty.
ShearAnnulusResult runShearAnnulus(const ShearAnnulusScenario &scenario,
                                   const LabRunOptions &options);

/// Shear annulus answers for the numerical checks: tau_max per normal pressure and the Janosi
/// c, phi and K when the result has a fit.
Quantities shearAnnulusQuantities(const ShearAnnulusResult &result);
/// Reruns the shear test on a wider box or finer grains (lab/NumericalChecks.hpp; outputs in
/// options.output_directory/check_<name>) and compares. The annulus, its axis (the region's
/// centre, about which the box widens) and the servo stay: the bed's stiffness under the annulus
/// depends on its area and the bed's depth, neither of which changes.
std::vector<NumericalCheck> checkShearAnnulus(const ShearAnnulusScenario &scenario,
                                              const ShearAnnulusResult &baseline,
                                              const CheckRequest &request,
                                              const LabRunOptions &options);

} // namespace grainlink::lab
