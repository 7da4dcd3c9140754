// Scene files: defaults, the shipped paper scene, overrides, and rejection of every kind of bad value.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "dem/scene.hpp"

namespace rbdem {
namespace {

const std::string source_dir = RBDEM_SOURCE_DIR;

TEST(Scene, ShippedPaperSceneEqualsBuiltInDefaults) {
  const Scene file = load_scene_file(source_dir + "/scenes/paper.toml");
  const Scene defaults;
  for (const auto& p : scene_parameters())
    EXPECT_EQ(parameter_text(file, p.key), parameter_text(defaults, p.key)) << p.key;
}

TEST(Scene, EveryKeyHasUnitDocAndValidDefault) {
  const Scene defaults;
  EXPECT_NO_THROW(validate(defaults));
  for (const auto& p : scene_parameters()) {
    EXPECT_FALSE(p.unit.empty()) << p.key;
    EXPECT_FALSE(p.doc.empty()) << p.key;
    EXPECT_NE(p.key.find('.'), std::string::npos) << p.key;
  }
}

TEST(Scene, PrintedSceneParsesBackToTheSameValues) {
  Scene s;
  set_parameter(s, "joint_set.dip_deg", "37.5");
  set_parameter(s, "rock.cohesion", "1.234567e7");
  set_parameter(s, "specimen.model", "plane_stress");
  const Scene back = parse_scene(to_toml(s), "printed");
  for (const auto& p : scene_parameters()) EXPECT_EQ(parameter_text(back, p.key), parameter_text(s, p.key)) << p.key;
}

TEST(Scene, SetOverridesOneKey) {
  Scene s;
  apply_override(s, "rock.cohesion=20e6");
  apply_override(s, " joint_set.dip_deg = 45 ");
  apply_override(s, "specimen.model=\"plane_stress\"");
  EXPECT_DOUBLE_EQ(s.rock.cohesion, 20e6);
  EXPECT_DOUBLE_EQ(s.joint_set.dip_deg, 45.0);
  EXPECT_EQ(s.specimen.model, "plane_stress");
}

TEST(Scene, JsonHoldsEverySection) {
  const auto j = scene_json(Scene{});
  for (const char* key : {"specimen", "joint_set", "mesh", "rock", "joint", "loading", "numerics", "elastic"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_DOUBLE_EQ(j["joint_set"]["dip_deg"].get<double>(), Scene{}.joint_set.dip_deg);
}

TEST(Scene, UnknownKeySuggestsTheNearestOne) {
  try {
    parse_scene("[rock]\ncohesoin = 1e6\n", "t.toml");
    FAIL() << "no error";
  } catch (const SceneError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("rock.cohesoin"), std::string::npos) << m;
    EXPECT_NE(m.find("rock.cohesion"), std::string::npos) << m;
  }
}

// Each bad value must be rejected with a message that names the key and the offending value.
struct BadValue {
  std::string toml;       // scene text
  std::string key;        // the key the message must name
  std::string fragment;   // and this part of the explanation
};

class SceneRejects : public ::testing::TestWithParam<BadValue> {};

TEST_P(SceneRejects, WithAMessageNamingTheKey) {
  const auto& bad = GetParam();
  try {
    parse_scene(bad.toml, "bad.toml");
    FAIL() << "accepted: " << bad.toml;
  } catch (const SceneError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find(bad.key), std::string::npos) << m;
    EXPECT_NE(m.find(bad.fragment), std::string::npos) << m;
  }
}

INSTANTIATE_TEST_SUITE_P(
    BadScenes, SceneRejects,
    ::testing::Values(BadValue{"[joint_set]\ndip_deg = 120\n", "joint_set.dip_deg", "out of range"},
                      BadValue{"[joint_set]\ndip_deg = -1\n", "joint_set.dip_deg", "[0, 90] deg"},
                      BadValue{"[joint_set]\nspacing = 0\n", "joint_set.spacing", "out of range"},
                      BadValue{"[joint_set]\nspacing = \"ten\"\n", "joint_set.spacing", "wrong type"},
                      BadValue{"[mesh]\nsize = -0.001\n", "mesh.size", "out of range"},
                      BadValue{"[mesh]\nsize = 0.05\n", "mesh.size", "too coarse"},
                      BadValue{"[rock]\ncohesion = -5e6\n", "rock.cohesion", "out of range"},
                      BadValue{"[rock]\nfriction_deg = 95\n", "rock.friction_deg", "out of range"},
                      BadValue{"[rock]\ndensity = true\n", "rock.density", "wrong type"},
                      BadValue{"[joint]\ntensile_strength = 0\n", "joint.tensile_strength", "out of range"},
                      BadValue{"[joint]\nstiffness_ratio = -1\n", "joint.stiffness_ratio", "out of range"},
                      BadValue{"[specimen]\nmodel = \"plain_strain\"\n", "specimen.model", "plane_strain"},
                      BadValue{"[specimen]\nwidth = 0\n", "specimen.width", "out of range"},
                      BadValue{"[loading]\nstop_fraction = 1.5\n", "loading.stop_fraction", "out of range"},
                      BadValue{"[loading]\nplaten_velocity = 0\n", "loading.platen_velocity", "out of range"},
                      BadValue{"[numerics]\ndamping = 1.0\n", "numerics.damping", "out of range"},
                      BadValue{"[numerics]\ndt_safety = 1.5\n", "numerics.dt_safety", "out of range"},
                      BadValue{"[numerics]\nmass_scaling = 0.5\n", "numerics.mass_scaling", "out of range"},
                      BadValue{"[numerics]\nthreads = 1.5\n", "numerics.threads", "wrong type"},
                      BadValue{"[numerics]\nelastic_start = 1\n", "numerics.elastic_start", "wrong type"},
                      BadValue{"[rock]\nmodulus = 1e9\n", "rock.modulus", "unknown key"},
                      BadValue{"[specimens]\nwidth = 0.05\n", "specimens.width", "unknown key"},
                      BadValue{"width = 0.05\n", "width", "[section] table"}));

TEST(Scene, BadOverrideNamesTheKey) {
  Scene s;
  EXPECT_THROW(apply_override(s, "rock.cohesion"), SceneError);
  try {
    apply_override(s, "joint_set.dip_deg=abc");
    FAIL();
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("joint_set.dip_deg"), std::string::npos);
  }
  EXPECT_THROW(apply_override(s, "rock.nothing=1"), SceneError);
}

TEST(Scene, SpacingUnderTwoMeshSizesIsRejectedBeforeMeshing) {
  Scene s;
  s.joint_set.spacing = 0.0015;
  EXPECT_THROW(validate(s), SceneError);
  s.joint_set.enabled = false;  // no joints, no layers to resolve
  EXPECT_NO_THROW(validate(s));
}

TEST(Scene, StrengthAtOrAboveTheModulusIsALikelyUnitMistake) {
  Scene s;
  EXPECT_NO_THROW(check_plausible(s));
  s.rock.effective_modulus = 160;  // GPa written where Pa is meant
  EXPECT_NO_THROW(validate(s));    // every key is within its range ...
  try {
    check_plausible(s);            // ... but not together
    FAIL();
  } catch (const SceneError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("rock.effective_modulus"), std::string::npos) << m;
    EXPECT_NE(m.find("--force"), std::string::npos) << m;
  }
  s = Scene{};
  s.joint.cohesion = s.joint.effective_modulus;
  EXPECT_THROW(check_plausible(s), SceneError);
}

