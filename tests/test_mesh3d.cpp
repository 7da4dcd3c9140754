// The 3D specimen's tetrahedral mesh (dem/specimen_mesh3.hpp, mesh/tetmesh.hpp): volume against the solid's,
// joints against their planes (position and area), layers that change only across joint faces, the surface tags,
// the quality report, determinism and the errors a user can cause.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <tuple>

#include "dem/scene.hpp"
#include "dem/specimen_mesh3.hpp"

namespace rbdem {
namespace {

using Vec = std::array<double, 3>;

Vec sub(const Vec& a, const Vec& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot(const Vec& a, const Vec& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double face_area(const TetMesh& m, const std::array<int, 3>& f) {
  const Vec u = sub(m.nodes[f[1]], m.nodes[f[0]]), v = sub(m.nodes[f[2]], m.nodes[f[0]]);
  const Vec c{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
  return 0.5 * std::sqrt(dot(c, c));
}

SpecimenGeometry3 cylinder(double dip, double dip_direction, double spacing) {
  SpecimenGeometry3 g;
  g.set1 = {dip, dip_direction, spacing, 0.0};
  return g;
}

// A 50 x 50 x 100 mm prism cut by three planes dipping 30 deg, 30 mm apart: each lies wholly inside (it meets
// neither the top nor the bottom), so each section is the rectangle W x B / cos(dip).
SpecimenGeometry3 prism30() {
  SpecimenGeometry3 g;
  g.shape = Shape3::prism;
  g.set1 = {30.0, 0.0, 0.03, 0.0};
  return g;
}

const TetMesh& meshed(const SpecimenGeometry3& g, double h) {
  static std::map<std::tuple<int, double, double, double, double>, TetMesh> cache;
  const auto key = std::make_tuple(int(g.shape), g.set1.dip_deg, g.set1.dip_direction_deg, g.set1.spacing, h);
  auto it = cache.find(key);
  if (it == cache.end()) it = cache.emplace(key, mesh_specimen3(g, h)).first;
  return it->second;
}

// Every node of a shared face lies on one joint plane.
bool on_a_plane(const TetMesh& m, const std::array<int, 3>& f, const std::vector<JointPlane>& planes, const Vec& c,
                double tol) {
  for (const auto& p : planes) {
    bool all = true;
    for (int v : f) all = all && std::abs(dot(p.normal, sub(m.nodes[v], c)) - p.r) < tol;
    if (all) return true;
  }
  return false;
}

// The faceted cylinder lies inside the solid (every node on or in it, every lateral face a chord of the convex
// surface), so its volume is at most pi R^2 H and falls short by at most the segments cut off by chords of the
// circle: a fraction (a/R)^2 / 6 for chords a, bounded here by a = 1.5 h.
TEST(Mesh3D, CylinderVolumeIsTheSolidsToTheFacetingError) {
  const double h = 0.006;
  const SpecimenGeometry3 g = cylinder(60.0, 30.0, 0.02);
  const TetMeshReport r = report(meshed(g, h));
  const double R = 0.5 * g.diameter, exact = g.volume();
  EXPECT_LE(r.volume, exact * (1 + 1e-12));
  EXPECT_GE(r.volume, exact * (1 - std::pow(1.5 * h / R, 2) / 6));
  EXPECT_GT(r.min_dihedral_deg, 0.0);
}

TEST(Mesh3D, PrismVolumeAndPlatenAreasAreExact) {
  const SpecimenGeometry3 g = prism30();
  const TetMesh& m = meshed(g, 0.006);
  EXPECT_NEAR(report(m).volume, g.volume(), 1e-12 * g.volume());
  double top = 0, bottom = 0;
  for (const auto& f : m.boundary) {
    if (f.tag == FaceTag::top) top += face_area(m, f.nodes);
    if (f.tag == FaceTag::bottom) bottom += face_area(m, f.nodes);
  }
  EXPECT_NEAR(top, g.width * g.depth, 1e-12);
  EXPECT_NEAR(bottom, g.width * g.depth, 1e-12);
}

// Joint faces lie on the planes and cover each plane's section once: their area is 3 W B / cos(30 deg). A face
// with all three nodes on a plane is a joint face, so the layer id changes across exactly the joint faces.
TEST(Mesh3D, JointFacesTileTheJointPlanesAndLayersChangeOnlyAcrossThem) {
  const SpecimenGeometry3 g = prism30();
  const TetMesh& m = meshed(g, 0.006);
  const auto planes = joint_planes(g, 0.003);
  ASSERT_EQ(planes.size(), 3u);
  EXPECT_EQ(m.num_layers(), 4u);
  const double tol = 1e-9;
  double joint_area = 0;
  std::size_t joints = 0;
  for (const auto& f : shared_faces(m)) {
    EXPECT_EQ(f.joint, m.layer[f.tets[0]] != m.layer[f.tets[1]]);
    EXPECT_EQ(f.joint, on_a_plane(m, f.nodes, planes, g.centre(), tol));
    if (f.joint) joint_area += face_area(m, f.nodes), ++joints;
  }
  EXPECT_GT(joints, 0u);
  EXPECT_NEAR(joint_area, 3 * g.width * g.depth / std::cos(30.0 * std::numbers::pi / 180), 1e-12);
}

// The same on the cylinder with a dip direction that turns the strike off both axes, and a second set.
TEST(Mesh3D, CylinderJointFacesLieOnTheirPlanesAtAnyDipDirection) {
  SpecimenGeometry3 g = cylinder(45.0, 30.0, 0.025);
  g.second_set = true;
  g.set2 = {70.0, 120.0, 0.03, 0.004};
  const TetMesh m = mesh_specimen3(g, 0.008);
  const auto planes = joint_planes(g, 0.004);
  std::vector<JointPlane> set1, set2;
  for (const auto& p : planes) (p.set == 0 ? set1 : set2).push_back(p);
  std::array<std::size_t, 2> joints{0, 0};
  for (const auto& f : shared_faces(m)) {
    EXPECT_EQ(f.joint, on_a_plane(m, f.nodes, planes, g.centre(), 1e-9));
    // The set a joint face is given is the set whose plane it lies on.
    if (f.set >= 0) {
      EXPECT_TRUE(on_a_plane(m, f.nodes, f.set == 0 ? set1 : set2, g.centre(), 1e-9));
    }
    if (f.joint) ++joints[std::size_t(f.set)];
  }
  EXPECT_GT(joints[0], 0u);
  EXPECT_GT(joints[1], 0u);
  EXPECT_GT(m.num_layers(), planes.size() + 1);  // crossing sets cut more pieces than parallel planes would
}

// Without joints the specimen is one layer: every shared face is rock.
TEST(Mesh3D, WithoutJointsTheSpecimenIsOneLayer) {
  SpecimenGeometry3 g = cylinder(60.0, 0.0, 0.02);
  g.joints = false;
  const TetMeshReport r = report(mesh_specimen3(g, 0.01));
  EXPECT_EQ(r.layers, 1u);
  EXPECT_EQ(r.joint_faces, 0u);
  EXPECT_GT(r.rock_faces, 0u);
}

// Every face of a tetrahedron is shared or on the surface; the surface is bottom and top (flat) and lateral.
TEST(Mesh3D, FacesAreSharedOrOnTheTaggedSurface) {
  const TetMesh& m = meshed(cylinder(60.0, 0.0, 0.02), 0.006);
  const TetMeshReport r = report(m);
  EXPECT_EQ(4 * r.tets, 2 * (r.rock_faces + r.joint_faces) + m.boundary.size());
  EXPECT_GT(r.bottom_faces, 0u);
  EXPECT_GT(r.top_faces, 0u);
  EXPECT_GT(r.lateral_faces, 0u);
  for (const auto& f : m.boundary) {
    const double R = 0.025;
    for (int v : f.nodes) {
      const auto& p = m.nodes[v];
      if (f.tag == FaceTag::bottom) {
        EXPECT_EQ(p[2], 0.0);
      } else if (f.tag == FaceTag::top) {
        EXPECT_EQ(p[2], 0.1);
      } else {
        EXPECT_NEAR(std::hypot(p[0] - R, p[1] - R), R, 1e-9);
      }
    }
  }
  for (std::size_t t = 0; t < m.num_tets(); ++t) ASSERT_GT(tet_volume(m, t), 0.0);
}

// The quality measures on known tetrahedra: the regular one (70.53 deg, ratio 1) and a flat sliver.
TEST(Mesh3D, QualityMeasuresOfKnownTetrahedra) {
  TetMesh m;
  m.nodes = {{1, 1, 1}, {1, -1, -1}, {-1, 1, -1}, {-1, -1, 1}, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 1, 1e-3}};
  m.tets = {{0, 1, 2, 3}, {4, 5, 6, 7}};
  if (tet_volume(m, 0) < 0) std::swap(m.tets[0][2], m.tets[0][3]);
  EXPECT_NEAR(min_dihedral_deg(m, 0), std::acos(1.0 / 3) * 180 / std::numbers::pi, 1e-10);
  EXPECT_NEAR(radius_ratio(m, 0), 1.0, 1e-12);
  EXPECT_LT(min_dihedral_deg(m, 1), 1.0);
  EXPECT_LT(radius_ratio(m, 1), 0.01);
}

TEST(Mesh3D, SameInputsGiveTheSameMeshBitForBit) {
  const SpecimenGeometry3 g = cylinder(30.0, 45.0, 0.02);
  const TetMesh a = mesh_specimen3(g, 0.01), b = mesh_specimen3(g, 0.01);
  EXPECT_EQ(a.nodes, b.nodes);
  EXPECT_EQ(a.tets, b.tets);
  EXPECT_EQ(a.layer, b.layer);
}

TEST(Mesh3D, BadInputNamesTheKeyAndTheFix) {
  auto message = [](const SpecimenGeometry3& g, double h) {
    try {
      mesh_specimen3(g, h);
    } catch (const SceneError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(cylinder(60, 0, 0.004), 0.005).find("joint_set.spacing"), std::string::npos);
  SpecimenGeometry3 g = cylinder(60, 0, 0.02);
  g.diameter = -0.05;
  EXPECT_NE(message(g, 0.005).find("specimen.diameter"), std::string::npos);
  EXPECT_NE(message(cylinder(60, 0, 0.02), 0.0).find("mesh.size"), std::string::npos);
  EXPECT_NE(message(cylinder(120, 0, 0.02), 0.005).find("dip_deg"), std::string::npos);
}

// A plane that would shave off a cap thinner than the limit is left out, and the note says how to keep it.
TEST(Mesh3D, ThinCapPlanesAreLeftOutWithANote) {
  SpecimenGeometry3 g = cylinder(0.0, 0.0, 0.0499);  // planes at z = 50 mm and 0.1 mm from the top and bottom
  std::vector<std::string> notes;
  const auto planes = joint_planes(g, 0.002, &notes);
  EXPECT_EQ(planes.size(), 1u);
  ASSERT_EQ(notes.size(), 2u);
  EXPECT_NE(notes[0].find("offset"), std::string::npos);
}

}  // namespace
}  // namespace rbdem
