#pragma once
// The seed's parameter estimation without calibration runs (Lichtenheldt & Schaefer 2013,
// section 2.3): from a soil and test description to the full parameter matrix Lambda_P (eq. 9),
// every derived value naming the equation it comes from (docs/physics.md §12, docs/lab.md).
#include "grainlink/config/ConfigNode.hpp"

#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

namespace grainlink::lab {

/// What `grainlink params` reads: the soil, the test the bed is for, and the modelling choices.
struct SoilTestDescription {
    std::string name = "soil";
    // soil
    double grain_density_kg_m3 = 0.0; ///< [kg/m^3] rho_p, the grains' solid density
    double poisson_ratio = 0.0;       ///< [-] nu, from the material
    double stick_angle_deg = 0.0;     ///< [deg] phi_h (seed eq. 5)
    double slip_angle_deg = 0.0;      ///< [deg] phi_g <= phi_h
    Eigen::Vector3d aspect_ratios = Eigen::Vector3d::Ones(); ///< [-] A_i per body axis (eq. 6)
    // test
    double expected_pressure_Pa = 0.0; ///< [Pa] p, the soil pressure expected under the tool
    double tool_size_m = 0.0;          ///< [m] L_min, smallest tool dimension (eq. 11)
    double plate_radius_m = 0.0;       ///< [m] R in eq. 10
    double bed_height_m = 0.0;         ///< [m] height of the grain bed
    double expected_sinkage_m = 0.0;   ///< [m] z_h = bed height - expected sinkage
    double gravity_m_s2 = 9.81;        ///< [m/s^2] g
    // model
    double resolution = 0.0;                  ///< [-] Gamma (eq. 11)
    double max_overlap_ratio = 0.0;           ///< [-] a_max = delta / r (eq. 10)
    double damping_fraction = 0.0;            ///< [-] of the critical damping, seed: 0.02..0.15
    double tangential_stiffness_ratio = 0.03; ///< [-] c_T / c_n (seed's lower bound)
    double radius_ratio_min_max = 1.0;        ///< [-] r_min / r_max of the size distribution
    double time_step_safety_factor = 0.5;     ///< [-] recommended dt = factor * stable limit
    std::optional<double> youngs_modulus_Pa;  ///< [Pa] given E instead of the minimum one

    /// Throws std::invalid_argument naming the quantity and its admissible range.
    void validate() const;
};

/// Reads the description (docs/lab.md); errors name the file, key and line.
SoilTestDescription parseSoilTestDescription(const config::ConfigNode &root);
SoilTestDescription loadSoilTestDescription(const std::string &path);

/// One derived quantity with its source, as printed and written by `grainlink params`.
struct DerivedValue {
    std::string key;    ///< name with unit, e.g. "youngs_modulus_Pa"
    std::string row;    ///< row of Lambda_P: normal, tangential, rotational, or "-"
    double value = 0.0; ///< SI
    std::string source; ///< "eq. 10", "input", ...
};

/// Lambda_P (eq. 9) and what it was derived from.
struct ParameterMatrix {
    SoilTestDescription input;
    // geometry (eq. 11)
    double radius_max_m = 0.0; ///< [m] r_max = L_min / (2 Gamma)
    double radius_min_m = 0.0; ///< [m] r_min = ratio * r_max
    // stiffness (eq. 10)
    double column_height_m = 0.0;              ///< [m] z_h
    double plate_force_share_N = 0.0;          ///< [N] (2 pi / 3) p R r
    double column_weight_N = 0.0;              ///< [N] (2 pi / 3) r^2 z_h rho g
    double worst_contact_force_N = 0.0;        ///< [N] F_max, the sum
    double normal_stiffness_N_m = 0.0;         ///< [N/m] c_n = F_max / (a_max r_max)
    double minimum_youngs_modulus_Pa = 0.0;    ///< [Pa] Hertz at a_max carries F_max
    double youngs_modulus_Pa = 0.0;            ///< [Pa] the minimum, or the given one
    double overlap_ratio_at_worst_force = 0.0; ///< [-] delta / r under F_max with that E
    double tangential_stiffness_N_m = 0.0;     ///< [N/m] c_T = ratio * c_n
    // damping: the stiffest pair is two smallest grains at the allowed overlap
    double stiffest_pair_stiffness_N_m = 0.0; ///< [N/m] Hertz tangent stiffness dF/d(delta)
    double stiffest_pair_mass_kg = 0.0;       ///< [kg] m* = m_min / 2
    double critical_damping_N_s_m = 0.0;      ///< [N s/m] 2 sqrt(k m*)
    double normal_damping_N_s_m = 0.0;        ///< [N s/m] k_N = fraction * critical
    double tangential_damping_N_s_m = 0.0;    ///< [N s/m] k_T = fraction * 2 sqrt(c_T m*)
    // inertia (eq. 12) of the largest grain, per body axis
    double grain_mass_max_kg = 0.0;          ///< [kg]
    Eigen::Vector3d inertia_kg_m2;           ///< [kg m^2] J_i = (1/9) pi rho r^3 (r / A_i)^2
    double solid_sphere_inertia_kg_m2 = 0.0; ///< [kg m^2] (8/15) pi rho r^5, for comparison
    // time step
    double rayleigh_time_s = 0.0;    ///< [s] T_R of the smallest grain
    double oscillator_limit_s = 0.0; ///< [s] 2 (sqrt(1 + zeta^2) - zeta) / omega, stiffest pair
    double dashpot_limit_s = 0.0;    ///< [s] m_min / k_N (grainlink's viscous check)
    double grainlink_limit_s = 0.0;  ///< [s] min(T_R / 2, m_min / k_N): what `dem` refuses above
    double stable_time_step_s = 0.0; ///< [s] min of all the limits above
    double recommended_time_step_s = 0.0; ///< [s] safety factor * stable

    /// Every value in printing order, each with its row of Lambda_P and its source.
    std::vector<DerivedValue> values() const;
};

/// Worst-case contact force of eq. 10 for grains of radius r (see docs/physics.md §12.2).
double worstContactForce(const SoilTestDescription &d, double radius_m);
/// Hertz force between two equal grains of radius r at overlap ratio a (seed eq. 3).
double hertzForceEqualGrains(double youngs_modulus_Pa, double poisson_ratio, double radius_m,
                             double overlap_ratio);
/// Rayleigh time of a grain (docs/physics.md §3.3).
double rayleighTime(double youngs_modulus_Pa, double poisson_ratio, double density_kg_m3,
                    double radius_m);

/// Derives Lambda_P; throws std::invalid_argument on an invalid description.
ParameterMatrix estimateParameters(const SoilTestDescription &description);

/// The matrix as a table for the terminal.
std::string formatTable(const ParameterMatrix &matrix);
/// `key: value  # row, source` lines (YAML) or `key,row,value,source` rows (CSV).
std::string formatYaml(const ParameterMatrix &matrix);
std::string formatCsv(const ParameterMatrix &matrix);
/// A `soil:` block in grainlink's scenario format (docs/scenario.md): simulation.time_step_s,
/// material and contact; deposition, walls and the rest are the user's.
std::string soilBlock(const ParameterMatrix &matrix);

} // namespace grainlink::lab
