// The 3D FE twin with joints: deal.II P1 elasticity on a TetMesh split along its joints, with zero-thickness
// triangular interface elements assembled by hand (deal.II has none). See fe_joints3.hpp for the model and
// tests/test_fe_joints3.cpp for the closed forms it meets; the split itself is deal.II-free (fe_joints3_mesh.cpp).
//
// Stages: check inputs and split the mesh (corner classes, one vertex per class) -> triangulation of the copies ->
// DoFs, constraints (platens, pins, ties of glued copies), sparsity with the interface couplings -> assemble cells
// (per-layer C, FEValues) and interfaces into the constrained matrix -> solve (UMFPACK or CG+AMG, solvers.cpp) ->
// distribute -> the force and the mean strains (cells plus the interfaces' jumps), the openings.
#include "continuum/fe_joints3.hpp"

#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/fe/fe_values.h>
#include <deal.II/fe/mapping_fe.h>
#include <deal.II/grid/tria.h>
#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/sparsity_pattern.h>
#include <deal.II/lac/vector.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <string>

#include "continuum/fe_internal.hpp"
#include "continuum/fe_joints3_split.hpp"
#include "continuum/solvers.hpp"

namespace rbdem::continuum {

namespace {

using namespace dealii;
constexpr int dim = 3;
constexpr const char* function = "solve_elastic_3d_jointed";
using internal::InterfaceElement3;
using internal::Split3;
using internal::Extent3;
using internal::Integrals3;
using internal::Stopwatch;

[[noreturn]] void fail(const std::string& what) { throw std::invalid_argument(std::string(function) + ": " + what); }

std::string text(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

int layer_of(const TetMesh& mesh, std::size_t t) { return mesh.layer.empty() ? 0 : mesh.layer[t]; }

// ---- Inputs ------------------------------------------------------------------------------------------------------

// Checks everything but the mesh and the interfaces (split_tet_mesh checks those); returns the number of layers.
std::size_t check_inputs(const TetMesh& mesh, const std::vector<theory::TIConstants>& layer_constants, double dip_deg,
                         double dip_direction_deg, const Fe3Options& o) {
  int max_layer = 0;
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) max_layer = std::max(max_layer, layer_of(mesh, t));
  const std::size_t n_layers = std::max(mesh.num_layers(), std::size_t(max_layer) + 1);
  if (layer_constants.size() != n_layers)
    fail("layer_constants has " + std::to_string(layer_constants.size()) + " entries but the mesh has " +
         std::to_string(n_layers) + " layers (mesh.layer_names: " + std::to_string(mesh.num_layers()) +
         ", largest layer id: " + std::to_string(max_layer) + "); give the constants of every layer, in layer id order");
  for (std::size_t l = 0; l < layer_constants.size(); ++l)
    if (!layer_constants[l].admissible()) {
      const auto& c = layer_constants[l];
      fail("layer_constants[" + std::to_string(l) + "] (E = " + text(c.E) + " Pa, nu = " + text(c.nu) +
           ", E' = " + text(c.E_prime) + " Pa, nu' = " + text(c.nu_prime) + ", G' = " + text(c.G_prime) +
           " Pa) is not admissible: it needs E, E', G' > 0, -1 < nu < 1 and 1 - nu - 2 nu'^2 E/E' > 0");
    }
  if (!std::isfinite(dip_deg) || !std::isfinite(dip_direction_deg))
    fail("the dip and dip direction must be finite angles in degrees");
  if (o.degree != 1)
    fail("Fe3Options::degree = " + std::to_string(o.degree) + "; the model with the joints has P1 elements only "
         "(its interface element is the three-node triangle): set degree = 1");
  if (!(o.platen_displacement > 0) || !std::isfinite(o.platen_displacement))
    fail("Fe3Options::platen_displacement = " + text(o.platen_displacement) +
         " m; give the positive downward displacement of the top platen in m (compression)");
  if (!(o.cg_tolerance > 0 && o.cg_tolerance < 1))
    fail("Fe3Options::cg_tolerance = " + text(o.cg_tolerance) + "; give a relative residual in (0, 1)");
  return n_layers;
}

// ---- Material and geometry ---------------------------------------------------------------------------------------

// One cell per tetrahedron, its vertices the copies of its corners, its material id its layer. Copies of one node
// share a position but not a vertex, so the two cells of an interface face are not neighbours: deal.II sees two
// boundary faces there, and nothing couples them but the interface element or the ties.
void make_triangulation(const TetMesh& mesh, const Split3& split, Triangulation<dim>& tria) {
  std::vector<Point<dim>> vertices(split.copy_node.size());
  for (std::size_t c = 0; c < vertices.size(); ++c) {
    const auto& p = mesh.nodes[std::size_t(split.copy_node[c])];
    vertices[c] = Point<dim>(p[0], p[1], p[2]);
  }
  std::vector<CellData<dim>> cells(mesh.tets.size(), CellData<dim>(4));  // 4 vertices: a tetrahedron
  for (std::size_t t = 0; t < mesh.tets.size(); ++t) {
    for (unsigned v = 0; v < 4; ++v) cells[t].vertices[v] = split.corner_copy[4 * t + v];
    cells[t].material_id = types::material_id(layer_of(mesh, t));
  }
  tria.create_triangulation(vertices, cells, SubCellData());
}

// ---- DoFs and constraints ----------------------------------------------------------------------------------------

using CopyDofs = std::vector<std::array<types::global_dof_index, 3>>;  // copy -> its u_x, u_y, u_z DoFs

// Position (its copy's node) and component of every DoF: where the AMG's rigid-body modes are evaluated.
internal::DofGeometry3 copy_geometry(const TetMesh& mesh, const Split3& split, const CopyDofs& cdof,
                                     types::global_dof_index n_dofs) {
  internal::DofGeometry3 g;
  g.point.resize(n_dofs);
  g.component.resize(n_dofs);
  for (std::size_t c = 0; c < cdof.size(); ++c) {
    const auto& p = mesh.nodes[std::size_t(split.copy_node[c])];
    for (unsigned k = 0; k < dim; ++k) {
      g.point[cdof[c][k]] = Point<dim>(p[0], p[1], p[2]);
      g.component[cdof[c][k]] = static_cast<unsigned char>(k);
    }
  }
  return g;
}

// The prescribed value of every DoF (NaN = free): the platens by position (every copy keeps its node's boundary
// position) and, between frictionless platens, the pins of fe_3d.hpp on one copy each.
std::vector<double> prescribed_values(const TetMesh& mesh, const Split3& split, const CopyDofs& cdof,
                                      types::global_dof_index n_dofs, const Extent3& z, const Fe3Options& o) {
  std::vector<double> fixed(n_dofs, std::numeric_limits<double>::quiet_NaN());
  const bool bonded = o.platens == Platens::bonded;
  const std::size_t none = cdof.size();
  std::size_t first = none, last = none;  // the bottom copies with the least and the greatest x (ties by y)
  bool any_top = false;
  auto before = [&](std::size_t a, std::size_t b) {
    const auto &p = mesh.nodes[std::size_t(split.copy_node[a])], &q = mesh.nodes[std::size_t(split.copy_node[b])];
    return p[0] != q[0] ? p[0] < q[0] : p[1] < q[1];
  };
  for (std::size_t c = 0; c < cdof.size(); ++c) {
    const double zc = mesh.nodes[std::size_t(split.copy_node[c])][2];
    const bool top = std::abs(zc - z.zmax) < z.tol, bottom = std::abs(zc - z.zmin) < z.tol;
    if (!top && !bottom) continue;
    fixed[cdof[c][2]] = top ? -o.platen_displacement : 0.0;
    any_top |= top;
    if (bonded) fixed[cdof[c][0]] = fixed[cdof[c][1]] = 0.0;
    if (!bottom) continue;
    if (first == none || before(c, first)) first = c;
    if (last == none || before(last, c)) last = c;
  }
  if (first == none || !any_top)
    fail(std::string("no tetrahedron has a node on the ") + (any_top ? "bottom (z = zmin)" : "top (z = zmax)") +
         " of the mesh's nodes; the specimen must stand on its lowest z and be loaded at its highest (remove nodes "
         "that no tetrahedron uses)");
  if (!bonded) {
    fixed[cdof[first][0]] = fixed[cdof[first][1]] = 0.0;  // the horizontal translations
    fixed[cdof[last][1]] = 0.0;                           // the rotation about z
  }
  return fixed;
}

// The prescribed values, and the glued copies tied to the smallest DoF of their class. A class that holds a
// prescribed DoF is prescribed as a whole (its members share position and value), so no DoF is both tied and fixed.
void make_constraints(const TetMesh& mesh, const Split3& split, const CopyDofs& cdof, types::global_dof_index n_dofs,
                      const Extent3& z, const Fe3Options& o, AffineConstraints<double>& constraints) {
  std::vector<double> fixed = prescribed_values(mesh, split, cdof, n_dofs, z, o);
  std::vector<unsigned> root(n_dofs);
  std::iota(root.begin(), root.end(), 0u);
  auto find = [&](unsigned i) {
    while (root[i] != i) i = root[i] = root[root[i]];
    return i;
  };
  for (const InterfaceElement3& e : split.interfaces)
    if (e.glued)
      for (unsigned i = 0; i < 3; ++i)
        for (unsigned k = 0; k < dim; ++k) {
          const unsigned a = find(unsigned(cdof[e.copy[0][i]][k])), b = find(unsigned(cdof[e.copy[1][i]][k]));
          if (a != b) root[std::max(a, b)] = std::min(a, b);
        }
  for (types::global_dof_index i = 0; i < n_dofs; ++i)  // a fixed member fixes its class (through its root)
    if (!std::isnan(fixed[i])) fixed[find(unsigned(i))] = fixed[i];
  for (types::global_dof_index i = 0; i < n_dofs; ++i) {
    const unsigned r = find(unsigned(i));
    if (!std::isnan(fixed[r])) {
      constraints.add_line(i);
      constraints.set_inhomogeneity(i, fixed[r]);
    } else if (r != i) {
      constraints.add_line(i);
      constraints.add_entry(i, r, 1.0);
    }
  }
  constraints.close();
}

// ---- Sparsity and assembly ---------------------------------------------------------------------------------------

// An interface element's DoFs, [side][node i][component] flattened; duplicates (the same copy on both sides, at the
// edge of a joint that ends inside the specimen) merged, slot[j] = where local DoF j of the 18 went.
struct ElementDofs {
  std::vector<types::global_dof_index> local;
  std::array<unsigned, 18> slot{};
};

std::vector<ElementDofs> interface_element_dofs(const Split3& split, const CopyDofs& cdof) {
  std::vector<ElementDofs> out;
  for (const InterfaceElement3& e : split.interfaces) {
    if (e.glued) continue;
    ElementDofs d;
    for (unsigned j = 0; j < 18; ++j) {
      const auto g = cdof[e.copy[j / 9][(j / 3) % 3]][j % 3];
      d.slot[j] = unsigned(std::find(d.local.begin(), d.local.end(), g) - d.local.begin());
      if (d.slot[j] == d.local.size()) d.local.push_back(g);
    }
    out.push_back(std::move(d));
  }
  return out;
}

// The cells' couplings and those of each interface element's DoFs, the constrained DoFs condensed.
void make_pattern(const DoFHandler<dim>& dof, const AffineConstraints<double>& constraints,
                  const std::vector<ElementDofs>& element_dofs, SparsityPattern& pattern) {
  DynamicSparsityPattern dsp(dof.n_dofs(), dof.n_dofs());
  DoFTools::make_sparsity_pattern(dof, dsp, constraints, /*keep_constrained_dofs=*/false);
  for (const ElementDofs& d : element_dofs) constraints.add_entries_local_to_global(d.local, dsp, false);
  pattern.copy_from(dsp);
}

// The cells, each with the stiffness C[l] of its layer l = material id.
void assemble_cells(const DoFHandler<dim>& dof, const Mapping<dim>& mapping, const Quadrature<dim>& q,
                    const std::vector<SymmetricTensor<4, dim>>& C, const AffineConstraints<double>& constraints,
                    SparseMatrix<double>& K, Vector<double>& b) {
  const FiniteElement<dim>& fe = dof.get_fe();
  FEValues<dim> values(mapping, fe, q, update_gradients | update_JxW_values);
  const FEValuesExtractors::Vector u(0);
  const unsigned n = fe.n_dofs_per_cell();
  FullMatrix<double> local(n, n);
  Vector<double> zero(n);
  std::vector<types::global_dof_index> dofs(n);
  std::vector<SymmetricTensor<2, dim>> eps(n), stress(n);
  for (const auto& cell : dof.active_cell_iterators()) {
    values.reinit(cell);
    const SymmetricTensor<4, dim>& Cl = C[cell->material_id()];
    local = 0;
    for (unsigned k = 0; k < q.size(); ++k) {
      for (unsigned i = 0; i < n; ++i) {
        eps[i] = values[u].symmetric_gradient(i, k);
        stress[i] = Cl * eps[i];
      }
      const double w = values.JxW(k);
      for (unsigned i = 0; i < n; ++i)
        for (unsigned j = i; j < n; ++j) local(i, j) += (eps[i] * stress[j]) * w;
    }
    for (unsigned i = 0; i < n; ++i)
      for (unsigned j = 0; j < i; ++j) local(i, j) = local(j, i);
    cell->get_dof_indices(dofs);
    constraints.distribute_local_to_global(local, zero, dofs, K, b);
  }
}

// Interface element (18 x 18) on [side][node i][component]: the exact integral of the linear jump against
// K = k_n n n^T + k_s (I - n n^T), i.e. sign_side sign_side' M_ij K with M_ij = A/12 (1 + delta_ij).
void interface_matrix(const InterfaceElement3& e, FullMatrix<double>& Ke) {
  double k[3][3];
  for (unsigned a = 0; a < 3; ++a)
    for (unsigned c = 0; c < 3; ++c) k[a][c] = (a == c ? e.k_s : 0.0) + (e.k_n - e.k_s) * e.normal[a] * e.normal[c];
  for (unsigned r = 0; r < 18; ++r)
    for (unsigned s = 0; s < 18; ++s) {
      const double sign = (r / 9 == s / 9) ? 1.0 : -1.0;
      const double m = e.area / 12.0 * ((r / 3) % 3 == (s / 3) % 3 ? 2.0 : 1.0);
      Ke(r, s) = sign * m * k[r % 3][s % 3];
    }
}

// The interface elements that are not glued, element_dofs[k] the DoFs of the k-th of them. Where both sides hold
// the same copy (the edge of a joint that ends inside the specimen) the jump is zero and the rows cancel.
void assemble_interfaces(const Split3& split, const std::vector<ElementDofs>& element_dofs,
                         const AffineConstraints<double>& constraints, SparseMatrix<double>& K, Vector<double>& b) {
  FullMatrix<double> Ke(18, 18);
  std::size_t k = 0;
  for (const InterfaceElement3& e : split.interfaces) {
    if (e.glued) continue;
    interface_matrix(e, Ke);
    const ElementDofs& d = element_dofs[k++];
    FullMatrix<double> Km(d.local.size(), d.local.size());
    for (unsigned i = 0; i < 18; ++i)
      for (unsigned j = 0; j < 18; ++j) Km(d.slot[i], d.slot[j]) += Ke(i, j);
    Vector<double> zero(d.local.size());
    constraints.distribute_local_to_global(Km, zero, d.local, K, b);
  }
}

// ---- Results -----------------------------------------------------------------------------------------------------

// The volume, the integral of sigma_zz over the cells, and of the strain over the jointed body: the cells' plus
// int sym([u] (x) n) dA over the interfaces (fe_joints3.hpp).
Integrals3 integrate_cells(const DoFHandler<dim>& dof, const Mapping<dim>& mapping, const Quadrature<dim>& q,
                          const std::vector<SymmetricTensor<4, dim>>& C, const Vector<double>& solution) {
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
      sum.sigma_zz += (C[cell->material_id()] * eps[k])[2][2] * w;
    }
  }
  return sum;
}

