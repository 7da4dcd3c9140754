// deal.II model of the Brazilian test: a homogeneous transversely isotropic disc under two opposite point forces
// on its vertical diameter. See fe_disc.hpp for the model, the pins and the three centre-stress estimates, and
// theory/disc.hpp for the closed forms it is checked against. The deal.II 9.4 pitfalls of docs/continuum.md are
// avoided as in continuum/fe_model.cpp: CellData<2>(3) for triangles, counter-clockwise cells (checked),
// MappingFE(FE_SimplexP(1)) passed explicitly; MPI before Trilinos is solvers.cpp's.
//
// Stages: check inputs -> disc geometry from the boundary nodes -> triangulation straight from the arrays (cell k
// is triangle k) -> DoFs, sparsity -> K per unit thickness (sigma = C eps, K_ij = int eps(phi_i) : C : eps(phi_j))
// -> point loads -P/t, +P/t on u_y of the top and bottom nodes -> keep the pinned rows of K, impose the pins ->
// solve (solvers.cpp) -> reactions (K u - f on the kept rows, times t) -> cell stresses -> centre estimates.
#include "continuum/fe_internal.hpp"
#include "continuum/fe_disc.hpp"
#include "continuum/solvers.hpp"

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
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

namespace rbdem::continuum {

namespace {

using namespace dealii;
constexpr int dim = 2;

std::string num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

[[noreturn]] void fail(const std::string& what) { throw std::invalid_argument("solve_disc: " + what); }

// ---- Inputs ------------------------------------------------------------------------------------------------------

void check_inputs(const TriMesh& mesh, const theory::TIConstants& c, double bedding_deg, double load,
                  double thickness, const DiscOptions& o) {
  if (mesh.triangles.empty() || mesh.nodes.empty()) fail("the mesh has no triangles; mesh the disc first");
  if (!c.admissible())
    fail("the transversely isotropic constants (E = " + num(c.E) + " Pa, nu = " + num(c.nu) + ", E' = " +
         num(c.E_prime) + " Pa, nu' = " + num(c.nu_prime) + ", G' = " + num(c.G_prime) +
         " Pa) are not admissible: they need E, E', G' > 0, -1 < nu < 1 and 1 - nu - 2 nu'^2 E/E' > 0 "
         "(docs/theory.md, section 2); check the units (Pa) and the pairing of E with nu and E' with nu'");
  if (!std::isfinite(bedding_deg)) fail("bedding_deg is not a finite angle; give the bedding dip in degrees");
  if (!(load > 0) || !std::isfinite(load))
    fail("load = " + num(load) + " N; give the positive diametral force P (compression) in N");
  if (!(thickness > 0) || !std::isfinite(thickness))
    fail("thickness = " + num(thickness) + " m; give the positive out-of-plane thickness in m");
  if (o.degree != 1 && o.degree != 2)
    fail("DiscOptions::degree = " + std::to_string(o.degree) + "; only 1 (P1) and 2 (P2) are supported");
  if (!(o.average_radius >= 0) || !std::isfinite(o.average_radius))
    fail("DiscOptions::average_radius = " + num(o.average_radius) + " m; give a radius >= 0 (0: R / 10)");
  if (!(o.cg_tolerance > 0 && o.cg_tolerance < 1))
    fail("DiscOptions::cg_tolerance = " + num(o.cg_tolerance) + "; give a relative residual in (0, 1)");
  if (!(o.geometry_tolerance > 0 && o.geometry_tolerance < 0.1))
    fail("DiscOptions::geometry_tolerance = " + num(o.geometry_tolerance) + "; give a fraction of R in (0, 0.1)");
  const int n = int(mesh.nodes.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (int v : mesh.triangles[t])
      if (v < 0 || v >= n)
        fail("triangle " + std::to_string(t) + " refers to node " + std::to_string(v) + " but the mesh has " +
             std::to_string(n) + " nodes");
    const double a = signed_area(mesh, t);
    if (!(a > 0))
      fail("triangle " + std::to_string(t) + " has signed area " + num(a) +
           " m^2; triangles must be counter-clockwise and non-degenerate");
  }
}

struct Disc {
  double cx = 0, cy = 0, R = 0;
  int top = -1, bottom = -1, centre = -1;
};

// The disc from its boundary: the highest and lowest boundary nodes are the load points; they must lie on one
// vertical line and every boundary node on the circle through them (fe_disc.hpp).
Disc disc_geometry(const TriMesh& mesh, double tolerance) {
  // Boundary edges: those of one triangle. Sorting the 3T edge keys counts them without a map.
  std::vector<std::pair<int, int>> edges;
  edges.reserve(3 * mesh.triangles.size());
  for (const auto& t : mesh.triangles)
    for (int k = 0; k < 3; ++k) edges.emplace_back(std::min(t[k], t[(k + 1) % 3]), std::max(t[k], t[(k + 1) % 3]));
  std::sort(edges.begin(), edges.end());
  std::vector<char> on_boundary(mesh.nodes.size(), 0), used(mesh.nodes.size(), 0);
  for (const auto& t : mesh.triangles)
    for (int v : t) used[v] = 1;
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i;
    while (j < edges.size() && edges[j] == edges[i]) ++j;
    if (j - i > 2)
      fail("the edge between nodes " + std::to_string(edges[i].first) + " and " + std::to_string(edges[i].second) +
           " belongs to " + std::to_string(j - i) + " triangles; the mesh must be a conforming triangulation of the disc");
    if (j - i == 1) on_boundary[edges[i].first] = on_boundary[edges[i].second] = 1;
    i = j;
  }
  Disc d;
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
    if (!on_boundary[i]) continue;
    if (d.top < 0 || mesh.nodes[i][1] > mesh.nodes[d.top][1]) d.top = int(i);
    if (d.bottom < 0 || mesh.nodes[i][1] < mesh.nodes[d.bottom][1]) d.bottom = int(i);
  }
  const auto& T = mesh.nodes[d.top];
  const auto& B = mesh.nodes[d.bottom];
  d.cx = 0.5 * (T[0] + B[0]), d.cy = 0.5 * (T[1] + B[1]);
  d.R = 0.5 * std::hypot(T[0] - B[0], T[1] - B[1]);
  const double tol = tolerance * d.R;
  auto node_text = [&](int i) {
    return "node " + std::to_string(i) + " (" + num(mesh.nodes[i][0]) + ", " + num(mesh.nodes[i][1]) + ")";
  };
  if (!(d.R > 0)) fail("the mesh has no extent in y; the disc must be loaded along y");
  if (std::abs(T[0] - B[0]) > tol)
    fail("the highest boundary " + node_text(d.top) + " and the lowest " + node_text(d.bottom) +
         " are not on one vertical line: the mesh needs nodes exactly at the top and bottom points (cx, cy +- R) "
         "of the disc, where the diametral load is applied");
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
    if (!on_boundary[i]) continue;
    const double r = std::hypot(mesh.nodes[i][0] - d.cx, mesh.nodes[i][1] - d.cy);
    if (std::abs(r - d.R) > tol)
      fail("boundary " + node_text(int(i)) + " lies at " + num(r) + " m from (" + num(d.cx) + ", " + num(d.cy) +
           "), not on the circle of radius R = " + num(d.R) +
           " m through the highest and lowest boundary nodes: the mesh must be a disc with nodes exactly at the top "
           "and bottom points (cx, cy +- R) of its vertical diameter");
  }
  double best = std::numeric_limits<double>::max();
  for (std::size_t i = 0; i < mesh.nodes.size(); ++i) {
    if (!used[i]) continue;
    const double r = std::hypot(mesh.nodes[i][0] - d.cx, mesh.nodes[i][1] - d.cy);
    if (r < best) best = r, d.centre = int(i);
  }
  if (d.centre == d.top || d.centre == d.bottom || on_boundary[d.centre])
    fail("no interior node is nearer the centre than the boundary; the centre pin needs an interior node "
         "(mesh the inside of the disc)");
  return d;
}

