#pragma once
// Angle of repose by the lifted-cylinder test: grains settle in an open tube standing on a rough
// floor, the tube is lifted slowly, the heap that forms is measured (docs/lab.md).
#include "grainlink/dem/Scenario.hpp"

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
};

/// Reads `name`, `soil:` (DEM soil keys, docs/scenario.md) and `repose:`; the deposition region
/// must lie inside the tube.
ReposeScenario parseRepose(const config::ConfigNode &root);
ReposeScenario loadRepose(const std::string &path);

/// Heap surface height in one radial bin.
struct ProfileBin {
    double radius_m = 0.0; ///< [m] bin centre, distance from the tube axis
    double height_m = 0.0; ///< [m] highest grain top in the bin (0: empty)
    std::size_t grains = 0;
};

struct ReposeResult {
    std::size_t particles = 0;
    double largest_radius_m = 0.0;
    double heap_height_m = 0.0;           ///< [m] highest grain top near the axis
    /// [deg] atan of the flank slope; NaN when no heap formed (fewer than 3 flank bins: the
    /// grains spread out, as frictionless or freely rolling spheres do)
    double angle_deg = 0.0;
    double angle_half_width_95_deg = 0.0; ///< [deg] from the slope's regression interval
    std::size_t flank_bins = 0; ///< bins fitted (height in (max(0.2 top, 3 r_max), 0.8 top))
    bool heapFormed() const { return flank_bins >= 3; }
    double settle_time_s = 0.0; ///< [s] after the tube left the heap
    bool settled = false;
    double final_kinetic_energy_per_grain_J = 0.0;
    std::vector<ProfileBin> profile;
    double wall_s = 0.0;
    std::string report() const;
};

struct ReposeOptions {
    std::string output_directory; ///< empty: nothing written
    double progress_interval_s = 5.0;
};

/// Heap profile and angle from grain positions (exposed for tests): bins of `bin_width_m` around
/// `centre`; the flank is the bins whose height lies between 20 % and 80 % of the heap's top
/// and above 3 r_max. Fewer than 3 such bins is no heap: the angle is then NaN.
void measureHeap(const std::vector<Eigen::Vector3d> &positions_m,
                 const std::vector<double> &radii_m, const Eigen::Vector2d &centre_m,
                 double bin_width_m, ReposeResult &result);

ReposeResult runRepose(const ReposeScenario &scenario, const ReposeOptions &options);

/// Writes heap_profile.csv and report.txt into `directory`.
void writeReposeOutputs(const ReposeResult &result, const std::string &directory);

} // namespace grainlink::lab