// Adds the interfaces' jumps to the strain integral; fills the mean opening and slip of every interface.
void integrate_interfaces(const Split3& split, const CopyDofs& cdof, const Vector<double>& u, Integrals3& sum,
                          JointedFe3Result& r) {
  r.interface_opening.assign(split.interfaces.size(), 0.0);
  r.interface_slip.assign(split.interfaces.size(), 0.0);
  for (std::size_t k = 0; k < split.interfaces.size(); ++k) {
    const InterfaceElement3& e = split.interfaces[k];
    if (e.glued) continue;
    Tensor<1, dim> jump, n;  // the mean jump over the triangle: the mean of its three nodes' (linear over it)
    for (unsigned c = 0; c < dim; ++c) {
      n[c] = e.normal[c];
      for (unsigned i = 0; i < 3; ++i) jump[c] += (u[cdof[e.copy[1][i]][c]] - u[cdof[e.copy[0][i]][c]]) / 3.0;
    }
    sum.strain += e.area * symmetrize(outer_product(jump, n));
    r.interface_opening[k] = jump * n;
    r.interface_slip[k] = (jump - (jump * n) * n).norm();
  }
}

}  // namespace

JointedFe3Result solve_elastic_3d_jointed(const TetMesh& mesh, const std::vector<theory::TIConstants>& layer_constants,
                                          double dip_deg, double dip_direction_deg,
                                          const std::vector<InterfaceFace>& interfaces, const Fe3Options& o) {
  Stopwatch total, clock;
  JointedFe3Result r;
  // ---- Inputs and the split.
  const Split3 split = internal::split_tet_mesh(function, mesh, interfaces);
  const std::size_t n_layers = check_inputs(mesh, layer_constants, dip_deg, dip_direction_deg, o);
  r.interface_faces = interfaces.size();
  r.copies = split.copy_node.size();
  for (int c : split.copies_per_node) r.duplicated_nodes += c > 1 ? std::size_t(c - 1) : 0;
  for (const InterfaceElement3& e : split.interfaces) {
    r.glued_faces += e.glued ? 1 : 0;
    r.inert_faces += e.copy[0] == e.copy[1] ? 1 : 0;
  }

  // ---- Triangulation of the copies, DoFs, constraints, sparsity.
  const Extent3 z = internal::extent_of(mesh);
  Triangulation<dim> tria;
  make_triangulation(mesh, split, tria);
  const FESystem<dim> fe(FE_SimplexP<dim>(1), dim);
  const MappingFE<dim> mapping(FE_SimplexP<dim>(1));
  const QGaussSimplex<dim> quadrature(2);  // as solve_elastic_3d's P1
  DoFHandler<dim> dof(tria);
  dof.distribute_dofs(fe);
  const auto n_dofs = dof.n_dofs();
  r.dofs = n_dofs, r.cells = tria.n_active_cells();
  const CopyDofs cdof = internal::vertex_dofs(dof, split.copy_node.size());
  AffineConstraints<double> constraints;
  make_constraints(mesh, split, cdof, n_dofs, z, o, constraints);
  r.constrained_dofs = constraints.n_constraints();
  const std::vector<ElementDofs> element_dofs = interface_element_dofs(split, cdof);
  SparsityPattern pattern;
  make_pattern(dof, constraints, element_dofs, pattern);
  r.setup_seconds = clock.lap();

  // ---- Assembly.
  std::vector<SymmetricTensor<4, dim>> C(n_layers);
  for (std::size_t l = 0; l < n_layers; ++l) C[l] = internal::stiffness_tensor_3d(layer_constants[l], dip_deg, dip_direction_deg);
  SparseMatrix<double> K(pattern);
  Vector<double> u(n_dofs), b(n_dofs);
  assemble_cells(dof, mapping, quadrature, C, constraints, K, b);
  assemble_interfaces(split, element_dofs, constraints, K, b);
  r.assemble_seconds = clock.lap();

  // ---- Solve.
  const bool direct = o.solver == Solver::direct || (o.solver == Solver::automatic && n_dofs < o.direct_dof_limit);
  r.solver_used = direct ? Solver::direct : Solver::cg_amg;
  if (direct) {
    internal::solve_direct(K, b, u);
  } else {
    internal::CgAmgSettings settings;
    settings.tolerance = o.cg_tolerance;
    settings.max_iterations = 20000;  // soft joints slow CG down: the near null space is the whole body's
    r.iterations = internal::solve_cg_amg_3d(K, b, u, copy_geometry(mesh, split, cdof, n_dofs), z.centre, settings,
                                             {function, "Fe3Options", text})
                       .iterations;
  }
  constraints.distribute(u);
  r.solve_seconds = clock.lap();

  // ---- The force, the mean strains, the openings.
  Integrals3 sum = integrate_cells(dof, mapping, quadrature, C, u);
  integrate_interfaces(split, cdof, u, sum, r);
  internal::fill_moduli_3d(sum, z, dip_deg, dip_direction_deg, o.platen_displacement, r);
  r.post_seconds = clock.lap();
  r.seconds = total.lap();
  return r;
}

}  // namespace rbdem::continuum
