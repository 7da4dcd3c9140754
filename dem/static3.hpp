// The static elastic solve of the 3D face-bond network: one rigid tetrahedral block per tetrahedron of a TetMesh,
// one face bond per shared face (dem/laws/face_bond.hpp), loaded in uniaxial compression between frictionless
// platens; the 3D counterpart of the 2D static solve (dem/static_solve.hpp) in its like-for-like linear model,
// every linear part closed and sticking. docs/theory.md, "The face bond's stiffness matrix"; docs/continuum.md,
// "The 3D DEM's static moduli".
//
// Degrees of freedom: 6 per block, the translation u of its centroid and a small rotation phi (world axes), in the
// order (u_x, u_y, u_z, phi_x, phi_y, phi_z).
//
// The platens are what the 2D static solve uses: a frictionless contact of each bottom or top boundary face with a
// rigid plane, a normal spring k_p A at the face's centroid with k_p = E*_rock / (2 r_in) (r_in the block's
// inradius, as dem/boundary/platens.cpp sets the 2D platen contact), on u_z + (phi x r)_z; no rotational or shear
// stiffness. The top platen closes by delta, the bottom one stays. The three rigid modes the platens leave (the
// horizontal translations and the rotation about z) are removed by holding u_x and u_y of one bottom block and u_y
// of the bottom block farthest from it in x: rigid constraints only, no stress.
#pragma once

#include <array>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/SparseCore>

#include "dem/stages/face_bond_kernel.hpp"
#include "mesh/tetmesh.hpp"

namespace rbdem {

// A 12 x 12 stiffness, row-major, on the dofs (u_i, phi_i, u_j, phi_j).
using FaceBondMatrix = std::array<double, 144>;

// The linearised stiffness of the face bond b at rest (no forces there, so no geometric terms): K = B^T D B, with
// B the map from the two blocks' dofs to the relative motion in the face frame,
//     g = u_j + phi_j x r_j - u_i - phi_i x r_i   (the gap at the bond point; d = [e1, e2, n] g),
//     theta = phi_j - phi_i                       (t = [e1, e2, n] theta),
// and D = diag(k_s', k_s', k_n', kb_1, kb_2, kb_t): the parallel bond's stiffnesses (FaceStiffness), plus the
// linear part's k_n A and k_s A on the normal and the slip when `linear_closed` (a closed face puts the linear
// part's force at the face's centroid, so it adds no bending or twist stiffness). Symmetric, positive
// semi-definite, and zero on the six rigid motions of the pair.
FaceBondMatrix face_bond_stiffness(const stages::FaceBondFrame& b, bool linear_closed = true);

// A bond material: effective modulus E* (Pa) and stiffness ratio kappa = k_n / k_s.
struct FaceMaterial {
  double modulus = 0, kappa = 1;
};

// How the symmetric positive definite systems of the 3D static solves are solved:
//   cholmod: CHOLMOD's supernodal Cholesky factorisation (SuiteSparse; fill-reducing ordering by AMD or METIS,
//            whichever fills less); its work is dense blocks in the BLAS, so its speed is the BLAS's (one solve
//            at 4 mm: 5.9 times less CPU than CG with OpenBLAS, 1.1 times with the reference BLAS); its factor,
//            reused, makes the static start's later active sets cheap (7 times less CPU at 6 mm;
//            benchmarks/bench_static3.cpp, docs/performance.md); needs a build with CHOLMOD (cholmod_available());
//   ldlt:    Eigen's simplicial LDLT with AMD ordering (its fill on tetrahedra costs minutes above ~100,000 dofs);
//   cg:      conjugate gradients with an incomplete Cholesky preconditioner, to a relative residual cg_tolerance;
//   automatic: cholmod where available, else ldlt up to direct_dof_limit dofs and cg above.
enum class Static3Solver { automatic, cholmod, ldlt, cg };

// Whether this build links CHOLMOD (the CMake option RBDEM_WITH_CHOLMOD).
bool cholmod_available();
// The kernels OpenBLAS runs ("Haswell" on every CPU with AVX2 and FMA unless OPENBLAS_CORETYPE says otherwise:
// rbdem pins them at load time so that 3D results do not depend on the CPU kind), or "" when the BLAS is another.
std::string blas_kernels();
const char* solver_name(Static3Solver s);

// A factorised stiffness: factor(K) once per matrix, then solve(f) for any number of right-hand sides. Where the
// matrix changes but its sparsity pattern does not (the linear parts of an active-set iteration opening and
// closing), factor() keeps the fill-reducing ordering and symbolic factorisation and redoes only the numeric one.
// Throws std::runtime_error naming the cause when K is not positive definite (a block or a rigid mode held by
// nothing) or an iterative solve does not converge.
class SpdSolver3 {
 public:
  SpdSolver3(Static3Solver solver, std::size_t direct_dof_limit = 30000, double cg_tolerance = 1e-10);
  ~SpdSolver3();
  SpdSolver3(const SpdSolver3&) = delete;
  SpdSolver3& operator=(const SpdSolver3&) = delete;

