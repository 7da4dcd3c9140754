// deal.II transversely isotropic elastic model on a TriMesh. See fe_model.hpp for the model and its boundary
// conditions, docs/theory.md (section 2) for the constants, docs/continuum.md for the deal.II 9.4 pitfalls avoided
// here (CellData<2>(3) for triangles, counter-clockwise cells, the mapping passed explicitly; MPI before Trilinos is
// solvers.cpp's).
//
// Stages, each a function below: check inputs -> triangulation straight from the arrays -> DoFs, sparsity and
// platen DoFs -> assemble K per unit thickness -> keep the platen rows of K, impose the platen displacements ->
// solve (solvers.cpp) -> reactions from the kept rows (the unconstrained residual K u; there is no body force) ->
// centroid fields. Also defines what the models of continuum/ share besides the solvers (fe_internal.hpp).
#include "continuum/fe_model.hpp"
#include "continuum/fe_internal.hpp"
#include "continuum/solvers.hpp"

#include <deal.II/base/config.h>
#include <deal.II/base/index_set.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_fe.h>
#include <deal.II/grid/tria.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/sparsity_pattern.h>
#include <deal.II/lac/vector.h>
#include <deal.II/numerics/matrix_tools.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

namespace rbdem::continuum {

// ---- What the models of continuum/ share (fe_internal.hpp) -----------------------------------------------------

namespace internal {

dealii::SymmetricTensor<4, 2> stiffness_tensor(const Stiffness3& C) {
  constexpr unsigned voigt[3][2] = {{0, 0}, {1, 1}, {0, 1}};
  dealii::SymmetricTensor<4, 2> t;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b) t[voigt[a][0]][voigt[a][1]][voigt[b][0]][voigt[b][1]] = C[a][b];
  return t;
}

void assemble_fe_values(const dealii::DoFHandler<2>& dof, const dealii::Mapping<2>& mapping,
                        const dealii::Quadrature<2>& q, const dealii::SymmetricTensor<4, 2>& C,
                        dealii::SparseMatrix<double>& K) {
  using namespace dealii;
  constexpr int dim = 2;
  const FiniteElement<dim>& fe = dof.get_fe();
  FEValues<dim> fev(mapping, fe, q, update_gradients | update_JxW_values);
  const FEValuesExtractors::Vector u(0);
  const unsigned n = fe.n_dofs_per_cell();
  FullMatrix<double> Ke(n, n);
  std::vector<SymmetricTensor<2, dim>> eps(n);
  std::vector<types::global_dof_index> local(n);
  for (const auto& cell : dof.active_cell_iterators()) {
    fev.reinit(cell);
    Ke = 0;
    for (unsigned qp = 0; qp < q.size(); ++qp) {
      for (unsigned i = 0; i < n; ++i) eps[i] = fev[u].symmetric_gradient(i, qp);
      for (unsigned i = 0; i < n; ++i) {
        const SymmetricTensor<2, dim> C_eps_i = C * eps[i];
        for (unsigned j = 0; j < n; ++j) Ke(i, j) += scalar_product(C_eps_i, eps[j]) * fev.JxW(qp);
      }
    }
    cell->get_dof_indices(local);
    K.add(local, Ke);
  }
}

}  // namespace internal

