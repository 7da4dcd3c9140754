// The FE twin with joints (continuum/fe_joints.hpp) against closed forms: glued interfaces reproduce the continuous
// model (continuum/fe_model.hpp), a joint normal to the load adds its compliance 1/k_n to H/E, a fine joint set tends
// to Goodman's equivalent continuum (theory::goodman), the node split works for through-going, ending and
// crossing joints, and uniform refinement keeps the patch tests and removes the bending stiffness of the constant
// strain triangles. The meshes are built here (structured triangles with nodes on the joint lines), so this suite
// needs neither gmsh nor the DEM library.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <map>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "continuum/fe_joints.hpp"
#include "continuum/fe_model.hpp"
#include "theory/elasticity.hpp"

namespace rbdem::continuum {
namespace {

using theory::Plane;
using theory::TIConstants;

constexpr double inf = std::numeric_limits<double>::infinity();
constexpr double thickness = 0.02;  // m

// nx x ny cells of dx x dy, node (i, j) at (i dx, j dy) with index j (nx + 1) + i, each cell cut along its
// "/" diagonal into two counter-clockwise triangles. So rows (dip 0), columns (dip 90) and diagonals j - i = k
// (dip atan(dy / dx)) are chains of mesh edges. layer(ic, jc) gets the triangle centroid in index coordinates.
struct Grid {
  int nx = 8, ny = 16;
  double dx = 0.005, dy = 0.005;
  double width() const { return nx * dx; }
  double height() const { return ny * dy; }
  int node(int i, int j) const { return j * (nx + 1) + i; }
};

TriMesh grid_mesh(const Grid& g, const std::function<int(double, double)>& layer) {
  TriMesh m;
  for (int j = 0; j <= g.ny; ++j)
    for (int i = 0; i <= g.nx; ++i) m.nodes.push_back({i * g.dx, j * g.dy});
  int max_layer = 0;
  for (int j = 0; j < g.ny; ++j)
    for (int i = 0; i < g.nx; ++i) {
      const int n00 = g.node(i, j), n10 = g.node(i + 1, j), n01 = g.node(i, j + 1), n11 = g.node(i + 1, j + 1);
      m.triangles.push_back({n00, n10, n11});  // centroid (i + 2/3, j + 1/3)
      m.layer.push_back(layer(i + 2.0 / 3.0, j + 1.0 / 3.0));
      m.triangles.push_back({n00, n11, n01});  // centroid (i + 1/3, j + 2/3)
      m.layer.push_back(layer(i + 1.0 / 3.0, j + 2.0 / 3.0));
      max_layer = std::max({max_layer, m.layer[m.layer.size() - 2], m.layer.back()});
    }
  for (int l = 0; l <= max_layer; ++l) m.layer_names.push_back("layer" + std::to_string(l));
  return m;
}

// A joint set at dip 0 (rows), 90 (columns) or atan(dy/dx) (diagonals), one joint every `every` grid lines, the
// first `every / 2` lines in (so that a specimen of n spacings holds n joints, not n - 1: Goodman's count); layer
// ids count the joints crossed from the bottom-left.
TriMesh jointed_mesh(const Grid& g, double dip_deg, int every) {
  return grid_mesh(g, [&](double ic, double jc) {
    const double index = dip_deg == 0 ? jc : dip_deg == 90 ? ic : jc - ic + g.nx;  // >= 0
    return int(std::floor((index + every / 2) / every));
  });
}

// The interface elements on the layer boundaries whose two nodes satisfy `keep` (all by default).
std::vector<InterfaceEdge> interfaces(const TriMesh& m, double k_n, double k_s,
                                      const std::function<bool(const std::array<double, 2>&,
                                                               const std::array<double, 2>&)>& keep = nullptr) {
  std::vector<InterfaceEdge> out;
  for (const auto& [a, b] : layer_interface_edges(m))
    if (!keep || keep(m.nodes[a], m.nodes[b])) out.push_back({a, b, k_n, k_s});
  return out;
}

std::vector<TIConstants> same_for_all(const TriMesh& m, const TIConstants& c) {
  return std::vector<TIConstants>(m.num_layers(), c);
}

JointedFeOptions jointed(Plane plane, Platens platens = Platens::frictionless) {
  JointedFeOptions o;
  o.plane = plane;
  o.platens = platens;
  o.solver = Solver::direct;
  return o;
}

FeOptions continuous(Plane plane, Platens platens = Platens::frictionless) {
  FeOptions o;
  o.plane = plane;
  o.platens = platens;
  o.solver = Solver::direct;
  return o;
}

// 1 / E_app gained, to first order in 1/k, when glued interfaces are given the finite stiffness of `f` (frictionless
// platens). The glued model has the uniform stress (0, -sigma, 0) (a patch test), so its interfaces carry the nodal
// forces lambda_i = int N_i t dl with the traction t = (0, -sigma n_y). Replacing the ties by springs adds the
// complementary energy lambda^T A^-1 lambda / 2, with A the assembled interface matrix (L M K per edge) on the jump
// components that are free: at a node on a platen the y-jump is zero whatever k (both copies have u_y fixed).
// Per unit sigma and volume W H this is the compliance gained. Without the platen nodes it is the continuum's
// sum L (t_n^2 / k_n + t_s^2 / k_s) / (W H).
double penalty_compliance(const TriMesh& m, const std::vector<InterfaceEdge>& f, double W, double H) {
  std::map<int, int> slot;  // node -> first row of its (x, y) jump
  for (const auto& e : f)
    for (const int v : {e.node_a, e.node_b}) slot.emplace(v, 0);
  int rows = 0;
  for (auto& [v, r] : slot) r = rows, rows += 2;
  std::vector<std::vector<double>> A(rows, std::vector<double>(rows, 0.0));
  std::vector<double> lambda(rows, 0.0);
  for (const auto& e : f) {
    const auto &p = m.nodes[e.node_a], &q = m.nodes[e.node_b];
    const double L = std::hypot(q[0] - p[0], q[1] - p[1]);
    const double sx = (q[0] - p[0]) / L, sy = (q[1] - p[1]) / L, nx = sy, ny = -sx;
    const double K[2][2] = {{e.k_n * nx * nx + e.k_s * sx * sx, e.k_n * nx * ny + e.k_s * sx * sy},
                            {e.k_n * ny * nx + e.k_s * sy * sx, e.k_n * ny * ny + e.k_s * sy * sy}};
    const int r[2] = {slot[e.node_a], slot[e.node_b]};
    for (int a = 0; a < 2; ++a) {
      lambda[r[a] + 1] += L / 2 * -ny;  // t = (0, -n_y) per unit sigma
      for (int b = 0; b < 2; ++b)
        for (int i = 0; i < 2; ++i)
          for (int j = 0; j < 2; ++j) A[r[a] + i][r[b] + j] += L * (a == b ? 1.0 / 3 : 1.0 / 6) * K[i][j];
    }
  }
  for (const auto& [v, r] : slot)
    if (std::abs(m.nodes[v][1]) < 1e-9 * H || std::abs(m.nodes[v][1] - H) < 1e-9 * H) {  // fixed y-jump
      for (int k = 0; k < rows; ++k) A[r + 1][k] = A[k][r + 1] = 0;
      A[r + 1][r + 1] = 1, lambda[r + 1] = 0;
    }
  std::vector<double> x = lambda;  // Gaussian elimination (A is symmetric positive definite)
  for (int k = 0; k < rows; ++k)
    for (int i = k + 1; i < rows; ++i) {
      const double factor = A[i][k] / A[k][k];
      if (factor == 0) continue;
      for (int j = k; j < rows; ++j) A[i][j] -= factor * A[k][j];
      x[i] -= factor * x[k];
    }
  for (int i = rows - 1; i >= 0; --i) {
    for (int j = i + 1; j < rows; ++j) x[i] -= A[i][j] * x[j];
    x[i] /= A[i][i];
  }
  double energy = 0;
  for (int i = 0; i < rows; ++i) energy += lambda[i] * x[i];
  return energy / (W * H);
}

// ---- Glued joints --------------------------------------------------------------------------------------------------

TEST(FeJoints, GluedJointsEqualTheContinuousModel) {
  const TIConstants layered{60e9, 0.2, 25e9, 0.12, 9e9};
  struct Case {
    double dip;
    Grid grid;
    int every;
  };
  const double h = 0.0025;
  const Case cases[] = {{0, {20, 40, h, h}, 4},
                        {45, {20, 40, h, h}, 4},
                        {90, {20, 40, h, h}, 4},
                        {std::atan(2.0) * 180 / std::numbers::pi, {20, 20, h, 2 * h}, 3}};
  for (const Case& c : cases) {
    const TriMesh m = jointed_mesh(c.grid, c.dip, c.every);
    const double W = c.grid.width(), H = c.grid.height();
    for (const Platens platens : {Platens::frictionless, Platens::bonded}) {
      const Plane plane = platens == Platens::bonded ? Plane::stress : Plane::strain;
      const FeResult ref = solve_elastic(m, layered, c.dip, thickness, continuous(plane, platens));
      const auto glued = interfaces(m, inf, inf);
      const JointedFeResult r =
          solve_elastic_jointed(m, same_for_all(m, layered), c.dip, glued, thickness, jointed(plane, platens));
      EXPECT_GT(r.duplicated_nodes, 0u);
      EXPECT_EQ(r.glued_edges, glued.size());
      EXPECT_EQ(r.dofs, 2 * (m.num_nodes() + r.duplicated_nodes));
      const double error = std::abs(r.apparent_modulus / ref.apparent_modulus - 1);
      EXPECT_LT(error, 1e-10) << "dip " << c.dip;
      EXPECT_LT(std::abs(r.bottom_force / r.top_force - 1), 1e-9);
      double field = 0;  // centroid displacements too
      for (std::size_t t = 0; t < m.num_triangles(); ++t)
        field = std::max({field, std::abs(r.ux[t] - ref.ux[t]), std::abs(r.uy[t] - ref.uy[t])});
      EXPECT_LT(field, 1e-12 * 1e-5 * 1e2);  // 1e-10 of the platen displacement
      std::printf("glued  dip %6.2f %-12s E_app %.9e Pa  |E/E_cont - 1| = %.1e  max |du| = %.1e m  (%zu edges)\n",
                  c.dip, platens == Platens::bonded ? "bonded" : "frictionless", r.apparent_modulus, error, field,
                  glued.size());

      if (platens != Platens::frictionless) continue;
      // Penalty-like: k = 1e6 E' / s (and 1e3 E' / s). Softer than glued by the complementary energy of the
      // interfaces under the glued model's uniform stress (penalty_compliance), to first order in 1/k (exactly at dip
      // 0). The second-order remainder is ~0.05 / (k s / E') of it; round-off grows with k, to ~5e-9 of E at 1e6.
      const double s = c.every * (c.dip == 0 ? c.grid.dy : c.dip == 90 ? c.grid.dx
                                                          : c.grid.dx * c.grid.dy / std::hypot(c.grid.dx, c.grid.dy));
      for (const double factor : {1e3, 1e6}) {
        const double k = factor * layered.E_prime / s;
        const auto stiff = interfaces(m, k, k);
        const JointedFeResult p =
            solve_elastic_jointed(m, same_for_all(m, layered), c.dip, stiff, thickness, jointed(plane, platens));
        const double loss = ref.apparent_modulus / p.apparent_modulus - 1;  // compliance gained, relative
        const double predicted = penalty_compliance(m, stiff, W, H) * ref.apparent_modulus;
        std::printf("stiff  dip %6.2f k = %.0e E'/s: E_cont/E - 1 = %.4e, first order %.4e, difference %.1e\n", c.dip,
                    factor, loss, predicted, loss - predicted);
        EXPECT_NEAR(loss, predicted, 1e-3 * predicted + 1e-8) << "dip " << c.dip << ", k = " << factor << " E'/s";
        EXPECT_LT(loss, 2 / factor);
      }
    }
  }
}

// ---- One joint normal to the load --------------------------------------------------------------------------------

// Frictionless platens, one horizontal joint, identical isotropic layers: the stress is uniform (0, -sigma, 0) in
// both layers, so u_x is continuous across the joint (no shear) and the joint closes by sigma / k_n:
//   delta = sigma H a22 + sigma / k_n  ->  H / E_app = H a22 + 1 / k_n,
// a22 = 1/E in plane stress and (1 - nu^2)/E in plane strain (the joint has no out-of-plane strain to restrain).
TEST(FeJoints, OneJointNormalToTheLoadAddsItsCompliance) {
  const double E = 20e9, nu = 0.25;
  const Grid g{8, 16, 0.005, 0.005};
  const TriMesh m = grid_mesh(g, [](double, double jc) { return jc < 8 ? 0 : 1; });
  const double H = g.height();
  for (const Plane plane : {Plane::stress, Plane::strain})
    for (const double kn : {0.5 * E / H, 10 * E / H}) {
      const auto f = interfaces(m, kn, 0.4 * kn);
      const JointedFeResult r = solve_elastic_jointed(m, {TIConstants::isotropic(E, nu), TIConstants::isotropic(E, nu)},
                                                      0, f, thickness, jointed(plane));
      const double a22 = plane == Plane::stress ? 1 / E : (1 - nu * nu) / E;
      const double expected = H / (H * a22 + 1 / kn);
      const double error = std::abs(r.apparent_modulus / expected - 1);
      std::printf("one joint %s k_n H/E = %4.1f: E_app %.12e Pa, closed form %.12e Pa, error %.1e\n",
                  plane == Plane::stress ? "plane stress" : "plane strain", kn * H / E, r.apparent_modulus, expected,
                  error);
      EXPECT_LT(error, 1e-10);
      EXPECT_LT(std::abs(r.bottom_force / r.top_force - 1), 1e-10);
      // Every joint edge closes by sigma / k_n: its mean opening is negative (compression) and exact.
      const double sigma = r.top_force / (g.width() * thickness);
      ASSERT_EQ(r.interface_opening.size(), f.size());
      for (const double opening : r.interface_opening) EXPECT_NEAR(opening / (-sigma / kn), 1.0, 1e-9);
      EXPECT_EQ(f.size(), std::size_t(g.nx));
      EXPECT_EQ(r.duplicated_nodes, std::size_t(g.nx + 1));
    }
}

// ---- A fine joint set tends to Goodman's continuum ---------------------------------------------------------------

// The errors of a refinement sequence (the joint spacing over the width, `ratio`): at round-off where the closed
// form is exact; else falling at first order (0.8 to 1.3) to within 2 % on the finest mesh.
void expect_exact_or_first_order(bool exact, double dip, const std::vector<double>& ratio,
                                 const std::vector<double>& error) {
  if (exact) {
    for (const double e : error) EXPECT_LT(e, 1e-10) << "dip " << dip;
    return;
  }
  for (std::size_t k = 1; k < error.size(); ++k) {
    EXPECT_LT(error[k], error[k - 1]) << "dip " << dip;
    const double order = std::log(error[k - 1] / error[k]) / std::log(ratio[k - 1] / ratio[k]);
    EXPECT_GT(order, 0.8) << "dip " << dip;
    EXPECT_LT(order, 1.3) << "dip " << dip;
  }
  EXPECT_LT(error.back(), 0.02) << "dip " << dip;
}

// Isotropic rock with joints at spacing s and k_n s, k_s s fixed, so that Goodman's continuum is the same for every
// s; only s / W changes. Uniform stress makes dips 0 and 90 exact at any s. At 45 deg the blocks cut by the free
// sides (a boundary layer about s wide) make the error first order in s / W.
TEST(FeJoints, FineSpacingTendsToGoodman) {
  const double E = 20e9, nu = 0.25, W = 0.05;
  const double kns = 1.0 * E, kss = 0.4 * E;  // k_n s, k_s s: E' = E / 2, G' = G / 2
  for (const double dip : {0.0, 90.0, 45.0}) {
    std::vector<double> ratio, error;
    for (const int nx : {8, 16, 32, 64}) {
      const Grid g{nx, 2 * nx, W / nx, W / nx};
      const int every = 2;
      const double s = dip == 45 ? every * g.dx / std::sqrt(2.0) : every * g.dx;
      const TriMesh m = jointed_mesh(g, dip, every);
      const auto f = interfaces(m, kns / s, kss / s);
      const JointedFeResult r = solve_elastic_jointed(m, same_for_all(m, TIConstants::isotropic(E, nu)), dip, f,
                                                      thickness, jointed(Plane::strain));
      const double goodman =
          theory::apparent_modulus(theory::goodman(E, nu, kns / s, kss / s, s), dip, Plane::strain);
      ratio.push_back(s / W);
      error.push_back(std::abs(r.apparent_modulus / goodman - 1));
      std::printf("Goodman dip %4.1f  s/W %.4f  DoFs %6zu  E_app %.6e  Goodman %.6e  error %.3e", dip, s / W, r.dofs,
                  r.apparent_modulus, goodman, error.back());
      if (error.size() > 1 && error.back() > 1e-9)
        std::printf("  order %.2f", std::log(error[error.size() - 2] / error.back()) /
                                        std::log(ratio[ratio.size() - 2] / ratio.back()));
      std::printf("  (%.2f s)\n", r.seconds);
    }
    expect_exact_or_first_order(dip != 45, dip, ratio, error);
  }
}

// Interbedded rocks: the layers alternate between two rocks (even layer ids rock 1, odd rock 2), one joint between
// every two layers. Salamon's medium (theory::interbedded: Backus' average of the two rocks plus the joints) is
// exact where the stress or the strain is uniform: at dip 0 when neither rock has a Poisson effect (the layers in
// series, nothing to restrain laterally), at dip 90 for any Poisson's ratios (the layers in parallel under one
// axial strain, free to expand sideways). At 45 deg the free sides cut the layers and the FE model tends to it at
// first order in s / W, as with one rock (FineSpacingTendsToGoodman).
TEST(FeJoints, InterbeddedRocksTendToSalamon) {
  const double E1 = 20e9, E2 = 10e9, W = 0.05;
  const double kns = 1.0 * E1, kss = 0.4 * E1;
  for (const auto& [nu1, nu2] : {std::pair{0.0, 0.0}, std::pair{0.25, 0.15}}) {
    for (const double dip : {0.0, 90.0, 45.0}) {
      const bool exact = dip == 90 || (dip == 0 && nu1 == 0 && nu2 == 0);
      if (!exact && nu1 != 0) continue;
      std::vector<double> ratio, error;
      for (const int nx : {8, 16, 32}) {
        if (exact && nx > 16) break;
        const Grid g{nx, 2 * nx, W / nx, W / nx};
        const int every = 2;
        const double s = dip == 45 ? every * g.dx / std::sqrt(2.0) : every * g.dx;
        const TriMesh m = jointed_mesh(g, dip, every);
        std::vector<TIConstants> layers(m.num_layers());
        for (std::size_t l = 0; l < layers.size(); ++l)
          layers[l] = TIConstants::isotropic(l % 2 ? E2 : E1, l % 2 ? nu2 : nu1);
        const JointedFeResult r = solve_elastic_jointed(m, layers, dip, interfaces(m, kns / s, kss / s), thickness,
                                                        jointed(Plane::strain));
        const double salamon = theory::apparent_modulus(
            theory::interbedded(E1, nu1, s, E2, nu2, s, kns / s, kss / s, s), dip, Plane::strain);
        ratio.push_back(s / W);
        error.push_back(std::abs(r.apparent_modulus / salamon - 1));
        std::printf("Salamon nu %.2f/%.2f dip %4.1f  s/W %.4f  E_app %.6e  Salamon %.6e  error %.3e\n", nu1, nu2, dip,
                    s / W, r.apparent_modulus, salamon, error.back());
      }
      expect_exact_or_first_order(exact, dip, ratio, error);
    }
  }
}

// ---- Joints that end, joints that cross --------------------------------------------------------------------------

TEST(FeJoints, JointEndingInsideTheSpecimenKeepsOneNode) {
  const double E = 20e9, nu = 0.25;
  const Grid g{8, 16, 0.005, 0.005};
  const TriMesh m = grid_mesh(g, [](double, double jc) { return jc < 8 ? 0 : 1; });
  const double kn = 2 * E / g.height();
  const double tip_x = 4 * g.dx;
  const auto partial = interfaces(m, kn, 0.4 * kn, [&](const auto& p, const auto& q) {
    return std::max(p[0], q[0]) <= tip_x + 1e-12;  // the joint runs from the left side to the tip at x = W/2
  });
  ASSERT_EQ(partial.size(), 4u);
  const std::vector<int> copies = count_node_copies(m, partial);
  EXPECT_EQ(copies[g.node(4, 8)], 1) << "tip";
  for (int i = 0; i < 4; ++i) EXPECT_EQ(copies[g.node(i, 8)], 2) << "joint node " << i;
  for (int i = 5; i <= 8; ++i) EXPECT_EQ(copies[g.node(i, 8)], 1) << "beyond the tip " << i;

  const std::vector<TIConstants> rock(2, TIConstants::isotropic(E, nu));
  const auto o = jointed(Plane::strain);
  const JointedFeResult r = solve_elastic_jointed(m, rock, 0, partial, thickness, o);
  EXPECT_EQ(r.duplicated_nodes, 4u);
  const double glued = solve_elastic_jointed(m, rock, 0, interfaces(m, inf, inf), thickness, o).apparent_modulus;
  const double cut = solve_elastic_jointed(m, rock, 0, interfaces(m, kn, 0.4 * kn), thickness, o).apparent_modulus;
  std::printf("ending joint: E glued %.6e > partial %.6e > cut %.6e Pa\n", glued, r.apparent_modulus, cut);
  EXPECT_LT(r.apparent_modulus, glued * (1 - 1e-3));
  EXPECT_GT(r.apparent_modulus, cut * (1 + 1e-3));
  EXPECT_LT(std::abs(r.bottom_force / r.top_force - 1), 1e-10);
}

TEST(FeJoints, CrossingJointsDuplicateNodesFourWays) {
  const double E = 20e9, nu = 0.25;
  const Grid g{8, 16, 0.005, 0.005};
  // Four quadrants: a horizontal joint at y = H/2 and a vertical one at x = W/2 cross at node (4, 8).
  const TriMesh m = grid_mesh(g, [](double ic, double jc) { return (jc < 8 ? 0 : 2) + (ic < 4 ? 0 : 1); });
  const std::vector<TIConstants> rock(4, TIConstants::isotropic(E, nu));
  const auto glued = interfaces(m, inf, inf);
  ASSERT_EQ(glued.size(), std::size_t(g.nx + g.ny));
  const std::vector<int> copies = count_node_copies(m, glued);
  EXPECT_EQ(copies[g.node(4, 8)], 4);
  EXPECT_EQ(copies[g.node(0, 8)], 2);
  EXPECT_EQ(copies[g.node(4, 0)], 2);
  EXPECT_EQ(copies[g.node(4, 16)], 2);

  for (const Plane plane : {Plane::strain, Plane::stress}) {
    const auto o = jointed(plane);
    const JointedFeResult r = solve_elastic_jointed(m, rock, 0, glued, thickness, o);
    // 3 extra at the crossing, 1 at each other node of the two lines (nx + 1 and ny + 1 nodes).
    EXPECT_EQ(r.duplicated_nodes, std::size_t(3 + g.nx + g.ny));
    const FeResult ref = solve_elastic(m, rock[0], 0, thickness, continuous(plane));
    EXPECT_LT(std::abs(r.apparent_modulus / ref.apparent_modulus - 1), 1e-10);

    // Finite stiffness on both: the vertical joint carries no traction in the uniform stress, the horizontal one
    // adds 1/k_n. And a glued vertical joint with a finite horizontal one (ties and springs at the same crossing).
    const double kn = 2 * E / g.height(), a22 = plane == Plane::stress ? 1 / E : (1 - nu * nu) / E;
    const double expected = g.height() / (g.height() * a22 + 1 / kn);
    auto horizontal = [](const auto& p, const auto& q) { return p[1] == q[1]; };
    std::vector<InterfaceEdge> mixed = interfaces(m, kn, 0.4 * kn);
    const JointedFeResult both = solve_elastic_jointed(m, rock, 0, mixed, thickness, o);
    for (auto& e : mixed)
      if (!horizontal(m.nodes[e.node_a], m.nodes[e.node_b])) e.k_n = e.k_s = inf;
    const JointedFeResult tied = solve_elastic_jointed(m, rock, 0, mixed, thickness, o);
    std::printf("crossing %s: glued error %.1e, cut error %.1e, half-glued error %.1e\n",
                plane == Plane::stress ? "plane stress" : "plane strain",
                std::abs(r.apparent_modulus / ref.apparent_modulus - 1), std::abs(both.apparent_modulus / expected - 1),
                std::abs(tied.apparent_modulus / expected - 1));
    EXPECT_LT(std::abs(both.apparent_modulus / expected - 1), 1e-10);
    EXPECT_LT(std::abs(tied.apparent_modulus / expected - 1), 1e-10);
    EXPECT_EQ(tied.glued_edges, std::size_t(g.ny));
  }
}

// ---- Refinement ------------------------------------------------------------------------------------------------

// refine_jointed_mesh: 4^r children per triangle in the parent's layer, counter-clockwise, 2^r halves per interface;
// the patch tests stay exact on the refined mesh and the fields come back as the mean over each parent's children.
TEST(FeJoints, RefinementKeepsThePatchTestsAndReturnsParentFields) {
  const double E = 20e9, nu = 0.25;
  const Grid g{8, 16, 0.005, 0.005};
  const TriMesh m = grid_mesh(g, [](double, double jc) { return jc < 8 ? 0 : 1; });
  const double H = g.height(), kn = 0.5 * E / H;
  const auto f = interfaces(m, kn, 0.4 * kn);
  const std::vector<TIConstants> rock(2, TIConstants::isotropic(E, nu));
  for (const int levels : {1, 2}) {
    const RefinedJointedMesh fine = refine_jointed_mesh(m, f, levels);
    const std::size_t children = std::size_t(1) << (2 * levels);
    ASSERT_EQ(fine.children, children);
    ASSERT_EQ(fine.mesh.num_triangles(), children * m.num_triangles());
    EXPECT_EQ(fine.interfaces.size(), f.size() << levels);
    for (std::size_t t = 0; t < fine.mesh.num_triangles(); ++t) {
      EXPECT_GT(signed_area(fine.mesh, t), 0.0);
      EXPECT_NEAR(signed_area(fine.mesh, t), signed_area(m, t / children) / double(children), 1e-18);
      EXPECT_EQ(fine.mesh.layer[t], m.layer[t / children]);
    }
    auto o = jointed(Plane::strain);
    o.refinement = levels;
    const JointedFeResult r = solve_elastic_jointed(m, rock, 0, f, thickness, o);
    const double expected = H / (H * (1 - nu * nu) / E + 1 / kn);  // one joint normal to the load
    EXPECT_LT(std::abs(r.apparent_modulus / expected - 1), 1e-10) << levels;
    EXPECT_EQ(r.interface_edges, f.size());
    ASSERT_EQ(r.interface_opening.size(), f.size());  // per given edge, the mean over its pieces
    const double sigma = r.top_force / (g.width() * thickness);
    for (const double opening : r.interface_opening) EXPECT_NEAR(opening / (-sigma / kn), 1.0, 1e-9) << levels;
    ASSERT_EQ(r.ux.size(), m.num_triangles());
    // Uniform strain: the mean displacement of a triangle is the value at its centroid, as unrefined.
    const JointedFeResult coarse = solve_elastic_jointed(m, rock, 0, f, thickness, jointed(Plane::strain));
    for (std::size_t t = 0; t < m.num_triangles(); ++t) {
      EXPECT_NEAR(r.ux[t], coarse.ux[t], 1e-16);
      EXPECT_NEAR(r.uy[t], coarse.uy[t], 1e-16);
      EXPECT_NEAR(r.syy[t] / coarse.syy[t], 1.0, 1e-9);
    }
    // Glued joints on the refined mesh equal the continuous model.
    const JointedFeResult glued = solve_elastic_jointed(m, rock, 0, interfaces(m, inf, inf), thickness, o);
    const FeResult cont = solve_elastic(m, rock[0], 0, thickness, continuous(Plane::strain));
    EXPECT_LT(std::abs(glued.apparent_modulus / cont.apparent_modulus - 1), 1e-10);
  }
}

// Constant strain triangles are too stiff in bending. Layers bent between soft joints (dip 45, k_n s = 0.01 E):
// each refinement level softens the model, and the change shrinks (measured 6.6e6, then 2.6e6 Pa: the free corners of
// the cut layers keep it from the fourfold of a smooth O(h^2) energy error).
TEST(FeJoints, RefinementRemovesTheBendingStiffnessOfConstantStrainTriangles) {
  const double E = 20e9, nu = 0.25;
  const Grid g{16, 32, 0.05 / 16, 0.05 / 16};
  const TriMesh m = jointed_mesh(g, 45, 4);
  const double s = 4 * g.dx / std::sqrt(2.0);
  const auto f = interfaces(m, 0.01 * E / s, 0.004 * E / s);
  std::vector<double> E_app;
  for (const int levels : {0, 1, 2}) {
    auto o = jointed(Plane::strain);
    o.refinement = levels;
    E_app.push_back(solve_elastic_jointed(m, same_for_all(m, TIConstants::isotropic(E, nu)), 45, f, thickness, o)
                        .apparent_modulus);
    std::printf("bending, refinement %d: E_app %.6e Pa\n", levels, E_app.back());
  }
  EXPECT_LT(E_app[1], E_app[0]);
  EXPECT_LT(E_app[2], E_app[1]);
  const double ratio = (E_app[0] - E_app[1]) / (E_app[1] - E_app[2]);
  std::printf("bending: successive changes %.3e, %.3e (ratio %.2f)\n", E_app[0] - E_app[1], E_app[1] - E_app[2],
              ratio);
  EXPECT_GT(ratio, 2.0);
}

// ---- Solvers ---------------------------------------------------------------------------------------------------

// CG+AMG (Trilinos ML, MPI initialised by the library) agrees with UMFPACK on a soft jointed specimen with ties.
TEST(FeJoints, CgAmgMatchesTheDirectSolver) {
  const double E = 20e9, nu = 0.25;
  const Grid g{32, 64, 0.05 / 32, 0.05 / 32};
  const TriMesh m = jointed_mesh(g, 45, 4);
  const double s = 4 * g.dx / std::sqrt(2.0);
  auto f = interfaces(m, E / s, 0.4 * E / s);
  for (std::size_t k = 0; k < f.size(); k += 3) f[k].k_n = f[k].k_s = inf;  // some glued edges too
  for (const Platens platens : {Platens::frictionless, Platens::bonded}) {
    auto o = jointed(Plane::strain, platens);
    const JointedFeResult direct = solve_elastic_jointed(m, same_for_all(m, TIConstants::isotropic(E, nu)), 45, f,
                                                         thickness, o);
    o.solver = Solver::cg_amg;
    const JointedFeResult cg = solve_elastic_jointed(m, same_for_all(m, TIConstants::isotropic(E, nu)), 45, f,
                                                     thickness, o);
    std::printf("CG+AMG %s: %u iterations, |E_cg / E_direct - 1| = %.1e, %zu DoFs\n",
                platens == Platens::bonded ? "bonded" : "frictionless", cg.iterations,
                std::abs(cg.apparent_modulus / direct.apparent_modulus - 1), cg.dofs);
    EXPECT_EQ(cg.solver_used, Solver::cg_amg);
    EXPECT_GT(cg.iterations, 0u);
    EXPECT_LT(std::abs(cg.apparent_modulus / direct.apparent_modulus - 1), 1e-7);
    EXPECT_LT(std::abs(cg.bottom_force / cg.top_force - 1), 1e-6);
  }
}

// ---- Bad input -----------------------------------------------------------------------------------------------------

void expect_invalid(const std::function<void()>& call, const std::string& fragment) {
  try {
    call();
    ADD_FAILURE() << "no exception; expected one naming \"" << fragment << "\"";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST(FeJoints, RejectsBadInputNamingTheProblem) {
  const Grid g{4, 8, 0.005, 0.005};
  const TriMesh m = grid_mesh(g, [](double, double jc) { return jc < 4 ? 0 : 1; });
  const std::vector<TIConstants> rock(2, TIConstants::isotropic(20e9, 0.25));
  const auto good = interfaces(m, 1e12, 1e12);
  auto solve = [&](const std::vector<TIConstants>& c, const std::vector<InterfaceEdge>& f) {
    return [&m, c, f] { solve_elastic_jointed(m, c, 0, f, thickness); };
  };
  // (0, 0) - (2, 0): both on the bottom, but no triangle has both.
  expect_invalid(solve(rock, {{g.node(0, 0), g.node(2, 0), 1e12, 1e12}}), "is not an edge of the mesh");
  expect_invalid(solve(rock, {{g.node(0, 0), g.node(1, 0), 1e12, 1e12}}), "is a boundary edge");
  expect_invalid(solve(rock, {{g.node(0, 0), g.node(0, 0), 1e12, 1e12}}), "joins a node to itself");
  expect_invalid(solve(rock, {{0, 100000, 1e12, 1e12}}), "refers to a node outside");
  expect_invalid(solve({rock[0]}, good), "layer_constants has 1 entries but the mesh has 2 layers");
  expect_invalid(solve({rock[0], rock[0], rock[0]}, good), "layer_constants has 3 entries");
  expect_invalid(solve({rock[0], TIConstants{20e9, 1.5, 20e9, 0.2, 1e9}}, good), "layer_constants[1]");
  auto twice = good;
  twice.push_back({good[0].node_b, good[0].node_a, 1e12, 1e12});
  expect_invalid(solve(rock, twice), "list each interface edge once");
  auto soft = good;
  soft[1].k_s = 0;
  expect_invalid(solve(rock, soft), "interfaces[1]");
  auto half = good;
  half[2].k_n = inf;
  expect_invalid(solve(rock, half), "give both infinite (glued) or both finite");
  expect_invalid([&] { count_node_copies(m, {{g.node(0, 0), g.node(2, 0), 1, 1}}); }, "is not an edge of the mesh");
  expect_invalid([&] { solve_elastic_jointed(m, rock, 0, good, -1); }, "thickness");
  JointedFeOptions o;
  o.refinement = 7;
  expect_invalid([&] { solve_elastic_jointed(m, rock, 0, good, thickness, o); }, "refinement");
  o.refinement = 1;
  expect_invalid([&] { solve_elastic_jointed(m, rock, 0, {{g.node(0, 0), g.node(2, 0), 1e12, 1e12}}, thickness, o); },
                 "is not an edge of the mesh");
}

TEST(FeJoints, LayerInterfaceEdgesAreSortedAndOnTheLayerBoundary) {
  const Grid g{4, 8, 0.005, 0.005};
  const TriMesh m = grid_mesh(g, [](double, double jc) { return jc < 4 ? 0 : 1; });
  const auto edges = layer_interface_edges(m);
  ASSERT_EQ(edges.size(), 4u);
  for (std::size_t k = 0; k < edges.size(); ++k) {
    EXPECT_EQ(edges[k], std::make_pair(g.node(int(k), 4), g.node(int(k) + 1, 4)));
  }
}

}  // namespace
}  // namespace rbdem::continuum
