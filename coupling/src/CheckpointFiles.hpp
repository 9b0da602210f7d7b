#pragma once
// The coordinator's side of a checkpoint on disk: <out>/checkpoints/window_<k>/coordinator.pb and
// the `latest` pointer that makes a checkpoint complete. Internal to coupling/.
#include "grainlink/coupling/Types.hpp"

#include <string>
#include <vector>

namespace grainlink::coupling {

/// What the coordinator needs to continue a run from a window boundary.
struct CoordinatorSnapshot {
    std::string run_id;
    std::uint64_t window = 0; ///< the next window to run
    Ticks tick = 0;           ///< its start
    Ticks macro_step_ticks = 0;
    std::vector<BodyState> states;      ///< accepted states at `tick`
    std::vector<Wrench> wrenches;       ///< the last accepted window's wrenches
    double cumulative_mismatch_J = 0.0; ///< [J]
};

/// <output_directory>/checkpoints/window_<window> (9 digits), absolute so that a participant
/// started from another folder writes to the same place.
std::string checkpointDirectory(const std::string &output_directory, std::uint64_t window);

/// Writes manifest.txt (every file in `directory` and the coordinator.pb to come, with its
/// FNV-1a checksum and size, and an end line with their count and the checksum of the list),
/// then coordinator.pb, into `directory` (the participants' parts are there already), then
/// moves <output_directory>/checkpoints/latest to it, each synced and renamed into place: a
/// checkpoint is complete or it does not exist. The two checkpoints before it stay, older ones
/// are removed.
void commitCheckpoint(const std::string &output_directory, const std::string &directory,
                      const CoordinatorSnapshot &snapshot);

/// The last complete checkpoint that is whole (its coordinator.pb readable, every file its
/// manifest lists unchanged), passing over damaged ones newest first with a warning naming the
/// file; `directory` receives its folder. Throws CouplingError when there is none.
CoordinatorSnapshot readLatestCheckpoint(const std::string &output_directory,
                                         std::string &directory);

} // namespace grainlink::coupling