namespace {

using namespace dealii;
constexpr int dim = 2;
constexpr types::boundary_id side_id = 0, bottom_id = 1, top_id = 2;

using internal::Stopwatch;

// ---- Inputs ------------------------------------------------------------------------------------------------------

struct Box {
  double xmin = 0, xmax = 0, ymin = 0, ymax = 0;
  double width() const { return xmax - xmin; }
  double height() const { return ymax - ymin; }
};

std::string constants_text(const theory::TIConstants& c) {
  std::ostringstream s;
  s << "E = " << c.E << " Pa, nu = " << c.nu << ", E' = " << c.E_prime << " Pa, nu' = " << c.nu_prime
    << ", G' = " << c.G_prime << " Pa";
  return s.str();
}

void check_inputs(const TriMesh& mesh, const theory::TIConstants& c, double bedding_deg, double thickness,
                  const FeOptions& o) {
  auto fail = [](const std::string& what) { throw std::invalid_argument("solve_elastic: " + what); };
  if (mesh.triangles.empty() || mesh.nodes.empty())
    fail("the mesh has no triangles; mesh the specimen first (rbdem::mesh_specimen or rbdem::read_msh)");
  if (!c.admissible())
    fail("the transversely isotropic constants (" + constants_text(c) +
         ") are not admissible: they need E, E', G' > 0, -1 < nu < 1 and 1 - nu - 2 nu'^2 E/E' > 0 "
         "(docs/theory.md, section 2); check the units (Pa) and the pairing of E with nu and E' with nu'");
  if (!std::isfinite(bedding_deg)) fail("bedding_deg is not a finite angle; give the bedding dip in degrees");
  if (!(thickness > 0) || !std::isfinite(thickness))
    fail("thickness = " + std::to_string(thickness) + " m; give the positive out-of-plane thickness in m");
  if (o.degree != 1 && o.degree != 2)
    fail("FeOptions::degree = " + std::to_string(o.degree) + "; only 1 (P1) and 2 (P2) are supported");
  if (!(o.platen_displacement > 0) || !std::isfinite(o.platen_displacement))
    fail("FeOptions::platen_displacement = " + std::to_string(o.platen_displacement) +
         " m; give the positive downward displacement of the top platen in m (compression)");
  if (!(o.cg_tolerance > 0 && o.cg_tolerance < 1))
    fail("FeOptions::cg_tolerance = " + std::to_string(o.cg_tolerance) + "; give a relative residual in (0, 1)");
  const int n = int(mesh.nodes.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (int v : mesh.triangles[t])
      if (v < 0 || v >= n)
        fail("triangle " + std::to_string(t) + " refers to node " + std::to_string(v) + " but the mesh has " +
             std::to_string(n) + " nodes");
    const double a = signed_area(mesh, t);
    if (!(a > 0))
      fail("triangle " + std::to_string(t) + " has signed area " + std::to_string(a) +
           " m^2; triangles must be counter-clockwise and non-degenerate (swap two nodes of clockwise triangles, "
           "as rbdem::mesh_specimen does)");
  }
}

Box bounding_box(const TriMesh& mesh) {
  Box b{std::numeric_limits<double>::max(), std::numeric_limits<double>::lowest(), std::numeric_limits<double>::max(),
        std::numeric_limits<double>::lowest()};
  for (const auto& tri : mesh.triangles)
    for (int v : tri) {
      const auto& p = mesh.nodes[v];
      b.xmin = std::min(b.xmin, p[0]), b.xmax = std::max(b.xmax, p[0]);
      b.ymin = std::min(b.ymin, p[1]), b.ymax = std::max(b.ymax, p[1]);
    }
  return b;
}

// ---- Triangulation and DoFs --------------------------------------------------------------------------------------

// Triangles in the order of a Morton (Z) curve through their centroids: neighbouring cells, and hence the DoFs that
// distribute_dofs numbers cell by cell, end up close in memory, which keeps the matrix-vector products of CG and
// AMG cache friendly (gmsh numbers nodes curve by curve and surface by surface). Returns the triangle of each cell.
std::vector<unsigned> morton_order(const TriMesh& mesh, const Box& box) {
  const std::size_t n = mesh.triangles.size();
  std::vector<std::pair<std::uint64_t, unsigned>> key(n);
  const double sx = 65535.0 / std::max(box.width(), 1e-300), sy = 65535.0 / std::max(box.height(), 1e-300);
  auto spread = [](std::uint64_t v) {  // 16 bits -> every other of 32 bits
    v = (v | (v << 8)) & 0x00FF00FFu;
    v = (v | (v << 4)) & 0x0F0F0F0Fu;
    v = (v | (v << 2)) & 0x33333333u;
    v = (v | (v << 1)) & 0x55555555u;
    return v;
  };
  for (std::size_t t = 0; t < n; ++t) {
    double x = 0, y = 0;
    for (int v : mesh.triangles[t]) x += mesh.nodes[v][0], y += mesh.nodes[v][1];
    const auto ix = std::uint64_t(std::clamp((x / 3 - box.xmin) * sx, 0.0, 65535.0));
    const auto iy = std::uint64_t(std::clamp((y / 3 - box.ymin) * sy, 0.0, 65535.0));
    key[t] = {spread(ix) | (spread(iy) << 1), unsigned(t)};
  }
  std::sort(key.begin(), key.end());
  std::vector<unsigned> order(n);
  for (std::size_t k = 0; k < n; ++k) order[k] = key[k].second;
  return order;
}

// One level-0 cell per triangle, cell k being triangle cell_triangle[k], with the vertices in the triangle's
// (counter-clockwise) order. Nodes no triangle uses are left out.
void make_triangulation(const TriMesh& mesh, const std::vector<unsigned>& cell_triangle, Triangulation<dim>& tria) {
  std::vector<unsigned> vertex_of(mesh.nodes.size(), numbers::invalid_unsigned_int);
  std::vector<Point<dim>> vertices;
  vertices.reserve(mesh.nodes.size());
  std::vector<CellData<dim>> cells(cell_triangle.size(), CellData<dim>(3));  // 3 vertices: a triangle, not a quad
  for (std::size_t k = 0; k < cell_triangle.size(); ++k)
    for (unsigned i = 0; i < 3; ++i) {
      const int v = mesh.triangles[cell_triangle[k]][i];
      if (vertex_of[v] == numbers::invalid_unsigned_int) {
        vertex_of[v] = unsigned(vertices.size());
        vertices.emplace_back(mesh.nodes[v][0], mesh.nodes[v][1]);
      }
      cells[k].vertices[i] = vertex_of[v];
    }
  tria.create_triangulation(vertices, cells, SubCellData());
}

// Boundary ids by coordinate: faces with both ends on y = ymin are the bottom platen, on y = ymax the top one.
void mark_platens(Triangulation<dim>& tria, const Box& box, double tol) {
  for (const auto& cell : tria.active_cell_iterators())
    for (const unsigned f : cell->face_indices()) {
      if (!cell->face(f)->at_boundary()) continue;
      const double y0 = cell->face(f)->vertex(0)[1], y1 = cell->face(f)->vertex(1)[1];
      if (std::abs(y0 - box.ymax) < tol && std::abs(y1 - box.ymax) < tol)
        cell->face(f)->set_boundary_id(top_id);
      else if (std::abs(y0 - box.ymin) < tol && std::abs(y1 - box.ymin) < tol)
        cell->face(f)->set_boundary_id(bottom_id);
      else
        cell->face(f)->set_boundary_id(side_id);
    }
}

// The u_x DoF of the bottom-left node (the frictionless pin).
types::global_dof_index corner_ux_dof(const DoFHandler<dim>& dof, const Box& box, double tol) {
  const FiniteElement<dim>& fe = dof.get_fe();
  types::global_dof_index best = numbers::invalid_dof_index;
  double best_x = std::numeric_limits<double>::max();
  for (const auto& cell : dof.active_cell_iterators())
    for (const unsigned v : cell->vertex_indices()) {
      const Point<dim>& p = cell->vertex(v);
      if (std::abs(p[1] - box.ymin) >= tol || p[0] >= best_x) continue;
      for (unsigned k = 0; k < fe.n_dofs_per_vertex(); ++k)
        if (fe.system_to_component_index(v * fe.n_dofs_per_vertex() + k).first == 0) {
          best = cell->vertex_dof_index(v, k);
          best_x = p[0];
        }
    }
  return best;
}

// ---- Assembly ----------------------------------------------------------------------------------------------------

// Element matrices of straight-sided (affine) triangles. With grad phi = J^-T ghat and a constant J,
//   K_ij = sum_q eps(phi_i) : C : eps(phi_j) JxW_q = |det J| sum_mn R_{b_i b_j}[m][n] D_{c_i c_j}[m][n],
//   R_ab[m][n] = sum_q w_q ghat_a[m] ghat_b[n]       (reference cell, computed once),
//   D_cd[m][n] = sum_kl Jinv[m][k] C_ckdl Jinv[n][l]  (per cell, 16 numbers),
// with c_i the vector component and b_i the scalar shape function of DoF i. This is the eps : C : eps contraction
// of the fe_values path regrouped so that the quadrature loop runs once on the reference cell.
class AffineElementMatrix {
 public:
  AffineElementMatrix(const FiniteElement<dim>& fe, const Quadrature<dim>& q, const SymmetricTensor<4, dim>& C)
      : n_(fe.n_dofs_per_cell()), nb_(fe.base_element(0).n_dofs_per_cell()), C_(C) {
    const FiniteElement<dim>& base = fe.base_element(0);
    const unsigned nb = nb_;
    R_.assign(nb * nb * dim * dim, 0.0);
    for (unsigned qp = 0; qp < q.size(); ++qp)
      for (unsigned a = 0; a < nb; ++a) {
        const Tensor<1, dim> ga = base.shape_grad(a, q.point(qp));
        for (unsigned b = 0; b < nb; ++b) {
          const Tensor<1, dim> gb = base.shape_grad(b, q.point(qp));
          for (unsigned m = 0; m < dim; ++m)
            for (unsigned n = 0; n < dim; ++n) R_[((a * nb + b) * dim + m) * dim + n] += q.weight(qp) * ga[m] * gb[n];
        }
      }
    comp_.resize(n_);
    shape_.resize(n_);
    for (unsigned i = 0; i < n_; ++i) {
      comp_[i] = fe.system_to_component_index(i).first;
      shape_[i] = fe.system_to_component_index(i).second;
    }
  }