// A scene written in MPa: every key is within its range and every strength is below its modulus, but each stress is
// a million times too small. Each is refused alone, naming its key and the fix.
TEST(Scene, StressesWrittenInMegapascalsAreLikelyUnitMistakes) {
  const std::vector<std::pair<std::string, std::string>> mistakes = {
      {"rock.effective_modulus", "20000"}, {"rock.tensile_strength", "6"}, {"joint.cohesion", "3.36"},
      {"loading.confining_pressure", "10"}, {"joint2.effective_modulus", "50000"}};
  for (const auto& [key, value] : mistakes) {
    Scene s;
    apply_override(s, key + "=" + value);
    EXPECT_NO_THROW(validate(s)) << key;
    try {
      check_plausible(s);
      ADD_FAILURE() << key << " = " << value << " passed";
    } catch (const SceneError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find(key), std::string::npos) << m;
      EXPECT_NE(m.find(value + "e6"), std::string::npos) << m;
      EXPECT_NE(m.find("--force"), std::string::npos) << m;
    }
  }
  Scene s;  // the bounds are not the check: a soft rock of 1 GPa and a lab pressure of 0.1 MPa pass
  apply_override(s, "rock.effective_modulus=1e9");
  apply_override(s, "loading.confining_pressure=1e5");
  EXPECT_NO_THROW(check_plausible(s));
}

TEST(Scene, FolderGivenAsSceneFileIsRefused) {
  EXPECT_THROW(load_scene_file(std::filesystem::temp_directory_path()), SceneError);
}

TEST(Scene, SyntaxErrorGivesLine) {
  try {
    parse_scene("[rock]\ncohesion = = 3\n", "broken.toml");
    FAIL();
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("broken.toml:2"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rbdem

namespace rbdem {
namespace {

TEST(Scene, DocsSceneReferenceIsUpToDate) {
  std::ifstream in(source_dir + "/docs/scene.md");
  ASSERT_TRUE(in) << "docs/scene.md is missing";
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_NE(text.str().find(parameter_reference()), std::string::npos)
      << "docs/scene.md differs from `rbdem --help-scene`: regenerate it (see the page's first lines)";
}

}  // namespace
}  // namespace rbdem
