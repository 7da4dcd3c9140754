// The linear solves shared by continuum/'s deal.II models (solvers.hpp): UMFPACK, and CG with smoothed-aggregation
// AMG (Trilinos ML) whose near null space is the rigid-body modes of plane elasticity, with the MPI set-up and the
// lock Trilinos needs. docs/continuum.md ("Solvers", "MPI") describes the settings and why.
#include "continuum/solvers.hpp"
#include "continuum/fe_internal.hpp"

#include <deal.II/base/index_set.h>
#include <deal.II/fe/fe.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/sparse_direct.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>

#include <Epetra_MultiVector.h>
#include <Teuchos_ParameterList.hpp>
#include <mpi.h>

#include <atomic>
#include <cassert>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>

namespace rbdem::continuum::internal {

namespace {

using namespace dealii;
constexpr int dim = 2;

// Trilinos runs under MPI_THREAD_SERIALIZED: every CG+AMG solve of continuum/, whichever model it belongs to, holds
// this one lock, so two threads (e.g. the elastic gate's dips, run two at a time) never enter Trilinos together.
std::mutex& trilinos_mutex() {
  static std::mutex m;
  return m;
}

// The BLAS lock (share_blas_lock): the front's once it is handed over, the module's own before.
std::mutex own_blas;
std::atomic<std::mutex*> shared_blas{nullptr};
std::mutex& blas() {
  std::mutex* m = shared_blas.load();
  return m ? *m : own_blas;
}

// Initialises MPI once for the whole process (Trilinos needs it even serially; docs/continuum.md, "Solvers"), unless
// the application already did (mpirun). Throws std::runtime_error naming `solver` and the option that avoids
// Trilinos (`direct_option`) when MPI has already been finalised.
void ensure_mpi(const char* solver, const std::string& direct_option) {
  static std::once_flag once;
  std::call_once(once, [&] {
    int initialized = 0;
    MPI_Initialized(&initialized);
    if (initialized) return;  // the application (e.g. under mpirun) owns MPI: leave it alone
    int finalized = 0;
    MPI_Finalized(&finalized);
    if (finalized)
      throw std::runtime_error(std::string(solver) +
                               ": MPI has already been finalised, but the CG+AMG solver (Trilinos) needs it; solve "
                               "before MPI_Finalize or use " + direct_option);
    int provided = 0;
    MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided);
    std::atexit([] {
      int done = 0;
      MPI_Finalized(&done);
      if (!done) MPI_Finalize();
    });
  });
}

// The rigid-body modes of plane elasticity at the DoFs: u = (1, 0), (0, 1) and the rotation (-(y - yc), x - xc)
// about `centre`. With the rotation ML needs a third fewer CG iterations than with the two translations of
// DoFTools::extract_constant_modes (P2 at 1e5 DoFs: 30 instead of 44). Built by hand: deal.II 9.4.1 has no
// DoFTools::extract_rigid_body_modes.
void fill_rigid_body_modes(const DofGeometry& geometry, const Point<dim>& centre, Epetra_MultiVector& modes) {
  const double xc = centre[0], yc = centre[1];
  for (std::size_t i = 0; i < geometry.component.size(); ++i) {
    const bool x = geometry.component[i] == 0;
    assert(x == (i % 2 == 0));  // node-wise (u_x, u_y) pairs, as "PDE equations" = 2 assumes
    modes[0][i] = x ? 1.0 : 0.0;
    modes[1][i] = x ? 0.0 : 1.0;
    modes[2][i] = x ? -(geometry.point[i][1] - yc) : geometry.point[i][0] - xc;
  }
}

}  // namespace

DofGeometry dof_geometry(const DoFHandler<dim>& dof) {
  const FiniteElement<dim>& fe = dof.get_fe();
  DofGeometry g;
  g.point.resize(dof.n_dofs());
  g.component.resize(dof.n_dofs());
  std::vector<types::global_dof_index> local(fe.n_dofs_per_cell());
  for (const auto& cell : dof.active_cell_iterators()) {
    cell->get_dof_indices(local);
    const Point<dim> v0 = cell->vertex(0);
    const Tensor<1, dim> e1 = cell->vertex(1) - v0, e2 = cell->vertex(2) - v0;
    for (unsigned i = 0; i < local.size(); ++i) {
      const Point<dim>& xi = fe.unit_support_point(i);
      g.point[local[i]] = v0 + xi[0] * e1 + xi[1] * e2;
      g.component[local[i]] = static_cast<unsigned char>(fe.system_to_component_index(i).first);
    }
  }
  return g;
}