  // Fills K (n x n, row-major) for the triangle with vertices v0, v1, v2 (counter-clockwise).
  void compute(const Point<dim>& v0, const Point<dim>& v1, const Point<dim>& v2, double* K) const {
    const double J00 = v1[0] - v0[0], J01 = v2[0] - v0[0], J10 = v1[1] - v0[1], J11 = v2[1] - v0[1];
    const double det = J00 * J11 - J01 * J10;
    const double inv[2][2] = {{J11 / det, -J01 / det}, {-J10 / det, J00 / det}};  // Jinv[m][k]
    double D[2][2][2][2];
    for (unsigned c = 0; c < dim; ++c)
      for (unsigned d = 0; d < dim; ++d) {
        double CJ[2][2];  // CJ[k][n] = sum_l C_ckdl Jinv[n][l]
        for (unsigned k = 0; k < dim; ++k)
          for (unsigned n = 0; n < dim; ++n) CJ[k][n] = C_[c][k][d][0] * inv[n][0] + C_[c][k][d][1] * inv[n][1];
        for (unsigned m = 0; m < dim; ++m)
          for (unsigned n = 0; n < dim; ++n) D[c][d][m][n] = det * (inv[m][0] * CJ[0][n] + inv[m][1] * CJ[1][n]);
      }
    for (unsigned i = 0; i < n_; ++i)
      for (unsigned j = i; j < n_; ++j) {
        const double* R = &R_[(shape_[i] * nb_ + shape_[j]) * dim * dim];
        const double(&Dc)[2][2] = D[comp_[i]][comp_[j]];
        K[i * n_ + j] = K[j * n_ + i] = R[0] * Dc[0][0] + R[1] * Dc[0][1] + R[2] * Dc[1][0] + R[3] * Dc[1][1];
      }
  }

