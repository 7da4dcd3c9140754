// The static elastic solve of the 3D face-bond network. See static3.hpp.
#include "dem/static3.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include <dlfcn.h>
#include <omp.h>

#include <Eigen/Dense>
#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#ifdef RBDEM_HAVE_CHOLMOD
#include <Eigen/CholmodSupport>
#endif

#include "common/blas_lock.hpp"
#include "dem/geometry3.hpp"

namespace rbdem {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// Row k of [r]x, the matrix with [r]x phi = r x phi.
Vec3 skew_row(Vec3 r, int k) {
  if (k == 0) return {0.0, -r.z, r.y};
  if (k == 1) return {r.z, 0.0, -r.x};
  return {-r.y, r.x, 0.0};
}

}  // namespace

FaceBondMatrix face_bond_stiffness(const stages::FaceBondFrame& b, bool linear_closed) {
  // B (6 x 12): rows d1, d2, dn, t1, t2, tn. The gap g = -u_i + [r_i]x phi_i + u_j - [r_j]x phi_j (phi x r =
  // -[r]x phi), resolved on the rest frame's axes; theta = phi_j - phi_i likewise.
  double B[6][12] = {};
  for (int a = 0; a < 3; ++a) {
    const Vec3 e = b.axes.r[a];
    for (int c = 0; c < 3; ++c) {
      const double ec = e[c];
      B[a][c] -= ec, B[a][6 + c] += ec;
      B[3 + a][3 + c] -= ec, B[3 + a][9 + c] += ec;
      const Vec3 si = skew_row(b.ri, c), sj = skew_row(b.rj, c);
      for (int q = 0; q < 3; ++q) B[a][3 + q] += ec * si[q], B[a][9 + q] -= ec * sj[q];
    }
  }
  const double lin = linear_closed ? 1.0 : 0.0;  // the linear part has the parallel bond's kb_n A and kb_s A
  const double D[6] = {(1 + lin) * b.k.ks, (1 + lin) * b.k.ks, (1 + lin) * b.k.kn, b.k.kb1, b.k.kb2, b.k.kt};
  FaceBondMatrix K{};
  for (int p = 0; p < 12; ++p)
    for (int q = p; q < 12; ++q) {
      double s = 0;
      for (int a = 0; a < 6; ++a) s += B[a][p] * D[a] * B[a][q];
      K[std::size_t(12 * p + q)] = K[std::size_t(12 * q + p)] = s;  // exactly symmetric
    }
  return K;
}


// --- the SPD solver ---------------------------------------------------------------------------------------------

