// Beds of two rocks by position along the joint normal ([beds], dem/materials.hpp): the same physical beds at every
// dip, the bed sequence's arithmetic, the scene's checks, and rock2.groups errors that name the dip.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "dem/materials.hpp"
#include "dem/scene.hpp"
#include "dem/specimen_mesh.hpp"
#include "dem/topology.hpp"

namespace rbdem {
namespace {

Scene bedded_scene() {
  Scene scene;
  scene.mesh.size = 0.0025;
  scene.joint_set.spacing = 0.01;
  scene.beds.pattern = "rock, rock2";
  return scene;
}

// The material of the block whose centroid is nearest to (x, y).
std::uint8_t material_at(const Topology<2>& topo, const MaterialMap& m, double x, double y) {
  std::size_t best = 0;
  double d2 = 1e300;
  for (std::size_t b = 0; b < topo.blocks.size(); ++b) {
    const double d = std::pow(topo.blocks.cx[b] - x, 2) + std::pow(topo.blocks.cy[b] - y, 2);
    if (d < d2) d2 = d, best = b;
  }
  return m.block[best];
}

// The specimen (50 x 100 mm) meshed at 0, 30, 60 and 90 deg: the points at the middle of beds -2 .. 1 along the
// normal through the centre (-15, -5, 5, 15 mm: one joint spacing apart, bed 0 just above the joint through the centre) lie in the
// same rock at every dip, alternating rock, rock2 as the pattern says; every rock bond inside a layer has its
// layer's rock, and both rocks are present.
TEST(Beds, SameRockAtTheSamePositionAtEveryDip) {
  const Scene base = bedded_scene();
  std::vector<std::vector<std::uint8_t>> sequences;
  for (const double dip : {0.0, 30.0, 60.0, 90.0}) {
    Scene scene = base;
    scene.joint_set.dip_deg = dip;
    const Topology<2> topo = build_topology(make_mesh(scene), 1.0, scene.rock.density);
    const MaterialMap m = assign_materials(topo, scene);
    const double beta = dip * std::numbers::pi / 180.0, nx = -std::sin(beta), ny = std::cos(beta);
    const double cx = 0.5 * (topo.xmin + topo.xmax), cy = 0.5 * (topo.ymin + topo.ymax);
    std::vector<std::uint8_t> seq;
    for (int k = -2; k <= 1; ++k) {
      const double s = (k + 0.5) * scene.joint_set.spacing;
      seq.push_back(material_at(topo, m, cx + s * nx, cy + s * ny));
      EXPECT_EQ(seq.back(), (k % 2 == 0) ? material_rock : material_rock2) << "dip " << dip << ", bed " << k;
    }
    sequences.push_back(seq);
    std::size_t rock = 0, rock2 = 0;
    for (std::size_t b = 0; b < topo.bonds.size(); ++b)
      if (topo.bonds.kind[b] == BondKind::rock) {
        EXPECT_EQ(m.bond[b], m.block[std::size_t(topo.bonds.j[b])]) << "dip " << dip;
        (m.bond[b] == material_rock2 ? rock2 : rock) += 1;
      }
    EXPECT_GT(rock, 0u);
    EXPECT_GT(rock2, 0u);
  }
  for (const auto& seq : sequences) EXPECT_EQ(seq, sequences.front());
}

// Thicknesses and an origin: the pattern repeats with the period sum(thickness) from joint_set.offset + origin.
TEST(Beds, ThicknessesAndOriginPlaceEachBed) {
  Scene scene;
  scene.beds.pattern = "rock, rock2";
  scene.beds.thickness = "0.005, 0.01";
  scene.beds.origin = 0.002;
  const BedSequence beds = bed_sequence(scene);
  ASSERT_EQ(beds.rock2.size(), 2u);
  EXPECT_DOUBLE_EQ(beds.period(), 0.015);
  EXPECT_EQ(beds.bed_at(0.003), 0u);     // 0.001 into the period
  EXPECT_EQ(beds.bed_at(0.008), 1u);     // 0.006
  EXPECT_EQ(beds.bed_at(0.0165), 1u);    // 0.0145
  EXPECT_EQ(beds.bed_at(0.0175), 0u);    // 0.0005 into the next period
  EXPECT_EQ(beds.bed_at(-0.001), 1u);    // 0.012 into the period before
  scene.joint_set.offset = 0.001;        // the beds move with the joints
  EXPECT_EQ(bed_sequence(scene).bed_at(0.0035), 0u);
  EXPECT_EQ(bed_sequence(scene).bed_at(0.0085), 1u);
  EXPECT_FALSE(uses_rock2(Scene{}));
  EXPECT_TRUE(uses_rock2(scene));
}

// A TOML array is the same as the comma separated list, and the scene round-trips through its TOML.
TEST(Beds, TomlArrayIsTheList) {
  const Scene a = parse_scene("[beds]\npattern = [\"rock\", \"rock2\", \"rock2\"]\nthickness = [0.01, 0.005, 0.005]\n");
  EXPECT_EQ(a.beds.pattern, "rock, rock2, rock2");
  EXPECT_EQ(a.beds.thickness, "0.01, 0.005, 0.005");
  const Scene b = parse_scene(to_toml(a));
  EXPECT_EQ(b.beds.pattern, a.beds.pattern);
  EXPECT_EQ(bed_sequence(b).thickness, bed_sequence(a).thickness);
}

void expect_scene_error(const std::string& toml, const std::vector<std::string>& fragments) {
  try {
    parse_scene(toml);
    ADD_FAILURE() << "accepted:\n" << toml;
  } catch (const SceneError& e) {
    for (const auto& f : fragments) EXPECT_NE(std::string(e.what()).find(f), std::string::npos) << e.what();
  }
}

TEST(Beds, BadInputsNameTheKeyAndTheFix) {
  expect_scene_error("[beds]\npattern = [\"rock\", \"shale\"]\n", {"beds.pattern", "'shale'", "rock2"});
  expect_scene_error("[beds]\npattern = [\"rock\", \"rock2\"]\nthickness = [0.01]\n",
                     {"beds.thickness", "differ in length", "2 beds"});
  expect_scene_error("[beds]\npattern = [\"rock\", \"rock2\"]\nthickness = [0.01, -0.01]\n",
                     {"beds.thickness", "'-0.01'", "positive"});
  expect_scene_error("[beds]\nthickness = [0.01]\n", {"beds.thickness", "beds.pattern"});
  expect_scene_error("[rock2]\ngroups = \"layer_1\"\n[beds]\npattern = [\"rock\", \"rock2\"]\n",
                     {"rock2.groups", "beds.pattern", "keep one"});
  expect_scene_error("[joint_set]\nenabled = false\n[beds]\npattern = [\"rock\", \"rock2\"]\n",
                     {"beds.pattern", "joint_set.enabled = false"});
  expect_scene_error("[joint_set]\npersistence = 0.8\njoint_length = 0.02\n[beds]\npattern = [\"rock\", \"rock2\"]\n",
                     {"beds.pattern", "persistence"});
}

// rock2.groups by layer number breaks across dips: the error names the dip of the mesh and points at beds.pattern.
TEST(Beds, LayerNamesTheMeshLacksNameTheDip) {
  Scene scene;
  scene.mesh.size = 0.0025;
  scene.joint_set.dip_deg = 90.0;  // 5 layers across the 50 mm width
  scene.rock2.groups = "layer_1, layer_11";
  const Topology<2> topo = build_topology(make_mesh(scene), 1.0, scene.rock.density);
  try {
    assign_materials(topo, scene);
    ADD_FAILURE() << "layer_11 accepted at 90 deg";
  } catch (const SceneError& e) {
    const std::string what = e.what();
    for (const char* f : {"rock2.groups", "'layer_11'", "joint_set.dip_deg = 90 deg", "beds.pattern"})
      EXPECT_NE(what.find(f), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace rbdem