 private:
  unsigned n_ = 0, nb_ = 0;
  SymmetricTensor<4, dim> C_;
  std::vector<double> R_;  // [a][b][m][n]
  std::vector<unsigned> comp_, shape_;
};

void assemble_affine(const DoFHandler<dim>& dof, const Quadrature<dim>& q, const SymmetricTensor<4, dim>& C,
                     SparseMatrix<double>& K) {
  const FiniteElement<dim>& fe = dof.get_fe();
  const AffineElementMatrix element(fe, q, C);
  const unsigned n = fe.n_dofs_per_cell();
  FullMatrix<double> Ke(n, n);
  std::vector<types::global_dof_index> local(n);
  for (const auto& cell : dof.active_cell_iterators()) {
    element.compute(cell->vertex(0), cell->vertex(1), cell->vertex(2), &Ke(0, 0));
    cell->get_dof_indices(local);
    K.add(local, Ke);
  }
}

// ---- Platens -----------------------------------------------------------------------------------------------------

// The platen u_y DoFs and the displacements imposed: u_y = -platen_displacement on the top platen and 0 on the
// bottom one, u_x = 0 on both (bonded) or at the bottom-left node (frictionless).
struct PlatenDofs {
  IndexSet top_uy, bottom_uy;
  std::map<types::global_dof_index, double> fixed;
};

PlatenDofs platen_dofs(const DoFHandler<dim>& dof, const Box& box, double tol, const FeOptions& options) {
  const FiniteElement<dim>& fe = dof.get_fe();
  const ComponentMask ux_mask = fe.component_mask(FEValuesExtractors::Scalar(0));
  const ComponentMask uy_mask = fe.component_mask(FEValuesExtractors::Scalar(1));
  PlatenDofs p;
  p.top_uy = DoFTools::extract_boundary_dofs(dof, uy_mask, {top_id});
  p.bottom_uy = DoFTools::extract_boundary_dofs(dof, uy_mask, {bottom_id});
  if (p.top_uy.n_elements() == 0 || p.bottom_uy.n_elements() == 0)
    throw std::invalid_argument("solve_elastic: no mesh edge lies on the " +
                                std::string(p.top_uy.n_elements() == 0 ? "top (y = ymax)" : "bottom (y = ymin)") +
                                " of the mesh's bounding box; the specimen must be a rectangle loaded along y");
  for (const auto i : p.top_uy) p.fixed[i] = -options.platen_displacement;
  for (const auto i : p.bottom_uy) p.fixed[i] = 0.0;
  if (options.platens == Platens::bonded)
    for (const auto i : DoFTools::extract_boundary_dofs(dof, ux_mask, {top_id, bottom_id})) p.fixed[i] = 0.0;
  else
    p.fixed[corner_ux_dof(dof, box, tol)] = 0.0;  // the one pin: rigid x-translation only
  return p;
}

// Rows of the unconstrained K for the platen u_y DoFs: their product with u is the reaction (residual K u - f,
// f = 0), per unit thickness. Kept before the boundary conditions overwrite them.
struct ReactionRows {
  std::vector<types::global_dof_index> column;
  std::vector<double> value;

