// Specimen meshing and bonded-block topology: conformity, joint length against the analytic chord lengths,
// block inertia against the closed form, and the .msh round trip.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <set>
#include <tuple>

#include <unistd.h>

#include <omp.h>

#include "dem/driver/summary.hpp"
#include "dem/materials.hpp"
#include "dem/mesh_cache.hpp"
#include "dem/model.hpp"
#include "dem/scene.hpp"
#include "dem/simulation_impl.hpp"
#include "dem/specimen_mesh.hpp"
#include "dem/topology.hpp"
#include "tests/weibull_check.hpp"

namespace rbdem {
namespace {

constexpr double W = 0.05, H = 0.10;

SpecimenGeometry geometry(double beta, double spacing, double offset = 0.0) {
  SpecimenGeometry g;
  g.width = W, g.height = H, g.dip_deg = beta, g.spacing = spacing, g.offset = offset;
  return g;
}

// Analytic total length of the lines n.(x - c) = offset + k s inside the rectangle, computed independently of the
// mesher: the chord length of a line at distance r from the centre, by integrating the indicator of the rectangle
// along the line (closed form: intersection of two slabs).
double analytic_joint_length(double beta, double s, double offset) {
  const double b = beta * std::numbers::pi / 180.0;
  const double dx = beta == 90 ? 0.0 : std::cos(b), dy = beta == 0 ? 0.0 : std::sin(b);
  const double nx = -dy, ny = dx;
  double total = 0;
  for (int k = -1000; k <= 1000; ++k) {
    const double r = offset + k * s;
    const double px = r * nx, py = r * ny;  // relative to the centre
    double lo = -1e9, hi = 1e9;
    auto slab = [&](double p, double d, double half) {
      if (std::abs(d) < 1e-15) {
        if (std::abs(p) >= half - 1e-12) lo = 1, hi = 0;
        return;
      }
      double a = (-half - p) / d, c = (half - p) / d;
      if (a > c) std::swap(a, c);
      lo = std::max(lo, a), hi = std::min(hi, c);
    };
    slab(px, dx, W / 2);
    slab(py, dy, H / 2);
    if (hi - lo > 1e-12) total += hi - lo;
  }
  return total;
}

void expect_conforming(const TriMesh& mesh, const Topology<2>& topo) {
  // Areas sum to W x H.
  double area = 0;
  for (double a : topo.blocks.area) area += a;
  EXPECT_NEAR(area, W * H, 1e-12 * W * H);
  // Every edge has one or two triangles; every single-triangle edge lies on the rectangle (no T-junction, no hole).
  std::map<std::pair<int, int>, int> uses;
  for (const auto& t : mesh.triangles)
    for (int e = 0; e < 3; ++e) ++uses[std::minmax(t[e], t[(e + 1) % 3])];
  double boundary_length = 0;
  for (const auto& [edge, n] : uses) {
    EXPECT_LE(n, 2);
    if (n == 1) {
      const auto& a = mesh.nodes[edge.first];
      const auto& b = mesh.nodes[edge.second];
      const bool on_side = (a[0] == 0 && b[0] == 0) || (a[0] == W && b[0] == W) || (a[1] == 0 && b[1] == 0) ||
                           (a[1] == H && b[1] == H);
      EXPECT_TRUE(on_side) << "free edge inside the specimen at (" << a[0] << ", " << a[1] << ")";
      boundary_length += std::hypot(b[0] - a[0], b[1] - a[1]);
    }
  }
  EXPECT_NEAR(boundary_length, 2 * (W + H), 1e-12);
  EXPECT_EQ(topo.bonds.size() + topo.boundary.size(), uses.size());
  // Every boundary edge got a side.
  for (auto s : topo.boundary.side) EXPECT_NE(s, Side::other);
}

class JointLength : public ::testing::TestWithParam<std::tuple<double, double>> {};

TEST_P(JointLength, EqualsAnalyticLengthOfJointLines) {
  const auto [beta, spacing] = GetParam();
  const double h = std::min(0.0025, spacing / 2);
  const TriMesh mesh = mesh_specimen(geometry(beta, spacing), h);
  EXPECT_TRUE(mesh.notes.empty()) << mesh.notes.front();
  const Topology<2> topo = build_topology(mesh, 1.0, 2700.0);
  expect_conforming(mesh, topo);
  const double expected = analytic_joint_length(beta, spacing, 0.0);
  EXPECT_NEAR(topo.total_length(BondKind::joint), expected, 1e-9 * expected) << "beta " << beta << " s " << spacing;
  // Layers: joint bonds separate different layers, rock bonds join the same layer.
  for (std::size_t b = 0; b < topo.bonds.size(); ++b)
    EXPECT_EQ(topo.bonds.kind[b] == BondKind::joint,
              topo.blocks.layer[topo.bonds.i[b]] != topo.blocks.layer[topo.bonds.j[b]]);
}

INSTANTIATE_TEST_SUITE_P(DipsAndSpacings, JointLength,
                         ::testing::Combine(::testing::Values(0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 90.0),
                                            ::testing::Values(0.005, 0.01, 0.02, 0.05)));

TEST(Mesh, NoJointBondsWhenTheSetMissesTheSpecimen) {
  // Lines at r = 0.1 + 0.2 k: the nearest is 0.1 m from the centre, outside the 0.05 x 0.1 specimen for beta = 0.
  const TriMesh mesh = mesh_specimen(geometry(0.0, 0.2, 0.1), 0.005);
  const Topology<2> topo = build_topology(mesh, 1.0, 2700.0);
  EXPECT_EQ(topo.count(BondKind::joint), 0u);
  EXPECT_EQ(mesh.num_layers(), 1u);
  expect_conforming(mesh, topo);
}

TEST(Mesh, HorizontalAndVerticalJointsAreExact) {
  for (double beta : {0.0, 90.0}) {
    const TriMesh mesh = mesh_specimen(geometry(beta, 0.01), 0.0025);
    const Topology<2> topo = build_topology(mesh, 1.0, 2700.0);
    for (std::size_t b = 0; b < topo.bonds.size(); ++b) {
      if (topo.bonds.kind[b] != BondKind::joint) continue;
      const auto& a = mesh.nodes[topo.bonds.node_a[b]];
      const auto& c = mesh.nodes[topo.bonds.node_b[b]];
      if (beta == 0.0) EXPECT_NEAR(a[1], c[1], 1e-15);
      else EXPECT_NEAR(a[0], c[0], 1e-15);
    }
  }
}

// mesh.structured: each piece between horizontal joints a grid of round(W / h) x round(H_piece / h) cells of two
// right triangles. Every triangle on a joint has its centroid a third of its row's height from the joint, so every
// joint bond has d = (h_below + h_above) / 3 and the same stiffness E*/d. Specimens it cannot grid are refused with
// the key to change.
TEST(Mesh, StructuredMeshGivesEveryJointBondTheSameCentroidDistance) {
  SpecimenGeometry g = geometry(0.0, 0.03, 0.01);  // joints at y - H/2 = -0.02, 0.01, 0.04: pieces 30, 30, 30, 10 mm
  g.structured = true;
  const double h = 0.0025;
  const TriMesh mesh = mesh_specimen(g, h);
  const Topology<2> topo = build_topology(mesh, 1.0, 2700.0);
  expect_conforming(mesh, topo);
  EXPECT_EQ(mesh.triangles.size(), std::size_t(2 * 20 * (12 + 12 + 12 + 4)));
  EXPECT_EQ(topo.count(BondKind::joint), std::size_t(3 * 20));
  for (std::size_t b = 0; b < topo.bonds.size(); ++b) {
    if (topo.bonds.kind[b] == BondKind::joint) {
      EXPECT_NEAR(topo.bonds.d[b], 2.0 * h / 3.0, 1e-12);
    }
  }
  const auto refused = [&](SpecimenGeometry bad, const std::string& key) {
    try {
      mesh_specimen(bad, h);
    } catch (const SceneError& e) {
      return std::string(e.what()).find(key) != std::string::npos;
    }
    return false;
  };
  SpecimenGeometry dipping = g, disc = g, seeded = g, two = g, bridged = g;
  dipping.dip_deg = 30;
  disc.disc = true, disc.height = disc.width;
  seeded.mesh_seed = 3;
  two.second_set = true, two.set2 = {90.0, 0.02, 0.0, 1.0, 0.02, 0.5};
  bridged.persistence = 0.5;
  EXPECT_TRUE(refused(dipping, "joint_set.dip_deg"));
  EXPECT_TRUE(refused(disc, "specimen.shape"));
  EXPECT_TRUE(refused(seeded, "mesh.seed"));
  EXPECT_TRUE(refused(two, "joint_set2.enabled"));
  EXPECT_TRUE(refused(bridged, "joint_set.persistence"));
}

// The same inputs give the same mesh, bit for bit, whatever the OpenMP default of the calling thread (gmsh meshes
// with OpenMP threads, and a mesh made on two threads differs from run to run), and the mesher hands that default
// back unchanged.
TEST(Mesh, SameInputsGiveTheSameMeshAndLeaveTheThreadDefaultAlone) {
  const int before = omp_get_max_threads();
  omp_set_num_threads(std::max(2, before));
  const TriMesh a = mesh_specimen(geometry(60, 0.01), 0.002);
  EXPECT_EQ(omp_get_max_threads(), std::max(2, before));
  const TriMesh b = mesh_specimen(geometry(60, 0.01), 0.002);
  omp_set_num_threads(before);
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  EXPECT_TRUE(a.nodes == b.nodes);
  EXPECT_TRUE(a.triangles == b.triangles);
  EXPECT_TRUE(a.layer == b.layer);
}

// Mesh statistics of a realization: triangles, smallest angle, mean and spread of the edge lengths.
struct MeshStats {
  std::size_t triangles = 0;
  double min_angle_deg = 180, edge_mean = 0, edge_sd = 0;
};

MeshStats mesh_stats(const TriMesh& m) {
  MeshStats st;
  st.triangles = m.triangles.size();
  double sum = 0, sum2 = 0;
  std::size_t n = 0;
  for (const auto& t : m.triangles)
    for (int v = 0; v < 3; ++v) {
      const auto& p = m.nodes[t[v]];
      const auto& a = m.nodes[t[(v + 1) % 3]];
      const auto& b = m.nodes[t[(v + 2) % 3]];
      const double ax = a[0] - p[0], ay = a[1] - p[1], bx = b[0] - p[0], by = b[1] - p[1];
      const double la = std::hypot(ax, ay), lb = std::hypot(bx, by);
      const double angle = std::acos((ax * bx + ay * by) / (la * lb)) * 180 / std::numbers::pi;
      st.min_angle_deg = std::min(st.min_angle_deg, angle);
      sum += la, sum2 += la * la, ++n;
    }
  st.edge_mean = sum / double(n);
  st.edge_sd = std::sqrt(sum2 / double(n) - st.edge_mean * st.edge_mean);
  return st;
}

// Nodes of `b` at the place of a node of `a` (to 1e-12 m).
std::size_t shared_nodes(const TriMesh& a, const TriMesh& b) {
  std::set<std::pair<long long, long long>> at;
  for (const auto& p : a.nodes) at.insert({std::llround(p[0] * 1e12), std::llround(p[1] * 1e12)});
  std::size_t shared = 0;
  for (const auto& p : b.nodes) shared += at.count({std::llround(p[0] * 1e12), std::llround(p[1] * 1e12)});
  return shared;
}

// mesh.seed: the same seed gives the same mesh bit for bit; seed 0 is the mesh of a scene without the key; other
// seeds give meshes that share hardly a node with it (corners and joint ends only) but have the same size and
// quality: triangle count and mean edge within 3 %, the smallest angle within 3 deg.
TEST(Mesh, SeedsGiveDifferentMeshesOfTheSameSizeAndQuality) {
  Scene scene = parse_scene("[mesh]\nsize = 0.002\n", "no seed");
  const TriMesh plain = make_mesh(scene);
  const TriMesh zero = make_mesh(parse_scene("[mesh]\nsize = 0.002\nseed = 0\n", "seed 0"));
  EXPECT_TRUE(plain.nodes == zero.nodes);
  EXPECT_TRUE(plain.triangles == zero.triangles);
  const MeshStats ref = mesh_stats(plain);
  std::vector<TriMesh> seeded;
  for (int seed : {1, 2, 3}) {
    scene.mesh.seed = seed;
    seeded.push_back(make_mesh(scene));
    const TriMesh again = make_mesh(scene);
    EXPECT_TRUE(seeded.back().nodes == again.nodes) << "seed " << seed;
    EXPECT_TRUE(seeded.back().triangles == again.triangles) << "seed " << seed;
    EXPECT_TRUE(seeded.back().layer == again.layer) << "seed " << seed;
    const MeshStats st = mesh_stats(seeded.back());
    EXPECT_NEAR(double(st.triangles) / double(ref.triangles), 1.0, 0.03) << "seed " << seed;
    EXPECT_NEAR(st.edge_mean / ref.edge_mean, 1.0, 0.03) << "seed " << seed;
    EXPECT_NEAR(st.edge_sd / ref.edge_sd, 1.0, 0.1) << "seed " << seed;
    EXPECT_NEAR(st.min_angle_deg, ref.min_angle_deg, 3.0) << "seed " << seed;
    EXPECT_EQ(seeded.back().layer_names, plain.layer_names) << "seed " << seed;
    EXPECT_LT(shared_nodes(plain, seeded.back()), plain.nodes.size() / 10) << "seed " << seed;
  }
  EXPECT_LT(shared_nodes(seeded[0], seeded[1]), seeded[0].nodes.size() / 10);
  EXPECT_LT(shared_nodes(seeded[1], seeded[2]), seeded[1].nodes.size() / 10);
}

TEST(Mesh, LayerNarrowerThanTwoElementsIsRejected) {
  try {
    mesh_specimen(geometry(30.0, 0.003), 0.002);
    FAIL();
  } catch (const SceneError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("joint_set.spacing"), std::string::npos) << m;
    EXPECT_NE(m.find("mesh.size <= 0.0015"), std::string::npos) << m;
  }
}

TEST(Blocks, InertiaEqualsTriangleClosedForm) {
  const TriMesh mesh = mesh_specimen(geometry(45.0, 0.02), 0.004);
  const double rho = 2500.0, t = 0.7;
  const Topology<2> topo = build_topology(mesh, t, rho);
  for (std::size_t k = 0; k < mesh.num_triangles(); ++k) {
    const auto& tri = mesh.triangles[k];
    const auto& a = mesh.nodes[tri[0]];
    const auto& b = mesh.nodes[tri[1]];
    const auto& c = mesh.nodes[tri[2]];
    auto sq = [](auto p, auto q) { return (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]); };
    // Polar moment of a triangle about its centroid: m (a^2 + b^2 + c^2) / 36 with side lengths a, b, c.
    const double m = rho * t * 0.5 * std::abs((b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]));
    const double closed = m * (sq(a, b) + sq(b, c) + sq(c, a)) / 36.0;
    EXPECT_NEAR(topo.blocks.mass[k], m, 1e-13 * m);
    EXPECT_NEAR(topo.blocks.inertia[k], closed, 1e-12 * closed);
  }
}

