// Writers of run results: summary.json, curve.csv, cracks.csv, the resolved scene, and (io/result_h5.hpp)
// result.h5 with result.xdmf. Physics never opens files; it hands plain results to these functions.
#pragma once

#include <filesystem>

#include <nlohmann/json.hpp>

#include "dem/driver/result.hpp"
#include "dem/scene.hpp"
#include "dem/specimen.hpp"

namespace rbdem::io {

// The summary.json object of a test run (contract in docs/outputs.md): the shared numbers, the protocol's own
// (TestResult::own) and the resolved scene.
nlohmann::json run_summary(const Scene& scene, const TestResult& r);

// Writes scene.toml, curve.csv, cracks.csv, fragments.csv, crack_rate.csv, result.h5, result.xdmf, forces.xdmf and
// summary.json into `dir` (created if needed), each atomically. summary.json is written last, so a folder with a summary.json
// holds a complete result. `specimen` is the one of the simulation that ran.
// `threads`: how many threads compress result.h5 (the cores the run may still use; 1 beside other runs).
void write_run(const std::filesystem::path& dir, const Scene& scene, const Specimen& specimen, const TestResult& r,
               int threads = 1);

// One row per curve point and per crack, one column per field of the record's table (dem/records.hpp).
void write_curve_csv(const std::filesystem::path& file, int dim, const std::vector<CurvePoint>& curve);
void write_cracks_csv(const std::filesystem::path& file, int dim, const std::vector<Crack>& cracks);
// One row per fragment (dem/driver/signals.hpp), in the given order (largest first).
void write_fragments_csv(const std::filesystem::path& file, const std::vector<Fragment>& fragments, int dim = 2);
// One row per strain bin of the crack rate.
void write_crack_rate_csv(const std::filesystem::path& file, const std::vector<CrackRateBin>& bins);
// Writes `text` to `file` + ".tmp" and renames it to `file` when complete (a reader never sees half a file).
void write_text_atomic(const std::filesystem::path& file, const std::string& text);
// Writes `text` to exactly `file` and checks every write, the fsync and the close: a full disk throws
// std::runtime_error naming the file and how much was written, never a silently truncated file.
void write_file_checked(const std::filesystem::path& file, const std::string& text);
// Creates `dir` if needed and proves it writable with a probe file; throws std::invalid_argument naming the
// folder otherwise (the CLI's exit status 2, before any run starts).
void require_writable_dir(const std::filesystem::path& dir);

}  // namespace rbdem::io