namespace {

// Smoothed-aggregation AMG (Trilinos ML, deal.II's elliptic defaults: Chebyshev smoother of degree 2, KLU on the
// coarsest level) with the rigid-body modes as near null space (`fill_modes` writes `n_modes` of them), preconditioning
// CG on the deal.II matrix. The DoFs of a node are consecutive (FESystem numbering), which ML's "PDE equations" =
// `components` needs. Trilinos runs on MPI_COMM_SELF: serial on each rank under mpirun.
template <class FillModes>
CgAmgReport run_cg_amg(const SparseMatrix<double>& K, const Vector<double>& b, Vector<double>& u, int components,
                       int n_modes, FillModes fill_modes, double tolerance, unsigned max_iterations, bool higher_order,
                       const SolveCaller& caller) {
  Stopwatch clock;
  CgAmgReport report;
  std::lock_guard<std::mutex> lock(trilinos_mutex());
  std::lock_guard<std::mutex> blas_lock(blas());  // after Trilinos's: the one order both are taken in
  ensure_mpi(caller.function, std::string(caller.options) + "::solver = Solver::direct");
  const auto n = K.m();
  TrilinosWrappers::SparseMatrix K_epetra;
  K_epetra.reinit(complete_index_set(n), complete_index_set(n), K, MPI_COMM_SELF, 0.0, true);

  TrilinosWrappers::PreconditionAMG::AdditionalData data;
  data.elliptic = true;
  data.higher_order_elements = higher_order;
  Teuchos::ParameterList parameters;
  std::unique_ptr<Epetra_MultiVector> no_modes;  // deal.II's constant modes would give translations only
  data.set_parameters(parameters, no_modes, K_epetra);
  Epetra_MultiVector modes(K_epetra.trilinos_matrix().OperatorDomainMap(), n_modes);
  fill_modes(modes);
  parameters.set("null space: type", "pre-computed");
  parameters.set("null space: dimension", modes.NumVectors());
  parameters.set("null space: vectors", modes.Values());
  parameters.set("PDE equations", components);

  TrilinosWrappers::PreconditionAMG amg;
  amg.initialize(K_epetra, parameters);
  report.precondition_seconds = clock.lap();

  SolverControl control(max_iterations, tolerance * b.l2_norm());
  SolverCG<Vector<double>> cg(control);
  try {
    cg.solve(K, u, b, amg);
  } catch (const SolverControl::NoConvergence& e) {
    throw std::runtime_error(std::string(caller.function) + ": CG+AMG did not reach " + caller.options +
                             "::cg_tolerance in " + std::to_string(e.last_step) + " iterations (residual " +
                             caller.number_text(e.last_residual) + "); try Solver::direct or a looser tolerance");
  }
  report.iterations = control.last_step();
  return report;
}

// The six rigid-body modes of 3D elasticity at the DoFs: three translations and the rotations about x, y and z
// through `centre`.
void fill_rigid_body_modes_3d(const DofGeometry3& geometry, const Point<3>& centre, Epetra_MultiVector& modes) {
  for (std::size_t i = 0; i < geometry.component.size(); ++i) {
    const int c = geometry.component[i];
    assert(c == int(i % 3));  // node-wise (u_x, u_y, u_z) triples, as "PDE equations" = 3 assumes
    const Tensor<1, 3> r = geometry.point[i] - centre;
    for (int k = 0; k < 3; ++k) modes[k][i] = c == k ? 1.0 : 0.0;
    // Rotation about axis a: u = e_a x r.
    modes[3][i] = c == 0 ? 0.0 : c == 1 ? -r[2] : r[1];
    modes[4][i] = c == 0 ? r[2] : c == 1 ? 0.0 : -r[0];
    modes[5][i] = c == 0 ? -r[1] : c == 1 ? r[0] : 0.0;
  }
}

}  // namespace

CgAmgReport solve_cg_amg(const SparseMatrix<double>& K, const Vector<double>& b, Vector<double>& u,
                         const DofGeometry& geometry, const CgAmgSettings& settings, const SolveCaller& caller) {
  assert(geometry.point.size() == K.m() && geometry.component.size() == K.m());
  return run_cg_amg(
      K, b, u, dim, 3, [&](Epetra_MultiVector& modes) { fill_rigid_body_modes(geometry, settings.centre, modes); },
      settings.tolerance, settings.max_iterations, settings.higher_order, caller);
}

CgAmgReport solve_cg_amg_3d(const SparseMatrix<double>& K, const Vector<double>& b, Vector<double>& u,
                            const DofGeometry3& geometry, const Point<3>& centre, const CgAmgSettings& settings,
                            const SolveCaller& caller) {
  assert(geometry.point.size() == K.m() && geometry.component.size() == K.m());
  return run_cg_amg(
      K, b, u, 3, 6, [&](Epetra_MultiVector& modes) { fill_rigid_body_modes_3d(geometry, centre, modes); },
      settings.tolerance, settings.max_iterations, settings.higher_order, caller);
}

void share_blas_lock(std::mutex* m) { shared_blas.store(m); }

double solve_direct(const SparseMatrix<double>& K, const Vector<double>& b, Vector<double>& u) {
  std::lock_guard<std::mutex> lock(blas());
  Stopwatch clock;
  SparseDirectUMFPACK umfpack;
  umfpack.initialize(K);
  const double factorise_seconds = clock.lap();
  umfpack.vmult(u, b);
  return factorise_seconds;
}

}  // namespace rbdem::continuum::internal