namespace {

using SpMat = Eigen::SparseMatrix<double>;

#ifdef RBDEM_HAVE_CHOLMOD
// CHOLMOD's supernodal LLT, with the column where a factorisation stopped (L->minor, in the permuted order, mapped
// back through L->Perm): the dof whose pivot was not positive.
struct CholmodLlt : Eigen::CholmodSupernodalLLT<SpMat, Eigen::Lower> {
  CholmodLlt() {
    cholmod().print = 0;  // the failure is reported by the exception below, not on stdout
  }
  long failed_column() const {
    const cholmod_factor* L = this->m_cholmodFactor;
    if (!L || L->minor >= L->n) return -1;
    return L->Perm ? long(static_cast<const int*>(L->Perm)[L->minor]) : long(L->minor);
  }
};
#endif

// OpenBLAS (Debian's, built for every x86-64 CPU) picks its kernels by the CPU it runs on: AVX-512 machines get
// the SkylakeX kernels, AVX2 machines the Haswell ones, and the two sum a supernode's products in another order, so
// a 3D static start, and every step after it, differed at round-off between the two kinds of machine (a 60 deg
// cylinder at 8 mm: 19.934760 against 19.940167 MPa, 204 against 205 cracks). At load time, before any BLAS call,
// every CPU with AVX2 and FMA is given the Haswell kernels, so that 3D results are the same on all of them; a CPU
// without them keeps OpenBLAS's choice, and OPENBLAS_CORETYPE set by the user is left as it is. Another BLAS (the
// reference BLAS, which has no such choice) is left alone.
struct PinOpenBlasKernels {
  PinOpenBlasKernels() {
    using Call = void (*)();
    const auto init = reinterpret_cast<Call>(dlsym(RTLD_DEFAULT, "gotoblas_dynamic_init"));
    const auto quit = reinterpret_cast<Call>(dlsym(RTLD_DEFAULT, "gotoblas_dynamic_quit"));
    if (!init || !quit || std::getenv("OPENBLAS_CORETYPE")) return;
    __builtin_cpu_init();
    if (!__builtin_cpu_supports("avx2") || !__builtin_cpu_supports("fma")) return;
    setenv("OPENBLAS_CORETYPE", "Haswell", 1);  // what gotoblas_dynamic_init reads
    quit();
    init();
    unsetenv("OPENBLAS_CORETYPE");
  }
};
const PinOpenBlasKernels pin_openblas_kernels;

// The BLAS to this thread alone (common/blas_lock.hpp), on one OpenMP thread, while CHOLMOD and its BLAS work.
// Debian's OpenBLAS (libopenblas0-openmp) runs its kernels on an OpenMP team of omp_get_max_threads(): on two cores
// that team, spinning in its barriers beside the caller's, took the 4 mm factorisation from 2.6 s on one thread to
// 6-8 s (benchmarks/bench_static3.cpp); the reference BLAS ignores the setting.
class BlasSection {
 public:
  BlasSection() : threads_(omp_get_max_threads()) { omp_set_num_threads(1); }
  ~BlasSection() { omp_set_num_threads(threads_); }
  BlasSection(const BlasSection&) = delete;
  BlasSection& operator=(const BlasSection&) = delete;

 private:
  BlasLock lock_;  // taken before the thread count is read and set, released after it is restored
  int threads_;
};

using Ldlt = Eigen::SimplicialLDLT<SpMat, Eigen::Lower, Eigen::AMDOrdering<int>>;
using Cg = Eigen::ConjugateGradient<SpMat, Eigen::Lower | Eigen::Upper,
                                    Eigen::IncompleteCholesky<double, Eigen::Lower, Eigen::AMDOrdering<int>>>;

bool same_pattern(const SpMat& K, const std::vector<int>& outer, const std::vector<int>& inner) {
  return std::size_t(K.outerSize() + 1) == outer.size() && std::size_t(K.nonZeros()) == inner.size() &&
         std::equal(outer.begin(), outer.end(), K.outerIndexPtr()) &&
         std::equal(inner.begin(), inner.end(), K.innerIndexPtr());
}

}  // namespace

std::string blas_kernels() {
  using Name = char* (*)();
  const auto name = reinterpret_cast<Name>(dlsym(RTLD_DEFAULT, "gotoblas_corename"));
  return name ? std::string(name()) : std::string();
}

bool cholmod_available() {
#ifdef RBDEM_HAVE_CHOLMOD
  return true;
#else
  return false;
#endif
}

const char* solver_name(Static3Solver s) {
  switch (s) {
    case Static3Solver::cholmod: return "cholmod";
    case Static3Solver::ldlt: return "ldlt";
    case Static3Solver::cg: return "cg";
    default: return "automatic";
  }
}

struct SpdSolver3::Impl {
  Static3Solver requested, used = Static3Solver::automatic;
  std::size_t direct_dof_limit;
  double cg_tolerance;
  int iterations = 0, analyses = 0, factorizations = 0;
  double factor_nonzeros = 0, factor_flops = 0;  // CHOLMOD's count of the last factor
  SpMat near;        // update()'s matrix, solved by CG on the factor of another
  bool has_near = false;
  std::vector<int> outer, inner;  // the pattern of the last symbolic factorisation
#ifdef RBDEM_HAVE_CHOLMOD
  std::unique_ptr<CholmodLlt> cholmod;
#endif
  std::unique_ptr<Ldlt> ldlt;
  std::unique_ptr<Cg> cg;
  SpMat cg_matrix;  // CG keeps a reference to its matrix, so it lives here