  void keep(const SparseMatrix<double>& K, const IndexSet& rows) {
    for (const auto row : rows)
      for (auto it = K.begin(row); it != K.end(row); ++it) {
        column.push_back(it->column());
        value.push_back(it->value());
      }
  }
  // Sum over the kept rows of (K u)_row.
  double sum(const Vector<double>& u) const {
    double s = 0;
    for (std::size_t k = 0; k < column.size(); ++k) s += value[k] * u[column[k]];
    return s;
  }
};

// ---- Fields ------------------------------------------------------------------------------------------------------

void centroid_fields(const DoFHandler<dim>& dof, const Mapping<dim>& mapping, const SymmetricTensor<4, dim>& C,
                     const std::vector<unsigned>& cell_triangle, const Vector<double>& u, FeResult& r) {
  const std::size_t n = dof.get_triangulation().n_active_cells();
  r.ux.resize(n), r.uy.resize(n), r.sxx.resize(n), r.syy.resize(n), r.sxy.resize(n);
  const Quadrature<dim> centroid(Point<dim>(1.0 / 3.0, 1.0 / 3.0));
  FEValues<dim> fev(mapping, dof.get_fe(), centroid, update_values | update_gradients);
  const FEValuesExtractors::Vector disp(0);
  std::vector<Tensor<1, dim>> value(1);
  std::vector<SymmetricTensor<2, dim>> strain(1);
  for (const auto& cell : dof.active_cell_iterators()) {
    fev.reinit(cell);
    fev[disp].get_function_values(u, value);
    fev[disp].get_function_symmetric_gradients(u, strain);
    const SymmetricTensor<2, dim> stress = C * strain[0];
    const std::size_t t = cell_triangle[cell->index()];
    r.ux[t] = value[0][0], r.uy[t] = value[0][1];
    r.sxx[t] = stress[0][0], r.syy[t] = stress[1][1], r.sxy[t] = stress[0][1];
  }
}

}  // namespace