  void factor(const Eigen::SparseMatrix<double>& K);
  // A matrix K close to the factorised one K_f, c K_f <= K <= K_f for some c in (0, 1] (the stiffness of an active
  // set against the all-closed one: opening a linear part removes at most half of its bond's stiffness, c = 1/2):
  // the factor is kept and solve() runs CG on K preconditioned by it. The preconditioned operator's spectrum lies in
  // [c, 1], so CG converges in a number of iterations set by c alone (about 20 for c = 1/2 to refine_tolerance), a
  // small part of a new factorisation. Where CG does not converge in 200 iterations (K far from K_f), K is
  // factorised. For the method cg, update() is factor().
  void update(const Eigen::SparseMatrix<double>& K);
  Eigen::VectorXd solve(const Eigen::VectorXd& f);

  Static3Solver used() const;  // the method chosen for the last factor() (never automatic)
  bool direct() const { return used() != Static3Solver::cg; }
  int iterations() const;      // CG's, summed over the solves
  int analyses() const;        // symbolic factorisations done (1 while the pattern stays)
  int factorizations() const;  // numeric ones
  // CHOLMOD's counts for the last factorisation: nonzeros of L and floating-point operations (0 for the others)
  double factor_nonzeros() const;
  double factor_flops() const;
  // The CG of update(): stops when the residual's norm in the factor's inverse, sqrt(r^T K_f^-1 r), is this
  // fraction of the right-hand side's (the error's energy norm to within 1 / sqrt(c) of it).
  double refine_tolerance = 1e-13;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct Static3Options {
  FaceMaterial rock{160e9, 1.5};   // the paper scene's rock (scenes/paper.toml)
  FaceMaterial joint{50e9, 1.5};   // and joint
  double platen_displacement = 1e-6;  // m, closure of the top platen (> 0)
  // The axes the lateral strains are read along: the strike (-sin dd, cos dd, 0) and the horizontal dip direction
  // (cos dd, sin dd, 0) of joints of dip direction dd (deg), as theory::plane_axes.
  double dip_direction_deg = 0;
  Static3Solver solver = Static3Solver::automatic;
  // Without CHOLMOD (solver automatic): the sparse LDLT up to this many dofs, CG with an incomplete Cholesky
  // preconditioner above (to a relative residual of cg_tolerance).
  std::size_t direct_dof_limit = 30000;
  double cg_tolerance = 1e-10;
};

// The response. The mean axial stress is <sigma_zz> = F H / V (F the mean of the two platens' forces), as the FE
// twin reads it (continuum/fe_3d.hpp). Two moduli:
//   platen_modulus = <sigma_zz> / (delta / H): the platens' reading, the contact springs' compliance included;
//   fit_modulus = <sigma_zz> / (-eps_zz) with eps the symmetric part of the displacement gradient that fits the
//     blocks' centroid displacements best in the least-squares sense (volume-weighted): the body's own strain,
//     free of the platen contacts, to compare with the continuum's mean-strain modulus.
// The lateral strains (tension positive) and apparent Poisson's ratios are read from the same fitted strain.
struct Static3Result {
  double platen_modulus = 0, fit_modulus = 0;  // Pa
  double mean_stress = 0;                      // Pa, compression positive
  double top_force = 0, bottom_force = 0;      // N, compression positive
  std::array<double, 6> strain{};              // fitted: xx, yy, zz, yz, xz, xy (tensor components)
  double strain_strike = 0, strain_dip = 0;
  double poisson_strike = 0, poisson_dip = 0;
  double volume = 0, height = 0;  // m^3, m
  std::size_t blocks = 0, rock_bonds = 0, joint_bonds = 0, platen_faces = 0, dofs = 0;
  // m, the joint bonds' centroid distances d: area-weighted mean, and harmonic mean A / sum(A / d) (the d of the
  // bonds' summed stiffness, the bonds of one joint plane acting side by side); 0 without joints
  double joint_d_mean = 0, joint_d_harmonic = 0;
  std::vector<double> u;    // 6 per block
  double assemble_seconds = 0, solve_seconds = 0;
  bool direct = false;  // a direct solver (else CG)
  Static3Solver solver = Static3Solver::automatic;  // the one used
  int iterations = 0;   // CG's
  double factor_nonzeros = 0, factor_flops = 0;  // CHOLMOD's factor: nonzeros of L, operations
  double strain_energy = 0;  // J, 1/2 u^T K u
  double platen_work = 0;    // J, 1/2 F_top delta
};

// Throws std::invalid_argument for an empty mesh, a non-positive displacement or modulus, or a mesh without
// bottom or top faces.
Static3Result solve_static3(const TetMesh& mesh, const Static3Options& options = {});

}  // namespace rbdem
