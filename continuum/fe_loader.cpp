// The front library's deal.II functions: each loads the module librbdem_fe.so once (see fe_module.hpp for why and
// common/module_loader.hpp for where it is looked for) and calls its definition through the module's table.
#include <string>
#include <vector>

#include "common/blas_lock.hpp"
#include "common/module_loader.hpp"
#include "continuum/fe_module.hpp"

namespace rbdem::continuum {

namespace {

const FeModule& module() {
  static const modules::ModuleSpec spec{
      RBDEM_FE_MODULE_NAME,
      "RBDEM_FE_MODULE",
      RBDEM_FE_MODULE_BUILT,
      RBDEM_FE_MODULE_INSTALLED,
      "rbdem_fe_module",
      "the deal.II continuum model",
      "Rebuild rbdem with deal.II (scripts/setup.sh build), or set RBDEM_FE_MODULE to the module's path"};
  // The module's solves hold the program's BLAS lock (common/blas_lock.hpp), handed over once.
  static const FeModule& table = [&]() -> const FeModule& {
    const FeModule& m = modules::load_once<FeModule>(spec);
    m.share_blas_lock(&blas_mutex());
    return m;
  }();
  return table;
}

}  // namespace

FeResult solve_elastic(const TriMesh& mesh, const theory::TIConstants& c, double bedding_deg, double thickness,
                       const FeOptions& options) {
  return module().solve_elastic(mesh, c, bedding_deg, thickness, options);
}

JointedFeResult solve_elastic_jointed(const TriMesh& mesh, const std::vector<theory::TIConstants>& layer_constants,
                                      double bedding_deg, const std::vector<InterfaceEdge>& interfaces,
                                      double thickness, const JointedFeOptions& options) {
  return module().solve_elastic_jointed(mesh, layer_constants, bedding_deg, interfaces, thickness, options);
}

DiscResult solve_disc(const TriMesh& mesh, const theory::TIConstants& c, double bedding_deg, theory::Plane plane,
                      double load, double thickness, const DiscOptions& options) {
  return module().solve_disc(mesh, c, bedding_deg, plane, load, thickness, options);
}

HoleResult solve_hole(const theory::TIConstants& c, double material_angle_deg, theory::Plane plane,
                      const HoleOptions& o) {
  return module().solve_hole(c, material_angle_deg, plane, o);
}

std::vector<std::pair<int, int>> layer_interface_edges(const TriMesh& mesh) {
  return module().layer_interface_edges(mesh);
}

std::vector<int> count_node_copies(const TriMesh& mesh, const std::vector<InterfaceEdge>& interfaces) {
  return module().count_node_copies(mesh, interfaces);
}

std::string dealii_version() { return module().dealii_version(); }

Fe3Result solve_elastic_3d(const TetMesh& mesh, const theory::TIConstants& c, double dip_deg,
                           double dip_direction_deg, const Fe3Options& options) {
  return module().solve_elastic_3d(mesh, c, dip_deg, dip_direction_deg, options);
}

JointedFe3Result solve_elastic_3d_jointed(const TetMesh& mesh, const std::vector<theory::TIConstants>& layer_constants,
                                          double dip_deg, double dip_direction_deg,
                                          const std::vector<InterfaceFace>& interfaces, const Fe3Options& options) {
  return module().solve_elastic_3d_jointed(mesh, layer_constants, dip_deg, dip_direction_deg, interfaces, options);
}

}  // namespace rbdem::continuum
