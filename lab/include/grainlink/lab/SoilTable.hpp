#pragma once
// Lookup table from particle parameters to macroscopic soil properties and back: the direct
// shear (and repose) test run over a grid of interparticle friction angle phi and grain-shape
// aspect-ratio angle gamma, and its inversion for a soil's datasheet friction angle psi (and
// angle of repose) without calibration runs (docs/lab.md, docs/physics.md §12.16).
#include "grainlink/config/ConfigNode.hpp"
#include "grainlink/dem/Scenario.hpp"

#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

namespace grainlink::lab {

/// The spec file of `grainlink soil-table`.
struct SoilTableSpec {
    std::string file;                            ///< the spec's path, for messages
    std::string direct_shear_path;               ///< base direct-shear scenario
    std::string repose_path;                     ///< base repose scenario; empty: no repose column
    std::vector<double> friction_angles_deg;     ///< phi: stick and slip angle of the grains
    std::vector<double> aspect_ratio_angles_deg; ///< gamma of the grain-shape law; 0: no rolling
                                                 ///< resistance (the sphere)
    std::optional<bool> fit_cohesion; ///< overrides the direct-shear scenario's fit_cohesion
};
SoilTableSpec parseSoilTableSpec(const config::ConfigNode &root);
SoilTableSpec loadSoilTableSpec(const std::string &path);

/// The soil with interparticle friction phi (stick = slip = phi; Mindlin: mu = tan phi) and the
/// grain-shape rolling law at gamma (gamma = 0: no rolling resistance).
dem::DemScenario soilWithGrainParameters(const dem::DemScenario &soil, double phi_deg,
                                         double gamma_deg);

/// One grid point of the table.
struct SoilTableRow {
    double phi_deg = 0.0, gamma_deg = 0.0;
    double psi_deg = 0.0, psi_half_width_95_deg = 0.0; ///< peak Mohr-Coulomb angle
    double cohesion_Pa = 0.0, cohesion_half_width_95_Pa = 0.0;
    double repose_deg = NAN, repose_half_width_95_deg = NAN; ///< NaN: no repose run
    double bulk_density_kg_m3 = 0.0; ///< [kg/m^3] settled bed of the shear box
    double packing_fraction = 0.0;   ///< [-]
};

struct SoilTableOptions {
    std::string output_csv;     ///< the table
    std::string command_line;   ///< written into the CSV's header
    std::string runs_directory; ///< each run's lab outputs; empty: none kept
    double progress_interval_s = 30.0;
};

/// Runs every (phi, gamma) and writes the table as it goes (a stopped run keeps its rows).
std::vector<SoilTableRow> generateSoilTable(const SoilTableSpec &spec,
                                            const SoilTableOptions &options);

/// The table on its (phi, gamma) grid.
struct SoilTable {
    std::string file;
    std::vector<double> phi_deg, gamma_deg; ///< grid axes, ascending
    /// [phi index][gamma index]
    Eigen::MatrixXd psi, psi_hw, repose, repose_hw, bulk_density, packing;
    bool has_repose = false;
    /// Bilinear interpolation of a grid quantity at (phi, gamma) inside the grid.
    double at(const Eigen::MatrixXd &q, double phi_deg, double gamma_deg) const;
};
/// Reads a table written by generateSoilTable; rows may come in any order but must fill the
/// grid. Errors name the file and the line.
SoilTable readSoilTable(const std::string &path);
SoilTable soilTableFromRows(const std::vector<SoilTableRow> &rows, const std::string &file);

struct SolutionPoint {
    double phi_deg = 0.0, gamma_deg = 0.0;
    double repose_deg = NAN; ///< interpolated at the point
};

/// (phi, gamma) for a target psi (and repose), with what limits its accuracy.
struct SoilInversion {
    double target_psi_deg = 0.0;
    std::optional<double> target_repose_deg;
    std::vector<SolutionPoint> curve; ///< psi(phi, gamma) = target, over the gamma range
    SolutionPoint chosen;
    std::string choice;                            ///< how `chosen` was picked, in words
    double psi_slope_deg_per_deg = 0.0;            ///< d psi / d phi at the point
    double psi_half_width_95_deg = 0.0;            ///< interpolated from the table
    double phi_from_measurement_deg = 0.0;         ///< psi half width / |d psi / d phi|
    std::optional<double> phi_from_resolution_deg; ///< interpolation error / |d psi / d phi|
    double phi_uncertainty_deg = 0.0;              ///< both in quadrature
    double repose_mismatch_deg = NAN;              ///< table repose - target at the point
    double packing_fraction = 0.0, bulk_density_kg_m3 = 0.0;
    std::string describe() const;
    /// The `tangential:` / `rolling:` lines to paste into a scenario's `contact:` block.
    std::string contactBlock() const;
};

/// Throws std::invalid_argument naming the table file and the psi (or repose) range it covers
/// when the target lies outside.
SoilInversion invertSoilTable(const SoilTable &table, double target_psi_deg,
                              std::optional<double> target_repose_deg = std::nullopt);

} // namespace grainlink::lab