// The cells whose centroid lies within r_avg of the centre, which centre_mean and centre_fit average over; decided
// from the mesh before any work so that a bad radius fails early.
std::vector<std::size_t> cells_within(const TriMesh& mesh, const Disc& disc, double r_avg) {
  std::vector<std::size_t> inside;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    double x = 0, y = 0;
    for (int v : mesh.triangles[t]) x += mesh.nodes[v][0] / 3, y += mesh.nodes[v][1] / 3;
    if (std::hypot(x - disc.cx, y - disc.cy) <= r_avg) inside.push_back(t);
  }
  if (inside.empty())
    fail("no triangle centroid lies within average_radius = " + num(r_avg) + " m of the centre (" + num(disc.cx) +
         ", " + num(disc.cy) + "); give a larger DiscOptions::average_radius or a finer mesh");
  return inside;
}

// ---- Triangulation, DoFs -----------------------------------------------------------------------------------------

// One level-0 cell per triangle in mesh order, vertices in the triangle's (counter-clockwise) order. Returns the
// deal.II vertex of each mesh node (invalid for nodes no triangle uses).
std::vector<unsigned> make_triangulation(const TriMesh& mesh, Triangulation<dim>& tria) {
  std::vector<unsigned> vertex_of(mesh.nodes.size(), numbers::invalid_unsigned_int);
  std::vector<Point<dim>> vertices;
  std::vector<CellData<dim>> cells(mesh.triangles.size(), CellData<dim>(3));  // 3: a triangle, not a quad
  for (std::size_t k = 0; k < mesh.triangles.size(); ++k)
    for (unsigned i = 0; i < 3; ++i) {
      const int v = mesh.triangles[k][i];
      if (vertex_of[v] == numbers::invalid_unsigned_int) {
        vertex_of[v] = unsigned(vertices.size());
        vertices.emplace_back(mesh.nodes[v][0], mesh.nodes[v][1]);
      }
      cells[k].vertices[i] = vertex_of[v];
    }
  tria.create_triangulation(vertices, cells, SubCellData());
  return vertex_of;
}

