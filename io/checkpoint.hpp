// checkpoint.h5: the full state of an interrupted run (TestCheckpoint: the engine's ModelState and the
// driver's curve, frames and peak tracking), so that `rbdem ucs ... --resume` continues it bit for bit. Layout
// (docs/outputs.md): attributes format, version, scene_toml; /engine (block states, bond broken flags and shear
// history, contact list with shear history, crack log, broad-phase lists, time, step, platen position, energy
// accumulators); /driver (curve, frames, peak sample and frame, sampling and peak-tracking scalars).
// Written under a temporary name and renamed when complete, so a checkpoint on disk is always whole.
#pragma once

#include <filesystem>

#include "dem/driver/ucs.hpp"

namespace rbdem::io {

// Throws std::runtime_error naming the file when HDF5 fails (the previous checkpoint, if any, is untouched).
void write_checkpoint(const std::filesystem::path& path, const TestCheckpoint& checkpoint);
// Throws std::runtime_error naming the file when it is missing or not a checkpoint of this rbdem version.
TestCheckpoint read_checkpoint(const std::filesystem::path& path);

}  // namespace rbdem::io