// ---- Public ------------------------------------------------------------------------------------------------------

FeResult solve_elastic(const TriMesh& mesh, const theory::TIConstants& c, double bedding_deg, double thickness,
                       const FeOptions& options) {
  check_inputs(mesh, c, bedding_deg, thickness, options);
  FeResult result;
  Stopwatch clock;

  // Setup: triangulation, DoFs, sparsity, platen DoFs.
  const Box box = bounding_box(mesh);
  const double tol = 1e-6 * std::max(box.width(), box.height());
  const std::vector<unsigned> cell_triangle = morton_order(mesh, box);
  Triangulation<dim> tria;
  make_triangulation(mesh, cell_triangle, tria);
  mark_platens(tria, box, tol);
  internal::SimplexSpace<dim> space(tria, options.degree);
  const auto& mapping = space.mapping;
  const auto& quadrature = space.quadrature;
  const auto& dof = space.dof;
  const auto& pattern = space.pattern;
  const auto n_dofs = dof.n_dofs();
  result.dofs = n_dofs;
  result.cells = tria.n_active_cells();
  const PlatenDofs platen = platen_dofs(dof, box, tol, options);
  result.setup_seconds = clock.lap();

  // Assembly per unit thickness; the platen rows are kept before the boundary values overwrite them.
  const SymmetricTensor<4, dim> C = internal::stiffness_tensor(stiffness_voigt(c, bedding_deg, options.plane));
  SparseMatrix<double> K(pattern);
  if (options.assembly == Assembly::affine)
    assemble_affine(dof, quadrature, C, K);
  else
    internal::assemble_fe_values(dof, mapping, quadrature, C, K);
  ReactionRows top_rows, bottom_rows;
  top_rows.keep(K, platen.top_uy);
  bottom_rows.keep(K, platen.bottom_uy);
  Vector<double> u(n_dofs), b(n_dofs);
  MatrixTools::apply_boundary_values(platen.fixed, K, u, b, true);  // symmetric: eliminates the columns too
  result.assemble_seconds = clock.lap();

  // Solve.
  const bool direct =
      options.solver == Solver::direct || (options.solver == Solver::automatic && n_dofs < options.direct_dof_limit);
  result.solver_used = direct ? Solver::direct : Solver::cg_amg;
  if (direct) {
    result.precondition_seconds = internal::solve_direct(K, b, u);
  } else {
    // The rotation mode about the centre of the specimen's bounding box.
    const Point<dim> centre(0.5 * (box.xmin + box.xmax), 0.5 * (box.ymin + box.ymax));
    const internal::CgAmgReport cg = internal::solve_cg_amg(
        K, b, u, internal::dof_geometry(dof), {centre, options.cg_tolerance, 10000, options.degree > 1},
        {"solve_elastic", "FeOptions", [](double v) { return std::to_string(v); }});
    result.iterations = cg.iterations;
    result.precondition_seconds = cg.precondition_seconds;
  }
  result.solve_seconds = clock.lap();

  // Reactions (compression positive) and fields.
  result.top_force = -top_rows.sum(u) * thickness;
  result.bottom_force = bottom_rows.sum(u) * thickness;
  result.apparent_modulus =
      (result.top_force / (box.width() * thickness)) / (options.platen_displacement / box.height());
  if (options.fields) centroid_fields(dof, mapping, C, cell_triangle, u, result);
  result.fields_seconds = clock.lap();
  return result;
}

std::string dealii_version() { return DEAL_II_PACKAGE_VERSION; }

}  // namespace rbdem::continuum
