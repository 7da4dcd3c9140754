// The 3D scene (specimen.dimension = 3): its keys, the defaults that follow the dimension, the refusal of every key
// that has no meaning in the other dimension, and the specimen the scene gives (dem/specimen_mesh3.hpp).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include "compare/verify/verify.hpp"
#include "dem/scene.hpp"
#include "dem/specimen_mesh3.hpp"
#include "theory/elasticity3.hpp"

namespace rbdem {
namespace {

std::string fmt_node(int tag, double x, double y, double z) {
  char line[128];
  std::snprintf(line, sizeof line, "%d %.17g %.17g %.17g\n", tag, x, y, z);
  return line;
}

Scene solid(const std::string& more = "") { return parse_scene("[specimen]\ndimension = 3\n" + more, "3d"); }

// The message of the SceneError a scene text raises ("" when it parses).
std::string refusal(const std::string& toml) {
  try {
    parse_scene(toml, "bad");
  } catch (const SceneError& e) {
    return e.what();
  }
  return "";
}

TEST(Scene3, TwoDimensionsStayTheDefault) {
  const Scene s;
  EXPECT_EQ(s.specimen.dimension, 2);
  EXPECT_EQ(s.specimen.shape, "rectangle");
  EXPECT_EQ(s.mesh.size, 0.001);
  EXPECT_EQ(s.joint_set.dip_direction_deg, 0.0);
  EXPECT_EQ(parse_scene("[mesh]\nsize = 0.002\n").specimen.dimension, 2);
}

// A 3D scene that gives neither the shape nor the mesh size is the cylinder at 3 mm; both follow the dimension in
// whichever order the keys come (a TOML table is read in key order, --set in the order given).
TEST(Scene3, ShapeAndMeshSizeFollowTheDimension) {
  const Scene s = solid();
  EXPECT_EQ(s.specimen.shape, "cylinder");
  EXPECT_EQ(s.mesh.size, mesh3_default_size);
  EXPECT_EQ(s.specimen.diameter, 0.05);
  EXPECT_EQ(s.specimen.height, 0.10);
  EXPECT_EQ(s.specimen.depth, 0.05);

  const Scene p = parse_scene("[specimen]\nshape = \"prism\"\ndimension = 3\n[mesh]\nsize = 0.008\n");
  EXPECT_EQ(p.specimen.shape, "prism");
  EXPECT_EQ(p.mesh.size, 0.008);

  Scene o;
  apply_override(o, "mesh.size=0.005");
  apply_override(o, "specimen.dimension=3");
  EXPECT_EQ(o.specimen.shape, "cylinder");
  EXPECT_EQ(o.mesh.size, 0.005);
  apply_override(o, "specimen.dimension=2");  // back to the plane: its defaults again, the given size kept
  EXPECT_EQ(o.specimen.shape, "rectangle");
  EXPECT_EQ(o.mesh.size, 0.005);
}

// The printed scene reads back to the same scene (run folders keep it, --resume reads it).
TEST(Scene3, PrintedSceneRoundTrips) {
  const Scene s = solid("shape = \"prism\"\ndepth = 0.04\n[joint_set]\ndip_direction_deg = 30\n");
  const Scene back = parse_scene(to_toml(s), "printed");
  EXPECT_EQ(to_toml(back), to_toml(s));
  EXPECT_EQ(back.specimen.dimension, 3);
  EXPECT_EQ(back.specimen.depth, 0.04);
  EXPECT_EQ(back.joint_set.dip_direction_deg, 30.0);
  EXPECT_EQ(back.mesh.size, mesh3_default_size);
}

// Every refusal names the key and says what to do.
TEST(Scene3, KeysWithoutMeaningInThreeDimensionsAreRefused) {
  const std::string d3 = "[specimen]\ndimension = 3\n";
  const std::pair<std::string, std::string> cases[] = {
      {d3 + "shape = \"disc\"\n[mesh]\nsize = 0.03\n", "specimen.thickness"},
      {d3 + "shape = \"disc\"\ndiameter = 0.05\nthickness = 0.1\n[mesh]\nsize = 0.02\n", "mesh.size"},
      {d3 + "shape = \"rectangle\"\n", "specimen.shape"},
      {d3 + "model = \"plane_stress\"\n", "specimen.model"},
      {d3 + "thickness = 0.05\n", "specimen.thickness"},
      {d3 + "contact_arc_deg = 0\n", "specimen.contact_arc_deg"},
      {d3 + "[mesh]\nstructured = true\n", "mesh.structured"},
      {d3 + "[joint_set]\npersistence = 0.5\n", "joint_set.persistence"},
      {d3 + "[joint_set2]\nenabled = true\npersistence = 0.5\nspacing = 0.02\n", "joint_set2.persistence"},
      {d3 + "[beds]\npattern = [\"rock\", \"rock2\"]\n", "beds.pattern"},
      {d3 + "[rock2]\ngroups = \"layer_1\"\n", "rock2.groups"},
      {d3 + "[joint2]\ngroups = \"joint_1\"\n", "joint2.groups"},
      {d3 + "[mesh]\nsize = 0.02\n", "mesh.size"},
      {d3 + "shape = \"prism\"\ndepth = 0.02\n[mesh]\nsize = 0.006\n", "mesh.size"},
      {d3 + "[mesh]\nsize = 0.006\n[joint_set]\nspacing = 0.005\n", "joint_set.spacing"},
      {d3 + "[mesh]\nsize = 0.006\n[joint_set2]\nenabled = true\nspacing = 0.005\n", "joint_set2.spacing"},
      {"[specimen]\ndimension = 4\n", "specimen.dimension"},
      {"[specimen]\nshape = \"cylinder\"\n", "specimen.shape"},
      {"[specimen]\ndepth = 0.03\n", "specimen.depth"},
      {"[joint_set]\ndip_direction_deg = 45\n", "joint_set.dip_direction_deg"},
      {"[joint_set2]\ndip_direction_deg = 45\n", "joint_set2.dip_direction_deg"},
      {"[joint_set]\ndip_direction_deg = 400\n", "joint_set.dip_direction_deg"},
  };
  for (const auto& [toml, key] : cases) {
    const std::string why = refusal(toml);
    EXPECT_NE(why.find(key), std::string::npos) << toml << "\n-> " << why;
  }
  // What 3D does read is accepted: a prism with both sets turned.
  EXPECT_EQ(refusal(d3 + "shape = \"prism\"\n[joint_set]\ndip_direction_deg = -90\n[joint_set2]\nenabled = true\n"
                         "dip_deg = 120\ndip_direction_deg = 350\nspacing = 0.02\n"),
            "");
}

// The specimen the scene gives: shape and sizes, each set's dip, dip direction (modulo 360) and spacing; a second
// set dipping past 90 deg is the same plane at 180 - dip with the dip direction turned by 180 deg.
TEST(Scene3, GeometryIsTheScenes) {
  const Scene s = solid("shape = \"prism\"\nwidth = 0.04\ndepth = 0.03\nheight = 0.08\n"
                        "[joint_set]\ndip_deg = 30\ndip_direction_deg = -90\nspacing = 0.012\noffset = 0.001\n"
                        "[joint_set2]\nenabled = true\ndip_deg = 120\ndip_direction_deg = 10\nspacing = 0.02\n");
  const SpecimenGeometry3 g = specimen_geometry3(s);
  EXPECT_EQ(g.shape, Shape3::prism);
  EXPECT_EQ(g.width, 0.04);
  EXPECT_EQ(g.depth, 0.03);
  EXPECT_EQ(g.height, 0.08);
  EXPECT_TRUE(g.joints);
  EXPECT_EQ(g.set1.dip_deg, 30.0);
  EXPECT_EQ(g.set1.dip_direction_deg, 270.0);
  EXPECT_EQ(g.set1.spacing, 0.012);
  EXPECT_EQ(g.set1.offset, 0.001);
  ASSERT_TRUE(g.second_set);
  EXPECT_DOUBLE_EQ(g.set2.dip_deg, 60.0);
  EXPECT_DOUBLE_EQ(g.set2.dip_direction_deg, 190.0);
  // The second set's normal is the one of dip 120 at dip direction 10 (up to its sign).
  const double d = 120 * std::numbers::pi / 180, a = 10 * std::numbers::pi / 180;
  const std::array<double, 3> n{-std::sin(d) * std::cos(a), -std::sin(d) * std::sin(a), std::cos(d)};
  const auto m = g.set2.normal();
  EXPECT_NEAR(std::abs(n[0] * m[0] + n[1] * m[1] + n[2] * m[2]), 1.0, 1e-12);

  const SpecimenGeometry3 c = specimen_geometry3(solid("[joint_set]\nenabled = false\n"));
  EXPECT_EQ(c.shape, Shape3::cylinder);
  EXPECT_FALSE(c.joints);
  EXPECT_FALSE(c.second_set);
  EXPECT_THROW(specimen_geometry3(Scene{}), SceneError);
  const Scene user = solid("[mesh]\nfile = \"no_such_file.msh\"\n");
  try {
    mesh_scene3(user);
    ADD_FAILURE() << "a missing mesh file was read";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("no_such_file.msh"), std::string::npos) << e.what();
  }
}

// The scene's mesh: a coarse prism of the scene's size, joints as the scene's dip gives them (a joint face has
// different layers on its two sides, so the layers count the planes).
TEST(Scene3, MeshIsTheScenesSpecimen) {
  const Scene s = solid("shape = \"prism\"\n[mesh]\nsize = 0.01\n[joint_set]\ndip_deg = 0\nspacing = 0.025\n");
  const TetMesh m = mesh_scene3(s);
  double vol = 0, zmax = 0;
  for (std::size_t t = 0; t < m.num_tets(); ++t) vol += tet_volume(m, t);
  for (const auto& p : m.nodes) zmax = std::max(zmax, p[2]);
  EXPECT_NEAR(vol, 0.05 * 0.05 * 0.10, 1e-12);
  EXPECT_NEAR(zmax, 0.10, 1e-12);
  // Horizontal planes through the centre, 25 mm apart, in a 100 mm prism: z = 25, 50, 75 mm, four layers.
  EXPECT_EQ(m.num_layers(), 4u);
}

// Two stacked cubes of side a, each cut into the six tetrahedra of Kuhn's subdivision (the same diagonal on the
// shared face from both sides), as a gmsh MSH 2.2 file with the physical volumes "lower" and "upper".
std::string two_cubes_msh(double a) {
  std::string s = "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n2\n3 1 \"lower\"\n3 2 \"upper\"\n"
                  "$EndPhysicalNames\n$Nodes\n12\n";
  auto node = [](int i, int j, int k) { return 1 + i + 2 * j + 4 * k; };  // gmsh node tags from 1
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) s += fmt_node(node(i, j, k), a * i, a * j, a * k);
  s += "$EndNodes\n$Elements\n12\n";
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  int id = 1;
  for (int cube = 0; cube < 2; ++cube)
    for (const auto& p : perms) {
      int x[3] = {0, 0, cube};
      std::string line = std::to_string(id++) + " 4 2 " + std::to_string(cube + 1) + " " + std::to_string(cube + 1);
      line += " " + std::to_string(node(x[0], x[1], x[2]));
      for (int step = 0; step < 3; ++step) {
        ++x[p[step]];
        line += " " + std::to_string(node(x[0], x[1], x[2]));
      }
      s += line + "\n";
    }
  return s + "$EndElements\n";
}

