// Stress concentration at a circular hole: the deal.II model of hole.hpp.
//
// Stages, each a function below: check inputs -> graded polar mesh (vertices and cells straight from arrays,
// boundary ids by coordinate, PolarManifold on the hole) -> DoFs and constraints (symmetry planes or three point
// pins) -> assemble K and the traction load per unit thickness -> UMFPACK (solvers.cpp) -> FE stress at the hole
// vertices.
#include "continuum/hole.hpp"
#include "continuum/solvers.hpp"

#include <deal.II/base/function.h>
#include <deal.II/base/geometry_info.h>
#include <deal.II/base/point.h>
#include <deal.II/base/quadrature.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/tensor.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_q.h>
#include <deal.II/grid/manifold_lib.h>
#include <deal.II/grid/tria.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/sparsity_pattern.h>
#include <deal.II/lac/vector.h>
#include <deal.II/numerics/vector_tools.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "continuum/fe_model.hpp"

namespace rbdem::continuum {

namespace {

using namespace dealii;
constexpr int dim = 2;
constexpr double pi = 3.14159265358979323846;

// Boundary ids: the hole, the square's edges (loaded by t = p n_x e_x, which is zero on y = +-L), and the two
// symmetry planes of the quarter model.
constexpr types::boundary_id hole_id = 0, outer_id = 1, symmetry_x_id = 2, symmetry_y_id = 3;
constexpr types::manifold_id hole_manifold_id = 1;

void check_inputs(const theory::TIConstants& c, double angle_deg, const HoleOptions& o) {
  auto fail = [](const std::string& what) { throw std::invalid_argument("solve_hole: " + what); };
  if (!c.admissible())
    fail("the transversely isotropic constants are not admissible (docs/theory.md, section 2); check the units (Pa) and the "
         "pairing of E with nu and E' with nu'");
  if (!std::isfinite(angle_deg)) fail("material_angle_deg is not finite; give the bedding angle in degrees");
  if (o.degree != 1 && o.degree != 2)
    fail("HoleOptions::degree = " + std::to_string(o.degree) + "; only 1 (Q1) and 2 (Q2) are supported");
  if (o.refinement < 0 || o.refinement > 8)
    fail("HoleOptions::refinement = " + std::to_string(o.refinement) + "; give a level in 0..8");
  if (!(o.plate_ratio > 2) || !std::isfinite(o.plate_ratio))
    fail("HoleOptions::plate_ratio = " + std::to_string(o.plate_ratio) +
         "; give the plate half-width over the hole radius, > 2 (20 to 80 for an infinite-plate comparison)");
  if (!(o.hole_radius > 0) || !std::isfinite(o.hole_radius))
    fail("HoleOptions::hole_radius = " + std::to_string(o.hole_radius) + " m; give a positive radius in m");
  if (!(o.applied_stress != 0) || !std::isfinite(o.applied_stress))
    fail("HoleOptions::applied_stress = " + std::to_string(o.applied_stress) + " Pa; give a non-zero stress");
}

// Material axes aligned with the load: S16 = S26 = 0 and the quarter model is exact.
bool aligned(double angle_deg) {
  const double r = std::remainder(angle_deg, 90.0);
  return std::abs(r) < 1e-9;
}

struct MeshSize {
  unsigned n_theta = 0;  // elements along the modelled arc (quarter or full circle)
  unsigned n_r = 0;      // elements along each ray
  bool quarter = true;
};

// Graded polar mesh of hole.hpp. Vertex (i, j): ray j at theta_j, i-th of n_r + 1 points along it; the cell
// (i, j) has the lexicographic vertices (i, j), (i+1, j), (i, j+1), (i+1, j+1): r then theta, counter-clockwise.
void make_mesh(const MeshSize& m, double a, double L, Triangulation<dim>& tria) {
  const unsigned n_rays = m.quarter ? m.n_theta + 1 : m.n_theta;
  const double dtheta = (m.quarter ? pi / 2 : 2 * pi) / m.n_theta;
  std::vector<Point<dim>> vertices;
  vertices.reserve(std::size_t(n_rays) * (m.n_r + 1));
  for (unsigned j = 0; j < n_rays; ++j) {
    // Exact directions on the axes (cos(pi/2) is 6e-17, not 0), so the symmetry planes are exactly x = 0, y = 0.
    const unsigned quarter_turn = m.quarter ? m.n_theta : m.n_theta / 4;
    double cs = std::cos(j * dtheta), sn = std::sin(j * dtheta);
    if (j % quarter_turn == 0) {
      const unsigned q = (j / quarter_turn) % 4;
      cs = (q == 0) ? 1 : (q == 2) ? -1 : 0;
      sn = (q == 1) ? 1 : (q == 3) ? -1 : 0;
    }
    const double R = L / std::max(std::abs(cs), std::abs(sn));  // ray to the square's edge
    for (unsigned i = 0; i <= m.n_r; ++i) {
      const double r = a * std::pow(R / a, double(i) / m.n_r);
      Point<dim> p(r * cs, r * sn);
      if (i == m.n_r)  // snap onto the square's edge, so the boundary ids by coordinate are exact
        for (unsigned d = 0; d < dim; ++d)
          if (std::abs(std::abs(p[d]) - L) < 1e-9 * L) p[d] = std::copysign(L, p[d]);
      vertices.push_back(p);
    }
  }
  auto index = [&](unsigned i, unsigned j) { return (j % n_rays) * (m.n_r + 1) + i; };
  std::vector<CellData<dim>> cells;
  cells.reserve(std::size_t(m.n_theta) * m.n_r);
  for (unsigned j = 0; j < m.n_theta; ++j)
    for (unsigned i = 0; i < m.n_r; ++i) {
      CellData<dim> cell;
      cell.vertices = {index(i, j), index(i + 1, j), index(i, j + 1), index(i + 1, j + 1)};
      cells.push_back(cell);
    }
  tria.create_triangulation(vertices, cells, SubCellData());

  const double tol = 1e-9 * L;
  for (const auto& cell : tria.active_cell_iterators())
    for (const auto f : cell->face_indices()) {
      const auto face = cell->face(f);
      if (!face->at_boundary()) continue;
      const Point<dim> p0 = face->vertex(0), p1 = face->vertex(1);
      if (std::abs(p0.norm() - a) < tol && std::abs(p1.norm() - a) < tol) {
        face->set_boundary_id(hole_id);
        face->set_manifold_id(hole_manifold_id);
      } else if (std::abs(p0[0]) < tol && std::abs(p1[0]) < tol) {
        face->set_boundary_id(symmetry_x_id);
      } else if (std::abs(p0[1]) < tol && std::abs(p1[1]) < tol) {
        face->set_boundary_id(symmetry_y_id);
      } else {
        face->set_boundary_id(outer_id);
      }
    }
  tria.set_manifold(hole_manifold_id, PolarManifold<dim>(Point<dim>(0, 0)));
}

// Quarter: u_x = 0 on x = 0, u_y = 0 on y = 0. Full plate: u = 0 at (0, -L) and u_x = 0 at (0, L), both on
// traction-free edges; with the self-equilibrated load these remove the rigid modes and carry no force.
void make_constraints(const DoFHandler<dim>& dof, const MappingQ<dim>& mapping, bool quarter, double L,
                      AffineConstraints<double>& constraints) {
  constraints.clear();
  if (quarter) {
    const Functions::ZeroFunction<dim> zero(dim);
    VectorTools::interpolate_boundary_values(mapping, dof, symmetry_x_id, zero, constraints,
                                             ComponentMask(std::vector<bool>{true, false}));
    VectorTools::interpolate_boundary_values(mapping, dof, symmetry_y_id, zero, constraints,
                                             ComponentMask(std::vector<bool>{false, true}));
  } else {
    const Point<dim> bottom(0, -L), top(0, L);
    for (const auto& cell : dof.active_cell_iterators())
      for (const auto v : cell->vertex_indices()) {
        if (cell->vertex(v).distance(bottom) < 1e-9 * L) {
          constraints.add_line(cell->vertex_dof_index(v, 0));
          constraints.add_line(cell->vertex_dof_index(v, 1));
        } else if (cell->vertex(v).distance(top) < 1e-9 * L) {
          constraints.add_line(cell->vertex_dof_index(v, 0));
        }
      }
  }
  constraints.close();
}

// Voigt strain [eps_xx, eps_yy, gamma_xy] of a displacement gradient.
std::array<double, 3> voigt_strain(const Tensor<2, dim>& g) {
  return {g[0][0], g[1][1], g[0][1] + g[1][0]};
}

std::array<double, 3> times(const Stiffness3& C, const std::array<double, 3>& e) {
  std::array<double, 3> s{};
  for (int r = 0; r < 3; ++r) s[r] = C[r][0] * e[0] + C[r][1] * e[1] + C[r][2] * e[2];
  return s;
}

void assemble(const DoFHandler<dim>& dof, const MappingQ<dim>& mapping, const Stiffness3& C, double p,
              const AffineConstraints<double>& constraints, SparseMatrix<double>& K, Vector<double>& f) {
  const auto& fe = dof.get_fe();
  const QGauss<dim> quadrature(fe.degree + 1);
  const QGauss<dim - 1> face_quadrature(fe.degree + 1);
  FEValues<dim> fev(mapping, fe, quadrature, update_gradients | update_JxW_values);
  FEFaceValues<dim> fefv(mapping, fe, face_quadrature, update_values | update_normal_vectors | update_JxW_values);
  const FEValuesExtractors::Vector u(0);
  const unsigned n = fe.n_dofs_per_cell();
  FullMatrix<double> Ke(n, n);
  Vector<double> fe_rhs(n);
  std::vector<std::array<double, 3>> eps(n), sig(n);
  std::vector<types::global_dof_index> dofs(n);
  for (const auto& cell : dof.active_cell_iterators()) {
    fev.reinit(cell);
    Ke = 0;
    fe_rhs = 0;
    for (const unsigned q : fev.quadrature_point_indices()) {
      for (unsigned i = 0; i < n; ++i) {
        eps[i] = voigt_strain(fev[u].gradient(i, q));
        sig[i] = times(C, eps[i]);
      }
      const double w = fev.JxW(q);
      for (unsigned i = 0; i < n; ++i)
        for (unsigned j = 0; j < n; ++j)
          Ke(i, j) += (eps[i][0] * sig[j][0] + eps[i][1] * sig[j][1] + eps[i][2] * sig[j][2]) * w;
    }
    // Far-field traction t = sigma_inf n = p n_x e_x on every edge of the square (zero on y = +-L).
    for (const auto fi : cell->face_indices()) {
      if (!cell->face(fi)->at_boundary() || cell->face(fi)->boundary_id() != outer_id) continue;
      fefv.reinit(cell, fi);
      for (const unsigned q : fefv.quadrature_point_indices()) {
        const Tensor<1, dim> t({p * fefv.normal_vector(q)[0], 0.0});
        for (unsigned i = 0; i < n; ++i) fe_rhs(i) += fefv[u].value(i, q) * t * fefv.JxW(q);
      }
    }
    cell->get_dof_indices(dofs);
    constraints.distribute_local_to_global(Ke, fe_rhs, dofs, K, f);
  }
}

struct VertexStress {
  Point<dim> x;
  std::array<double, 3> sigma{};  // sum over the cells sharing the vertex, [xx, yy, xy]
  double hoop_strain = 0;         // sum over the cells sharing the vertex of t . eps(u_h) . t
  int count = 0;
};

// The FE stress C eps(u_h) at each hole-boundary vertex, from FEValues at the unit-cell vertices of every cell
// touching the hole, averaged over the (one or two) cells sharing the vertex.
std::map<unsigned, VertexStress> hole_vertex_stress(const DoFHandler<dim>& dof, const MappingQ<dim>& mapping,
                                                    const Stiffness3& C, const Vector<double>& solution) {
  std::vector<Point<dim>> unit_vertices;
  for (const unsigned v : GeometryInfo<dim>::vertex_indices())
    unit_vertices.push_back(GeometryInfo<dim>::unit_cell_vertex(v));
  const Quadrature<dim> at_vertices(unit_vertices, std::vector<double>(unit_vertices.size(), 1.0));
  FEValues<dim> fev(mapping, dof.get_fe(), at_vertices, update_gradients | update_quadrature_points);
  const FEValuesExtractors::Vector u(0);
  std::vector<Tensor<2, dim>> grads(unit_vertices.size());
  std::map<unsigned, VertexStress> out;
  for (const auto& cell : dof.active_cell_iterators())
    for (const auto fi : cell->face_indices()) {
      if (!cell->face(fi)->at_boundary() || cell->face(fi)->boundary_id() != hole_id) continue;
      fev.reinit(cell);
      fev[u].get_function_gradients(solution, grads);
      for (unsigned fv = 0; fv < GeometryInfo<dim>::vertices_per_face; ++fv) {
        const unsigned v = GeometryInfo<dim>::face_to_cell_vertices(fi, fv);
        const auto s = times(C, voigt_strain(grads[v]));
        auto& vs = out[cell->vertex_index(v)];
        vs.x = fev.quadrature_point(v);
        for (int k = 0; k < 3; ++k) vs.sigma[k] += s[k];
        const Tensor<1, dim> t({-vs.x[1] / vs.x.norm(), vs.x[0] / vs.x.norm()});
        vs.hoop_strain += t * (grads[v] * t);
        ++vs.count;
      }
    }
  return out;
}

}  // namespace

HoleResult solve_hole(const theory::TIConstants& c, double material_angle_deg, theory::Plane plane,
                      const HoleOptions& o) {
  check_inputs(c, material_angle_deg, o);
  const auto start = std::chrono::steady_clock::now();
  HoleResult result;
  const double a = o.hole_radius, L = o.plate_ratio * o.hole_radius, p = o.applied_stress;
  const Stiffness3 C = stiffness_voigt(c, material_angle_deg, plane);

  MeshSize m;
  m.quarter = aligned(material_angle_deg) && !o.full_plate;
  const unsigned level = 1u << unsigned(o.refinement);
  const unsigned n_r0 = std::max(1u, unsigned(std::lround(4 * std::log(o.plate_ratio) / (pi / 2))));
  m.n_theta = (m.quarter ? 4 : 16) * level;
  m.n_r = n_r0 * level;
  result.quarter = m.quarter;
  result.hole_element_size = a * (pi / 2) / (4 * level);

  Triangulation<dim> tria;
  make_mesh(m, a, L, tria);
  const FESystem<dim> fe(FE_Q<dim>(unsigned(o.degree)), dim);
  const MappingQ<dim> mapping(unsigned(o.degree));
  DoFHandler<dim> dof(tria);
  dof.distribute_dofs(fe);
  result.dofs = dof.n_dofs();
  result.cells = tria.n_active_cells();

  AffineConstraints<double> constraints;
  make_constraints(dof, mapping, m.quarter, L, constraints);
  DynamicSparsityPattern dsp(dof.n_dofs());
  DoFTools::make_sparsity_pattern(dof, dsp, constraints, false);
  SparsityPattern pattern;
  pattern.copy_from(dsp);
  SparseMatrix<double> K(pattern);
  Vector<double> f(dof.n_dofs()), u(dof.n_dofs());
  assemble(dof, mapping, C, p, constraints, K, f);

  internal::solve_direct(K, f, u);
  constraints.distribute(u);

  // Hoop and radial stress at the hole vertices; the top of the hole is the vertex with the largest y.
  // The hoop stress from the hoop strain: on the traction-free hole sigma_rr = tau_rtheta = 0, so
  // eps_thetatheta = S_tt sigma_thetatheta with S_tt = 1 / E along the tangent (the compliance rotated to the
  // tangent frame, tangent at phi + 90 deg from x).
  const auto a_material = theory::reduced_compliance(c, plane);
  result.scf_max = -std::numeric_limits<double>::infinity();
  double top_y = -std::numeric_limits<double>::infinity();
  for (const auto& [index, vs] : hole_vertex_stress(dof, mapping, C, u)) {
    (void)index;
    const double sxx = vs.sigma[0] / vs.count, syy = vs.sigma[1] / vs.count, sxy = vs.sigma[2] / vs.count;
    const double phi = std::atan2(vs.x[1], vs.x[0]), cs = std::cos(phi), sn = std::sin(phi);
    const double hoop_pointwise = (sxx * sn * sn + syy * cs * cs - 2 * sxy * sn * cs) / p;
    const double radial = (sxx * cs * cs + syy * sn * sn + 2 * sxy * sn * cs) / p;
    const double S_tt = theory::rotated_compliance(a_material, material_angle_deg - (phi * 180 / pi + 90))[0][0];
    const double hoop = vs.hoop_strain / vs.count / S_tt / p;
    result.radial_stress_residual = std::max(result.radial_stress_residual, std::abs(radial));
    if (hoop > result.scf_max) {
      result.scf_max = hoop;
      result.scf_max_angle_deg = phi * 180 / pi;
    }
    if (vs.x[1] > top_y) {
      top_y = vs.x[1];
      result.scf = hoop;
      result.scf_pointwise = hoop_pointwise;
    }
  }
  result.scf_closed_form = aligned(material_angle_deg) ? hole_scf_closed_form(theory::rotated_compliance(
                                           theory::reduced_compliance(c, plane), material_angle_deg))
                                     : std::numeric_limits<double>::quiet_NaN();
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace rbdem::continuum
