#pragma once
// The prepared bed of the lab tests (docs/lab.md): settled once through the packing cache and
// copied per run, measured for summary.json; the test's axis in the deposition region, the
// highest grain under a round tool, the lab CSVs and the wall clock.
#include "grainlink/config/ConfigNode.hpp"
#include "grainlink/dem/DemSystem.hpp"
#include "grainlink/dem/Scenario.hpp"
#include "grainlink/lab/LabSummary.hpp"

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

/// The horizontal area a bed fills and the floor it stands on, for its packing fraction.
struct BedFootprint {
    double area_m2 = 0.0; ///< [m^2]
    double floor_m = 0.0; ///< [m] z of the floor
};
/// The deposition region's: its x-y area and its lower z.
BedFootprint regionFootprint(const dem::DemScenario &soil);

/// A settled bed, prepared once; each run copies `system` (`dem::DemSystem sys = *bed.system`).
struct LabBed {
    std::unique_ptr<dem::DemSystem> system; ///< the settled bed, never stepped by the test
    LabBedSummary summary;                  ///< its grains, surface, packing, seed, wall time
};

/// Settles `soil` (or reads it from the packing cache) via dem::prepareSoil.
LabBed prepareLabBed(const dem::DemScenario &soil, const BedFootprint &footprint,
                     double progress_interval_s);

/// The bed settled in `system` from `soil` on `footprint`: grains, time step, surface, bulk
/// density and packing fraction (docs/physics.md §12.15), the deposition's seed. Leaves
/// from_cache and wall_s to the caller.
LabBedSummary measureBed(const dem::DemSystem &system, const dem::DemScenario &soil,
                         const BedFootprint &footprint);

/// The reports' "  bed: ..." line (grains, largest radius, time step, where the packing came
/// from and how long it took), in the stream's own precision.
void writeBedLine(std::ostream &out, const LabBedSummary &bed);

/// Seconds on the steady clock since `since`.
double secondsSince(std::chrono::steady_clock::time_point since);

/// The test's axis (x, y) [m]: `centre` when set, else the middle of the deposition region.
Eigen::Vector2d testCentre(const dem::DemScenario &soil,
                           const std::optional<Eigen::Vector2d> &centre);

/// Refuses, at `where`, a round tool of `radius_m` about the test's axis that reaches past the
/// bed (the deposition region) in x or y: it would press on the wall, not on the soil.
void refuseBeyondBed(const config::ConfigNode &where, const dem::DemScenario &soil,
                     const std::optional<Eigen::Vector2d> &centre, double radius_m,
                     const std::string &tool);

/// [m] Highest grain top among grains overlapping the vertical cylinder of `radius_m` about
/// `centre`, and at least `floor_m`: a tool started above it never appears inside a grain.
double highestGrainUnder(const dem::ParticleStore &grains, const Eigen::Vector2d &centre,
                         double radius_m, double floor_m);

/// Opens `directory / name` for a lab CSV, writes the `header` line (column names with units)
/// and sets 10 significant digits; throws naming the file when it cannot be written.
std::ofstream openCsv(const std::filesystem::path &directory, const std::string &name,
                      const std::string &header);

} // namespace grainlink::lab
