// The HDF5 result file of a UCS run (result.h5), its XDMF companion for ParaView (result.xdmf), and a reader.
// This is the one writer of the run's full record: the scene, the mesh, the bonds with their breakage, the
// stress-strain history, the crack log and the block positions of every saved frame. The layout is documented
// in docs/outputs.md; in short (T blocks = triangles, N nodes, B bonds, C cracks, P curve points):
//
//   /scene     attributes toml, json (the resolved scene)
//   /mesh      nodes (N x 2, m), triangles (T x 3, ccw), layer (T), centroid (T x 2, m),
//              block_connectivity (T x 3: 3t, 3t+1, 3t+2, the disconnected triangles ParaView draws)
//   /bonds     i, j, node_a, node_b, kind (0 rock, 1 joint), length (m), midpoint (B x 2, m),
//              break_time (s), break_strain (NaN while intact), break_mode (0 intact, 1 tensile, 2 shear)
//   /history   one 1-D dataset per curve.csv column (P rows)
//   /cracks    time_s, strain, x_m, y_m, kind, mode, bond, sigma_pa, tau_pa (C rows, the crack log in order)
//   /frames/NNNNN  x, y, theta (T, double), vertices (3T x 3, float, m, z = 0), damage (T, broken bonds of the
//              block by then); attributes step, time, strain, stress, label, cracks
//   /summary   attribute json (the summary.json text)
//
// HDF5 library: the OpenMPI build, the one deal.II links (io/CMakeLists.txt says why). The file is written under
// a temporary name and renamed when complete.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "dem/scene.hpp"
#include "dem/topology.hpp"
#include "mesh/trimesh.hpp"
#include "dem/driver/ucs.hpp"

namespace rbdem::io {

// Writes result.h5 of one run to `path` (any name; written as path + ".tmp", then renamed). Throws
// std::runtime_error naming the file when HDF5 fails, std::invalid_argument when mesh, topology and result
// disagree (frames or cracks that do not belong to this mesh). The datasets are compressed on `threads` threads.
void write_result_h5(const std::filesystem::path& path, const Scene& scene, const TriMesh& mesh, const Topology& topo,
                     const TestResult& result, int threads = 1);

// Writes the XDMF 3 file that makes `h5_path` (written by write_result_h5) a time series in ParaView: one
// temporal grid per frame, disconnected triangles (3 vertices per block, so cracks open visibly), cell attributes
// layer, damage and rotation (rad). Datasets are referenced by the h5 file's name relative to the XDMF file, so
// keep the two side by side.
void write_result_xdmf(const std::filesystem::path& xdmf_path, const std::filesystem::path& h5_path,
                       std::size_t num_blocks, const std::vector<Frame>& frames);

// What read_result_h5 gives back.
struct StoredRun {
  std::vector<CurvePoint> curve;
  std::vector<Crack> cracks;
  std::vector<Frame> frames;  // metadata always; x, y, theta when read with positions
  TriMesh mesh;               // nodes, triangles, layer (layer_names when stored)
  std::string scene_toml, scene_json, summary_json;
};

// Reads a result.h5. Throws std::runtime_error naming the file and the missing piece when it is not one.
StoredRun read_result_h5(const std::filesystem::path& path, bool with_positions = true);

// Shape of a dataset in an HDF5 file (e.g. "/frames/00003/vertices"), or nothing when the file has no such dataset.
std::optional<std::vector<std::uint64_t>> h5_dataset_shape(const std::filesystem::path& path,
                                                           const std::string& dataset);

}  // namespace rbdem::io
