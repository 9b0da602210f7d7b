#pragma once
// Angle of repose by the lifted-cylinder test: grains settle in an open tube standing on a rough
// floor, the tube is lifted slowly, the heap that forms is measured (docs/lab.md).
#include "grainlink/config/ConfigNode.hpp"
#include "grainlink/dem/Scenario.hpp"
#include "grainlink/lab/LabExperiment.hpp"

#include <optional>
#include <string>
#include <vector>

namespace grainlink::lab {

/// The `repose:` section.
struct ReposeSpec {
    double tube_radius_m = 0.0;              ///< [m] inner radius of the open tube
    double tube_height_m = 0.0;              ///< [m] tube length; it stands on the floor at z = 0
    int tube_segments = 48;                  ///< facets around
    double lift_speed_m_s = 0.0;             ///< [m/s] upward tube speed
    double settle_kinetic_energy_J = 1e-8;   ///< [J] heap settled below this mean KE per grain ...
    double max_settle_time_s = 1.0;          ///< [s] ... or after this long once the tube is off
    double bin_width_m = 0.0;                ///< [m] radial bin of the profile; 0: 2 r_max
    std::optional<Eigen::Vector2d> centre_m; ///< [m] tube axis; unset: deposition region centre
};

struct ReposeScenario {
    std::string name = "repose";
    dem::DemScenario soil;
    ReposeSpec test;
    std::vector<config::KeyWarning> warnings; ///< deprecated spellings read
};

/// Reads `name`, `soil:` (DEM soil keys, docs/scenario.md, without `packing_cache_directory`:
/// the fill is never cached) and `repose:`; the deposition region must lie inside the tube.
ReposeScenario parseRepose(const config::ConfigNode &root);
ReposeScenario loadRepose(const std::string &path);

/// Heap surface height in one radial bin.
struct ProfileBin {
    double radius_m = 0.0; ///< [m] bin centre, distance from the tube axis
    double height_m = 0.0; ///< [m] highest grain top in the bin (0: empty)
    std::size_t grains = 0;
};

/// The lift: the tube drawn off the fill at lift_speed_m_s, the heap left to come to rest.
struct ReposeRun {
    double lift_speed_m_s = 0.0; ///< [m/s]
    double settle_time_s = 0.0;  ///< [s] after the tube left the heap
    bool settled = false;
    double final_kinetic_energy_per_grain_J = 0.0;
    std::vector<Eigen::Vector3d> positions_m; ///< [m] the grains at the end: the heap
    std::vector<double> radii_m;              ///< [m]
    double wall_s = 0.0;
};

struct ReposeResult : LabResult {
    static constexpr const char *kTest = "repose";
    static constexpr const char *kCsvFiles = "heap_profile.csv";
    std::vector<ReposeRun> runs; ///< the one lift
    // The heap measured from the lift's grains (measureHeap): the test's fit.
    double heap_height_m = 0.0; ///< [m] highest grain top near the axis
    /// [deg] atan of the flank slope; NaN when no heap formed (fewer than 3 flank bins: the
    /// grains spread out, as frictionless or freely rolling spheres do)
    double angle_deg = 0.0;
    double angle_half_width_95_deg = 0.0; ///< [deg] from the slope's regression interval
    std::size_t flank_bins = 0; ///< bins fitted (height in (max(0.2 top, 3 r_max), 0.8 top))
    bool heapFormed() const { return flank_bins >= 3; }
    std::vector<ProfileBin> profile;
    std::string report() const;
    LabSummary summary() const;
    /// heap_profile.csv.
    void writeCsvs(const std::string &directory) const;
};

/// Heap profile and angle from grain positions (exposed for tests): bins of `bin_width_m` around
/// `centre`; the flank is the bins whose height lies between 20 % and 80 % of the heap's top
/// and above 3 r_max. Fewer than 3 such bins is no heap: the angle is then NaN.
void measureHeap(const std::vector<Eigen::Vector3d> &positions_m,
                 const std::vector<double> &radii_m, const Eigen::Vector2d &centre_m,
                 double bin_width_m, ReposeResult &result);

/// Fills the tube, lifts it, measures the heap (runLabExperiment: the fill is the bed, the lift
/// the one run, the heap's flank line the fit; no heap leaves the angle NaN and says so in
/// fit_note). Writes its outputs into options.output_directory unless empty.
ReposeResult runRepose(const ReposeScenario &scenario, const LabRunOptions &options);

} // namespace grainlink::lab
