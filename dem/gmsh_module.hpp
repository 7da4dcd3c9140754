// The boundary between gmsh and the rest of rbdem. Internal to the DEM library: not installed for users.
//
// gmsh and the OpenCASCADE, FLTK, MED and other libraries it links take about 0.09 s to load and relocate, longer
// than meshing the default specimen and a tenth of a whole 60 deg UCS run on two threads. Only meshing a specimen
// and reading a .msh file need gmsh, and a run whose mesh is cached (mesh_cache.hpp) does neither. So the gmsh
// translation units (gmsh_session.cpp, gmsh_mesher.cpp) are built into a module of their own, librbdem_gmsh.so,
// which is loaded (dlopen) the first time a mesh is made or read; mesh_specimen and read_msh (specimen_mesh.hpp)
// do the checks that need no gmsh themselves and hand the rest to the module through the table below. The module
// is looked for as common/module_loader.hpp says, first at $RBDEM_GMSH_MODULE when that is set.
#pragma once

#include <array>
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "dem/specimen_mesh.hpp"
#include "dem/specimen_mesh3.hpp"
#include "mesh/tetmesh.hpp"
#include "mesh/trimesh.hpp"

namespace rbdem::gmsh_io {

// What the module needs to mesh a specimen: the geometry, its joint segments (already chosen), and the unit
// vectors SpecimenGeometry computes (so that the module links none of the DEM library).
struct MeshJob {
  SpecimenGeometry geometry;
  std::vector<JointSegment> segments;
  std::array<std::array<double, 2>, 2> direction{};  // along the joints of set 0 and set 1
  std::array<double, 2> normal{};                    // the first set's normal (orders the layers)
  double h = 0.0;                                    // target edge length, m
  std::string msh_out;                               // also write the mesh here when not empty
};

// A mesh, or why there is none: the module throws nothing across its boundary.
struct MeshOutcome {
  TriMesh mesh;
  std::string error;  // empty on success; else the message of the SceneError the caller raises
};

// What the module needs to mesh a 3D specimen: the solid and the joint planes that cut it (already chosen).
struct MeshJob3 {
  SpecimenGeometry3 geometry;
  std::vector<JointPlane> planes;
  std::array<double, 3> centre{};  // SpecimenGeometry3::centre() (the module links none of the DEM library)
  double h = 0.0;                  // target edge length, m
  int seed = 0;                    // mesh realization (mesh.seed): 0 = the reference mesh (mesh_specimen3)
};

struct MeshOutcome3 {
  TetMesh mesh;
  std::string error;  // empty on success
};

// Bumped whenever a signature below or a struct it passes changes; the sizes catch a stale module as well.
inline constexpr int gmsh_module_abi = 6;

struct GmshModule {
  int abi = gmsh_module_abi;
  std::size_t sizes[7] = {sizeof(MeshJob),  sizeof(MeshOutcome),       sizeof(TriMesh), sizeof(SpecimenGeometry),
                          sizeof(MeshJob3), sizeof(SpecimenGeometry3), sizeof(TetMesh)};
  MeshOutcome (*mesh_specimen)(const MeshJob&) = nullptr;
  // The triangles and interfaces of a .msh file that has passed read_msh's pre-scan.
  MeshOutcome (*read_msh)(const std::string& path) = nullptr;
  // The tetrahedra of a 3D specimen (specimen_mesh3.hpp).
  MeshOutcome3 (*mesh_specimen3)(const MeshJob3&) = nullptr;
  // The tetrahedra of a user .msh file, one layer per physical volume (specimen_mesh3.hpp, read_msh3).
  MeshOutcome3 (*read_msh3)(const std::string& path) = nullptr;
};

// The front's calls (gmsh_loader.cpp): each loads the module at the first call (thread-safe; std::runtime_error
// naming the paths tried when no module fits) and raises the module's error as a SceneError.
TriMesh mesh_with_gmsh(const MeshJob& job);
TriMesh read_with_gmsh(const std::filesystem::path& path);
TetMesh mesh3_with_gmsh(const MeshJob3& job);
TetMesh read3_with_gmsh(const std::filesystem::path& path);

// The module's 3D mesher (gmsh_mesher3.cpp), which the table above points to.
MeshOutcome3 mesh_specimen3(const MeshJob3& job);
MeshOutcome3 read_msh3(const std::string& path);

}  // namespace rbdem::gmsh_io

// The module's one exported symbol: its table, filled with its own (hidden) definitions of the functions above.
extern "C" const rbdem::gmsh_io::GmshModule* rbdem_gmsh_module();
