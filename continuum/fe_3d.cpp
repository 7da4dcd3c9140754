// The 3D FE twin on tetrahedra: FE_SimplexP<3> of degree 1 or 2 on the TetMesh, a homogeneous TI material rotated
// to the joint planes, frictionless or bonded platens. See fe_3d.hpp for the model and the quantities it returns.
#include "continuum/fe_3d.hpp"

#include <deal.II/base/function.h>
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
#include <deal.II/lac/vector.h>
#include <deal.II/numerics/matrix_tools.h>
#include <deal.II/numerics/vector_tools.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>

#include "continuum/fe_internal.hpp"
#include "continuum/solvers.hpp"

namespace rbdem::continuum {

namespace {

using namespace dealii;
constexpr int dim = 3;
constexpr types::boundary_id lateral_id = 0, bottom_id = 1, top_id = 2;
using internal::Extent3;
using internal::Integrals3;
using internal::Stopwatch;

void check_inputs(const TetMesh& mesh, const theory::TIConstants& c, double dip_deg, double dip_direction_deg,
                  const Fe3Options& o) {
  auto fail = [](const std::string& what) { throw std::invalid_argument("solve_elastic_3d: " + what); };
  if (mesh.tets.empty() || mesh.nodes.empty())
    fail("the mesh has no tetrahedra; mesh the specimen first (rbdem::mesh_specimen3)");
  if (!c.admissible())
    fail("the transversely isotropic constants are not admissible: they need E, E', G' > 0, -1 < nu < 1 and "
         "1 - nu - 2 nu'^2 E/E' > 0 (docs/theory.md, section 2); check the units (Pa)");
  if (!std::isfinite(dip_deg) || !std::isfinite(dip_direction_deg))
    fail("the dip and dip direction must be finite angles in degrees");
  if (o.degree != 1 && o.degree != 2)
    fail("Fe3Options::degree = " + std::to_string(o.degree) + "; only 1 (P1) and 2 (P2) are supported");
  if (!(o.platen_displacement > 0) || !std::isfinite(o.platen_displacement))
    fail("Fe3Options::platen_displacement must be a positive displacement in m (compression)");
  if (!(o.cg_tolerance > 0 && o.cg_tolerance < 1)) fail("Fe3Options::cg_tolerance must lie in (0, 1)");
  const int n = int(mesh.nodes.size());
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    for (int v : mesh.tets[t])
      if (v < 0 || v >= n) fail("tetrahedron " + std::to_string(t) + " names a node that does not exist");
    if (!(tet_volume(mesh, t) > 0))
      fail("tetrahedron " + std::to_string(t) + " has a non-positive volume; order its nodes so that "
           "det(b - a, c - a, d - a) > 0 (rbdem::mesh_specimen3 does)");
  }
}

// One cell per tetrahedron, one vertex per node (the same numbering), the platens marked by height.
void make_triangulation(const TetMesh& mesh, const Extent3& z, Triangulation<dim>& tria) {
  std::vector<Point<dim>> vertices;
  vertices.reserve(mesh.nodes.size());
  for (const auto& p : mesh.nodes) vertices.emplace_back(p[0], p[1], p[2]);
  std::vector<CellData<dim>> cells(mesh.tets.size(), CellData<dim>(4));  // 4: tetrahedra (the default is hexahedra)
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    for (unsigned v = 0; v < 4; ++v) cells[t].vertices[v] = unsigned(mesh.tets[t][v]);
    cells[t].material_id = types::material_id(mesh.layer.empty() ? 0 : mesh.layer[t]);
  }
  tria.create_triangulation(vertices, cells, SubCellData());
  for (const auto& cell : tria.active_cell_iterators())
    for (const auto f : cell->face_indices()) {
      if (!cell->face(f)->at_boundary()) continue;
      const double zc = cell->face(f)->center()[2];
      cell->face(f)->set_boundary_id(std::abs(zc - z.zmax) < z.tol   ? top_id
                                     : std::abs(zc - z.zmin) < z.tol ? bottom_id
                                                                     : lateral_id);
    }
}

