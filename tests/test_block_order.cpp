// The blocks' order (mesh/block_order.hpp, mesh.block_order): the Hilbert curve against its definition, the
// reordered mesh against the mesh it came from, its locality, and runs in either order.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "dem/driver/driver.hpp"
#include "dem/driver/registry.hpp"
#include "dem/mesh_cache.hpp"
#include "dem/scene.hpp"
#include "dem/specimen_mesh.hpp"
#include "dem/specimen_mesh3.hpp"
#include "dem/topology.hpp"
#include "mesh/block_order.hpp"

namespace rbdem {
namespace {

// Every cell of a 2^bits grid, by its Hilbert index: the indices are 0 .. 4^bits - 1 (or 8^bits - 1), each once,
// the curve starts at the origin, and consecutive cells share a side (one coordinate differs by one).
template <std::size_t N>
void check_curve(int bits) {
  const std::uint32_t n = 1u << bits;
  std::size_t cells = 1;
  for (std::size_t i = 0; i < N; ++i) cells *= n;
  std::vector<std::array<std::uint32_t, N>> at(cells);
  std::vector<char> seen(cells, 0);
  for (std::size_t c = 0; c < cells; ++c) {
    std::array<std::uint32_t, N> x;
    std::size_t r = c;
    for (std::size_t i = 0; i < N; ++i) x[i] = std::uint32_t(r % n), r /= n;
    const std::uint64_t h = hilbert_index(x, bits);
    ASSERT_LT(h, cells);
    ASSERT_FALSE(seen[h]) << "two cells at index " << h;
    seen[h] = 1;
    at[h] = x;
  }
  for (std::size_t i = 0; i < N; ++i) EXPECT_EQ(at[0][i], 0u);
  for (std::size_t h = 1; h < cells; ++h) {
    int distance = 0;
    for (std::size_t i = 0; i < N; ++i) distance += std::abs(int(at[h][i]) - int(at[h - 1][i]));
    ASSERT_EQ(distance, 1) << "index " << h - 1 << " -> " << h;
  }
}

TEST(HilbertIndex, VisitsEveryCellOnceStepByStepToANeighbour) {
  check_curve<2>(1);
  check_curve<2>(5);
  check_curve<3>(1);
  check_curve<3>(4);
}

TEST(HilbertIndex, RefusesACellOutsideItsGridAndBitsOutOfRange) {
  EXPECT_THROW(hilbert_index(std::array<std::uint32_t, 2>{16, 0}, 4), std::invalid_argument);
  EXPECT_THROW(hilbert_index(std::array<std::uint32_t, 3>{0, 0, 0}, 22), std::invalid_argument);
  EXPECT_THROW(hilbert_index(std::array<std::uint32_t, 2>{0, 0}, 0), std::invalid_argument);
  EXPECT_EQ(hilbert_index(std::array<std::uint32_t, 3>{(1u << 21) - 1, 0, 0}, 21) >> 63, 0u);
}

// The share of bonds whose two blocks lie in different ranges when the blocks are cut into `ranges` equal ranges,
// as the engine's threads hold them.
double crossing_share(const Topology<2>& topo, int ranges) {
  const std::size_t nb = topo.blocks.size();
  std::size_t crossing = 0;
  for (std::size_t b = 0; b < topo.bonds.size(); ++b)
    crossing += std::size_t(topo.bonds.i[b]) * ranges / nb != std::size_t(topo.bonds.j[b]) * ranges / nb;
  return double(crossing) / double(topo.bonds.size());
}

TEST(BlockOrder, TheReorderedMeshHoldsTheSameTrianglesInTheSameLayers) {
  Scene scene;
  scene.mesh.size = 0.004;
  const TriMesh before = make_mesh(scene);
  scene.mesh.block_order = "hilbert";
  const TriMesh after = make_mesh(scene);
  EXPECT_EQ(after.nodes, before.nodes);
  ASSERT_EQ(after.triangles.size(), before.triangles.size());
  EXPECT_NE(after.triangles, before.triangles);  // gmsh's order is not the curve's
  std::map<std::array<int, 3>, int> was;
  for (std::size_t t = 0; t < before.triangles.size(); ++t) was[before.triangles[t]] = before.layer[t];
  for (std::size_t t = 0; t < after.triangles.size(); ++t) {
    const auto found = was.find(after.triangles[t]);
    ASSERT_NE(found, was.end());
    EXPECT_EQ(found->second, after.layer[t]);
    was.erase(found);
  }
  EXPECT_TRUE(was.empty());
  TriMesh copy = after;
  EXPECT_THROW(apply_block_order(copy, "morton"), std::invalid_argument);
  std::vector<int> twice(copy.triangles.size(), 0);  // not a permutation
  EXPECT_THROW(reorder_elements(copy, twice), std::invalid_argument);
  EXPECT_THROW(reorder_elements(copy, {0, 1}), std::invalid_argument);
  EXPECT_EQ(copy.triangles, after.triangles);  // left as it was
  // The mesh cache keeps the two orders apart, and the default order's key is the key from before the option.
  const std::string hilbert_key = mesh_cache_key_text(scene);
  scene.mesh.block_order = "mesh";
  EXPECT_NE(mesh_cache_key_text(scene), hilbert_key);
  EXPECT_EQ(mesh_cache_key_text(scene).find("block_order"), std::string::npos);
  EXPECT_NE(hilbert_key.find("mesh.block_order=hilbert"), std::string::npos) << hilbert_key;
}

TEST(BlockOrder, ATetrahedralMeshKeepsItsBoundaryFacesOnTheirTetrahedra) {
  Scene scene;
  scene.specimen.dimension = 3;
  scene.specimen.shape = "cylinder";
  scene.mesh.size = 0.01;
  const TetMesh before = mesh_scene3(scene);
  scene.mesh.block_order = "hilbert";
  const TetMesh after = mesh_scene3(scene);
  ASSERT_EQ(after.tets.size(), before.tets.size());
  EXPECT_NE(after.tets, before.tets);
  ASSERT_EQ(after.boundary.size(), before.boundary.size());
  for (std::size_t f = 0; f < after.boundary.size(); ++f) {
    const BoundaryFace& face = after.boundary[f];
    EXPECT_EQ(after.tets[face.tet], before.tets[before.boundary[f].tet]);
    for (int v : face.nodes)
      EXPECT_NE(std::find(after.tets[face.tet].begin(), after.tets[face.tet].end(), v), after.tets[face.tet].end());
  }
  std::multiset<std::pair<std::array<int, 4>, int>> a, b;
  for (std::size_t t = 0; t < after.tets.size(); ++t) a.insert({after.tets[t], after.layer[t]});
  for (std::size_t t = 0; t < before.tets.size(); ++t) b.insert({before.tets[t], before.layer[t]});
  EXPECT_EQ(a, b);
  // Cut into 16 ranges, fewer faces join two ranges (10 mm: 0.42 of them in gmsh's order, 0.19 along the curve;
  // 4 mm: 0.39 and 0.09).
  std::array<double, 2> share{};
  for (int k = 0; k < 2; ++k) {
    const TetMesh& m = k == 0 ? before : after;
    const auto faces = shared_faces(m);
    std::size_t crossing = 0;
    for (const auto& f : faces)
      crossing += std::size_t(f.tets[0]) * 16 / m.tets.size() != std::size_t(f.tets[1]) * 16 / m.tets.size();
    share[k] = double(crossing) / double(faces.size());
  }
  EXPECT_LT(share[1], 0.5 * share[0]) << share[0] << " -> " << share[1];
}

// The reason for the order: cut into 16 ranges, gmsh's order puts about half the bonds across two ranges; along
// the curve a range is a compact patch, and only the bonds on its rim cross (a patch of n blocks has a rim of
// order sqrt(n) bonds).
TEST(BlockOrder, AlongTheCurveFewBondsCrossTwoThreadsRanges) {
  Scene scene;
  scene.mesh.size = 0.002;
  const Topology<2> mesh_order = build_topology(make_mesh(scene), scene.specimen.thickness, scene.rock.density);
  scene.mesh.block_order = "hilbert";
  const Topology<2> curve = build_topology(make_mesh(scene), scene.specimen.thickness, scene.rock.density);
  ASSERT_EQ(curve.bonds.size(), mesh_order.bonds.size());
  const double before = crossing_share(mesh_order, 16), after = crossing_share(curve, 16);
  RecordProperty("crossing_mesh_order", std::to_string(before));
  RecordProperty("crossing_hilbert", std::to_string(after));
  EXPECT_LT(after, 0.5 * before) << before << " -> " << after;
}

// A run in either order is the same model: the same bonded lattice, so the same stability limit and the same
// elastic response up to round-off; the cracks then differ in detail. Along the curve the run is still the same
// at 1 and 2 threads to the last bit.
TEST(BlockOrder, ARunAlongTheCurveIsTheSameModelAndTheSameAtOneAndTwoThreads) {
  Scene scene;
  scene.mesh.size = 0.004;
  scene.joint_set.dip_deg = 60;
  scene.numerics.threads = 1;
  const TestResult as_meshed = run_test("ucs", scene, make_mesh(scene));
  scene.mesh.block_order = "hilbert";
  const TriMesh mesh = make_mesh(scene);
  const TestResult one = run_test("ucs", scene, mesh);
  scene.numerics.threads = 2;
  const TestResult two = run_test("ucs", scene, mesh);
  // The stability limit is a power iteration (300 steps) from a start that follows the block order: converged to
  // about 1e-4 on this mesh, whichever the start.
  EXPECT_NEAR(one.dt_critical, as_meshed.dt_critical, 1e-3 * as_meshed.dt_critical);
  EXPECT_NEAR(one.elastic_start_strain, as_meshed.elastic_start_strain, 1e-9 * as_meshed.elastic_start_strain);
  EXPECT_NEAR(one.peak_stress, as_meshed.peak_stress, 0.05 * as_meshed.peak_stress);
  EXPECT_EQ(two.peak_stress, one.peak_stress);
  EXPECT_EQ(two.steps, one.steps);
  EXPECT_EQ(two.cracks.size(), one.cracks.size());
  std::printf("mesh order: peak %.6g Pa, %ld steps, %zu cracks, start strain %.9g; hilbert: %.6g Pa, %ld steps, "
              "%zu cracks, start strain %.9g\n", as_meshed.peak_stress, as_meshed.steps, as_meshed.cracks.size(),
              as_meshed.elastic_start_strain, one.peak_stress, one.steps, one.cracks.size(), one.elastic_start_strain);
}

}  // namespace
}  // namespace rbdem