  Eigen::VectorXd direct_solve(const Eigen::VectorXd& f) const;
  bool refine(const Eigen::VectorXd& f, double tolerance, Eigen::VectorXd& x);

  Static3Solver choose(std::size_t n) const {
    if (requested == Static3Solver::cholmod && !cholmod_available())
      throw std::invalid_argument("the 3D static solve: solver cholmod was asked for, but this build has no "
                                  "CHOLMOD; configure with -DRBDEM_WITH_CHOLMOD=ON (libsuitesparse-dev) or use "
                                  "ldlt or cg");
    if (requested != Static3Solver::automatic) return requested;
    if (cholmod_available()) return Static3Solver::cholmod;
    return n <= direct_dof_limit ? Static3Solver::ldlt : Static3Solver::cg;
  }
  // Redo the symbolic analysis only when the method or the pattern changed.
  bool analyse(const SpMat& K, Static3Solver method) {
    if (method == used && same_pattern(K, outer, inner)) return false;
    used = method;
    outer.assign(K.outerIndexPtr(), K.outerIndexPtr() + K.outerSize() + 1);
    inner.assign(K.innerIndexPtr(), K.innerIndexPtr() + K.nonZeros());
    ++analyses;
    return true;
  }
};

SpdSolver3::SpdSolver3(Static3Solver solver, std::size_t direct_dof_limit, double cg_tolerance)
    : impl_(std::make_unique<Impl>()) {
  impl_->requested = solver, impl_->direct_dof_limit = direct_dof_limit, impl_->cg_tolerance = cg_tolerance;
}
SpdSolver3::~SpdSolver3() = default;

void SpdSolver3::factor(const SpMat& K_in) {
  Impl& s = *impl_;
  SpMat compressed;
  if (!K_in.isCompressed()) compressed = K_in, compressed.makeCompressed();
  const SpMat& K = K_in.isCompressed() ? K_in : compressed;
  const Static3Solver method = s.choose(std::size_t(K.rows()));
  const bool fresh = s.analyse(K, method);
  s.has_near = false, s.near = SpMat();
  ++s.factorizations;
  auto not_definite = [](long dof) {
    return std::runtime_error(
        "the 3D static solve: the stiffness is not positive definite" +
        (dof >= 0 ? " (pivot of reduced dof " + std::to_string(dof) + ", block " + std::to_string(dof / 6) +
                        " or near it)"
                  : std::string()) +
        ": a block or a rigid motion is held by nothing (a block without bonds, platens missing?)");
  };
  if (method == Static3Solver::cholmod) {
#ifdef RBDEM_HAVE_CHOLMOD
    const BlasSection blas;
    if (fresh || !s.cholmod) s.cholmod = std::make_unique<CholmodLlt>(), s.cholmod->analyzePattern(K);
    s.cholmod->factorize(K);
    s.factor_nonzeros = s.cholmod->cholmod().lnz, s.factor_flops = s.cholmod->cholmod().fl;
    if (s.cholmod->info() != Eigen::Success) throw not_definite(s.cholmod->failed_column());
#endif
  } else if (method == Static3Solver::ldlt) {
    if (fresh || !s.ldlt) s.ldlt = std::make_unique<Ldlt>(), s.ldlt->analyzePattern(K);
    s.ldlt->factorize(K);
    if (s.ldlt->info() != Eigen::Success) throw not_definite(-1);
  } else {
    s.cg = std::make_unique<Cg>();
    s.cg->setTolerance(s.cg_tolerance);
    s.cg->setMaxIterations(K.rows());
    s.cg_matrix = K;
    s.cg->compute(s.cg_matrix);
    if (s.cg->info() != Eigen::Success)
      throw std::runtime_error("the 3D static solve: the incomplete Cholesky preconditioner failed");
  }
}