// The prescribed DoFs: the platens' displacements and, for frictionless platens, the three pins of the rigid
// horizontal motions (fe_3d.hpp).
std::map<types::global_dof_index, double> fixed_dofs(const DoFHandler<dim>& dof, const Mapping<dim>& mapping,
                                                     const Extent3& z, const Fe3Options& o) {
  std::map<types::global_dof_index, double> fixed;
  const bool bonded = o.platens == Platens::bonded;
  const ComponentMask mask = bonded ? ComponentMask(3, true) : ComponentMask({false, false, true});
  const double d = o.platen_displacement;
  VectorTools::interpolate_boundary_values(mapping, dof, bottom_id, Functions::ZeroFunction<dim>(dim), fixed, mask);
  VectorTools::interpolate_boundary_values(mapping, dof, top_id,
                                           Functions::ConstantFunction<dim>(std::vector<double>{0.0, 0.0, -d}),
                                           fixed, mask);
  if (bonded) return fixed;
  // The bottom vertices with the least and the greatest x (ties broken by y): far apart along x.
  using Pin = std::pair<Point<dim>, types::global_dof_index>;  // position, u_x DoF (u_y follows it)
  auto before = [](const Point<dim>& a, const Point<dim>& b) { return a[0] != b[0] ? a[0] < b[0] : a[1] < b[1]; };
  bool any = false;
  Pin first, last;
  for (const auto& cell : dof.active_cell_iterators())
    for (const auto v : cell->vertex_indices()) {
      const Point<dim>& p = cell->vertex(v);
      if (std::abs(p[2] - z.zmin) > z.tol) continue;
      const Pin pin{p, cell->vertex_dof_index(v, 0)};
      if (!any || before(p, first.first)) first = pin;
      if (!any || before(last.first, p)) last = pin;
      any = true;
    }
  fixed[first.second] = 0.0;      // u_x
  fixed[first.second + 1] = 0.0;  // u_y
  fixed[last.second + 1] = 0.0;   // u_y: the rotation about z
  return fixed;
}

void assemble(const DoFHandler<dim>& dof, const Mapping<dim>& mapping, const Quadrature<dim>& q,
              const SymmetricTensor<4, dim>& C, SparseMatrix<double>& K) {
  const FiniteElement<dim>& fe = dof.get_fe();
  FEValues<dim> values(mapping, fe, q, update_gradients | update_JxW_values);
  const FEValuesExtractors::Vector u(0);
  const unsigned n = fe.n_dofs_per_cell();
  FullMatrix<double> local(n, n);
  std::vector<types::global_dof_index> dofs(n);
  std::vector<SymmetricTensor<2, dim>> eps(n), stress(n);
  for (const auto& cell : dof.active_cell_iterators()) {
    values.reinit(cell);
    local = 0;
    for (unsigned k = 0; k < q.size(); ++k) {
      for (unsigned i = 0; i < n; ++i) {
        eps[i] = values[u].symmetric_gradient(i, k);
        stress[i] = C * eps[i];
      }
      const double w = values.JxW(k);
      for (unsigned i = 0; i < n; ++i)
        for (unsigned j = i; j < n; ++j) local(i, j) += (eps[i] * stress[j]) * w;
    }
    for (unsigned i = 0; i < n; ++i)
      for (unsigned j = 0; j < i; ++j) local(i, j) = local(j, i);
    cell->get_dof_indices(dofs);
    K.add(dofs, local);
  }
}

internal::DofGeometry3 dof_geometry_3d(const DoFHandler<dim>& dof, const Mapping<dim>& mapping) {
  internal::DofGeometry3 g;
  g.point.resize(dof.n_dofs());
  DoFTools::map_dofs_to_support_points(mapping, dof, g.point);
  g.component.resize(dof.n_dofs());
  const FiniteElement<dim>& fe = dof.get_fe();
  std::vector<types::global_dof_index> local(fe.n_dofs_per_cell());
  for (const auto& cell : dof.active_cell_iterators()) {
    cell->get_dof_indices(local);
    for (unsigned i = 0; i < local.size(); ++i)
      g.component[local[i]] = static_cast<unsigned char>(fe.system_to_component_index(i).first);
  }
  return g;
}

// The volume, the integral of the strain tensor and of sigma_zz over the specimen.
Integrals3 integrate(const DoFHandler<dim>& dof, const Mapping<dim>& mapping, const Quadrature<dim>& q,
                    const SymmetricTensor<4, dim>& C, const Vector<double>& solution) {
  FEValues<dim> values(mapping, dof.get_fe(), q, update_gradients | update_JxW_values);
  const FEValuesExtractors::Vector u(0);
  std::vector<SymmetricTensor<2, dim>> eps(q.size());
  Integrals3 sum;
  for (const auto& cell : dof.active_cell_iterators()) {
    values.reinit(cell);
    values[u].get_function_symmetric_gradients(solution, eps);
    for (unsigned k = 0; k < q.size(); ++k) {
      const double w = values.JxW(k);
      sum.volume += w;
      sum.strain += eps[k] * w;
      sum.sigma_zz += (C * eps[k])[2][2] * w;
    }
  }
  return sum;
}

}  // namespace