TEST(Bonds, NormalPointsFromFirstToSecondBlockAndAdjacencyIsComplete) {
  const TriMesh mesh = mesh_specimen(geometry(60.0, 0.01), 0.0025);
  const Topology<2> topo = build_topology(mesh, 1.0, 2700.0);
  const auto& B = topo.blocks;
  const auto& N = topo.bonds;
  for (std::size_t b = 0; b < N.size(); ++b) {
    EXPECT_LT(N.i[b], N.j[b]);
    EXPECT_NEAR(std::hypot(N.nx[b], N.ny[b]), 1.0, 1e-14);
    EXPECT_GT(N.nx[b] * (B.cx[N.j[b]] - B.cx[N.i[b]]) + N.ny[b] * (B.cy[N.j[b]] - B.cy[N.i[b]]), 0.0);
    EXPECT_NEAR(N.d[b], N.nx[b] * (B.cx[N.j[b]] - B.cx[N.i[b]]) + N.ny[b] * (B.cy[N.j[b]] - B.cy[N.i[b]]), 1e-15);
  }
  std::vector<int> count(B.size(), 0);
  for (std::size_t k = 0; k < B.size(); ++k)
    for (int o = topo.bond_offset[k]; o < topo.bond_offset[k + 1]; ++o) {
      const int b = topo.bond_of[o];
      EXPECT_TRUE(N.i[b] == int(k) || N.j[b] == int(k));
      ++count[k];
    }
  std::vector<int> edges(B.size(), 0);
  for (int blk : topo.boundary.block) ++edges[blk];
  for (std::size_t k = 0; k < B.size(); ++k) EXPECT_EQ(count[k] + edges[k], 3);
}