void SpdSolver3::update(const SpMat& K) {
  Impl& s = *impl_;
  if (s.used == Static3Solver::cg || s.factorizations == 0 || K.rows() != long(s.outer.size()) - 1) return factor(K);
  s.near = K, s.has_near = true;
}

Eigen::VectorXd SpdSolver3::Impl::direct_solve(const Eigen::VectorXd& f) const {
#ifdef RBDEM_HAVE_CHOLMOD
  if (used == Static3Solver::cholmod) {
    const BlasSection blas;
    return cholmod->solve(f);
  }
#endif
  return ldlt->solve(f);
}

// CG on `near` preconditioned by the factor (see update()). False when it has not converged in `max_iterations`.
bool SpdSolver3::Impl::refine(const Eigen::VectorXd& f, double tolerance, Eigen::VectorXd& x) {
  const int max_iterations = 200;
  x = Eigen::VectorXd::Zero(f.size());
  Eigen::VectorXd r = f, z = direct_solve(r), p = z;
  double rz = r.dot(z);
  const double stop = tolerance * tolerance * rz;
  for (int it = 0; it < max_iterations; ++it) {
    if (rz <= stop) return true;
    const Eigen::VectorXd q = near * p;
    const double alpha = rz / p.dot(q);
    x += alpha * p, r -= alpha * q;
    z = direct_solve(r);
    const double next = r.dot(z);
    p = z + (next / rz) * p;
    rz = next;
    ++iterations;
  }
  return rz <= stop;
}

Eigen::VectorXd SpdSolver3::solve(const Eigen::VectorXd& f) {
  Impl& s = *impl_;
  if (s.factorizations == 0) throw std::logic_error("SpdSolver3::solve before factor");
  if (s.has_near) {
    Eigen::VectorXd x;
    if (s.refine(f, refine_tolerance, x)) return x;
    factor(SpMat(s.near));  // too far from the factor's matrix for it to precondition: factorise this one
  }
  if (s.used != Static3Solver::cg) return s.direct_solve(f);
  Eigen::VectorXd x = s.cg->solve(f);
  if (s.cg->info() != Eigen::Success)
    throw std::runtime_error("the 3D static solve: CG did not converge; use a direct solver (cholmod or ldlt)");
  s.iterations += int(s.cg->iterations());
  return x;
}

Static3Solver SpdSolver3::used() const { return impl_->used; }
int SpdSolver3::iterations() const { return impl_->iterations; }
int SpdSolver3::analyses() const { return impl_->analyses; }
int SpdSolver3::factorizations() const { return impl_->factorizations; }
double SpdSolver3::factor_nonzeros() const { return impl_->factor_nonzeros; }
double SpdSolver3::factor_flops() const { return impl_->factor_flops; }

