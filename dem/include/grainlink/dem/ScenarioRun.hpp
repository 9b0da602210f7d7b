#pragma once
// Drives a DEM scenario: cached deposition, the run phase with prescribed bodies, the time
// series, snapshots, checkpoints, progress and the closing summary.
#include "grainlink/dem/Checkpoint.hpp"
#include "grainlink/dem/Scenario.hpp"

#include <string>

namespace grainlink::dem {

struct RunOptions {
    std::string output_directory;
    bool resume = false; ///< continue from output_directory/checkpoint.bin
    double progress_interval_s = 5.0;
};

struct RunSummary {
    std::size_t particles = 0;
    std::uint64_t steps = 0;
    double simulated_s = 0.0;
    double wall_s = 0.0;
    double particle_steps_per_s = 0.0;
    bool packing_from_cache = false;
};

/// The scenario's system with its settled packing: read from the packing cache when an identical
/// soil setup was settled before, else deposited, settled and cached. No bodies yet.
std::unique_ptr<DemSystem> prepareSoil(const DemScenario &scenario, double progress_interval_s,
                                       bool *from_cache = nullptr);

/// What a resumed run must share with the run that wrote its checkpoint, as checkpoint extras
/// named `fingerprint:<key>`: the time step, the grains (count, seed, radii, material), the
/// contact law's stiffness-setting numbers, and each body (name, triangles, size).
CheckpointExtras scenarioFingerprint(const DemScenario &scenario);

/// Refuses to resume from the checkpoint at `path` (whose extras are `saved`) when the scenario
/// differs from the one that wrote it, naming every key that changed and both values. A
/// checkpoint written before fingerprints existed is accepted.
void checkFingerprint(const CheckpointExtras &saved, const DemScenario &scenario,
                      const std::string &path);

/// Runs to the end; throws (after saving what is readable) on bad input or a failed step.
RunSummary runScenario(const DemScenario &scenario, const RunOptions &options);

} // namespace grainlink::dem