// The DoF of component `component` at deal.II vertex `vertex`.
types::global_dof_index vertex_dof(const DoFHandler<dim>& dof, unsigned vertex, unsigned component) {
  const FiniteElement<dim>& fe = dof.get_fe();
  for (const auto& cell : dof.active_cell_iterators())
    for (const unsigned v : cell->vertex_indices()) {
      if (cell->vertex_index(v) != vertex) continue;
      for (unsigned k = 0; k < fe.n_dofs_per_vertex(); ++k)
        if (fe.system_to_component_index(v * fe.n_dofs_per_vertex() + k).first == component)
          return cell->vertex_dof_index(v, k);
    }
  throw std::logic_error("solve_disc: no DoF at a mesh vertex");
}

// ---- Pins, reactions ---------------------------------------------------------------------------------------------

using Pin = std::pair<int, unsigned>;  // (mesh node, component)

// The point constraints of each DiscPins choice (fe_disc.hpp).
std::vector<Pin> pin_list(DiscPins pins, const Disc& disc) {
  switch (pins) {
    case DiscPins::centre_and_top: return {{disc.centre, 0}, {disc.centre, 1}, {disc.top, 0}};
    case DiscPins::diameter_ends: return {{disc.top, 0}, {disc.bottom, 0}, {disc.centre, 1}};
    case DiscPins::centre_top_and_bottom: return {{disc.centre, 0}, {disc.centre, 1}, {disc.top, 0}, {disc.bottom, 0}};
  }
  return {};
}

// A row of the unconstrained K and f at a pin: the reaction is (K u - f)_row, kept before the constraints
// overwrite it.
struct KeptRow {
  std::vector<std::pair<types::global_dof_index, double>> entries;
  double f = 0;
};

