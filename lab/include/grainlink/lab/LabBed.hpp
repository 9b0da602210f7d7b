#pragma once
// What every lab test on a settled bed shares (docs/lab.md): the bed settled once through the
// packing cache and copied per run, the test's axis in the deposition region, the highest grain
// under a round tool, and the wall clock.
#include "grainlink/config/ConfigNode.hpp"
#include "grainlink/dem/DemSystem.hpp"
#include "grainlink/dem/Scenario.hpp"

#include <Eigen/Core>

#include <chrono>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <ostream>
#include <string>

namespace grainlink::lab {

/// A settled bed, prepared once; each run copies `system` (`dem::DemSystem sys = *bed.system`).
struct LabBed {
    std::unique_ptr<dem::DemSystem> system; ///< the settled bed, never stepped by the test
    bool from_cache = false;                ///< the packing came from the packing cache
    double preparation_wall_s = 0.0;        ///< [s] wall time to deposit or read the packing
    std::size_t particles = 0;              ///< grains in the bed
    double largest_radius_m = 0.0;          ///< [m] largest grain radius of the deposition
    double time_step_s = 0.0;               ///< [s] the bed's DEM time step
    double surface_m = 0.0;                 ///< [m] bed surface, dem::bedSurface (98th percentile)
};

/// Settles `soil` (or reads it from the packing cache) via dem::prepareSoil.
LabBed prepareLabBed(const dem::DemScenario &soil, double progress_interval_s);

/// The reports' "  bed: ..." line (grains, largest radius, time step, where the packing came
/// from and how long it took), in the stream's own precision.
void writeBedLine(std::ostream &out, std::size_t particles, double largest_radius_m,
                  double time_step_s, bool from_cache, double preparation_wall_s);

/// Seconds on the steady clock since `since`.
double secondsSince(std::chrono::steady_clock::time_point since);

/// The optional `centre_m: [x, y]` [m] of a test section; fails naming the key unless two numbers.
std::optional<Eigen::Vector2d> parseCentre(const config::ConfigNode &section);

/// The test's axis (x, y) [m]: `centre` when set, else the middle of the deposition region.
Eigen::Vector2d testCentre(const dem::DemScenario &soil,
                           const std::optional<Eigen::Vector2d> &centre);

/// [m] Highest grain top among grains overlapping the vertical cylinder of `radius_m` about
/// `centre`, and at least `floor_m`: a tool started above it never appears inside a grain.
double highestGrainUnder(const dem::ParticleStore &grains, const Eigen::Vector2d &centre,
                         double radius_m, double floor_m);

/// Opens `directory / name` for a lab CSV, writes the `header` line (column names with units)
/// and sets 10 significant digits; throws naming the file when it cannot be written.
std::ofstream openCsv(const std::filesystem::path &directory, const std::string &name,
                      const std::string &header);

} // namespace grainlink::lab
