// The linear solves of continuum/'s deal.II models (fe_model.cpp, fe_joints.cpp, fe_disc.cpp, hole.cpp): UMFPACK,
// and CG preconditioned by smoothed-aggregation AMG with the rigid-body modes of plane elasticity as near null
// space (docs/continuum.md, "Solvers"); defined in solvers.cpp. Internal to continuum/: it includes deal.II, which
// nothing outside this folder may.
#pragma once

#include <mutex>
#include <string>
#include <vector>

#include <deal.II/base/point.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/vector.h>

namespace rbdem::continuum::internal {

// Coordinates and vector component (0: u_x, 1: u_y) of every DoF: where the AMG's rigid-body modes are evaluated.
struct DofGeometry {
  std::vector<dealii::Point<2>> point;
  std::vector<unsigned char> component;
};

// The support points of the affine cells of `dof` (straight-sided triangles: exact for the meshes of continuum/).
DofGeometry dof_geometry(const dealii::DoFHandler<2>& dof);

// The caller of solve_cg_amg, for its messages: the public function ("solve_elastic") and its options type
// ("FeOptions"), and how the caller writes the residual of a CG that did not converge (each model kept its own
// number format when the solvers were merged, so the messages did not change).
struct SolveCaller {
  const char* function;
  const char* options;
  std::string (*number_text)(double);
};

// What the CG+AMG solve needs besides the system: the rotation mode's centre (each model its own: the specimen's
// bounding box, the disc's centre), the relative residual, the CG iteration limit, and whether the elements are of
// higher order (ML's higher_order_elements, for P2).
struct CgAmgSettings {
  dealii::Point<2> centre;
  double tolerance = 0;
  unsigned max_iterations = 0;
  bool higher_order = false;
};

// What a CG+AMG solve reports: the CG iterations, and the seconds from the call to a ready preconditioner (waiting
// for the Trilinos lock, MPI, the Epetra copy of K, the AMG set-up).
struct CgAmgReport {
  unsigned iterations = 0;
  double precondition_seconds = 0;
};

// Solves K u = b (K symmetric positive definite, the DoFs of a node consecutive as in FESystem's numbering) by CG
// preconditioned with AMG whose near null space is the three rigid-body modes at `geometry`. u holds the start
// value. Throws std::runtime_error naming the caller when CG does not reach the tolerance.
CgAmgReport solve_cg_amg(const dealii::SparseMatrix<double>& K, const dealii::Vector<double>& b,
                         dealii::Vector<double>& u, const DofGeometry& geometry, const CgAmgSettings& settings,
                         const SolveCaller& caller);

// The same in 3D: the support point and component (0, 1, 2: u_x, u_y, u_z) of every DoF, and the six rigid-body
// modes about `centre` as the AMG's near null space (settings.centre is not used).
struct DofGeometry3 {
  std::vector<dealii::Point<3>> point;
  std::vector<unsigned char> component;
};
CgAmgReport solve_cg_amg_3d(const dealii::SparseMatrix<double>& K, const dealii::Vector<double>& b,
                            dealii::Vector<double>& u, const DofGeometry3& geometry, const dealii::Point<3>& centre,
                            const CgAmgSettings& settings, const SolveCaller& caller);

// Solves K u = b with UMFPACK. Returns the seconds of the factorisation.
double solve_direct(const dealii::SparseMatrix<double>& K, const dealii::Vector<double>& b, dealii::Vector<double>& u);

// Makes the solves above hold `m` while they run the BLAS (UMFPACK; the AMG's set-up and CG): the front library's
// lock, common/blas_lock.hpp. Until it is called they hold a lock of the module's own.
void share_blas_lock(std::mutex* m);

}  // namespace rbdem::continuum::internal
