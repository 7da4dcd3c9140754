// The gmsh session and the readers of the current gmsh model that dem/specimen_mesh.cpp (meshing) and
// dem/msh_import.cpp (user meshes) share. Internal to the DEM library: not installed for users.
#pragma once

#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "mesh/trimesh.hpp"

namespace rbdem::gmsh_io {

// gmsh keeps global state: one session at a time, always finalized, never left open on an exception.
// Threads: gmsh's option General.NumThreads (default 1) sets the calling thread's OpenMP default through
// omp_set_num_threads. gmsh meshes with OpenMP threads, and a mesh made on two threads differs from run to run, so
// the session meshes on one thread (a mesh is the same for the same inputs, bit for bit). When it ends it puts the
// OpenMP default back as it found it: before, it stayed at one thread, and every engine built later in that thread
// with numerics.threads = 0 ("all cores") ran on one core.
class GmshSession {
 public:
  GmshSession();
  ~GmshSession();
  GmshSession(const GmshSession&) = delete;
  GmshSession& operator=(const GmshSession&) = delete;

 private:
  std::lock_guard<std::mutex> lock_;
  int omp_threads_;
};

// A mesh realization's grading: for each (curve tag, point count with both ends) of the current model, in order,
// the curve's 1D mesh set to that many points in a geometric progression whose log-ratio from its first to its
// last segment is amplitude x (2u - 1), u uniform in [0, 1) from a std::mt19937_64 seeded with `seed` (one draw per
// curve, the same sequence on every platform). A curve of fewer than three points is left as it is.
void grade_by_progression(const std::vector<std::pair<int, int>>& points, int seed, double amplitude);

// The last gmsh error message, or `fallback`.
std::string gmsh_error(const std::string& fallback);

// Orients every triangle counter-clockwise and snaps nodes lying within `tol` of the rectangle's sides
// onto them exactly (OpenCASCADE returns 0.09999999999999999 for 0.1).
void tidy(TriMesh& mesh, double width, double height, double tol);

// Collects the first-order triangles of the current gmsh model, one layer per entry of `layer_entities`, and the
// line elements of its physical curve groups as TriMesh::interfaces (unnamed groups are called "curve_<tag>").
TriMesh collect_triangles(const std::vector<std::vector<int>>& layer_entities, std::vector<std::string> names,
                          const std::string& source);

}  // namespace rbdem::gmsh_io
