// The static elastic solve against the explicit engine and against the closed form of an aligned block grid
// (docs/theory.md, sections 3, 5).
#include <gtest/gtest.h>

#include <omp.h>

#include <cmath>
#include <cstdio>
#include <numeric>

#include "compare/verify/dem_measures.hpp"
#include "dem/topology.hpp"
#include "tests/simulations.hpp"

namespace rbdem {
namespace {

Scene unbreakable_scene() {
  Scene s;
  s.rock.tensile_strength = s.rock.cohesion = s.joint.tensile_strength = s.joint.cohesion = 1e11;
  s.numerics.threads = 1;
  return s;
}

// An explicit UCS run from rest (no static elastic start, nothing breaks): the slope of its stress-strain curve
// after the start-up transient equals the static solve's apparent modulus of the same mesh, across the layers
// (beta = 0) and with sliding joints (beta = 60). The experiment is `rbdem verify`'s (compare/verify/dem_measures.hpp).
TEST(Static, ExplicitInitialSlopeMatchesStaticSolveWithin2Percent) {
  for (const bool slip : {false, true})  // bonded interfaces stick (default) or slide (PFC's LPB)
  for (const double beta : {0.0, 60.0}) {
    SCOPED_TRACE(testing::Message() << "beta = " << beta << ", slip_when_bonded = " << slip);
    const verify::SlopeMeasure m = verify::static_and_explicit_moduli(beta, slip);
    const StaticResult& st = m.static_state;
    ASSERT_EQ(m.cracks, 0u);
    ASSERT_GT(m.curve_points, 100u);
    EXPECT_NEAR(m.explicit_modulus / st.apparent_modulus, 1.0, 0.02)
        << "explicit " << m.explicit_modulus << " Pa, static " << st.apparent_modulus << " Pa";
    EXPECT_NEAR(st.top_force / st.bottom_force, 1.0, 1e-8);
    if (slip) EXPECT_GT(st.sliding_bonds, 0u);  // the slip states are exercised
    else EXPECT_EQ(st.sliding_bonds, 0u);
  }
}

// The Krylov path (BiCGSTAB preconditioned by the first state's LDLT) and the last-resort sparse LU give the
// same solution: a tolerance no iteration can reach forces the refactorisation and then the LU fallback.
TEST(Static, KrylovAndDirectFallbackAgree) {
  Scene scene = unbreakable_scene();
  scene.rock.slip_when_bonded = scene.joint.slip_when_bonded = true;  // the non-symmetric case
  scene.mesh.size = 0.004;
  const auto sim = fixtures::with_platens(scene);
  const StaticResult krylov = sim->solve_static();
  StaticOptions forced;
  forced.krylov_tolerance = 1e-300;
  const StaticResult direct = sim->solve_static(forced);
  EXPECT_GT(krylov.krylov_iterations, 0);
  EXPECT_EQ(krylov.direct_fallbacks, 0);
  EXPECT_GT(direct.direct_fallbacks, 0);
  EXPECT_NEAR(direct.apparent_modulus / krylov.apparent_modulus, 1.0, 1e-8);
  EXPECT_EQ(direct.sliding_bonds, krylov.sliding_bonds);
  EXPECT_EQ(direct.open_bonds, krylov.open_bonds);
}

// The static solve on several threads (StaticOptions::threads) gives the very solution of one thread: BiCGSTAB's
// products add each row's entries in the order of the column-major product, and the triangular solves give each
// unknown the operations of Eigen's sequential solves, in the same order. The case goes through the Krylov path
// (sliding bonds, later active-set states).
TEST(Static, KrylovProductsAndTriangularSolvesOnThreadsAreBitIdentical) {
  Scene scene = unbreakable_scene();
  scene.rock.slip_when_bonded = scene.joint.slip_when_bonded = true;
  scene.mesh.size = 0.004;
  const auto sim = fixtures::with_platens(scene);
  const StaticResult one = sim->solve_static();
  ASSERT_GT(one.krylov_iterations, 0);
  for (int n : {2, 3}) {
    const std::atomic<int> threads{n};
    StaticOptions threaded;
    threaded.threads = &threads;
    const StaticResult many = sim->solve_static(threaded);
    EXPECT_EQ(many.krylov_iterations, one.krylov_iterations) << n << " threads";
    EXPECT_EQ(many.u, one.u) << n << " threads";
    EXPECT_EQ(many.fs_lin, one.fs_lin) << n << " threads";
  }
  // 2 threads asked for inside another parallel region: the solves get a team of one, which must do every subtree.
  const std::atomic<int> two{2};
  StaticOptions nested;
  nested.threads = &two;
  StaticResult inner;
  const int levels = omp_get_max_active_levels();
  omp_set_max_active_levels(1);
#pragma omp parallel num_threads(2)
  {
#pragma omp single
    inner = sim->solve_static(nested);
  }
  omp_set_max_active_levels(levels);
  EXPECT_EQ(inner.u, one.u);
}

// The active set settles: on the paper specimen at 60 deg (2 mm) a few dozen linear parts near the open/closed
// boundary used to cycle until max_iterations. A linear part that has changed state twice now keeps it, so the
// iteration stops within a few solves, holding under 1 % of the bonds, with a modulus between 95 % of the linear
// (all closed) one and that one: opening only softens.
TEST(Static, ActiveSetSettlesWithoutCycling) {
  Scene scene = unbreakable_scene();
  scene.mesh.size = 0.002;
  scene.joint_set.dip_deg = 60;
  const auto sim = fixtures::with_platens(scene);
  const StaticResult r = sim->solve_static();
  std::printf("60 deg, 2 mm: %d active-set iterations, %d Krylov iterations, %zu open, %zu held of %zu bonds\n",
              r.active_set_iterations, r.krylov_iterations, r.open_bonds, r.held_bonds, sim->num_bonds());
  EXPECT_LT(r.active_set_iterations, 10);
  EXPECT_GT(r.open_bonds, 0u);  // the active set is exercised
  EXPECT_LT(double(r.held_bonds), 0.01 * double(sim->num_bonds()));
  StaticOptions closed;
  closed.linear_parts_always_closed = true;
  const StaticResult linear = sim->solve_static(closed);
  EXPECT_LT(r.apparent_modulus, linear.apparent_modulus);  // opening only softens
  EXPECT_GT(r.apparent_modulus, 0.95 * linear.apparent_modulus);
}

// nx x ny rectangular blocks of a (along x) by b (along y) on an aligned grid, one bond per shared face; the
// top and bottom rows touch the platens. BlockGeometry::shape holds a triangle inscribed in the rectangle (the
// engine takes the platen stiffness from its inradius; the static solve takes the platen contact points from
// the boundary edges' midpoints).
Topology<2> block_grid(int nx, int ny, double a, double b, double thickness) {
  Topology<2> t;
  t.thickness = thickness;
  t.xmin = 0, t.xmax = nx * a, t.ymin = 0, t.ymax = ny * b;
  auto id = [nx](int i, int j) { return j * nx + i; };
  auto& B = t.blocks;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      B.cx.push_back((i + 0.5) * a), B.cy.push_back((j + 0.5) * b);
      B.area.push_back(a * b);
      B.mass.push_back(2700.0 * thickness * a * b);
      B.inertia.push_back(B.mass.back() * (a * a + b * b) / 12.0);
      B.radius.push_back(0.5 * std::hypot(a, b));
      B.shape.push_back({-0.5 * a, -0.5 * b, 0.5 * a, -0.5 * b, 0.0, 0.5 * b});
      B.layer.push_back(0);
    }
  auto bond = [&](int p, int q, double mx, double my, double nxv, double nyv, double L, double d) {
    auto& N = t.bonds;
    N.i.push_back(p), N.j.push_back(q), N.node_a.push_back(-1), N.node_b.push_back(-1);
    N.mx.push_back(mx), N.my.push_back(my), N.length.push_back(L), N.nx.push_back(nxv), N.ny.push_back(nyv);
    N.d.push_back(d), N.kind.push_back(BondKind::rock);
  };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      if (i + 1 < nx) bond(id(i, j), id(i + 1, j), (i + 1) * a, (j + 0.5) * b, 1.0, 0.0, b, a);
      if (j + 1 < ny) bond(id(i, j), id(i, j + 1), (i + 0.5) * a, (j + 1) * b, 0.0, 1.0, a, b);
    }
  auto edge = [&](int blk, double mx, double my, double L, Side side) {
    auto& E = t.boundary;
    E.block.push_back(blk), E.node_a.push_back(-1), E.node_b.push_back(-1);
    E.mx.push_back(mx), E.my.push_back(my), E.length.push_back(L), E.side.push_back(side);
    const bool horizontal = side == Side::top || side == Side::bottom;
    E.ax.push_back(horizontal ? mx - 0.5 * L : mx), E.ay.push_back(horizontal ? my : my - 0.5 * L);
    E.bx.push_back(horizontal ? mx + 0.5 * L : mx), E.by.push_back(horizontal ? my : my + 0.5 * L);
  };
  for (int i = 0; i < nx; ++i) {
    edge(id(i, 0), (i + 0.5) * a, 0.0, a, Side::bottom);
    edge(id(i, ny - 1), (i + 0.5) * a, ny * b, a, Side::top);
  }
  for (int j = 0; j < ny; ++j) {
    edge(id(0, j), 0.0, (j + 0.5) * b, b, Side::left);
    edge(id(nx - 1, j), nx * a, (j + 0.5) * b, b, Side::right);
  }
  const std::size_t n = B.size();
  t.bond_offset.assign(n + 1, 0);
  for (std::size_t k = 0; k < t.bonds.size(); ++k) ++t.bond_offset[t.bonds.i[k] + 1], ++t.bond_offset[t.bonds.j[k] + 1];
  std::partial_sum(t.bond_offset.begin(), t.bond_offset.end(), t.bond_offset.begin());
  t.bond_of.resize(std::size_t(t.bond_offset[n]));
  std::vector<int> fill(t.bond_offset.begin(), t.bond_offset.end() - 1);
  for (std::size_t k = 0; k < t.bonds.size(); ++k)
    t.bond_of[std::size_t(fill[t.bonds.i[k]]++)] = int(k), t.bond_of[std::size_t(fill[t.bonds.j[k]]++)] = int(k);
  return t;
}