// A user mesh in 3D: one layer per physical volume, named as the file names them, the faces between the layers
// joints, the surface tagged for the platens; Kuhn's tetrahedra of either orientation turned positive.
TEST(Scene3, UserMeshWithTetrahedra) {
  const double a = 0.02;
  const auto dir = std::filesystem::temp_directory_path() / "rbdem_test_scene3";
  std::filesystem::create_directories(dir);
  const auto file = dir / "two_cubes.msh";
  std::ofstream(file) << two_cubes_msh(a);
  const Scene s = solid("[mesh]\nfile = \"" + file.string() + "\"\n");
  const TetMesh m = mesh_scene3(s);
  ASSERT_EQ(m.num_tets(), 12u);
  EXPECT_EQ(m.num_nodes(), 12u);
  ASSERT_EQ(m.num_layers(), 2u);
  EXPECT_EQ(m.layer_names[0], "lower");
  EXPECT_EQ(m.layer_names[1], "upper");
  double vol = 0;
  for (std::size_t t = 0; t < m.num_tets(); ++t) {
    EXPECT_GT(tet_volume(m, t), 0.0) << "tet " << t;
    vol += tet_volume(m, t);
  }
  EXPECT_NEAR(vol, 2 * a * a * a, 1e-15);
  const TetMeshReport r = report(m);
  EXPECT_EQ(r.joint_faces, 2u);  // the shared square, two triangles
  EXPECT_EQ(r.rock_faces, 12u);  // six inner faces in each cube's Kuhn subdivision
  EXPECT_EQ(r.bottom_faces, 2u);
  EXPECT_EQ(r.top_faces, 2u);
  EXPECT_EQ(r.lateral_faces, 16u);

  // No physical volume: refused, naming the file.
  const auto bare = dir / "no_volumes.msh";
  std::string text = two_cubes_msh(a);
  text.replace(text.find("$PhysicalNames"), text.find("$Nodes") - text.find("$PhysicalNames"), "");
  for (std::size_t at = text.find(" 4 2 "); at != std::string::npos; at = text.find(" 4 2 ", at + 1))
    text.replace(at + 5, 1, "0");  // physical tag 0: none
  std::ofstream(bare) << text;
  try {
    mesh_scene3(solid("[mesh]\nfile = \"" + bare.string() + "\"\n"));
    ADD_FAILURE() << "a mesh without physical volumes was read";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("physical volume"), std::string::npos) << e.what();
  }
}

// `rbdem verify` runs the 3D paper scene from its own copy of the keys (an installed binary has no scenes/):
// it must be the shipped scenes/cylinder.toml, key for key.
TEST(Verify3, CylinderSceneIsTheShippedOne) {
  const Scene shipped = load_scene_file(std::filesystem::path(RBDEM_SOURCE_DIR) / "scenes" / "cylinder.toml");
  EXPECT_EQ(to_toml(verify::cylinder_scene()), to_toml(shipped));
}

}  // namespace
}  // namespace rbdem
