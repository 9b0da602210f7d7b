#pragma once
// Binary checkpoint of the complete DEM state (particles, contact histories, bodies, clock):
// a run restarted from it continues bit-identically to one that never stopped.
#include "grainlink/dem/DemSystem.hpp"

#include <cstdint>
#include <map>
#include <string>

namespace grainlink::dem {

/// Small named numbers a driver keeps beside the DEM state (phase, output counters, ...).
using CheckpointExtras = std::map<std::string, double>;

/// Writes atomically (temporary file, then rename): a crash never leaves a half-written file.
void writeCheckpoint(const DemSystem &system, const std::string &path,
                     const CheckpointExtras &extras = {});
/// Restores into a system built from the same scenario (same materials, planes and bodies).
/// Throws naming the file when it is missing, truncated or from another format version.
CheckpointExtras readCheckpoint(DemSystem &system, const std::string &path);
/// Only the driver's extras of a checkpoint (to rebuild the bodies before restoring).
CheckpointExtras readCheckpointExtras(const std::string &path);

} // namespace grainlink::dem
