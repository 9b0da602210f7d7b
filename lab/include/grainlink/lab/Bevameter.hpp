#pragma once
// Virtual bevameter, pressure-sinkage: a circular plate pushed at constant speed into a settled
// bed, p(z) per plate size, and Bekker's law fitted over the sizes (docs/lab.md).
#include "grainlink/config/ConfigNode.hpp"
#include "grainlink/dem/Scenario.hpp"
#include "grainlink/lab/BekkerFit.hpp"
#include "grainlink/lab/LabExperiment.hpp"

#include <optional>
#include <string>
#include <vector>

namespace grainlink::lab {

/// The `bevameter:` section.
struct BevameterSpec {
    std::vector<double> plate_radii_m;                ///< [m] one run per plate
    double plate_thickness_m = 0.0;                   ///< [m] 0: a fifth of the radius
    int plate_segments = 48;                          ///< facets around the rim
    std::optional<double> plate_friction_coefficient; ///< unset: the grains' own angles
    double speed_m_s = 0.0;                           ///< [m/s] downward plate speed
    double max_sinkage_m = 0.0;                       ///< [m] the run stops at this sinkage
    double start_clearance_m = 0.001;        ///< [m] plate bottom above the highest grain under it
    double sample_interval_s = 0.005;        ///< [s] force averaged over each interval
    double min_resolution = 10.0;            ///< [-] required R / r_max (seed: Gamma >= 10)
    std::optional<Eigen::Vector2d> centre_m; ///< [m] plate axis (x, y); unset: region centre
    double fit_min_sinkage_m = 0.0;          ///< [m] points at smaller sinkage are not fitted
};

struct BevameterScenario {
    std::string name = "bevameter";
    dem::DemScenario soil;
    BevameterSpec test;
    std::vector<config::KeyWarning> warnings; ///< deprecated spellings read
};

/// Reads `name`, `soil:` (the DEM soil keys of docs/scenario.md) and `bevameter:`.
BevameterScenario parseBevameter(const config::ConfigNode &root);
BevameterScenario loadBevameter(const std::string &path);

struct BevameterSample {
    double time_s = 0.0;      ///< [s] since the plate started moving, interval middle
    double sinkage_m = 0.0;   ///< [m] plate bottom below the settled surface, interval mean
    double force_N = 0.0;     ///< [N] vertical soil reaction, interval mean (impulse / time)
    double pressure_Pa = 0.0; ///< [Pa] force / (pi R^2)
};

struct PlateRun {
    double plate_radius_m = 0.0;
    double resolution = 0.0;    ///< [-] R / r_max (Gamma with L_min = 2 R)
    double surface_m = 0.0;     ///< [m] settled bed surface (98th percentile of grain tops)
    double wall_gap_m = 0.0;    ///< [m] plate rim to the nearest side of the region
    double depth_below_m = 0.0; ///< [m] bed left under the plate at the largest sinkage
    std::vector<BevameterSample> samples;
    std::uint64_t steps = 0;
    double wall_s = 0.0;
    PressureSinkageCurve curve() const;
};

struct BevameterResult : LabResult {
    static constexpr const char *kTest = "bevameter";
    static constexpr const char *kCsvFiles = "pressure_sinkage.csv,bekker_fit.csv";
    std::vector<PlateRun> runs; ///< one per plate, in the scenario's order
    std::optional<BekkerFit> fit;
    std::string report() const;
    LabSummary summary() const;
    /// pressure_sinkage.csv and bekker_fit.csv.
    void writeCsvs(const std::string &directory) const;
};

/// Settles (or reads) the bed once, runs every plate on a copy of it, fits Bekker's law
/// (runLabExperiment); writes its outputs into options.output_directory unless empty.
BevameterResult runBevameter(const BevameterScenario &scenario, const LabRunOptions &options);

} // namespace grainlink::lab
