// The FE twin with joints: deal.II P1 elasticity on a TriMesh split along its joints, with zero-thickness interface
// elements assembled by hand (deal.II has none). See fe_joints.hpp for the model and tests/test_fe_joints.cpp for
// the closed forms it meets; docs/continuum.md describes the homogenized model whose platens and solvers it
// shares. deal.II stays in this file and in the solvers it shares with that model (solvers.cpp).
//
// Stages: check inputs -> split the mesh (corner classes, one vertex per class) -> triangulation of the copies ->
// DoFs, constraints (platens, pin, ties of glued copies), sparsity with the interface couplings -> assemble cells
// (constant strain triangles, per-layer C) and interfaces into the constrained matrix, and the platen rows of the
// unconstrained one into two vectors (reactions) -> solve (UMFPACK or CG+AMG, solvers.cpp) -> distribute ->
// reactions, fields.
#include "common/union_find.hpp"
#include "continuum/fe_internal.hpp"
#include "continuum/fe_joints.hpp"
#include "continuum/solvers.hpp"

#include <deal.II/base/index_set.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>
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
#include <cstdint>
#include <limits>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace rbdem::continuum {

namespace {

using namespace dealii;
constexpr int dim = 2;

using internal::Stopwatch;

[[noreturn]] void fail(const char* function, const std::string& what) {
  throw std::invalid_argument(std::string(function) + ": " + what);
}

// ---- Small tools -------------------------------------------------------------------------------------------------

struct Box {
  double xmin = 0, xmax = 0, ymin = 0, ymax = 0;
  double width() const { return xmax - xmin; }
  double height() const { return ymax - ymin; }
};

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

int layer_of(const TriMesh& mesh, std::size_t t) { return mesh.layer.empty() ? 0 : mesh.layer[t]; }

std::string text(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// ---- Mesh checks and edges ---------------------------------------------------------------------------------------

void check_mesh(const char* function, const TriMesh& mesh) {
  if (mesh.triangles.empty() || mesh.nodes.empty())
    fail(function, "the mesh has no triangles; mesh the specimen first");
  if (!mesh.layer.empty() && mesh.layer.size() != mesh.triangles.size())
    fail(function, "mesh.layer has " + std::to_string(mesh.layer.size()) + " entries but the mesh has " +
                       std::to_string(mesh.triangles.size()) + " triangles; give one layer id per triangle (or none)");
  const int n = int(mesh.nodes.size());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    for (int v : mesh.triangles[t])
      if (v < 0 || v >= n)
        fail(function, "triangle " + std::to_string(t) + " refers to node " + std::to_string(v) +
                           " but the mesh has " + std::to_string(n) + " nodes");
    const double a = signed_area(mesh, t);
    if (!(a > 0))
      fail(function, "triangle " + std::to_string(t) + " has signed area " + text(a) +
                         " m^2; triangles must be counter-clockwise and non-degenerate");
    if (layer_of(mesh, t) < 0)
      fail(function, "triangle " + std::to_string(t) + " has the negative layer id " +
                         std::to_string(layer_of(mesh, t)));
  }
}

// The one or two triangles on each mesh edge, with the corner (3 t + i) of each end in each triangle.
struct EdgeSides {
  int n = 0;                      // triangles on the edge: 1 (boundary) or 2 (interior); more is a broken mesh
  std::array<unsigned, 2> tri{};  // the triangles
  std::array<std::array<unsigned, 2>, 2> corner{};  // corner[k][0 / 1]: corner of the smaller / larger node in tri[k]
  int interface = -1;             // index into the interfaces, -1 if none
};

using EdgeMap = std::unordered_map<std::uint64_t, EdgeSides>;

EdgeMap edge_map(const char* function, const TriMesh& mesh) {
  EdgeMap edges;
  edges.reserve(mesh.triangles.size() * 2);
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
    for (unsigned i = 0; i < 3; ++i) {
      const int a = mesh.triangles[t][i], b = mesh.triangles[t][(i + 1) % 3];
      EdgeSides& e = edges[unordered_pair_key(a, b)];
      if (e.n == 2)
        fail(function, "the mesh edge (" + std::to_string(a) + ", " + std::to_string(b) +
                           ") belongs to more than two triangles; the mesh is not a manifold");
      const unsigned ca = unsigned(3 * t + i), cb = unsigned(3 * t + (i + 1) % 3);
      e.tri[e.n] = unsigned(t);
      e.corner[e.n] = a < b ? std::array<unsigned, 2>{ca, cb} : std::array<unsigned, 2>{cb, ca};
      ++e.n;
    }
  return edges;
}

// Marks the interface edges in `edges`; throws for interfaces a user can get wrong.
void mark_interfaces(const char* function, const TriMesh& mesh, const std::vector<InterfaceEdge>& interfaces,
                     EdgeMap& edges) {
  const int n = int(mesh.nodes.size());
  for (std::size_t k = 0; k < interfaces.size(); ++k) {
    const InterfaceEdge& f = interfaces[k];
    const std::string name = "interfaces[" + std::to_string(k) + "] = (" + std::to_string(f.node_a) + ", " +
                             std::to_string(f.node_b) + ")";
    if (f.node_a < 0 || f.node_a >= n || f.node_b < 0 || f.node_b >= n)
      fail(function, name + " refers to a node outside 0 .. " + std::to_string(n - 1));
    if (f.node_a == f.node_b) fail(function, name + " joins a node to itself; give the two end nodes of a mesh edge");
    const auto it = edges.find(unordered_pair_key(f.node_a, f.node_b));
    if (it == edges.end())
      fail(function, name + " is not an edge of the mesh (no triangle has both nodes); joints must follow "
                            "chains of mesh edges (put nodes on the joint lines when meshing)");
    if (it->second.n != 2)
      fail(function, name + " is a boundary edge of the mesh (one triangle); an interface needs a triangle on "
                            "each side");
    if (it->second.interface >= 0)
      fail(function, name + " is the same edge as interfaces[" + std::to_string(it->second.interface) +
                         "]; list each interface edge once");
    const bool glued_n = std::isinf(f.k_n) && f.k_n > 0, glued_s = std::isinf(f.k_s) && f.k_s > 0;
    if (!(f.k_n > 0) || !(f.k_s > 0))
      fail(function, name + " has k_n = " + text(f.k_n) + " Pa/m, k_s = " + text(f.k_s) +
                         " Pa/m; both stiffnesses must be > 0 (+inf for a glued edge)");
    if (glued_n != glued_s)
      fail(function, name + " has k_n = " + text(f.k_n) + " Pa/m, k_s = " + text(f.k_s) +
                         " Pa/m; give both infinite (glued) or both finite (a large finite value acts as a penalty)");
    it->second.interface = int(k);
  }
}

// ---- The split ---------------------------------------------------------------------------------------------------

// Corners (3 t + i) grouped into classes connected through non-interface interior edges: each class is one copy
// (vertex) of its node. Copies are numbered in the order of first appearance along `triangle_order`.
struct Split {
  std::vector<unsigned> corner_copy;  // corner -> copy
  std::vector<int> copy_node;         // copy -> mesh node
  std::vector<int> copies_per_node;   // mesh node -> number of copies
};

Split split_mesh(const TriMesh& mesh, const EdgeMap& edges, const std::vector<unsigned>& triangle_order) {
  UnionFind corners(3 * mesh.triangles.size());
  for (const auto& [key, e] : edges)
    if (e.n == 2 && e.interface < 0)
      for (unsigned end = 0; end < 2; ++end) corners.unite(e.corner[0][end], e.corner[1][end]);
  Split s;
  s.corner_copy.assign(3 * mesh.triangles.size(), std::numeric_limits<unsigned>::max());
  s.copies_per_node.assign(mesh.nodes.size(), 0);
  std::vector<unsigned> copy_of_root(3 * mesh.triangles.size(), std::numeric_limits<unsigned>::max());
  for (const unsigned t : triangle_order)
    for (unsigned i = 0; i < 3; ++i) {
      const unsigned c = 3 * t + i, root = corners.find(c);
      if (copy_of_root[root] == std::numeric_limits<unsigned>::max()) {
        copy_of_root[root] = unsigned(s.copy_node.size());
        s.copy_node.push_back(mesh.triangles[t][i]);
        ++s.copies_per_node[mesh.triangles[t][i]];
      }
      s.corner_copy[c] = copy_of_root[root];
    }
  return s;
}

// One interface edge after the split: the copies of its end nodes p, q on both sides, its geometry and stiffness.
struct Interface {
  std::array<unsigned, 4> copy{};  // p side 1, q side 1, p side 2, q side 2
  double length = 0;               // m
  double nx = 0, ny = 0;           // unit normal
  double k_n = 0, k_s = 0;         // Pa/m
  bool glued = false;
  double side2 = 1;                // +1 when side 2 lies on the +n side of the edge: [u] . n side2 > 0 opens it
};

std::vector<Interface> interface_elements(const TriMesh& mesh, const std::vector<InterfaceEdge>& interfaces,
                                          const EdgeMap& edges, const Split& split) {
  std::vector<Interface> out(interfaces.size());
  for (std::size_t k = 0; k < interfaces.size(); ++k) {
    const InterfaceEdge& f = interfaces[k];
    const EdgeSides& e = edges.at(unordered_pair_key(f.node_a, f.node_b));
    Interface& g = out[k];
    // end 0 = the smaller node p, end 1 = the larger node q
    g.copy = {split.corner_copy[e.corner[0][0]], split.corner_copy[e.corner[0][1]], split.corner_copy[e.corner[1][0]],
              split.corner_copy[e.corner[1][1]]};
    const auto& p = mesh.nodes[std::min(f.node_a, f.node_b)];
    const auto& q = mesh.nodes[std::max(f.node_a, f.node_b)];
    const double dx = q[0] - p[0], dy = q[1] - p[1];
    g.length = std::hypot(dx, dy);
    // n = s rotated by -90 deg. K = k_n n n^T + k_s s s^T does not depend on the signs of n and s.
    g.nx = dy / g.length, g.ny = -dx / g.length;
    g.k_n = f.k_n, g.k_s = f.k_s;
    g.glued = std::isinf(f.k_n);
    double cx = 0, cy = 0;  // centroid of the triangle on side 2
    for (int v : mesh.triangles[e.tri[1]]) cx += mesh.nodes[v][0] / 3, cy += mesh.nodes[v][1] / 3;
    g.side2 = (cx - p[0]) * g.nx + (cy - p[1]) * g.ny > 0 ? 1.0 : -1.0;
  }
  return out;
}

// ---- Ordering and triangulation ----------------------------------------------------------------------------------

// Triangles along a Morton (Z) curve through their centroids (as fe_model.cpp): neighbouring cells, and the DoFs
// distribute_dofs numbers cell by cell, end up close in memory, which keeps CG and AMG cache friendly.
std::vector<unsigned> morton_order(const TriMesh& mesh, const Box& box) {
  const std::size_t n = mesh.triangles.size();
  std::vector<std::pair<std::uint64_t, unsigned>> key(n);
  const double sx = 65535.0 / std::max(box.width(), 1e-300), sy = 65535.0 / std::max(box.height(), 1e-300);
  auto spread = [](std::uint64_t v) {
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

// Cell k = triangle cell_triangle[k], its vertices the copies of its corners in counter-clockwise order. Copies of
// one node share a position but not a vertex, so the two cells of an interface edge are not neighbours: deal.II
// sees two boundary faces there, and nothing couples them but the interface element or the ties.
void make_triangulation(const TriMesh& mesh, const Split& split, const std::vector<unsigned>& cell_triangle,
                        Triangulation<dim>& tria) {
  std::vector<Point<dim>> vertices(split.copy_node.size());
  for (std::size_t c = 0; c < vertices.size(); ++c)
    vertices[c] = Point<dim>(mesh.nodes[split.copy_node[c]][0], mesh.nodes[split.copy_node[c]][1]);
  std::vector<CellData<dim>> cells(cell_triangle.size(), CellData<dim>(3));  // 3 vertices: a triangle
  for (std::size_t k = 0; k < cell_triangle.size(); ++k)
    for (unsigned i = 0; i < 3; ++i) cells[k].vertices[i] = split.corner_copy[3 * cell_triangle[k] + i];
  tria.create_triangulation(vertices, cells, SubCellData());
}

// ---- Assembly ----------------------------------------------------------------------------------------------------

// Constant strain triangle: K_e = A B^T C B per unit thickness, B (3 x 6) the strain [xx, yy, xy (engineering)] of
// the nodal displacements. `comp[i]`, `vert[i]`: component and vertex of the cell's local DoF i.
void cst_matrix(const std::array<Point<dim>, 3>& v, const Stiffness3& C, const std::array<unsigned, 6>& comp,
                const std::array<unsigned, 6>& vert, FullMatrix<double>& K) {
  const double two_area = (v[1][0] - v[0][0]) * (v[2][1] - v[0][1]) - (v[2][0] - v[0][0]) * (v[1][1] - v[0][1]);
  double dNdx[3], dNdy[3];
  for (unsigned a = 0; a < 3; ++a) {
    const Point<dim>&p1 = v[(a + 1) % 3], &p2 = v[(a + 2) % 3];
    dNdx[a] = (p1[1] - p2[1]) / two_area;
    dNdy[a] = (p2[0] - p1[0]) / two_area;
  }
  double B[3][6];
  for (unsigned i = 0; i < 6; ++i) {
    const unsigned a = vert[i];
    B[0][i] = comp[i] == 0 ? dNdx[a] : 0.0;
    B[1][i] = comp[i] == 1 ? dNdy[a] : 0.0;
    B[2][i] = comp[i] == 0 ? dNdy[a] : dNdx[a];
  }
  const double area = 0.5 * std::abs(two_area);
  for (unsigned i = 0; i < 6; ++i) {
    double CB[3];
    for (unsigned r = 0; r < 3; ++r) CB[r] = C[r][0] * B[0][i] + C[r][1] * B[1][i] + C[r][2] * B[2][i];
    for (unsigned j = 0; j < 6; ++j) K(j, i) = area * (B[0][j] * CB[0] + B[1][j] * CB[1] + B[2][j] * CB[2]);
  }
}

// Interface element (8 x 8) on the DoFs [p1x p1y q1x q1y p2x p2y q2x q2y] per unit thickness: the exact integral
// of the linear jump against K = k_n n n^T + k_s s s^T, i.e. sign_a sign_b L M_pq K.
void interface_matrix(const Interface& g, FullMatrix<double>& K) {
  const double sx = -g.ny, sy = g.nx;  // tangent
  const double k[2][2] = {{g.k_n * g.nx * g.nx + g.k_s * sx * sx, g.k_n * g.nx * g.ny + g.k_s * sx * sy},
                          {g.k_n * g.ny * g.nx + g.k_s * sy * sx, g.k_n * g.ny * g.ny + g.k_s * sy * sy}};
  const double M[2][2] = {{1.0 / 3.0, 1.0 / 6.0}, {1.0 / 6.0, 1.0 / 3.0}};
  for (unsigned i = 0; i < 8; ++i)
    for (unsigned j = 0; j < 8; ++j) {
      const double sign = ((i < 4) == (j < 4)) ? 1.0 : -1.0;
      K(i, j) = sign * g.length * M[(i / 2) % 2][(j / 2) % 2] * k[i % 2][j % 2];
    }
}

// ---- Inputs ------------------------------------------------------------------------------------------------------

// Checks the mesh and every input of solve_elastic_jointed but the interfaces (mark_interfaces); returns the number
// of layers.
std::size_t check_inputs(const char* function, const TriMesh& mesh,
                         const std::vector<theory::TIConstants>& layer_constants, double bedding_deg,
                         double thickness, const JointedFeOptions& o) {
  check_mesh(function, mesh);
  int max_layer = 0;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) max_layer = std::max(max_layer, layer_of(mesh, t));
  const std::size_t n_layers = std::max(mesh.num_layers(), std::size_t(max_layer) + 1);
  if (layer_constants.size() != n_layers)
    fail(function, "layer_constants has " + std::to_string(layer_constants.size()) + " entries but the mesh has " +
                       std::to_string(n_layers) + " layers (mesh.layer_names: " +
                       std::to_string(mesh.num_layers()) + ", largest layer id: " + std::to_string(max_layer) +
                       "); give the constants of every layer, in layer id order");
  for (std::size_t l = 0; l < layer_constants.size(); ++l)
    if (!layer_constants[l].admissible()) {
      const auto& c = layer_constants[l];
      fail(function, "layer_constants[" + std::to_string(l) + "] (E = " + text(c.E) + " Pa, nu = " + text(c.nu) +
                         ", E' = " + text(c.E_prime) + " Pa, nu' = " + text(c.nu_prime) + ", G' = " + text(c.G_prime) +
                         " Pa) is not admissible: it needs E, E', G' > 0, -1 < nu < 1 and 1 - nu - 2 nu'^2 E/E' > 0");
    }
  if (!std::isfinite(bedding_deg)) fail(function, "bedding_deg is not a finite angle; give the bedding dip in degrees");
  if (!(thickness > 0) || !std::isfinite(thickness))
    fail(function, "thickness = " + text(thickness) + " m; give the positive out-of-plane thickness in m");
  if (!(o.platen_displacement > 0) || !std::isfinite(o.platen_displacement))
    fail(function, "JointedFeOptions::platen_displacement = " + text(o.platen_displacement) +
                       " m; give the positive downward displacement of the top platen in m (compression)");
  if (!(o.cg_tolerance > 0 && o.cg_tolerance < 1))
    fail(function, "JointedFeOptions::cg_tolerance = " + text(o.cg_tolerance) + "; give a relative residual in (0, 1)");
  return n_layers;
}

// Throws unless a boundary edge lies on the top and one on the bottom of the bounding box, as fe_model requires.
void require_platen_edges(const char* function, const TriMesh& mesh, const EdgeMap& edges, const Box& box,
                          double tol) {
  bool top_edge = false, bottom_edge = false;
  for (const auto& [key, e] : edges) {
    if (e.n != 1) continue;
    const auto &p = mesh.nodes[key >> 32], &q = mesh.nodes[key & 0xFFFFFFFFu];
    top_edge |= std::abs(p[1] - box.ymax) < tol && std::abs(q[1] - box.ymax) < tol;
    bottom_edge |= std::abs(p[1] - box.ymin) < tol && std::abs(q[1] - box.ymin) < tol;
  }
  if (!top_edge || !bottom_edge)
    fail(function, "no mesh edge lies on the " + std::string(!top_edge ? "top (y = ymax)" : "bottom (y = ymin)") +
                       " of the mesh's bounding box; the specimen must be a rectangle loaded along y");
}

// ---- DoFs and constraints ----------------------------------------------------------------------------------------

using CopyDofs = std::vector<std::array<types::global_dof_index, 2>>;  // copy -> its u_x, u_y DoFs

// Position (its copy's node) and component of every DoF: where the AMG's rigid-body modes are evaluated.
internal::DofGeometry copy_geometry(const TriMesh& mesh, const Split& split, const CopyDofs& cdof,
                                    types::global_dof_index n_dofs) {
  internal::DofGeometry g;
  g.point.resize(n_dofs);
  g.component.resize(n_dofs);
  for (std::size_t c = 0; c < cdof.size(); ++c)
    for (unsigned k = 0; k < dim; ++k) {
      g.point[cdof[c][k]] = Point<dim>(mesh.nodes[split.copy_node[c]][0], mesh.nodes[split.copy_node[c]][1]);
      g.component[cdof[c][k]] = static_cast<unsigned char>(k);
    }
  return g;
}

// The platen u_y DoFs (1 = yes): their rows of the unconstrained K give the reactions.
struct PlatenDofs {
  std::vector<char> top_uy, bottom_uy;
};

// Platen values by position (every copy keeps its node's boundary position); the pin on one copy of the
// bottom-left node; glued copies tied to the smallest DoF of their class. A class that holds a platen or pinned DoF
// is fixed as a whole (all its members share position and value), so no DoF is both tied and fixed. Fills and
// closes `constraints`; returns the platen u_y DoFs.
PlatenDofs make_constraints(const TriMesh& mesh, const Split& split, const std::vector<Interface>& elements,
                            const CopyDofs& cdof, types::global_dof_index n_dofs, const Box& box, double tol,
                            const JointedFeOptions& o, AffineConstraints<double>& constraints) {
  const std::size_t n_copies = cdof.size();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> fixed(n_dofs, nan);
  PlatenDofs platen{std::vector<char>(n_dofs, 0), std::vector<char>(n_dofs, 0)};
  std::size_t pin = n_copies;
  for (std::size_t c = 0; c < n_copies; ++c) {
    const auto& p = mesh.nodes[split.copy_node[c]];
    const bool top = std::abs(p[1] - box.ymax) < tol, bottom = std::abs(p[1] - box.ymin) < tol;
    if (top) fixed[cdof[c][1]] = -o.platen_displacement, platen.top_uy[cdof[c][1]] = 1;
    if (bottom) fixed[cdof[c][1]] = 0.0, platen.bottom_uy[cdof[c][1]] = 1;
    if (o.platens == Platens::bonded && (top || bottom)) fixed[cdof[c][0]] = 0.0;
    if (bottom && (pin == n_copies || p[0] < mesh.nodes[split.copy_node[pin]][0])) pin = c;
  }
  if (o.platens == Platens::frictionless) fixed[cdof[pin][0]] = 0.0;  // removes the rigid x-translation only
  UnionFind tied(n_dofs);
  for (const Interface& g : elements)
    if (g.glued)
      for (unsigned k = 0; k < dim; ++k) {
        tied.unite(unsigned(cdof[g.copy[0]][k]), unsigned(cdof[g.copy[2]][k]));  // p: side 1 = side 2
        tied.unite(unsigned(cdof[g.copy[1]][k]), unsigned(cdof[g.copy[3]][k]));  // q
      }
  for (types::global_dof_index i = 0; i < n_dofs; ++i)  // a fixed member fixes its class (through its root)
    if (!std::isnan(fixed[i])) fixed[tied.find(unsigned(i))] = fixed[i];
  for (types::global_dof_index i = 0; i < n_dofs; ++i) {
    const unsigned root = tied.find(unsigned(i));
    if (!std::isnan(fixed[root])) {
      constraints.add_line(i);
      constraints.set_inhomogeneity(i, fixed[root]);
    } else if (root != i) {
      constraints.add_line(i);
      constraints.add_entry(i, root, 1.0);
    }
  }
  constraints.close();
  return platen;
}

// ---- Sparsity and assembly ---------------------------------------------------------------------------------------

using ElementDofs = std::array<types::global_dof_index, 8>;  // [p1x p1y q1x q1y p2x p2y q2x q2y]

// The DoFs of each interface element, in the order of `elements` without the glued edges (ties, not elements).
std::vector<ElementDofs> interface_element_dofs(const std::vector<Interface>& elements, const CopyDofs& cdof) {
  std::vector<ElementDofs> element_dofs;
  for (const Interface& g : elements)
    if (!g.glued)
      element_dofs.push_back({cdof[g.copy[0]][0], cdof[g.copy[0]][1], cdof[g.copy[1]][0], cdof[g.copy[1]][1],
                              cdof[g.copy[2]][0], cdof[g.copy[2]][1], cdof[g.copy[3]][0], cdof[g.copy[3]][1]});
  return element_dofs;
}

// The cells' couplings and those of each interface element's 8 DoFs, the constrained DoFs condensed.
void make_pattern(const DoFHandler<dim>& dof, const AffineConstraints<double>& constraints,
                  const std::vector<ElementDofs>& element_dofs, SparsityPattern& pattern) {
  DynamicSparsityPattern dsp(dof.n_dofs(), dof.n_dofs());
  DoFTools::make_sparsity_pattern(dof, dsp, constraints, /*keep_constrained_dofs=*/false);
  for (const auto& d : element_dofs) {
    std::vector<types::global_dof_index> local(d.begin(), d.end());
    std::sort(local.begin(), local.end());
    local.erase(std::unique(local.begin(), local.end()), local.end());  // the tip of an ending joint: one copy
    constraints.add_entries_local_to_global(local, dsp, false);
  }
  pattern.copy_from(dsp);
}

// The system per unit thickness: the constrained K u = b, and the platen rows of the unconstrained K summed into
// g_top, g_bottom on the way (reaction = g . u with the distributed u).
struct JointedSystem {
  JointedSystem(const SparsityPattern& pattern, const AffineConstraints<double>& c, const PlatenDofs& p)
      : constraints(c), platen(p), K(pattern), b(pattern.n_rows()), g_top(pattern.n_rows()),
        g_bottom(pattern.n_rows()) {}

  // Adds the element matrix Ke of the (distinct) DoFs `local`; `zero` is its load vector, zero, of the same size.
  void add(const FullMatrix<double>& Ke, const std::vector<types::global_dof_index>& local, Vector<double>& zero) {
    constraints.distribute_local_to_global(Ke, zero, local, K, b);
    for (unsigned i = 0; i < local.size(); ++i) {
      Vector<double>* g = platen.top_uy[local[i]] ? &g_top : platen.bottom_uy[local[i]] ? &g_bottom : nullptr;
      if (g)
        for (unsigned j = 0; j < local.size(); ++j) (*g)[local[j]] += Ke(i, j);
    }
  }

  const AffineConstraints<double>& constraints;
  const PlatenDofs& platen;
  SparseMatrix<double> K;
  Vector<double> b, g_top, g_bottom;
};

// The constant strain triangles, each with the stiffness C[l] of its layer l.
void assemble_cells(const DoFHandler<dim>& dof, const TriMesh& mesh, const std::vector<unsigned>& cell_triangle,
                    const std::vector<Stiffness3>& C, JointedSystem& system) {
  const FiniteElement<dim>& fe = dof.get_fe();
  std::array<unsigned, 6> comp{}, vert{};
  for (unsigned i = 0; i < 6; ++i) {
    comp[i] = fe.system_to_component_index(i).first;
    vert[i] = fe.system_to_component_index(i).second;  // the vertex: P1 has one shape function per vertex
  }
  FullMatrix<double> Ke(6, 6);
  Vector<double> zero(6);
  std::vector<types::global_dof_index> local(6);
  for (const auto& cell : dof.active_cell_iterators()) {
    cst_matrix({cell->vertex(0), cell->vertex(1), cell->vertex(2)}, C[layer_of(mesh, cell_triangle[cell->index()])],
               comp, vert, Ke);
    cell->get_dof_indices(local);
    system.add(Ke, local, zero);
  }
}

// The interface elements that are not glued, element_dofs[k] the DoFs of the k-th of them.
void assemble_interfaces(const std::vector<Interface>& elements, const std::vector<ElementDofs>& element_dofs,
                         JointedSystem& system) {
  FullMatrix<double> Ke(8, 8);
  std::size_t k = 0;
  for (const Interface& g : elements) {
    if (g.glued) continue;
    interface_matrix(g, Ke);
    // At the tip of a joint that ends inside the specimen both sides hold the same copy: its jump is zero and its
    // rows cancel. The local DoFs are merged first, since deal.II's local-to-global functions expect them unique.
    std::vector<types::global_dof_index> local;
    std::array<unsigned, 8> slot{};
    for (unsigned i = 0; i < 8; ++i) {
      const auto d = element_dofs[k][i];
      slot[i] = unsigned(std::find(local.begin(), local.end(), d) - local.begin());
      if (slot[i] == local.size()) local.push_back(d);
    }
    ++k;
    FullMatrix<double> Km(local.size(), local.size());
    for (unsigned i = 0; i < 8; ++i)
      for (unsigned j = 0; j < 8; ++j) Km(slot[i], slot[j]) += Ke(i, j);
    Vector<double> zero(local.size());
    system.add(Km, local, zero);
  }
}

// ---- Results -----------------------------------------------------------------------------------------------------

// Per interface (the order of `elements`): the mean normal jump over the edge, positive when its sides separate;
// 0 for a glued edge.
std::vector<double> interface_openings(const std::vector<Interface>& elements, const CopyDofs& cdof,
                                       const Vector<double>& u) {
  std::vector<double> opening(elements.size(), 0.0);
  for (std::size_t k = 0; k < elements.size(); ++k) {
    const Interface& g = elements[k];
    if (g.glued) continue;
    double jump[2];  // mean jump over the edge: the mean of its two ends (linear along the edge)
    for (unsigned c = 0; c < dim; ++c)
      jump[c] = 0.5 * (u[cdof[g.copy[2]][c]] - u[cdof[g.copy[0]][c]] + u[cdof[g.copy[3]][c]] - u[cdof[g.copy[1]][c]]);
    opening[k] = g.side2 * (jump[0] * g.nx + jump[1] * g.ny);
  }
  return opening;
}

// The displacement at the centroid and the stress of every triangle (mesh order) into r.ux ... r.sxy.
void centroid_fields(const TriMesh& mesh, const Split& split, const CopyDofs& cdof, const std::vector<Stiffness3>& C,
                     const Vector<double>& u, JointedFeResult& r) {
  const std::size_t n = mesh.triangles.size();
  r.ux.assign(n, 0), r.uy.assign(n, 0), r.sxx.assign(n, 0), r.syy.assign(n, 0), r.sxy.assign(n, 0);
  for (std::size_t t = 0; t < n; ++t) {
    std::array<double, 6> ue{};  // [x0 y0 x1 y1 x2 y2]
    for (unsigned i = 0; i < 3; ++i) {
      const unsigned c = split.corner_copy[3 * t + i];
      ue[2 * i] = u[cdof[c][0]], ue[2 * i + 1] = u[cdof[c][1]];
      r.ux[t] += ue[2 * i] / 3, r.uy[t] += ue[2 * i + 1] / 3;
    }
    // Strain of the constant strain triangle, then sigma = C_l eps.
    const auto &p0 = mesh.nodes[mesh.triangles[t][0]], &p1 = mesh.nodes[mesh.triangles[t][1]],
               &p2 = mesh.nodes[mesh.triangles[t][2]];
    const std::array<std::array<double, 2>, 3> v{{{p0[0], p0[1]}, {p1[0], p1[1]}, {p2[0], p2[1]}}};
    const double two_area = (v[1][0] - v[0][0]) * (v[2][1] - v[0][1]) - (v[2][0] - v[0][0]) * (v[1][1] - v[0][1]);
    double eps[3] = {0, 0, 0};
    for (unsigned a = 0; a < 3; ++a) {
      const auto &q1 = v[(a + 1) % 3], &q2 = v[(a + 2) % 3];
      const double dx = (q1[1] - q2[1]) / two_area, dy = (q2[0] - q1[0]) / two_area;
      eps[0] += dx * ue[2 * a], eps[1] += dy * ue[2 * a + 1], eps[2] += dy * ue[2 * a] + dx * ue[2 * a + 1];
    }
    const Stiffness3& Cl = C[layer_of(mesh, t)];
    r.sxx[t] = Cl[0][0] * eps[0] + Cl[0][1] * eps[1] + Cl[0][2] * eps[2];
    r.syy[t] = Cl[1][0] * eps[0] + Cl[1][1] * eps[1] + Cl[1][2] * eps[2];
    r.sxy[t] = Cl[2][0] * eps[0] + Cl[2][1] * eps[1] + Cl[2][2] * eps[2];
  }
}

// solve_elastic_jointed with o.refinement levels: the given interfaces checked on the given mesh, the refined mesh
// solved once, its fields and openings returned per given triangle and interface.
JointedFeResult solve_refined(const TriMesh& mesh, const std::vector<theory::TIConstants>& layer_constants,
                              double bedding_deg, const std::vector<InterfaceEdge>& interfaces, double thickness,
                              const JointedFeOptions& o) {
  constexpr const char* function = "solve_elastic_jointed";
  if (o.refinement < 0 || o.refinement > 4)
    fail(function, "JointedFeOptions::refinement = " + std::to_string(o.refinement) +
                       "; give 0 to 4 uniform refinement levels");
  check_mesh(function, mesh);
  {
    EdgeMap edges = edge_map(function, mesh);  // the given interfaces are checked on the given mesh
    mark_interfaces(function, mesh, interfaces, edges);
  }
  Stopwatch total;
  const RefinedJointedMesh fine = refine_jointed_mesh(mesh, interfaces, o.refinement);
  JointedFeOptions once = o;
  once.refinement = 0;
  JointedFeResult r = solve_elastic_jointed(fine.mesh, layer_constants, bedding_deg, fine.interfaces, thickness, once);
  r.interface_edges = interfaces.size();
  r.glued_edges = 0;
  for (const auto& e : interfaces) r.glued_edges += std::isinf(e.k_n) ? 1 : 0;
  if (o.fields)
    for (auto* v : {&r.ux, &r.uy, &r.sxx, &r.syy, &r.sxy}) *v = parent_means(*v, fine.children);
  r.interface_opening = parent_means(r.interface_opening, std::size_t(1) << o.refinement);  // 2 halves per level
  r.seconds = total.lap();
  return r;
}

}  // namespace

// ---- Public ------------------------------------------------------------------------------------------------------

std::vector<std::pair<int, int>> layer_interface_edges(const TriMesh& mesh) {
  check_mesh("layer_interface_edges", mesh);
  const EdgeMap edges = edge_map("layer_interface_edges", mesh);
  std::vector<std::pair<int, int>> out;
  for (const auto& [key, e] : edges)
    if (e.n == 2 && layer_of(mesh, e.tri[0]) != layer_of(mesh, e.tri[1]))
      out.emplace_back(int(key >> 32), int(key & 0xFFFFFFFFu));
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<int> count_node_copies(const TriMesh& mesh, const std::vector<InterfaceEdge>& interfaces) {
  check_mesh("count_node_copies", mesh);
  EdgeMap edges = edge_map("count_node_copies", mesh);
  mark_interfaces("count_node_copies", mesh, interfaces, edges);
  std::vector<unsigned> order(mesh.triangles.size());
  std::iota(order.begin(), order.end(), 0u);
  return split_mesh(mesh, edges, order).copies_per_node;
}

JointedFeResult solve_elastic_jointed(const TriMesh& mesh, const std::vector<theory::TIConstants>& layer_constants,
                                      double bedding_deg, const std::vector<InterfaceEdge>& interfaces,
                                      double thickness, const JointedFeOptions& o) {
  constexpr const char* function = "solve_elastic_jointed";
  if (o.refinement != 0) return solve_refined(mesh, layer_constants, bedding_deg, interfaces, thickness, o);
  Stopwatch total, clock;
  JointedFeResult r;

  // ---- Inputs.
  const std::size_t n_layers = check_inputs(function, mesh, layer_constants, bedding_deg, thickness, o);
  EdgeMap edges = edge_map(function, mesh);
  mark_interfaces(function, mesh, interfaces, edges);

  // ---- Split, triangulation, DoFs.
  const Box box = bounding_box(mesh);
  const double tol = 1e-6 * std::max(box.width(), box.height());
  require_platen_edges(function, mesh, edges, box, tol);
  const std::vector<unsigned> cell_triangle = morton_order(mesh, box);
  const Split split = split_mesh(mesh, edges, cell_triangle);
  const std::vector<Interface> elements = interface_elements(mesh, interfaces, edges, split);
  for (int c : split.copies_per_node) r.duplicated_nodes += c > 1 ? std::size_t(c - 1) : 0;
  Triangulation<dim> tria;
  make_triangulation(mesh, split, cell_triangle, tria);
  const FESystem<dim> fe(FE_SimplexP<dim>(1), dim);
  DoFHandler<dim> dof(tria);
  dof.distribute_dofs(fe);
  const auto n_dofs = dof.n_dofs();
  r.dofs = n_dofs, r.cells = tria.n_active_cells(), r.interface_edges = interfaces.size();
  const CopyDofs cdof = internal::vertex_dofs(dof, split.copy_node.size());

  // ---- Constraints (platens, pin, ties of glued copies) and the sparsity with the interface couplings.
  AffineConstraints<double> constraints;
  const PlatenDofs platen = make_constraints(mesh, split, elements, cdof, n_dofs, box, tol, o, constraints);
  r.constrained_dofs = constraints.n_constraints();
  for (const Interface& g : elements) r.glued_edges += g.glued ? 1 : 0;
  const std::vector<ElementDofs> element_dofs = interface_element_dofs(elements, cdof);
  SparsityPattern pattern;
  make_pattern(dof, constraints, element_dofs, pattern);
  r.setup_seconds = clock.lap();

  // ---- Assembly per unit thickness.
  std::vector<Stiffness3> C(n_layers);
  for (std::size_t l = 0; l < n_layers; ++l) C[l] = stiffness_voigt(layer_constants[l], bedding_deg, o.plane);
  JointedSystem system(pattern, constraints, platen);
  assemble_cells(dof, mesh, cell_triangle, C, system);
  assemble_interfaces(elements, element_dofs, system);
  r.assemble_seconds = clock.lap();

  // ---- Solve.
  const bool direct = o.solver == Solver::direct || (o.solver == Solver::automatic && n_dofs < o.direct_dof_limit);
  r.solver_used = direct ? Solver::direct : Solver::cg_amg;
  Vector<double> u(n_dofs);
  if (direct) {
    internal::solve_direct(system.K, system.b, u);
  } else {
    // The rotation mode about the centre of the specimen's bounding box; soft joints need more CG iterations.
    const Point<dim> centre(0.5 * (box.xmin + box.xmax), 0.5 * (box.ymin + box.ymax));
    r.iterations = internal::solve_cg_amg(system.K, system.b, u, copy_geometry(mesh, split, cdof, n_dofs),
                                          {centre, o.cg_tolerance, 20000, false},
                                          {function, "JointedFeOptions", text})
                       .iterations;
  }
  constraints.distribute(u);
  r.solve_seconds = clock.lap();

  // ---- Reactions (compression positive) and fields.
  r.top_force = -(system.g_top * u) * thickness;
  r.bottom_force = (system.g_bottom * u) * thickness;
  r.apparent_modulus = (r.top_force / (box.width() * thickness)) / (o.platen_displacement / box.height());
  r.interface_opening = interface_openings(elements, cdof, u);
  if (o.fields) centroid_fields(mesh, split, cdof, C, u, r);
  r.fields_seconds = clock.lap();
  r.seconds = total.lap();
  return r;
}

}  // namespace rbdem::continuum