namespace {

Vec3 node(const TetMesh& m, int k) {
  const auto& p = m.nodes[std::size_t(k)];
  return {p[0], p[1], p[2]};
}
Tri tri_of(const TetMesh& m, const std::array<int, 3>& n) { return {node(m, n[0]), node(m, n[1]), node(m, n[2])}; }
Tet tet_of(const TetMesh& m, std::size_t t) {
  const auto& n = m.tets[t];
  return {node(m, n[0]), node(m, n[1]), node(m, n[2]), node(m, n[3])};
}

// The blocks: centroid, volume and inradius 3 V / (surface area) of each tetrahedron.
struct Blocks {
  std::vector<Vec3> c;
  std::vector<double> volume, inradius;
};
Blocks blocks_of(const TetMesh& m) {
  Blocks b;
  const std::size_t n = m.num_tets();
  b.c.resize(n), b.volume.resize(n), b.inradius.resize(n);
  for (std::size_t t = 0; t < n; ++t) {
    const Tet T = tet_of(m, t);
    b.c[t] = centroid(T), b.volume[t] = signed_volume(T);
    if (!(b.volume[t] > 0)) throw std::invalid_argument("solve_static3: tetrahedron " + std::to_string(t) +
                                                        " has a non-positive volume; remesh the specimen");
    double surface = 0;
    for (int f = 0; f < 4; ++f) surface += face_of({T[std::size_t(f)], T[std::size_t((f + 1) % 4)],
                                                   T[std::size_t((f + 2) % 4)]}).area;
    b.inradius[t] = 3.0 * b.volume[t] / surface;
  }
  return b;
}

// A platen contact: block, the lever arm to the face's centroid, its spring k_p A, top or bottom.
struct PlatenSpring {
  int block;
  Vec3 r;
  double k;
  bool top;
  // u_z + (phi x r)_z at the face's centroid as a functional of the block's six dofs.
  std::array<double, 6> row() const { return {0.0, 0.0, 1.0, r.y, -r.x, 0.0}; }
};

// The dofs left after the three rigid constraints (u_x, u_y of one bottom block, u_y of the bottom block
// farthest from it in x): index in the reduced system, -1 for a held dof.
std::vector<int> free_dofs(std::size_t blocks, const std::vector<PlatenSpring>& springs, const Blocks& B) {
  int first = -1, far = -1;
  for (const PlatenSpring& s : springs)
    if (!s.top && (first < 0 || s.block < first)) first = s.block;
  for (const PlatenSpring& s : springs)
    if (!s.top && (far < 0 || std::abs(B.c[std::size_t(s.block)].x - B.c[std::size_t(first)].x) >
                                   std::abs(B.c[std::size_t(far)].x - B.c[std::size_t(first)].x)))
      far = s.block;
  std::vector<int> map(6 * blocks, 0);
  map[std::size_t(6 * first)] = map[std::size_t(6 * first + 1)] = map[std::size_t(6 * far + 1)] = -1;
  int next = 0;
  for (int& k : map) k = k < 0 ? -1 : next++;
  return map;
}

// The strain that fits the blocks' displacements best: u_b ~ c + G (x_b - x_mean), volume-weighted least
// squares, G = R M^-1 with M = sum V (x - x_mean)(x - x_mean)^T and R = sum V u (x - x_mean)^T; eps = sym(G).
std::array<double, 6> fitted_strain(const Blocks& B, const std::vector<double>& u) {
  const std::size_t n = B.c.size();
  Vec3 mean{};
  double V = 0;
  for (std::size_t b = 0; b < n; ++b) mean += B.volume[b] * B.c[b], V += B.volume[b];
  mean = (1.0 / V) * mean;
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero(), R = Eigen::Matrix3d::Zero();
  for (std::size_t b = 0; b < n; ++b) {
    const Vec3 x = B.c[b] - mean;
    const Eigen::Vector3d dx(x.x, x.y, x.z), ub(u[6 * b], u[6 * b + 1], u[6 * b + 2]);
    M += B.volume[b] * dx * dx.transpose();
    R += B.volume[b] * ub * dx.transpose();
  }
  const Eigen::Matrix3d G = R * M.inverse(), e = 0.5 * (G + G.transpose());
  return {e(0, 0), e(1, 1), e(2, 2), e(1, 2), e(0, 2), e(0, 1)};
}

// What the assembly leaves: the reduced stiffness, its load, the bonds' matrices and dofs for the energy.
struct Assembly {
  Eigen::SparseMatrix<double> K;
  Eigen::VectorXd f;
  std::vector<FaceBondMatrix> bond_k;
  std::vector<std::array<int, 2>> bond_blocks;
};

Assembly assemble(const TetMesh& mesh, const Blocks& B, const std::vector<PlatenSpring>& springs,
                  const std::vector<int>& map, const Static3Options& o, Static3Result& r) {
  Assembly a;
  const std::vector<SharedFace> faces = shared_faces(mesh);
  std::vector<Eigen::Triplet<double>> T;
  T.reserve(faces.size() * 144 + springs.size() * 36);
  auto add = [&](int gp, int gq, double v) {
    const int p = map[std::size_t(gp)], q = map[std::size_t(gq)];
    if (p >= 0 && q >= 0 && v != 0.0) T.emplace_back(p, q, v);
  };
  double joint_area = 0, joint_ad = 0, joint_a_over_d = 0;
  for (const SharedFace& f : faces) {
    const FaceMaterial& mat = f.joint ? o.joint : o.rock;
    const std::size_t i = std::size_t(f.tets[0]), j = std::size_t(f.tets[1]);
    const FaceBond law{1.0 / mat.kappa, {}, 0.0};
    const stages::FaceBondFrame fr = stages::face_bond_frame(B.c[i], B.c[j], tri_of(mesh, f.nodes), law,
                                                             mat.modulus, std::numeric_limits<double>::infinity());
    const FaceBondMatrix K = face_bond_stiffness(fr, true);
    const int dof[2] = {6 * int(i), 6 * int(j)};
    for (int p = 0; p < 12; ++p)
      for (int q = 0; q < 12; ++q) add(dof[p / 6] + p % 6, dof[q / 6] + q % 6, K[std::size_t(12 * p + q)]);
    a.bond_k.push_back(K), a.bond_blocks.push_back({int(i), int(j)});
    if (f.joint) {
      ++r.joint_bonds;
      const double d = dot(fr.axes.r[2], B.c[j] - B.c[i]);
      joint_area += fr.section.A, joint_ad += fr.section.A * d, joint_a_over_d += fr.section.A / d;
    } else {
      ++r.rock_bonds;
    }
  }
  r.joint_d_mean = joint_area > 0 ? joint_ad / joint_area : 0.0;
  r.joint_d_harmonic = joint_area > 0 ? joint_area / joint_a_over_d : 0.0;
  a.f = Eigen::VectorXd::Zero(long(std::count_if(map.begin(), map.end(), [](int k) { return k >= 0; })));
  for (const PlatenSpring& s : springs) {
    const auto row = s.row();
    for (int p = 0; p < 6; ++p) {
      for (int q = 0; q < 6; ++q)
        add(6 * s.block + p, 6 * s.block + q, s.k * row[std::size_t(p)] * row[std::size_t(q)]);
      // The top platen at -delta: the spring's energy 1/2 k (u_zc + delta)^2 loads the dofs by -k delta row.
      const int gp = map[std::size_t(6 * s.block + p)];
      if (s.top && gp >= 0) a.f[gp] -= s.k * o.platen_displacement * row[std::size_t(p)];
    }
  }
  a.K.resize(a.f.size(), a.f.size());
  a.K.setFromTriplets(T.begin(), T.end());
  return a;
}

Eigen::VectorXd solve_system(const Assembly& a, const Static3Options& o, Static3Result& r) {
  SpdSolver3 solver(o.solver, o.direct_dof_limit, o.cg_tolerance);
  solver.factor(a.K);
  Eigen::VectorXd x = solver.solve(a.f);
  r.solver = solver.used(), r.direct = solver.direct(), r.iterations = solver.iterations();
  r.factor_nonzeros = solver.factor_nonzeros(), r.factor_flops = solver.factor_flops();
  return x;
}

std::vector<PlatenSpring> platen_springs(const TetMesh& mesh, const Blocks& B, const FaceMaterial& rock) {
  std::vector<PlatenSpring> s;
  for (const BoundaryFace& bf : mesh.boundary) {
    if (bf.tag == FaceTag::lateral) continue;
    const Face f = face_of(tri_of(mesh, bf.nodes));
    const std::size_t t = std::size_t(bf.tet);
    s.push_back({bf.tet, f.centroid - B.c[t], rock.modulus / (2.0 * B.inradius[t]) * f.area, bf.tag == FaceTag::top});
  }
  return s;
}

void check(const TetMesh& mesh, const Static3Options& o) {
  auto fail = [](const std::string& what) { throw std::invalid_argument("solve_static3: " + what); };
  if (mesh.num_tets() < 2) fail("the mesh has fewer than two tetrahedra; mesh the specimen first");
  if (!(o.platen_displacement > 0) || !std::isfinite(o.platen_displacement))
    fail("platen_displacement must be a positive length in m");
  for (const FaceMaterial* m : {&o.rock, &o.joint})
    if (!(m->modulus > 0) || !(m->kappa > 0) || !std::isfinite(m->modulus) || !std::isfinite(m->kappa))
      fail("the rock's and the joint's effective modulus and stiffness ratio must be positive and finite");
}

}  // namespace