// Vertical modulus of a grid of a x b blocks, from the interior rows (the platen rows are left out), and the
// lateral strain; k_n = the normal stiffness per area of a vertical bond in compression (2 E*/b: parallel bond
// and closed linear part).
struct GridMeasurement {
  double modulus, kn, lateral_over_axial;
};
GridMeasurement measure_grid(double a, double b) {
  const int nx = 6, ny = 12;
  const Scene scene = unbreakable_scene();
  const Topology<2> topo = block_grid(nx, ny, a, b, 0.5);
  const auto sim = fixtures::with_platens(scene, topo);
  StaticOptions o;
  o.platen_displacement = 1e-7;
  const StaticResult r = sim->solve_static(o);
  auto row_mean = [&](int j, const std::vector<double>& u) {
    double s = 0;
    for (int i = 0; i < nx; ++i) s += u[std::size_t(j * nx + i)];
    return s / nx;
  };
  auto col_mean = [&](int i, const std::vector<double>& u) {
    double s = 0;
    for (int j = 2; j < ny - 2; ++j) s += u[std::size_t(j * nx + i)];
    return s / (ny - 4);
  };
  const int j1 = 2, j2 = ny - 3;
  const std::vector<double> ux = r.component(0), uy = r.component(1);
  const double eps_yy = (row_mean(j2, uy) - row_mean(j1, uy)) / ((j2 - j1) * b);
  const double eps_xx = (col_mean(nx - 1, ux) - col_mean(0, ux)) / ((nx - 1) * a);
  const double stress = -0.5 * (r.top_force + r.bottom_force) / (nx * a * topo.thickness);
  // a vertical bond: j = i + nx
  int vertical = -1;
  for (std::size_t k = 0; k < topo.bonds.size() && vertical < 0; ++k)
    if (topo.bonds.ny[k] == 1.0) vertical = int(k);
  const BondStiffness k = sim->engine().model().stiffness(vertical);
  return {stress / eps_yy, (k.kbnA + k.knA) / (k.L * topo.thickness), eps_xx / eps_yy};
}

// docs/theory.md, section 3: rigid a x b blocks on an aligned grid with full-face bonds of normal stiffness k_n per area give
// E_y = k_n b, E_x = k_n a and nu = 0. E_x is measured by the same vertical test on the grid of b x a blocks.
TEST(Static, AlignedGridOfRectangularBlocksGivesKnTimesSize) {
  const double a = 0.004, b = 0.0025;
  const GridMeasurement y = measure_grid(a, b);
  EXPECT_NEAR(y.modulus / (y.kn * b), 1.0, 1e-9);
  EXPECT_NEAR(y.lateral_over_axial, 0.0, 1e-9);
  const GridMeasurement x = measure_grid(b, a);  // the b x a grid loaded vertically: E_x of the a x b grid
  EXPECT_NEAR(x.modulus / (x.kn * a), 1.0, 1e-9);
  EXPECT_NEAR(x.lateral_over_axial, 0.0, 1e-9);
  // with k_n = 2 E*/d and d = the block size along the load, both are 2 E*
  const Scene scene;
  EXPECT_NEAR(y.modulus / (2.0 * scene.rock.effective_modulus), 1.0, 1e-9);
}

}  // namespace
}  // namespace rbdem
