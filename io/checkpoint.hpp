// checkpoint.h5: the full state of an interrupted run (TestCheckpoint: the simulation's snapshot and the driver's
// curve, frames and peak tracking), so that `rbdem ucs ... --resume` continues it bit for bit. Layout
// (docs/outputs.md): attributes format, version, scene_toml, test; /state (every field of the snapshot: the block
// states, the bond and contact histories, the crack log, the broad-phase lists, the clock, the energy accounts;
// the boundary components' fields in their groups, e.g. /state/platens; scalars as attributes, arrays as datasets,
// each with its type and extent beside it); /driver (curve, frames, peak sample and frame, sampling and
// peak-tracking scalars). Written under a temporary name and renamed when complete, so a checkpoint on disk is
// always whole.
#pragma once

#include <filesystem>

#include "dem/driver/result.hpp"

namespace rbdem::io {

// Throws std::runtime_error naming the file when HDF5 fails (the previous checkpoint, if any, is untouched).
void write_checkpoint(const std::filesystem::path& path, const TestCheckpoint& checkpoint);
// Throws std::runtime_error naming the file when it is missing or not a checkpoint of this rbdem version.
TestCheckpoint read_checkpoint(const std::filesystem::path& path);

}  // namespace rbdem::io