// Keeps the rows of the pinned DoFs, then imposes the pins (zero displacement) on K u = b. Returns the kept rows.
std::vector<KeptRow> impose_pins(const std::vector<Pin>& pins, const DoFHandler<dim>& dof,
                                 const std::vector<unsigned>& vertex_of, SparseMatrix<double>& K, Vector<double>& u,
                                 Vector<double>& b) {
  std::vector<KeptRow> kept(pins.size());
  std::map<types::global_dof_index, double> fixed;
  for (std::size_t k = 0; k < pins.size(); ++k) {
    const auto row = vertex_dof(dof, vertex_of[pins[k].first], pins[k].second);
    for (auto it = K.begin(row); it != K.end(row); ++it) kept[k].entries.emplace_back(it->column(), it->value());
    kept[k].f = b[row];
    fixed[row] = 0.0;
  }
  MatrixTools::apply_boundary_values(fixed, K, u, b, true);  // symmetric: eliminates the columns too
  return kept;
}

// The pins' reactions (N, for the thickness) into result.reactions and result.max_reaction. With three pins they
// are 0 by statics (the load has no resultant and no moment): anything above 1e-6 P means the load or the pins are
// not what this file thinks they are.
void pin_reactions(const std::vector<Pin>& pins, const std::vector<KeptRow>& kept, const Vector<double>& u,
                   double load, double thickness, DiscResult& result) {
  for (std::size_t k = 0; k < pins.size(); ++k) {
    double s = -kept[k].f;
    for (const auto& [col, value] : kept[k].entries) s += value * u[col];
    result.reactions.push_back({pins[k].first, int(pins[k].second), s * thickness});
    result.max_reaction = std::max(result.max_reaction, std::abs(s * thickness));
  }
  if (pins.size() == 3 && result.max_reaction > 1e-6 * load)
    throw std::runtime_error("solve_disc: the statically determinate pins carry a reaction of " +
                             num(result.max_reaction) + " N for a load of " + num(load) +
                             " N; it must be 0 (internal check)");
}

// ---- Centre estimates --------------------------------------------------------------------------------------------

struct CellStress {
  theory::DiscStress mean;  // the cell mean (= the centroid value: the stress is at most linear in a cell)
  double area = 0;
  std::array<std::array<double, 2>, 3> vertex{};
};

theory::DiscStress stress_of(const SymmetricTensor<2, dim>& s) { return {s[0][0], s[1][1], s[0][1]}; }

// Constant term of the area-weighted least-squares quadratic through the cell means of the cells with centroid
// within r of (cx, cy); monomials in X = (x - cx) / r, Y = (y - cy) / r, their cell means by the edge-midpoint
// rule (exact for quadratics). NaN with fewer than 12 cells or a singular normal matrix.
theory::DiscStress quadratic_fit(const std::vector<CellStress>& cells, const std::vector<std::size_t>& inside,
                                 double cx, double cy, double r) {
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  if (inside.size() < 12) return {nan, nan, nan};
  constexpr int m = 6;
  double M[m][m + 3] = {};  // the normal matrix and the three right-hand sides
  double scale = 0;         // the area: M[0][0] before elimination
  for (const std::size_t k : inside) {
    const CellStress& c = cells[k];
    double f[m] = {};
    for (int e = 0; e < 3; ++e) {
      const double X = (0.5 * (c.vertex[e][0] + c.vertex[(e + 1) % 3][0]) - cx) / r;
      const double Y = (0.5 * (c.vertex[e][1] + c.vertex[(e + 1) % 3][1]) - cy) / r;
      const double mono[m] = {1, X, Y, X * X, X * Y, Y * Y};
      for (int i = 0; i < m; ++i) f[i] += mono[i] / 3;
    }
    const double rhs[3] = {c.mean.xx, c.mean.yy, c.mean.xy};
    for (int i = 0; i < m; ++i) {
      for (int j = 0; j < m; ++j) M[i][j] += c.area * f[i] * f[j];
      for (int s = 0; s < 3; ++s) M[i][m + s] += c.area * f[i] * rhs[s];
    }
    scale += c.area;
  }
  for (int col = 0; col < m; ++col) {  // Gauss-Jordan with partial pivoting
    int p = col;
    for (int i = col + 1; i < m; ++i)
      if (std::abs(M[i][col]) > std::abs(M[p][col])) p = i;
    if (!(std::abs(M[p][col]) > 1e-12 * scale)) return {nan, nan, nan};
    std::swap(M[p], M[col]);
    for (int i = 0; i < m; ++i) {
      if (i == col) continue;
      const double factor = M[i][col] / M[col][col];
      for (int j = col; j < m + 3; ++j) M[i][j] -= factor * M[col][j];
    }
  }
  return {M[0][m] / M[0][0], M[0][m + 1] / M[0][0], M[0][m + 2] / M[0][0]};
}

