// The HDF5 result file of a run (result.h5), its XDMF companion for ParaView (result.xdmf), and a reader.
// This is the one writer of the run's full record: the scene, the mesh, the bonds with their breakage, the
// stress-strain history, the crack log and the block poses of every saved frame. The layout is documented in
// docs/outputs.md; in short (T blocks = cells, N nodes, B bonds, C cracks, P curve points, d the dimension, v the
// vertices of a cell):
//
//   /scene     attributes toml, json (the resolved scene)
//   /mesh      nodes (N x d, m), triangles (2D) or tetrahedra (3D) (T x v), layer (T), centroid (T x d, m),
//              block_connectivity (T x v: v t .. v t + v - 1, the disconnected cells ParaView draws)
//   /bonds     i, j, node_a, node_b (2D; 3D: nodes, B x 3), kind (0 rock, 1 joint), length (2D, m; 3D: area, m^2),
//              midpoint (B x d, m), break_time (s), break_strain (NaN while intact), break_mode (0 intact,
//              1 tensile, 2 shear)
//   /history   one 1-D dataset per field of the curve (CurvePoint's table, dem/records.hpp; P rows)
//   /cracks    one 1-D dataset per field of the crack log (Crack's table; C rows, in order), orientation_deg
//   /frames/NNNNN  the pose components (2D: x, y, theta; T each, double), vertices (v T x 3, float, m), damage
//              (T, broken bonds of the block by then); attributes: Frame's table (step, time, strain, stress,
//              label, cracks)
//   /frames/NNNNN/network  the force network (L links: intact bonds, then contacts): centroid (T x 3, float, m),
//              blocks (L x 2), kind (L, uint8: 0 bond, 1 contact), force (L x 3, float, N, on the second block),
//              normal_force (L, float, N, tension positive)
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

#include "dem/driver/result.hpp"
#include "dem/scene.hpp"
#include "dem/specimen.hpp"

namespace rbdem::io {

// Writes result.h5 of one run to `path` (any name; written as path + ".tmp", then renamed). Throws
// std::runtime_error naming the file when HDF5 fails, std::invalid_argument when the specimen and the result
// disagree (frames or cracks that do not belong to it). The datasets are compressed on `threads` threads.
void write_result_h5(const std::filesystem::path& path, const Scene& scene, const Specimen& specimen,
                     const TestResult& result, int threads = 1);

// Writes the XDMF 3 file that makes `h5_path` (written by write_result_h5) a time series in ParaView: one
// temporal grid per frame, disconnected cells (each block's own vertices, so cracks open visibly), cell attributes
// layer, damage and (2D) rotation (rad). Datasets are referenced by the h5 file's name relative to the XDMF file,
// so keep the two side by side. `test` names the run in the file.
void write_result_xdmf(const std::filesystem::path& xdmf_path, const std::filesystem::path& h5_path,
                       const Specimen& specimen, const std::string& test, const std::vector<Frame>& frames);

// Writes forces.xdmf: the force network of each frame of `h5_path` as a time series of line cells between the
// block centroids (one per intact bond, then one per contact), with cell attributes normal_force (N, tension
// positive), force (the vector on the second block, N) and kind (0 bond, 1 contact). Keep it beside the h5 file.
void write_network_xdmf(const std::filesystem::path& xdmf_path, const std::filesystem::path& h5_path,
                        const Specimen& specimen, const std::string& test, const std::vector<Frame>& frames);

// What read_result_h5 gives back.
struct StoredRun {
  std::vector<CurvePoint> curve;
  std::vector<Crack> cracks;
  std::vector<Frame> frames;  // the scalars always; the poses and force networks when read with positions
  int dim = 2;
  std::vector<double> nodes;  // the mesh: nodes (dim per node), cells, layer per cell, layer names when stored
  std::vector<int> cells, layer;
  std::vector<std::string> layer_names;
  std::string scene_toml, scene_json, summary_json;
};

// Reads a result.h5. Throws std::runtime_error naming the file and the missing piece when it is not one.
StoredRun read_result_h5(const std::filesystem::path& path, bool with_positions = true);

// Shape of a dataset in an HDF5 file (e.g. "/frames/00003/vertices"), or nothing when the file has no such dataset.
std::optional<std::vector<std::uint64_t>> h5_dataset_shape(const std::filesystem::path& path,
                                                           const std::string& dataset);

}  // namespace rbdem::io
