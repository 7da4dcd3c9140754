// Writers of run results: summary.json, curve.csv, cracks.csv and the resolved scene. Physics never opens files;
// it hands plain results to these functions.
#pragma once

#include <filesystem>

#include <nlohmann/json.hpp>

#include "dem/scene.hpp"
#include "dem/topology.hpp"
#include "dem/ucs.hpp"

namespace rbdem::io {

// The summary.json object of a UCS run (contract in docs/outputs.md).
nlohmann::json ucs_summary(const Scene& scene, const UcsResult& r);

// Writes summary.json, curve.csv, cracks.csv and scene.toml into `dir` (created if needed). summary.json is
// written last and atomically, so a folder with a summary.json holds a complete result.
void write_ucs(const std::filesystem::path& dir, const Scene& scene, const UcsResult& r);

void write_curve_csv(const std::filesystem::path& file, const std::vector<CurvePoint>& curve);
void write_cracks_csv(const std::filesystem::path& file, const std::vector<Crack>& cracks);
void write_text_atomic(const std::filesystem::path& file, const std::string& text);

}  // namespace rbdem::io
