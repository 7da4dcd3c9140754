// The front of the gmsh module: loads librbdem_gmsh.so once (gmsh_module.hpp says why, common/module_loader.hpp
// where it is looked for) and calls it through the module's table, holding the BLAS (gmsh's meshers call it;
// common/blas_lock.hpp).
#include <string>

#include "common/blas_lock.hpp"
#include "common/module_loader.hpp"
#include "dem/gmsh_module.hpp"

namespace rbdem::gmsh_io {

namespace {

const GmshModule& module() {
  static const modules::ModuleSpec spec{
      RBDEM_GMSH_MODULE_NAME,
      "RBDEM_GMSH_MODULE",
      RBDEM_GMSH_MODULE_BUILT,
      RBDEM_GMSH_MODULE_INSTALLED,
      "rbdem_gmsh_module",
      "the gmsh mesher",
      "Rebuild rbdem (scripts/setup.sh build), or set RBDEM_GMSH_MODULE to the module's path",
      /*lazy=*/true};
  return modules::load_once<GmshModule>(spec);
}

TriMesh mesh_or_throw(MeshOutcome out) {
  if (!out.error.empty()) throw SceneError(out.error);
  return std::move(out.mesh);
}

}  // namespace

TriMesh mesh_with_gmsh(const MeshJob& job) {
  const GmshModule& m = module();
  const BlasLock blas;
  return mesh_or_throw(m.mesh_specimen(job));
}

TriMesh read_with_gmsh(const std::filesystem::path& path) {
  const GmshModule& m = module();
  const BlasLock blas;
  return mesh_or_throw(m.read_msh(path.string()));
}

TetMesh mesh3_with_gmsh(const MeshJob3& job) {
  const GmshModule& m = module();
  const BlasLock blas;
  MeshOutcome3 out = m.mesh_specimen3(job);
  if (!out.error.empty()) throw SceneError(out.error);
  return std::move(out.mesh);
}

TetMesh read3_with_gmsh(const std::filesystem::path& path) {
  const GmshModule& m = module();
  const BlasLock blas;
  MeshOutcome3 out = m.read_msh3(path.string());
  if (!out.error.empty()) throw SceneError(out.error);
  return std::move(out.mesh);
}

}  // namespace rbdem::gmsh_io
