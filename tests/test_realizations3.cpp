// 3D mesh realizations (mesh.seed on a 3D scene; dem/specimen_mesh3.hpp, mesh_specimen3): a nonzero seed gives
// another tetrahedral mesh of the same solid and the same joint planes, of the same size and quality; the same seed
// gives the same mesh bit for bit, and seed 0 is the reference mesh.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <set>

#include "dem/mesh_cache.hpp"
#include "dem/scene.hpp"
#include "dem/specimen_mesh3.hpp"

namespace rbdem {
namespace {

using Vec = std::array<double, 3>;

double face_area(const TetMesh& m, const std::array<int, 3>& f) {
  const Vec& a = m.nodes[f[0]];
  const Vec u{m.nodes[f[1]][0] - a[0], m.nodes[f[1]][1] - a[1], m.nodes[f[1]][2] - a[2]};
  const Vec v{m.nodes[f[2]][0] - a[0], m.nodes[f[2]][1] - a[1], m.nodes[f[2]][2] - a[2]};
  const Vec c{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  return 0.5 * std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]);
}

// The nodes of `b` that are also (to the bit) nodes of `a`.
std::size_t shared_nodes(const TetMesh& a, const TetMesh& b) {
  const std::set<Vec> in_a(a.nodes.begin(), a.nodes.end());
  std::size_t n = 0;
  for (const auto& p : b.nodes) n += in_a.count(p);
  return n;
}

// The paper's cylinder (joints every 10 mm dipping 60 deg) at 10 mm tetrahedra, meshed once per seed.
constexpr double h = 0.01;
SpecimenGeometry3 paper_cylinder() {
  SpecimenGeometry3 g;
  g.set1 = {60.0, 0.0, 0.01, 0.0};
  return g;
}
const TetMesh& paper_mesh(int seed) {
  static std::map<int, TetMesh> cache;
  auto it = cache.find(seed);
  if (it == cache.end()) it = cache.emplace(seed, mesh_specimen3(paper_cylinder(), h, seed)).first;
  return it->second;
}

// Seeds 1 and 2 move every node but the geometry's own vertices (the ends of the curves: where joint planes meet
// the rims and one another), so the meshes share few nodes; they keep gmsh's size, so the block count stays near
// the reference mesh's (within 1 % at 8 mm for seeds 1-4; 10 % asked here); each faceted cylinder still lies
// inside the solid within the chords' error, as seed 0's.
TEST(Realizations3, SeedsGiveDifferentMeshesOfTheSameSolid) {
  const SpecimenGeometry3 g = paper_cylinder();
  const TetMesh& ref = paper_mesh(0);
  const TetMeshReport r0 = report(ref);
  const double R = 0.5 * g.diameter, exact = g.volume();
  for (const int seed : {1, 2}) {
    SCOPED_TRACE(seed);
    const TetMesh& m = paper_mesh(seed);
    const TetMeshReport r = report(m);
    EXPECT_LT(double(shared_nodes(ref, m)), 0.1 * double(m.nodes.size()));
    EXPECT_NEAR(double(r.tets), double(r0.tets), 0.1 * double(r0.tets));
    EXPECT_EQ(r.layers, r0.layers);
    EXPECT_LE(r.volume, exact * (1 + 1e-12));
    EXPECT_GE(r.volume, exact * (1 - std::pow(1.5 * h / R, 2) / 6));
    EXPECT_GT(r.min_dihedral_deg, 0.0);
  }
  EXPECT_LT(double(shared_nodes(paper_mesh(1), paper_mesh(2))), 0.1 * double(ref.nodes.size()));
}

// The joint planes are the same planes on every realization: on the prism, whose sections are exact rectangles,
// the joint faces of each seed tile the three planes inside it, 3 W B / cos(30 deg), and the volume is W B H.
TEST(Realizations3, JointPlanesAndVolumeAreTheSameOnEverySeed) {
  SpecimenGeometry3 g;
  g.shape = Shape3::prism;
  g.set1 = {30.0, 0.0, 0.03, 0.0};
  const double want = 3 * g.width * g.depth / std::cos(30.0 * std::numbers::pi / 180);
  for (const int seed : {0, 3, 4}) {
    SCOPED_TRACE(seed);
    const TetMesh m = mesh_specimen3(g, 0.008, seed);
    double joint_area = 0;
    for (const auto& f : shared_faces(m))
      if (f.joint) joint_area += face_area(m, f.nodes);
    EXPECT_NEAR(joint_area, want, 1e-12);
    EXPECT_NEAR(report(m).volume, g.volume(), 1e-12 * g.volume());
  }
}

// The same seed gives the same mesh bit for bit (gmsh meshes on one thread; the grading's random numbers are
// mt19937_64's, the same on every platform).
TEST(Realizations3, SameSeedGivesTheSameMeshBitForBit) {
  const TetMesh again = mesh_specimen3(paper_cylinder(), h, 1);
  EXPECT_EQ(again.nodes, paper_mesh(1).nodes);
  EXPECT_EQ(again.tets, paper_mesh(1).tets);
  EXPECT_EQ(again.layer, paper_mesh(1).layer);
}

// A 3D scene takes mesh.seed (it was refused before realizations existed in 3D) and its mesh is the seeded one.
TEST(Realizations3, SceneSeedReachesTheMesh) {
  const Scene s = parse_scene("[specimen]\ndimension = 3\n[mesh]\nsize = 0.01\nseed = 2\n[joint_set]\nspacing = 0.01\n",
                              "3d");
  EXPECT_EQ(s.mesh.seed, 2);
  const TetMesh m = mesh_scene3(s);
  EXPECT_EQ(m.nodes, paper_mesh(2).nodes);
  EXPECT_EQ(m.tets, paper_mesh(2).tets);
}

// The mesh cache keeps 3D meshes as it keeps 2D ones (dem/mesh_cache.hpp): the cached mesh is the mesh gmsh made,
// every value equal; each seed is a file of its own; a damaged file is ignored and written anew.
TEST(Realizations3, MeshCacheGivesBackTheSeededMesh) {
  const auto dir = std::filesystem::temp_directory_path() / ("rbdem-mesh3-cache-test-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  ::setenv("RBDEM_CACHE_DIR", dir.c_str(), 1);
  ::setenv("RBDEM_MESH_CACHE", "on", 1);
  Scene scene = parse_scene("[specimen]\ndimension = 3\n[mesh]\nsize = 0.01\nseed = 1\n", "3d");
  const TetMesh& fresh = paper_mesh(1);
  auto equal = [](const TetMesh& a, const TetMesh& b) {
    bool same = a.nodes == b.nodes && a.tets == b.tets && a.layer == b.layer && a.layer_names == b.layer_names &&
                a.layer_rows == b.layer_rows && a.notes == b.notes && a.boundary.size() == b.boundary.size();
    for (std::size_t k = 0; same && k < a.boundary.size(); ++k)
      same = a.boundary[k].nodes == b.boundary[k].nodes && a.boundary[k].tet == b.boundary[k].tet &&
             a.boundary[k].tag == b.boundary[k].tag;
    return same;
  };
  bool cached = true;
  EXPECT_TRUE(equal(make_mesh3_cached(scene, &cached), fresh));
  EXPECT_FALSE(cached);
  const auto file = mesh_cache_file(scene);
  ASSERT_TRUE(std::filesystem::exists(file));
  EXPECT_TRUE(equal(make_mesh3_cached(scene, &cached), fresh));
  EXPECT_TRUE(cached);
  Scene other = scene;
  other.mesh.seed = 2;
  EXPECT_NE(mesh_cache_file(other), file);
  {  // one byte changed in the middle: the checksum fails, the mesh is made again
    std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(std::streamoff(std::filesystem::file_size(file) / 2));
    f.put('\x5a');
  }
  EXPECT_TRUE(equal(make_mesh3_cached(scene, &cached), fresh));
  EXPECT_FALSE(cached);
  ::unsetenv("RBDEM_MESH_CACHE");
  ::unsetenv("RBDEM_CACHE_DIR");
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace rbdem