// Blocks and bonds as sorted tuples, independent of node and triangle numbering.
auto signature(const Topology<2>& t) {
  std::vector<std::tuple<long, long, long, int>> blocks;
  for (std::size_t k = 0; k < t.blocks.size(); ++k)
    blocks.emplace_back(std::lround(t.blocks.cx[k] * 1e9), std::lround(t.blocks.cy[k] * 1e9),
                        std::lround(t.blocks.area[k] * 1e15), t.blocks.layer[k]);
  std::vector<std::tuple<long, long, long, int>> bonds;
  for (std::size_t b = 0; b < t.bonds.size(); ++b)
    bonds.emplace_back(std::lround(t.bonds.mx[b] * 1e9), std::lround(t.bonds.my[b] * 1e9),
                       std::lround(t.bonds.length[b] * 1e9), int(t.bonds.kind[b]));
  std::sort(blocks.begin(), blocks.end());
  std::sort(bonds.begin(), bonds.end());
  return std::make_pair(blocks, bonds);
}

TEST(Mesh, WrittenMshReadsBackToTheSameBlocksAndBonds) {
  const auto path = std::filesystem::temp_directory_path() / "rbdem_test_roundtrip.msh";
  const TriMesh written = mesh_specimen(geometry(30.0, 0.01), 0.0025, path);
  const TriMesh read = read_msh(path);
  EXPECT_EQ(read.num_triangles(), written.num_triangles());
  EXPECT_EQ(read.num_layers(), written.num_layers());
  EXPECT_EQ(read.layer_names, written.layer_names);
  const auto a = signature(build_topology(written, 1.0, 2700.0));
  const auto b = signature(build_topology(read, 1.0, 2700.0));
  EXPECT_EQ(a.first, b.first);
  EXPECT_EQ(a.second, b.second);
  std::filesystem::remove(path);
}