// The FE stress of every cell at its centroid (the cell mean: the stress is constant (P1) or linear (P2) in a
// cell), with the cell's area and vertices; cell k is triangle k.
std::vector<CellStress> cell_stresses(const TriMesh& mesh, const DoFHandler<dim>& dof, const Mapping<dim>& mapping,
                                      const FiniteElement<dim>& fe, const SymmetricTensor<4, dim>& C,
                                      const Vector<double>& u) {
  std::vector<CellStress> cells(mesh.triangles.size());
  const Quadrature<dim> centroid(Point<dim>(1.0 / 3.0, 1.0 / 3.0));
  FEValues<dim> fev(mapping, fe, centroid, update_gradients);
  const FEValuesExtractors::Vector disp(0);
  std::vector<SymmetricTensor<2, dim>> strain(1);
  for (const auto& cell : dof.active_cell_iterators()) {
    fev.reinit(cell);
    fev[disp].get_function_symmetric_gradients(u, strain);
    const std::size_t t = cell->index();  // cell k is triangle k
    cells[t].mean = stress_of(C * strain[0]);
    cells[t].area = signed_area(mesh, t);
    for (int v = 0; v < 3; ++v) cells[t].vertex[v] = mesh.nodes[mesh.triangles[t][v]];
  }
  return cells;
}

// centre_mean: the area-weighted mean of the cell means within r_avg (`inside`), with the area and the number of
// cells it averages over.
void centre_mean(const std::vector<CellStress>& cells, const std::vector<std::size_t>& inside, DiscResult& result) {
  theory::DiscStress s;
  double area = 0;
  for (const std::size_t t : inside) {
    s.xx += cells[t].area * cells[t].mean.xx, s.yy += cells[t].area * cells[t].mean.yy;
    s.xy += cells[t].area * cells[t].mean.xy, area += cells[t].area;
  }
  result.centre_mean = {s.xx / area, s.yy / area, s.xy / area};
  result.average_area = area;
  result.average_cells = inside.size();
}

// centre_point: the FE stress at (cx, cy) in every cell that contains it (barycentric coordinates >= -1e-10),
// area-weighted.
theory::DiscStress centre_point(const DoFHandler<dim>& dof, const Mapping<dim>& mapping, const FiniteElement<dim>& fe,
                                const SymmetricTensor<4, dim>& C, const Vector<double>& u, double cx, double cy) {
  const FEValuesExtractors::Vector disp(0);
  std::vector<SymmetricTensor<2, dim>> strain(1);
  theory::DiscStress s;
  double area = 0;
  for (const auto& cell : dof.active_cell_iterators()) {
    const Point<dim> v0 = cell->vertex(0);
    const Tensor<1, dim> e1 = cell->vertex(1) - v0, e2 = cell->vertex(2) - v0;
    const double det = e1[0] * e2[1] - e1[1] * e2[0];
    const double dx = cx - v0[0], dy = cy - v0[1];
    const double xi = (dx * e2[1] - dy * e2[0]) / det, eta = (e1[0] * dy - e1[1] * dx) / det;
    if (xi < -1e-10 || eta < -1e-10 || 1 - xi - eta < -1e-10) continue;
    const Quadrature<dim> at(Point<dim>(std::clamp(xi, 0.0, 1.0), std::clamp(eta, 0.0, 1.0)));
    FEValues<dim> fev(mapping, fe, at, update_gradients);
    fev.reinit(cell);
    fev[disp].get_function_symmetric_gradients(u, strain);
    const theory::DiscStress here = stress_of(C * strain[0]);
    const double a = 0.5 * std::abs(det);
    s.xx += a * here.xx, s.yy += a * here.yy, s.xy += a * here.xy, area += a;
  }
  if (area > 0) return {s.xx / area, s.yy / area, s.xy / area};
  const double nan = std::numeric_limits<double>::quiet_NaN();
  return {nan, nan, nan};  // unreachable for a disc: its centre lies in some cell
}

}  // namespace

