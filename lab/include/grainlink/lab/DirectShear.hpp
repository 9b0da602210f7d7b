#pragma once
// Direct shear box: a split box of grains, the lower half fixed, the upper half moved along x at
// constant speed under a top plate that a force servo keeps at a constant normal load; tau(d)
// per normal stress, peak and residual strength, and the Mohr-Coulomb line tau = c + sigma tan psi
// fitted with its confidence intervals (docs/lab.md, docs/physics.md §12.15).
#include "grainlink/dem/Scenario.hpp"
#include "grainlink/lab/LabConfig.hpp"
#include "grainlink/lab/LabExperiment.hpp"

#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

namespace grainlink::lab {

/// The `direct_shear:` section. The box spans [0, L] x [0, W] in x and y, its floor is z = 0 and
/// the shear plane z = lower_height_m.
struct DirectShearSpec {
    double length_m = 0.0;                  ///< [m] L, along the shear direction x
    double width_m = 0.0;                   ///< [m] W, along y
    double lower_height_m = 0.0;            ///< [m] height of the lower half: the shear plane
    double upper_height_m = 0.0;            ///< [m] height of the upper frame above the shear plane
    std::vector<double> normal_stresses_Pa; ///< [Pa] one shear run per stress, same bed
    double shear_speed_m_s = 0.0;           ///< [m/s] upper half along +x
    double max_displacement_m = 0.0;        ///< [m] the run stops at this displacement
    double sample_interval_s = 0.005;       ///< [s] forces averaged over each interval
    double residual_fraction = 0.25;        ///< [-] residual tau: mean over this last share of d
    std::optional<double> wall_friction_coefficient; ///< frames and plate; unset: the grains'
    double plate_clearance_m = 0.0005; ///< [m] gap between the top plate's edge and the frame
    double start_clearance_m = 0.001;  ///< [m] plate bottom above the highest grain at start
    /// Top-plate force servo (LabConfig.hpp, physics.md §12.11): shearing starts once N stayed
    /// within consolidation_tolerance for hold_s, which must happen within max_load_time_s.
    ServoSpec servo{0.0, 0.0, 0.0, 0.0, 0.02, 0.3}; // hold 0.02 s, 0.3 s to load
    double control_interval_s = 0.0005;    ///< [s] servo update period (`servo.control_interval_s`)
    double consolidation_tolerance = 0.05; ///< [-] |N - N_target| / N_target (`servo.tolerance`)
    bool fit_cohesion = true;              ///< false: tau = sigma tan psi through the origin
};

struct DirectShearScenario {
    std::string name = "direct_shear";
    dem::DemScenario soil;
    DirectShearSpec test;
    std::vector<config::KeyWarning> warnings; ///< deprecated spellings read, a box too narrow
};

/// Reads `name`, `soil:` (DEM soil keys of docs/scenario.md, without `walls`: the test builds
/// its box) and `direct_shear:`; the deposition region must lie inside the box. The servo's old
/// `max_consolidation_time_s` still reads as `max_load_time_s`, with a line in `warnings`.
DirectShearScenario parseDirectShear(const config::ConfigNode &root);
DirectShearScenario loadDirectShear(const std::string &path);

/// The soil with the box's floor and four side planes as its walls (the deposition's box).
dem::DemScenario boxedSoil(const dem::DemScenario &soil, const DirectShearSpec &box);

struct BoxShearSample {
    double time_s = 0.0;           ///< [s] since shearing started, interval middle
    double displacement_m = 0.0;   ///< [m] d of the upper half, interval middle
    double shear_force_N = 0.0;    ///< [N] x force that moves the upper frame and the plate
    double normal_force_N = 0.0;   ///< [N] N, the soil's reaction on the top plate
    double area_m2 = 0.0;          ///< [m^2] A = W (L - d), the shear plane's overlap
    double shear_stress_Pa = 0.0;  ///< [Pa] tau = F / A
    double normal_stress_Pa = 0.0; ///< [Pa] sigma = (N + m_above g) / A
    double plate_height_m = 0.0;   ///< [m] top plate rise since shearing started (dilatancy)
};

struct BoxShearRun {
    double target_normal_stress_Pa = 0.0; ///< [Pa] as asked (on the full area L W)
    double target_force_N = 0.0;          ///< [N] sigma L W, what the servo holds
    double grains_above_weight_N = 0.0;   ///< [N] grains above the shear plane at the start
    double consolidation_s = 0.0;         ///< [s] simulated time until the load was held
    std::vector<BoxShearSample> samples;
    double peak_shear_stress_Pa = 0.0;      ///< [Pa] largest tau
    double peak_normal_stress_Pa = 0.0;     ///< [Pa] sigma in the same sample
    double peak_displacement_m = 0.0;       ///< [m]
    double residual_shear_stress_Pa = 0.0;  ///< [Pa] mean tau over the last residual_fraction
    double residual_normal_stress_Pa = 0.0; ///< [Pa] mean sigma there
    double mean_normal_force_N = 0.0;       ///< [N] N averaged over the shearing
    double max_normal_force_error = 0.0;    ///< [-] max |N - target| / target over the shearing
    std::uint64_t steps = 0;
    double wall_s = 0.0;
};

/// tau = c + sigma tan psi by least squares (Eigen), standard errors from s^2 (X^T X)^-1.
struct MohrCoulombFit {
    double cohesion_Pa = 0.0;
    double friction_angle_deg = 0.0;    ///< psi
    double cohesion_se_Pa = 0.0;        ///< standard error (0 when not fitted)
    double friction_angle_se_deg = 0.0; ///< through d(atan s)/ds = 1 / (1 + s^2)
    double cohesion_half_width_95_Pa = 0.0;
    double friction_angle_half_width_95_deg = 0.0;
    bool cohesion_fitted = true;
    int degrees_of_freedom = 0;
    double rms_residual_Pa = 0.0;
    std::string describe(const std::string &label) const;
};

/// Fits (sigma_i, tau_i); with_cohesion false forces c = 0. Throws std::invalid_argument with
/// too few points for a standard error (3 with cohesion, 2 without) or when all sigma are equal.
MohrCoulombFit fitMohrCoulomb(const std::vector<double> &normal_stress_Pa,
                              const std::vector<double> &shear_stress_Pa, bool with_cohesion);

struct DirectShearResult : LabResult {
    static constexpr const char *kTest = "direct_shear";
    static constexpr const char *kCsvFiles = "shear_curves.csv,mohr_coulomb.csv";
    std::vector<BoxShearRun> runs; ///< one per normal stress, in the scenario's order
    std::optional<MohrCoulombFit> peak_fit, residual_fit;
    std::string report() const;
    LabSummary summary() const;
    /// shear_curves.csv and mohr_coulomb.csv.
    void writeCsvs(const std::string &directory) const;
};

/// Settles (or reads) the bed once in the closed box, then shears a copy of it per stress
/// (runLabExperiment); writes its outputs into options.output_directory unless empty.
DirectShearResult runDirectShear(const DirectShearScenario &scenario, const LabRunOptions &options);

} // namespace grainlink::lab