TEST(Mesh, UserMeshWithoutPhysicalSurfacesIsRejected) {
  const auto path = std::filesystem::temp_directory_path() / "rbdem_test_nophys.msh";
  std::ofstream(path) << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Entities\n0 0 1 0\n1 0 0 0 1 1 0 0 0\n$EndEntities\n"
                         "$Nodes\n1 3 1 3\n2 1 0 3\n1\n2\n3\n0 0 0\n1 0 0\n0 1 0\n$EndNodes\n"
                         "$Elements\n1 1 1 1\n2 1 2 1\n1 1 2 3\n$EndElements\n";
  try {
    read_msh(path);
    FAIL();
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("physical surface"), std::string::npos) << e.what();
  }
  std::filesystem::remove(path);
}

TEST(Mesh, UserMeshWithQuadranglesIsRejected) {
  const auto path = std::filesystem::temp_directory_path() / "rbdem_test_quads.msh";
  std::ofstream(path) << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n"
                         "$PhysicalNames\n1\n2 1 \"layer_0\"\n$EndPhysicalNames\n"
                         "$Entities\n0 0 1 0\n1 0 0 0 1 1 0 1 1 0\n$EndEntities\n"
                         "$Nodes\n1 4 1 4\n2 1 0 4\n1\n2\n3\n4\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n$EndNodes\n"
                         "$Elements\n1 1 1 1\n2 1 3 1\n1 1 2 3 4\n$EndElements\n";
  try {
    read_msh(path);
    FAIL();
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("triangles only"), std::string::npos) << e.what();
  }
  std::filesystem::remove(path);
}

TEST(Mesh, MissingMeshFileIsAClearError) {
  EXPECT_THROW(read_msh("/nonexistent/specimen.msh"), SceneError);
}

// Two unit-square triangles over [0, 1]^2, for the import checks.
TriMesh square() {
  TriMesh m;
  m.nodes = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  m.layer = {0, 0};
  m.layer_names = {"layer_0"};
  return m;
}

std::string refusal(TriMesh m) {
  try {
    check_user_mesh(m, "m.msh");
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

TEST(MeshImport, ClockwiseTrianglesAreTurnedAndNoted) {
  TriMesh m = square();
  std::swap(m.triangles[1][1], m.triangles[1][2]);
  check_user_mesh(m, "m.msh");
  EXPECT_GT(signed_area(m, 1), 0.0);
  ASSERT_EQ(m.notes.size(), 1u);
  EXPECT_NE(m.notes[0].find("1 clockwise"), std::string::npos) << m.notes[0];
}

TEST(MeshImport, ZeroAreaTriangleIsRefused) {
  TriMesh m = square();
  m.nodes.push_back({0.5, 0});
  m.triangles.push_back({0, 4, 1});
  m.layer.push_back(0);
  EXPECT_NE(refusal(m).find("degenerate"), std::string::npos) << refusal(m);
}

TEST(MeshImport, DuplicateNodesAreRefused) {
  TriMesh m = square();
  m.nodes.push_back({1, 1});  // a second node on top of node 2
  m.triangles[1] = {0, 4, 3};
  EXPECT_NE(refusal(m).find("two nodes at (1, 1)"), std::string::npos) << refusal(m);
}

TEST(MeshImport, TJunctionIsRefused) {
  TriMesh m = square();
  // A second cell right of x = 1, split at (1, 0.5): that node hangs on the first cell's edge x = 1.
  m.nodes.insert(m.nodes.end(), {{2, 0}, {2, 1}, {1, 0.5}});
  for (std::array<int, 3> t : {std::array<int, 3>{1, 4, 6}, {6, 4, 5}, {6, 5, 2}}) {
    m.triangles.push_back(t);
    m.layer.push_back(0);
  }
  EXPECT_NE(refusal(m).find("T-junction"), std::string::npos) << refusal(m);
  // The same cells, conforming: the left cell split at (1, 0.5) too.
  m.triangles[0] = {0, 1, 6};
  m.triangles[1] = {0, 6, 2};
  m.triangles.push_back({0, 2, 3});
  m.layer.push_back(0);
  EXPECT_EQ(refusal(m), "");
}

// gmsh 4.8 reads damaged MSH 3 and binary files without checking their counts (tests/fuzz/fuzz_msh found a
// 199-byte file that made it allocate 3.4 GB): rbdem reads ASCII MSH 2.x and 4.x only, which it checks first.
TEST(MeshImport, OnlyAsciiMsh2And4AreRead) {
  const auto path = std::filesystem::temp_directory_path() / "rbdem_test_format.msh";
  for (const char* head : {"3.2 0 8", "3.2 2 8", "4.0 0 8", "4.1 1 8", "4.1 2 8", "5 0 8", "1.0 0 8"}) {
    std::ofstream(path) << "$MeshFormat\n" << head << "\n$EndMeshFormat\n";
    try {
      read_msh(path);
      FAIL() << "a file with `" << head << "` was read";
    } catch (const SceneError& e) {
      const std::string what = e.what();
      EXPECT_TRUE(what.find("MSH 4.1 or 2.2") != std::string::npos || what.find("ASCII") != std::string::npos)
          << head << ": " << what;
    }
  }
  std::filesystem::remove(path);
}

// gmsh takes a section by the start of its header (`$ElementsH2` is read as $Elements) and then crashes on the
// unchecked elements (tests/fuzz/fuzz_msh): only exact, single $Nodes and $Elements headers get past rbdem.
TEST(MeshImport, SectionHeadersMustBeExact) {
  const auto path = std::filesystem::temp_directory_path() / "rbdem_test_headers.msh";
  const std::string nodes = "$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n$EndNodes\n";
  for (const std::string& body : {nodes + "$ElementsH2\n1\n1 2 2 0 1 1 2 5\n$EndElements\n",
                                  std::string("$NOD\n1\n1 0 0 0\n$ENDNOD\n"),
                                  nodes + nodes + "$Elements\n1\n1 2 2 0 1 1 2 3\n$EndElements\n"}) {
    std::ofstream(path) << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n" << body;
    try {
      read_msh(path);
      FAIL() << "read: " << body;
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find("section header"), std::string::npos) << e.what();
    }
  }
  std::filesystem::remove(path);
}

// gmsh 4.8 indexes its per-dimension positions in $PhysicalNames by the dimension the file gives and crashed on one
// outside 0-3 (tests/fuzz/fuzz_msh); other sections run readers rbdem does not check, and a line longer than gmsh's
// buffer is read in pieces. All of these are refused before gmsh reads the file; the same file with sane names reads.
TEST(MeshImport, PhysicalNamesAndOtherSectionsAreCheckedBeforeGmshReadsThem) {
  const auto path = std::filesystem::temp_directory_path() / "rbdem_test_names.msh";
  const std::string head = "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
  const std::string mesh2 =
      "$Nodes\n4\n1 0 0 0\n2 0.01 0 0\n3 0.01 0.01 0\n4 0 0.01 0\n$EndNodes\n"
      "$Elements\n2\n1 2 2 1 1 1 2 3\n2 2 2 1 1 1 3 4\n$EndElements\n";
  const std::string names = "$PhysicalNames\n1\n2 1 \"layer_0\"\n$EndPhysicalNames\n";
  auto refused = [&](const std::string& text, const std::string& expect) {
    std::ofstream(path, std::ios::trunc) << text;
    try {
      read_msh(path);
      ADD_FAILURE() << "read: " << text;
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find(expect), std::string::npos) << e.what();
    }
  };
  refused(head + "$PhysicalNames\n1\n70000 1 \"layer_0\"\n$EndPhysicalNames\n", "dimension 70000");
  refused(head + "$PhysicalNames\n1\n-1 1 \"layer_0\"\n$EndPhysicalNames\n", "dimension -1");
  refused(head + "$PhysicalNames\n2\n2 1 \"layer_0\"\n$EndPhysicalNames\n", "not a number");
  refused(head + "$PhysicalNames\n1\n2 1 layer_0\n$EndPhysicalNames\n", "double quotes");
  refused(head + names + names, "section header `$PhysicalNames`");
  refused(head + "$NodeData\n1\n$EndNodeData\n", "section header `$NodeData`");
  refused(head + "$MeshFormat\n4.1 1 8\n$EndMeshFormat\n", "section header `$MeshFormat`");
  refused(head + std::string(1500, ' ') + "\n", "1500 characters");
  // MSH 2.2 with the same names reads; its lines are checked against gmsh's shorter buffer.
  std::ofstream(path, std::ios::trunc) << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n" << names << mesh2;
  EXPECT_EQ(read_msh(path).triangles.size(), 2u);
  refused("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n2 1 \"" + std::string(300, 'x') +
              "\"\n$EndPhysicalNames\n" + mesh2,
          "characters");
  std::filesystem::remove(path);
}