// ---- Public ------------------------------------------------------------------------------------------------------

DiscResult solve_disc(const TriMesh& mesh, const theory::TIConstants& c, double bedding_deg, theory::Plane plane,
                      double load, double thickness, const DiscOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  check_inputs(mesh, c, bedding_deg, load, thickness, options);
  const Disc disc = disc_geometry(mesh, options.geometry_tolerance);
  const double r_avg = options.average_radius > 0 ? options.average_radius : disc.R / 10;
  DiscResult result;
  result.cx = disc.cx, result.cy = disc.cy, result.radius = disc.R;
  result.top_node = disc.top, result.bottom_node = disc.bottom, result.centre_node = disc.centre;
  result.average_radius = r_avg;
  const std::vector<std::size_t> inside = cells_within(mesh, disc, r_avg);

  Triangulation<dim> tria;
  const std::vector<unsigned> vertex_of = make_triangulation(mesh, tria);
  internal::SimplexSpace<dim> space(tria, options.degree);
  const auto& fe = space.fe;
  const auto& mapping = space.mapping;
  const auto& quadrature = space.quadrature;
  const auto& dof = space.dof;
  const auto& pattern = space.pattern;
  const auto n_dofs = dof.n_dofs();
  result.dofs = n_dofs;
  result.cells = tria.n_active_cells();

  // Per unit thickness: the point forces are P / t.
  const SymmetricTensor<4, dim> C = internal::stiffness_tensor(stiffness_voigt(c, bedding_deg, plane));
  SparseMatrix<double> K(pattern);
  internal::assemble_fe_values(dof, mapping, quadrature, C, K);
  Vector<double> u(n_dofs), b(n_dofs);
  b[vertex_dof(dof, vertex_of[disc.top], 1)] = -load / thickness;
  b[vertex_dof(dof, vertex_of[disc.bottom], 1)] = load / thickness;
  const std::vector<Pin> pins = pin_list(options.pins, disc);
  const std::vector<KeptRow> kept = impose_pins(pins, dof, vertex_of, K, u, b);

  const bool direct =
      options.solver == Solver::direct || (options.solver == Solver::automatic && n_dofs < options.direct_dof_limit);
  result.solver_used = direct ? Solver::direct : Solver::cg_amg;
  if (direct) {
    internal::solve_direct(K, b, u);
  } else {
    // The rotation mode about the disc centre.
    result.iterations = internal::solve_cg_amg(K, b, u, internal::dof_geometry(dof),
                                               {Point<dim>(disc.cx, disc.cy), options.cg_tolerance, 10000,
                                                options.degree > 1},
                                               {"solve_disc", "DiscOptions", num})
                            .iterations;
  }
  pin_reactions(pins, kept, u, load, thickness, result);

  // Cell stresses and the three centre estimates.
  const std::vector<CellStress> cells = cell_stresses(mesh, dof, mapping, fe, C, u);
  if (options.fields) {
    result.sxx.resize(cells.size()), result.syy.resize(cells.size()), result.sxy.resize(cells.size());
    for (std::size_t t = 0; t < cells.size(); ++t)
      result.sxx[t] = cells[t].mean.xx, result.syy[t] = cells[t].mean.yy, result.sxy[t] = cells[t].mean.xy;
  }
  centre_mean(cells, inside, result);
  result.centre_fit = quadratic_fit(cells, inside, disc.cx, disc.cy, r_avg);
  result.centre_point = centre_point(dof, mapping, fe, C, u, disc.cx, disc.cy);
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace rbdem::continuum