Static3Result solve_static3(const TetMesh& mesh, const Static3Options& o) {
  check(mesh, o);
  Static3Result r;
  const auto t0 = Clock::now();
  const Blocks B = blocks_of(mesh);
  const std::vector<PlatenSpring> springs = platen_springs(mesh, B, o.rock);
  bool bottom = false, top = false;
  for (const PlatenSpring& s : springs) (s.top ? top : bottom) = true;
  if (!bottom || !top) throw std::invalid_argument("solve_static3: the mesh has no bottom or no top faces; "
                                                   "tag its boundary (boundary_faces) before the solve");
  const std::vector<int> map = free_dofs(mesh.num_tets(), springs, B);
  const Assembly a = assemble(mesh, B, springs, map, o, r);
  r.assemble_seconds = seconds_since(t0);

  const auto t1 = Clock::now();
  const Eigen::VectorXd x = solve_system(a, o, r);
  r.solve_seconds = seconds_since(t1);

  r.u.assign(map.size(), 0.0);
  for (std::size_t k = 0; k < map.size(); ++k)
    if (map[k] >= 0) r.u[k] = x[map[k]];
  const double delta = o.platen_displacement;
  for (const PlatenSpring& s : springs) {
    const auto row = s.row();
    double uz = 0;
    for (int p = 0; p < 6; ++p) uz += row[std::size_t(p)] * r.u[std::size_t(6 * s.block + p)];
    const double overlap = s.top ? uz + delta : -uz;  // into the platen
    (s.top ? r.top_force : r.bottom_force) += s.k * overlap;
    r.strain_energy += 0.5 * s.k * overlap * overlap;
  }
  for (std::size_t b = 0; b < a.bond_k.size(); ++b) {
    double q[12];
    for (int p = 0; p < 12; ++p) q[p] = r.u[std::size_t(6 * a.bond_blocks[b][std::size_t(p / 6)] + p % 6)];
    for (int p = 0; p < 12; ++p)
      for (int c = 0; c < 12; ++c) r.strain_energy += 0.5 * q[p] * a.bond_k[b][std::size_t(12 * p + c)] * q[c];
  }
  r.platen_work = 0.5 * r.top_force * delta;

  double zmin = std::numeric_limits<double>::infinity(), zmax = -zmin;
  for (const auto& p : mesh.nodes) zmin = std::min(zmin, p[2]), zmax = std::max(zmax, p[2]);
  for (double v : B.volume) r.volume += v;
  r.height = zmax - zmin;
  r.blocks = mesh.num_tets(), r.platen_faces = springs.size(), r.dofs = std::size_t(a.f.size());
  r.mean_stress = 0.5 * (r.top_force + r.bottom_force) * r.height / r.volume;
  r.platen_modulus = r.mean_stress / (delta / r.height);
  r.strain = fitted_strain(B, r.u);
  r.fit_modulus = r.mean_stress / -r.strain[2];
  const double dd = o.dip_direction_deg * std::numbers::pi / 180.0;
  const Vec3 strike{-std::sin(dd), std::cos(dd), 0.0}, dip{std::cos(dd), std::sin(dd), 0.0};
  auto normal_strain = [&](Vec3 n) {
    const auto& e = r.strain;
    return e[0] * n.x * n.x + e[1] * n.y * n.y + 2.0 * e[5] * n.x * n.y;  // horizontal n
  };
  r.strain_strike = normal_strain(strike), r.strain_dip = normal_strain(dip);
  r.poisson_strike = -r.strain_strike / r.strain[2], r.poisson_dip = -r.strain_dip / r.strain[2];
  return r;
}

}  // namespace rbdem