// `text` written to `path` and read as a mesh: "read N triangles", or the refusal's message.
std::string read_outcome(const std::filesystem::path& path, const std::string& text) {
  std::ofstream(path, std::ios::trunc) << text;
  try {
    return "read " + std::to_string(read_msh(path).triangles.size()) + " triangles";
  } catch (const SceneError& e) {
    return e.what();
  }
}

// gmsh 4.8 allocates its node and element tables from the counts a $Nodes or $Elements header declares, before it
// reads the blocks: a header declaring 86 540 488 nodes over four made it allocate 1.4 GB and then read the mesh
// (tests/fuzz/fuzz_msh). A header must declare what its blocks hold; the same mesh with true headers reads.
TEST(MeshImport, HeadersMustDeclareWhatTheBlocksHold) {
  const auto path = std::filesystem::temp_directory_path() / "rbdem_test_counts.msh";
  auto mesh = [](const std::string& nodes_header, const std::string& node_block, const std::string& elements_header,
                 const std::string& coordinates) {
    return "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n2 1 \"layer_0\"\n$EndPhysicalNames\n"
           "$Entities\n0 0 1 0\n1 0 0 0 0.01 0.01 0 1 1 0\n$EndEntities\n$Nodes\n" +
           nodes_header + "\n" + node_block + "\n1\n2\n3\n4\n" + coordinates +
           "\n0.01 0 0\n0.01 0.01 0\n0 0.01 0\n$EndNodes\n$Elements\n" + elements_header +
           "\n2 1 2 2\n1 1 2 3\n2 1 3 4\n$EndElements\n";
  };
  auto outcome = [&](const std::string& text) { return read_outcome(path, text); };
  EXPECT_EQ(outcome(mesh("1 4 1 4", "2 1 0 4", "1 2 1 2", "0 0 0")), "read 2 triangles");
  const std::pair<std::string, std::string> refusals[] = {
      {mesh("1 86540488 1 4", "2 1 0 4", "1 2 1 2", "0 0 0"), "declares 86540488 nodes and the file holds 4"},
      {mesh("1 4 1 4", "2 1 0 4", "1 86540488 1 2", "0 0 0"), "declares 86540488 elements and the file holds 2"},
      {mesh("1 4 1 173000000", "2 1 0 4", "1 2 1 2", "0 0 0"), "node tags 1 to 173000000 and the file holds 1 to 4"},
      {mesh("1 4 1 4", "2 1 0 4", "1 2 1 9", "0 0 0"), "element tags 1 to 9 and the file holds 1 to 2"},
      {mesh("1 4 1", "2 1 0 4", "1 2 1 2", "0 0 0"), "$Nodes header is not"},
      {mesh("1 4 1 4 7", "2 1 0 4", "1 2 1 2", "0 0 0"), "$Nodes header is not"},
      {mesh("1 4 1 4", "2 1 0 4 0", "1 2 1 2", "0 0 0"), "node block header is not"},
      {mesh("1 4 1 4", "2 1 1 4", "1 2 1 2", "0 0 0"), "parametric"},
      {mesh("1 4 1 4", "2 1 0 4", "1 2 1 2", "0 0 0 0.5"), "exactly x y z"},
  };
  for (const auto& [text, expect] : refusals)
    EXPECT_NE(outcome(text).find(expect), std::string::npos) << outcome(text) << "\n(expected: " << expect << ")";
  std::filesystem::remove(path);
}

