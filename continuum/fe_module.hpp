// The boundary between the deal.II continuum models and the rest of rbdem.
//
// deal.II and the Trilinos, PETSc and OpenCASCADE libraries it links take about 0.15 s to load and relocate, longer
// than the whole elastic start of a failure run. So the deal.II translation units are built into a module of their
// own, librbdem_fe.so, which is loaded (dlopen) the first time an FE model is solved; a run whose elastic gate is
// cached never loads it. The public functions of fe_model.hpp, fe_joints.hpp, fe_disc.hpp, hole.hpp, fe_3d.hpp and
// fe_joints3.hpp are defined in the front library rbdem_continuum (fe_loader.cpp), which forwards the deal.II solves
// through the table below. Callers include the usual headers and never see the module.
//
// The module is looked for as common/module_loader.hpp says, first at $RBDEM_FE_MODULE when that is set. A
// missing or mismatched module is an error that names the paths tried.
#pragma once

#include <cstddef>
#include <mutex>
#include <string>

#include "continuum/fe_3d.hpp"
#include "continuum/fe_disc.hpp"
#include "continuum/fe_joints.hpp"
#include "continuum/fe_joints3.hpp"
#include "continuum/fe_model.hpp"
#include "continuum/hole.hpp"

namespace rbdem::continuum {

// Bumped whenever a signature below or a struct it passes changes; the sizes catch a stale module as well.
inline constexpr int fe_module_abi = 4;

struct FeModule {
  int abi = fe_module_abi;
  std::size_t sizes[11] = {sizeof(FeOptions),   sizeof(FeResult),   sizeof(JointedFeOptions),
                           sizeof(JointedFeResult), sizeof(DiscOptions), sizeof(DiscResult),
                           sizeof(Fe3Options),  sizeof(Fe3Result), sizeof(TetMesh),
                           sizeof(InterfaceFace), sizeof(JointedFe3Result)};
  FeResult (*solve_elastic)(const TriMesh&, const theory::TIConstants&, double, double, const FeOptions&) = nullptr;
  JointedFeResult (*solve_elastic_jointed)(const TriMesh&, const std::vector<theory::TIConstants>&, double,
                                           const std::vector<InterfaceEdge>&, double,
                                           const JointedFeOptions&) = nullptr;
  DiscResult (*solve_disc)(const TriMesh&, const theory::TIConstants&, double, theory::Plane, double, double,
                           const DiscOptions&) = nullptr;
  HoleResult (*solve_hole)(const theory::TIConstants&, double, theory::Plane, const HoleOptions&) = nullptr;
  std::vector<std::pair<int, int>> (*layer_interface_edges)(const TriMesh&) = nullptr;
  std::vector<int> (*count_node_copies)(const TriMesh&, const std::vector<InterfaceEdge>&) = nullptr;
  std::string (*dealii_version)() = nullptr;
  Fe3Result (*solve_elastic_3d)(const TetMesh&, const theory::TIConstants&, double, double,
                                const Fe3Options&) = nullptr;
  JointedFe3Result (*solve_elastic_3d_jointed)(const TetMesh&, const std::vector<theory::TIConstants>&, double, double,
                                               const std::vector<InterfaceFace>&, const Fe3Options&) = nullptr;
  // The front's BLAS lock (common/blas_lock.hpp), handed over once after loading: the module's direct and AMG
  // solves hold it, so they never run the BLAS beside CHOLMOD, gmsh or each other.
  void (*share_blas_lock)(std::mutex*) = nullptr;
};

}  // namespace rbdem::continuum

// The module's one exported symbol: its table, filled with its own (hidden) definitions of the functions above.
extern "C" const rbdem::continuum::FeModule* rbdem_fe_module();