Fe3Result solve_elastic_3d(const TetMesh& mesh, const theory::TIConstants& c, double dip_deg,
                           double dip_direction_deg, const Fe3Options& options) {
  check_inputs(mesh, c, dip_deg, dip_direction_deg, options);
  Fe3Result result;
  Stopwatch clock;
  const Extent3 z = internal::extent_of(mesh);
  Triangulation<dim> tria;
  make_triangulation(mesh, z, tria);
  internal::SimplexSpace<dim> space(tria, options.degree);
  const auto& mapping = space.mapping;
  const auto& quadrature = space.quadrature;
  const auto& dof = space.dof;
  const auto& pattern = space.pattern;
  const auto n_dofs = dof.n_dofs();
  result.dofs = n_dofs;
  result.cells = tria.n_active_cells();
  const auto fixed = fixed_dofs(dof, mapping, z, options);
  result.setup_seconds = clock.lap();

  const SymmetricTensor<4, dim> C = internal::stiffness_tensor_3d(c, dip_deg, dip_direction_deg);
  SparseMatrix<double> K(pattern);
  assemble(dof, mapping, quadrature, C, K);
  Vector<double> u(n_dofs), b(n_dofs);
  MatrixTools::apply_boundary_values(fixed, K, u, b, true);  // symmetric: eliminates the columns too
  result.assemble_seconds = clock.lap();

  const bool direct =
      options.solver == Solver::direct || (options.solver == Solver::automatic && n_dofs < options.direct_dof_limit);
  result.solver_used = direct ? Solver::direct : Solver::cg_amg;
  if (direct) {
    internal::solve_direct(K, b, u);
  } else {
    internal::CgAmgSettings settings;
    settings.tolerance = options.cg_tolerance;
    settings.max_iterations = 10000;
    settings.higher_order = options.degree > 1;
    const auto cg = internal::solve_cg_amg_3d(K, b, u, dof_geometry_3d(dof, mapping), z.centre, settings,
                                              {"solve_elastic_3d", "Fe3Options",
                                               [](double v) { return std::to_string(v); }});
    result.iterations = cg.iterations;
  }
  result.solve_seconds = clock.lap();

  // F H = int sigma_zz dV (fe_3d.hpp); compression positive.
  const Integrals3 sum = integrate(dof, mapping, quadrature, C, u);
  internal::fill_moduli_3d(sum, z, dip_deg, dip_direction_deg, options.platen_displacement, result);
  result.post_seconds = clock.lap();
  return result;
}

namespace internal {

SymmetricTensor<4, 3> stiffness_tensor_3d(const theory::TIConstants& c, double dip_deg, double dip_direction_deg) {
  const theory::Compliance6 S = theory::rotated_compliance(c, dip_deg, dip_direction_deg);
  FullMatrix<double> Sm(6, 6);
  for (unsigned i = 0; i < 6; ++i)
    for (unsigned j = 0; j < 6; ++j) Sm(i, j) = S[i][j];
  FullMatrix<double> Cm(6, 6);
  Cm.invert(Sm);
  constexpr unsigned voigt[3][3] = {{0, 5, 4}, {5, 1, 3}, {4, 3, 2}};
  SymmetricTensor<4, 3> C;
  for (unsigned i = 0; i < 3; ++i)
    for (unsigned j = i; j < 3; ++j)
      for (unsigned k = 0; k < 3; ++k)
        for (unsigned l = k; l < 3; ++l) C[i][j][k][l] = Cm(voigt[i][j], voigt[k][l]);
  return C;
}

Extent3 extent_of(const TetMesh& mesh) {
  Extent3 h;
  double extent = 0;
  std::array<double, 3> lo = mesh.nodes[0], hi = mesh.nodes[0];
  for (const auto& p : mesh.nodes)
    for (int i = 0; i < 3; ++i) lo[i] = std::min(lo[i], p[i]), hi[i] = std::max(hi[i], p[i]);
  for (int i = 0; i < 3; ++i) extent = std::max(extent, hi[i] - lo[i]);
  h.zmin = lo[2], h.zmax = hi[2], h.tol = 1e-6 * extent;
  h.centre = Point<3>(0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2]));
  return h;
}

namespace {
double along(const SymmetricTensor<2, 3>& t, const theory::Vec3& d) {
  double v = 0;
  for (unsigned i = 0; i < 3; ++i)
    for (unsigned j = 0; j < 3; ++j) v += d[i] * t[i][j] * d[j];
  return v;
}
}  // namespace

void fill_moduli_3d(const Integrals3& sum, const Extent3& z, double dip_deg, double dip_direction_deg,
                    double platen_displacement, Fe3Result& r) {
  const double H = z.zmax - z.zmin, axial_strain = -platen_displacement / H;
  const theory::PlaneAxes axes = theory::plane_axes(dip_deg, dip_direction_deg);
  r.volume = sum.volume;
  r.axial_force = -sum.sigma_zz / H;  // F H = int sigma_zz dV (fe_3d.hpp); compression positive
  const double mean_stress = sum.sigma_zz / sum.volume;
  r.mean_axial_strain = sum.strain[2][2] / sum.volume;
  r.apparent_modulus = mean_stress / axial_strain;
  r.mean_strain_modulus = mean_stress / r.mean_axial_strain;
  r.strain_strike = along(sum.strain, axes.strike) / sum.volume;
  r.strain_dip = along(sum.strain, axes.dip_direction) / sum.volume;
  r.poisson_strike = -r.strain_strike / r.mean_axial_strain;
  r.poisson_dip = -r.strain_dip / r.mean_axial_strain;
}

}  // namespace internal

}  // namespace rbdem::continuum