// gmsh 4.8 allocates a line buffer of 128 bytes per entity the $Entities header declares, before it reads one: a
// header of `10 13 1002113248654051872 0` made it allocate 1.6 GB (its 32-bit product) from a file of 263 bytes
// (tests/fuzz/fuzz_msh). The header must declare the entity lines that follow, each with its box and its lists.
TEST(MeshImport, EntitiesMustDeclareTheLinesThatFollow) {
  const auto path = std::filesystem::temp_directory_path() / "rbdem_test_entities.msh";
  auto mesh = [](const std::string& entities) {
    return "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$PhysicalNames\n1\n2 1 \"layer_0\"\n$EndPhysicalNames\n"
           "$Entities\n" + entities + "$EndEntities\n$Nodes\n1 4 1 4\n2 1 0 4\n1\n2\n3\n4\n0 0 0\n0.01 0 0\n"
           "0.01 0.01 0\n0 0.01 0\n$EndNodes\n$Elements\n1 2 1 2\n2 1 2 2\n1 1 2 3\n2 1 3 4\n$EndElements\n";
  };
  auto outcome = [&](const std::string& text) { return read_outcome(path, text); };
  const std::string point = "1 0 0 0 0\n", surface = "1 0 0 0 0.01 0.01 0 1 1 0\n";
  EXPECT_EQ(outcome(mesh("0 0 1 0\n" + surface)), "read 2 triangles");
  EXPECT_EQ(outcome(mesh("1 0 1 0\n" + point + surface)), "read 2 triangles");
  const std::pair<std::string, std::string> refusals[] = {
      {mesh("10 13 1002113248654051872 0\n" + surface), "declares 10 13 1002113248654051872 0 entities"},
      {mesh("9223372036854775807 9223372036854775807 1 0\n" + surface), "more than the 1000000"},
      {mesh("0 0 2 0\n" + surface), "entity line 2 of dimension 2"},
      {mesh("0 0 1\n" + surface), "$Entities header is not"},
      {mesh("0 0 -1 0\n" + surface), "$Entities header is not"},
      {mesh("0 0 1 0 5\n" + surface), "$Entities header is not"},
      {mesh("0 0 1 0\n1 0 0 0 0.01 0.01 0 1 1\n"), "entity line 1 of dimension 2"},
      {mesh("0 0 1 0\n1 0 0 0 0.01 0.01 0 1 1 0 7\n"), "entity line 1 of dimension 2"},
      {mesh("0 0 1 0\n1 0 0 0 0.01 0.01 0 99999999 1 0\n"), "entity line 1 of dimension 2"},
      {mesh("1 0 1 0\n1 0 0 0 0 0 0\n" + surface), "entity line 1 of dimension 0"},
  };
  for (const auto& [text, expect] : refusals)
    EXPECT_NE(outcome(text).find(expect), std::string::npos) << outcome(text) << "\n(expected: " << expect << ")";
  std::filesystem::remove(path);
}

TEST(MeshImport, NonMeshFileIsRefusedBeforeGmshReadsIt) {
  const auto path = std::filesystem::temp_directory_path() / "rbdem_test_script.msh";
  std::ofstream(path) << "Point(1) = {0, 0, 0, 1};\n";
  try {
    read_msh(path);
    FAIL();
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("$MeshFormat"), std::string::npos) << e.what();
  }
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace rbdem

namespace rbdem {
namespace {

// Total length of the joint bonds on the interface named `name`.
double interface_length(const Topology<2>& topo, const std::string& name) {
  double total = 0;
  for (std::size_t b = 0; b < topo.bonds.size(); ++b) {
    const int f = topo.bonds.interface[b];
    if (f >= 0 && topo.interface_names[std::size_t(f)] == name) total += topo.bonds.length[b];
  }
  return total;
}

// Two sets: each set's joints are chains of mesh edges on its own physical curve group, and each set's joint length
// is the analytic length of its lines (the crossings split the edges, not the length).
TEST(JointSets, EachSetsJointLengthEqualsItsAnalyticLength) {
  int checked = 0;
  for (const auto& [dip1, dip2] : {std::pair{0.0, 90.0}, std::pair{60.0, 150.0}, std::pair{30.0, 75.0}}) {
    SpecimenGeometry g = geometry(dip1, 0.01);
    g.second_set = true;
    g.set2.dip_deg = dip2, g.set2.spacing = 0.02, g.set2.offset = 0.004;
    const TriMesh mesh = mesh_specimen(g, 0.0025);
    const Topology<2> topo = build_topology(mesh, 1.0, 2700.0);
    expect_conforming(mesh, topo);
    ASSERT_EQ(topo.interface_names, (std::vector<std::string>{"joint_set", "joint_set2"}));
    if (!mesh.notes.empty()) continue;  // a corner piece left out: the analytic sum would hold that line
    const double first = analytic_joint_length(dip1, 0.01, 0.0);
    // The second set dips beyond 90 deg at 150: the same lines as -30 deg, whose normal and offset flip sign.
    const double second = dip2 > 90.0 ? analytic_joint_length(dip2 - 180.0, 0.02, -0.004)
                                      : analytic_joint_length(dip2, 0.02, 0.004);
    EXPECT_NEAR(interface_length(topo, "joint_set"), first, 1e-9 * first) << dip1 << "/" << dip2;
    EXPECT_NEAR(interface_length(topo, "joint_set2"), second, 1e-9 * second) << dip1 << "/" << dip2;
    EXPECT_NEAR(topo.total_length(BondKind::joint), first + second, 1e-9 * (first + second));
    ++checked;
  }
  EXPECT_EQ(checked, 3);
}

// Non-persistent joints: horizontal joints 20 mm apart at y = 10, 30, ..., 90 mm, pieces 10 mm long with 10 mm
// bridges (persistence 0.5), the piece of each joint centred on the specimen's axis (stagger 0): pieces over
// x = 0-10, 20-30 and 40-50 mm, 30 mm of joint per line, 150 mm in all. No joint runs through, so one layer, and a
// bond in a bridge is rock.
TEST(JointSets, NonPersistentJointsArePiecesWithRockBridges) {
  SpecimenGeometry g = geometry(0.0, 0.02);
  g.persistence = 0.5, g.joint_length = 0.01, g.stagger = 0.0;
  const std::vector<JointSegment> pieces = joint_segments(g);
  ASSERT_EQ(pieces.size(), 15u);
  const TriMesh mesh = mesh_specimen(g, 0.0025);
  const Topology<2> topo = build_topology(mesh, 1.0, 2700.0);
  expect_conforming(mesh, topo);
  EXPECT_EQ(mesh.num_layers(), 1u);
  EXPECT_NEAR(topo.total_length(BondKind::joint), 0.15, 1e-12);
  for (std::size_t b = 0; b < topo.bonds.size(); ++b) {
    const auto& a = mesh.nodes[std::size_t(topo.bonds.node_a[b])];
    const auto& c = mesh.nodes[std::size_t(topo.bonds.node_b[b])];
    const double x = 0.5 * (a[0] + c[0]), y = 0.5 * (a[1] + c[1]);
    const bool on_line = std::abs(a[1] - c[1]) < 1e-12 && std::abs(std::remainder(y - 0.01, 0.02)) < 1e-9;
    const bool in_piece = x < 0.01 || (x > 0.02 && x < 0.03) || x > 0.04;
    EXPECT_EQ(topo.bonds.kind[b] == BondKind::joint, on_line && in_piece) << "bond at " << x << ", " << y;
  }
  // Staggered by half a period, the next joint's pieces sit over the first one's bridges.
  g.stagger = 0.5;
  const std::vector<JointSegment> staggered = joint_segments(g);
  double at_30mm = 0;
  for (const auto& s : staggered)
    if (std::abs(s.a[1] - 0.07) < 1e-12) {
      at_30mm += s.length();
      EXPECT_GE(s.a[0], 0.01 - 1e-12);
    }
  EXPECT_NEAR(at_30mm, 0.02, 1e-12);  // the joint at y = 70 mm: pieces over 10-20 and 30-40 mm
}

// The interfaces survive the .msh round trip: the same joint bonds, also inside a layer.
TEST(JointSets, InterfacesReadBackFromTheWrittenMsh) {
  const auto path = std::filesystem::temp_directory_path() / "rbdem_test_interfaces.msh";
  SpecimenGeometry g = geometry(60.0, 0.01);
  g.persistence = 0.6, g.joint_length = 0.012;
  g.second_set = true, g.set2.dip_deg = 150.0, g.set2.spacing = 0.025;
  const TriMesh written = mesh_specimen(g, 0.0025, path);
  const TriMesh read = read_msh(path);
  ASSERT_EQ(read.interfaces.size(), written.interfaces.size());
  const auto a = signature(build_topology(written, 1.0, 2700.0));
  const auto b = signature(build_topology(read, 1.0, 2700.0));
  EXPECT_EQ(a.second, b.second);
  std::filesystem::remove(path);
}

// Materials by name and number: the second rock on the layers rock2.groups names (by name or layer number), the
// second joint on the second generated set and on the interfaces joint2.groups names; a name the mesh lacks is a
// SceneError that names the key. Blocks of rock2 carry its density.
TEST(Materials, AssignedByLayerAndInterfaceNames) {
  Scene scene;
  scene.mesh.size = 0.0025;
  scene.joint_set.dip_deg = 0.0, scene.joint_set.spacing = 0.025, scene.joint_set.offset = 0.0125;
  scene.joint_set2.enabled = true, scene.joint_set2.dip_deg = 90.0, scene.joint_set2.spacing = 0.02;
  scene.rock2.groups = "layer_1, 3";
  scene.rock2.density = 2 * scene.rock.density;
  const TriMesh mesh = make_mesh(scene);
  const Topology<2> topo = build_topology(mesh, 1.0, scene.rock.density);
  const MaterialMap m = assign_materials(topo, scene);
  std::size_t joint2 = 0, rock2 = 0;
  for (std::size_t b = 0; b < topo.bonds.size(); ++b) {
    const int f = topo.bonds.interface[b];
    const std::string on = f >= 0 ? topo.interface_names[std::size_t(f)] : "";
    const int li = topo.blocks.layer[std::size_t(topo.bonds.i[b])];
    if (topo.bonds.kind[b] == BondKind::rock) {
      EXPECT_EQ(m.bond[b], (li == 1 || li == 3) ? material_rock2 : material_rock);
      rock2 += m.bond[b] == material_rock2;
    } else {
      EXPECT_EQ(m.bond[b], on == "joint_set2" ? material_joint2 : material_joint) << on;
      joint2 += m.bond[b] == material_joint2;
    }
  }
  EXPECT_GT(joint2, 0u);
  EXPECT_GT(rock2, 0u);
  const Model model = build_model(topo, scene, 1.0);
  for (std::size_t b = 0; b < topo.blocks.size(); ++b)
    EXPECT_DOUBLE_EQ(model.mass[b], topo.blocks.mass[b] * (m.block[b] == material_rock2 ? 2.0 : 1.0));

  // joint2.groups moves the first set onto the second joint material too.
  scene.joint2.groups = "joint_set";
  const MaterialMap all = assign_materials(topo, scene);
  for (std::size_t b = 0; b < topo.bonds.size(); ++b)
    if (topo.bonds.kind[b] == BondKind::joint) {
      EXPECT_EQ(all.bond[b], material_joint2);
    }

  for (const auto& [key, value] : {std::pair{"rock2.groups", "sandstone"}, std::pair{"rock2.groups", "999"},
                                   std::pair{"joint2.groups", "fault"}}) {
    Scene bad = scene;
    set_parameter(bad, key, value);
    try {
      assign_materials(topo, bad);
      ADD_FAILURE() << key << " = " << value << " was accepted";
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(value), std::string::npos) << e.what();
    }
  }
}

// Bond strength heterogeneity: with rock.weibull_modulus = m every rock bond's tensile strength and cohesion are
// scaled by one factor w drawn from the Weibull distribution F(w) = 1 - exp(-(w Gamma(1 + 1/m))^m) (mean 1), the
// softening bond's r_u by 1 / w^2 (the same fracture energy); joint bonds (m = 0) keep the stated strength. The
// factors pass a Kolmogorov-Smirnov test against F at the 1 % level, their mean and coefficient of variation match
// the closed forms, and the same seed gives the same factors.
TEST(Materials, WeibullStrengthFactorsFollowTheirDistribution) {
  Scene scene;
  scene.mesh.size = 0.002;
  const double m = 3.0;
  scene.rock.weibull_modulus = m;
  const TriMesh mesh = make_mesh(scene);
  const Topology<2> topo = build_topology(mesh, 1.0, scene.rock.density);
  const Model uniform = build_model(topo, Scene{}, 1.0);
  const Model model = build_model(topo, scene, 1.0);
  std::vector<double> w;
  for (std::size_t b = 0; b < topo.bonds.size(); ++b) {
    const double f = model.frame.strength_factor[b];
    if (topo.bonds.kind[b] == BondKind::joint) {
      EXPECT_EQ(f, 1.0);
      EXPECT_EQ(model.frame.tension_limit[b], uniform.frame.tension_limit[b]);
      continue;
    }
    EXPECT_DOUBLE_EQ(model.frame.tension_limit[b], f * uniform.frame.tension_limit[b]);
    EXPECT_DOUBLE_EQ(model.frame.cohesion_A[b], f * uniform.frame.cohesion_A[b]);
    EXPECT_NEAR(model.frame.rupture[b], uniform.frame.rupture[b] / (f * f), 1e-12 * model.frame.rupture[b]);
    w.push_back(f);
  }
  expect_weibull_factors(w, m);
  // The same seed gives the same factors; another seed other factors.
  EXPECT_EQ(build_model(topo, scene, 1.0).frame.strength_factor, model.frame.strength_factor);
  scene.mesh.strength_seed = 1;
  EXPECT_NE(build_model(topo, scene, 1.0).frame.strength_factor, model.frame.strength_factor);
}

// Crack counts by material: synthetic cracks on the first bond of each material, tensile, plus one shear crack on
// a second-set joint; materials the specimen lacks (rock2 here) are not listed.
TEST(Materials, CracksAreCountedByMaterial) {
  Scene scene;
  scene.mesh.size = 0.0025;
  scene.joint_set2.enabled = true, scene.joint_set2.dip_deg = 120.0, scene.joint_set2.spacing = 0.02;
  const Topology<2> topo = build_topology(make_mesh(scene), 1.0, scene.rock.density);
  const MaterialMap m = assign_materials(topo, scene);
  std::vector<Crack> cracks;
  std::array<int, material_count> bonds{};
  std::array<bool, material_count> seen{};
  for (std::size_t b = 0; b < topo.bonds.size(); ++b) {
    ++bonds[m.bond[b]];
    if (!seen[m.bond[b]]) {
      seen[m.bond[b]] = true;
      Crack c;
      c.bond = int(b), c.mode = BreakMode::tensile;
      cracks.push_back(c);
      if (m.bond[b] == material_joint2) c.mode = BreakMode::shear, c.bond = int(b), cracks.push_back(c);
    }
  }
  const auto counts = count_cracks_by_material(cracks, describe(topo, nullptr, m.bond));
  ASSERT_EQ(counts.size(), 3u);
  EXPECT_EQ(counts[0].material, "rock");
  EXPECT_EQ(counts[1].material, "joint");
  EXPECT_EQ(counts[2].material, "joint2");
  for (const auto& c : counts) EXPECT_EQ(c.tensile, 1) << c.material;
  EXPECT_EQ(counts[0].shear + counts[1].shear, 0);
  EXPECT_EQ(counts[2].shear, 1);
  EXPECT_EQ(counts[0].bonds, bonds[material_rock]);
  EXPECT_EQ(counts[2].bonds, bonds[material_joint2]);
}

// The dip of a mesh's joints read back from its joint edges (what the failure classification of a user mesh uses).
TEST(JointSets, JointDipIsReadFromTheJointEdges) {
  for (double dip : {0.0, 30.0, 75.0, 90.0}) {
    const Topology<2> topo = build_topology(mesh_specimen(geometry(dip, 0.01), 0.0025), 1.0, 2700.0);
    EXPECT_NEAR(joint_dip_deg(describe(topo, nullptr, {}), -1.0), dip, 1e-6) << dip;
  }
  const Topology<2> intact = build_topology(mesh_specimen(geometry(0.0, 0.2, 0.1), 0.005), 1.0, 2700.0);
  EXPECT_EQ(joint_dip_deg(describe(intact, nullptr, {}), -1.0), -1.0);
}

}  // namespace
// The mesh cache (dem/mesh_cache.hpp) gives back the mesh gmsh made, every value equal; a damaged file is
// ignored and written anew; strength seeds share a mesh, another dip does not; a user mesh is never cached.
TEST(MeshCache, GivesBackTheSameMeshAndIgnoresDamagedFiles) {
  const auto dir = std::filesystem::temp_directory_path() / ("rbdem-mesh-cache-test-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  ::setenv("RBDEM_CACHE_DIR", dir.c_str(), 1);
  ::setenv("RBDEM_MESH_CACHE", "on", 1);
  Scene scene;
  scene.mesh.size = 0.004;
  auto equal = [](const TriMesh& a, const TriMesh& b) {
    bool same = a.nodes == b.nodes && a.triangles == b.triangles && a.layer == b.layer &&
                a.layer_names == b.layer_names && a.notes == b.notes && a.interfaces.size() == b.interfaces.size();
    for (std::size_t k = 0; same && k < a.interfaces.size(); ++k)
      same = a.interfaces[k].name == b.interfaces[k].name && a.interfaces[k].edges == b.interfaces[k].edges;
    return same;
  };
  const TriMesh fresh = make_mesh(scene);
  bool cached = true;
  EXPECT_TRUE(equal(make_mesh_cached(scene, &cached), fresh));
  EXPECT_FALSE(cached);
  const auto file = mesh_cache_file(scene);
  ASSERT_TRUE(std::filesystem::exists(file));
  EXPECT_TRUE(equal(make_mesh_cached(scene, &cached), fresh));
  EXPECT_TRUE(cached);

  Scene other_seed = scene;
  other_seed.mesh.strength_seed = 7;  // strengths, not the mesh
  EXPECT_EQ(mesh_cache_file(other_seed), file);
  Scene other_dip = scene;
  other_dip.joint_set.dip_deg = 30.0;
  EXPECT_NE(mesh_cache_file(other_dip), file);
  Scene structured = scene;  // another mesh; off, the key leaves it out (the files before it stay valid)
  structured.mesh.structured = true;
  EXPECT_NE(mesh_cache_file(structured), file);
  EXPECT_EQ(mesh_cache_key_text(scene).find("mesh.structured"), std::string::npos);

  {  // one byte changed in the middle: the checksum fails, the mesh is made again and the file rewritten
    std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(std::streamoff(std::filesystem::file_size(file) / 2));
    f.put('\x5a');
  }
  EXPECT_TRUE(equal(make_mesh_cached(scene, &cached), fresh));
  EXPECT_FALSE(cached);
  EXPECT_TRUE(equal(make_mesh_cached(scene, &cached), fresh));
  EXPECT_TRUE(cached);
  std::filesystem::resize_file(file, 100);  // cut short
  EXPECT_TRUE(equal(make_mesh_cached(scene, &cached), fresh));
  EXPECT_FALSE(cached);

  Scene user = scene;
  user.mesh.file = "any.msh";
  EXPECT_TRUE(mesh_cache_file(user).empty());
  ::setenv("RBDEM_MESH_CACHE", "off", 1);
  EXPECT_TRUE(mesh_cache_file(scene).empty());
  ::unsetenv("RBDEM_MESH_CACHE");
  ::unsetenv("RBDEM_CACHE_DIR");
  std::filesystem::remove_all(dir);
}

}  // namespace rbdem
