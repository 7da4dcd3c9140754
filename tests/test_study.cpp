// Study files, case expansion, the Jaeger table and the calibration file reader.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>
#include <unistd.h>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "theory/elasticity.hpp"
#include "study/calibrate.hpp"
#include "study/study.hpp"

namespace rbdem::study {
namespace {

const std::filesystem::path source_dir = RBDEM_SOURCE_DIR;

TEST(Study, ShippedStudiesLoadAndExpandToTheirCases) {
  const std::map<std::string, std::size_t> expected{{"study_joint_strength.toml", 28},
                                                     {"study_spacing.toml", 21},
                                                     {"study_stiffness_ratio.toml", 28}};
  for (const auto& [file, count] : expected) {
    const StudySpec spec = load_study(source_dir / "scenes" / file);
    const auto cases = expand(spec);
    EXPECT_EQ(cases.size(), count) << file;
    std::set<std::string> ids;
    for (const auto& c : cases) {
      EXPECT_TRUE(ids.insert(c.id).second) << "duplicate case " << c.id;
      EXPECT_EQ(c.scene.joint_set.dip_deg, c.beta);
      EXPECT_NO_THROW(validate(c.scene));
    }
  }
}

TEST(Study, ScaledValuesFollowTheBaseScene) {
  const StudySpec spec = load_study(source_dir / "scenes/study_joint_strength.toml");
  const auto cases = expand(spec);
  const Scene base = spec.base;
  // strength_ratio = 0.5, any dip
  const auto it = std::find_if(cases.begin(), cases.end(), [](const Case& c) { return c.group == "strength_ratio=0.5"; });
  ASSERT_NE(it, cases.end());
  EXPECT_DOUBLE_EQ(it->scene.joint.cohesion, 0.5 * base.rock.cohesion);
  EXPECT_DOUBLE_EQ(it->scene.joint.tensile_strength, 0.5 * base.rock.tensile_strength);
  EXPECT_DOUBLE_EQ(it->scene.rock.cohesion, base.rock.cohesion);  // rock fixed
}

TEST(Study, BadStudyFilesNameTheProblem) {
  const auto dir = std::filesystem::temp_directory_path() / "rbdem_test_study";
  std::filesystem::create_directories(dir);
  auto expect_error = [&](const std::string& text, const std::string& fragment) {
    const auto path = dir / "bad.toml";
    std::ofstream(path) << text;
    try {
      load_study(path);
      FAIL() << "accepted:\n" << text;
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
    }
  };
  expect_error("[study]\ndips = [0, 120]\n", "dips must lie in [0, 90]");
  expect_error("[study]\n[study.set]\n\"rock.cohesoin\" = 1e6\n", "rock.cohesoin");
  expect_error("[study]\n[[axis]]\nname = \"a\"\nlabels = [\"x\", \"y\"]\n[axis.set]\n\"rock.cohesion\" = [1e6]\n",
               "1 values for 2 labels");
  expect_error("[study]\n[[axis]]\nname = \"a\"\n[axis.set]\n\"joint.friction_deg\" = [95]\n", "joint.friction_deg");
  expect_error("[study]\nnmae = \"x\"\n", "unknown key 'nmae'");
  expect_error("[sutdy]\n", "unknown key 'sutdy'");
  std::filesystem::remove_all(dir);
}

// Synthetic results of a dip study (no runs): each case's peak from its dip.
template <class Peak>
std::vector<CaseResult> synthetic_dip_results(const std::vector<double>& dips, Peak peak_of) {
  StudySpec spec = dip_study(Scene{}, "synthetic");
  if (!dips.empty()) spec.dips = dips;
  std::vector<CaseResult> results;
  for (const auto& c : expand(spec)) {
    CaseResult r;
    r.c = c;
    r.summary = {{"peak_stress_pa", peak_of(c.beta)}, {"strain_at_peak", 1e-4}, {"youngs_modulus_pa", 2e11},
                 {"failure_mode", "x"}, {"steps", 10}, {"scene", scene_json(c.scene)},
                 {"cracks", {{"rock_tensile", 0}, {"rock_shear", 0}, {"joint_tensile", 0}, {"joint_shear", 0}}}};
    results.push_back(r);
  }
  return results;
}

TEST(Study, TableHasJaegerBesideTheMeasuredStrength) {
  // A dip study whose beta = 90 strength is 50 MPa.
  const auto results = synthetic_dip_results({}, [](double beta) {
    return beta == 90 ? 50e6 : 20e6 + std::abs(beta - 60) * 1e5;
  });
  const auto dir = std::filesystem::temp_directory_path() / "rbdem_test_table";
  std::filesystem::create_directories(dir);
  const auto groups = write_tables(results, dir);
  ASSERT_EQ(groups.size(), 1u);
  EXPECT_EQ(groups[0].min_beta_deg, 60.0);
  EXPECT_DOUBLE_EQ(groups[0].strength_90_pa, 50e6);
  EXPECT_DOUBLE_EQ(groups[0].anisotropy_ratio, 50e6 / 20e6);
  const Scene s;
  EXPECT_DOUBLE_EQ(groups[0].jaeger_min_beta_deg, 45 + s.joint.friction_deg / 2);
  // The default joint's interface sticks while bonded: its envelope has twice the bond cohesion (contact_law.hpp).
  EXPECT_NEAR(groups[0].jaeger_min_pa, theory::jaeger_min_uniaxial_strength(2 * s.joint.cohesion, s.joint.friction_deg), 1);
  std::ifstream in(dir / "table.csv");
  std::string header, line60;
  std::getline(in, header);
  EXPECT_NE(header.find("jaeger_pa"), std::string::npos);
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("beta=60,", 0) == 0) line60 = line;
  const double jaeger60 = theory::jaeger_strength({2 * s.joint.cohesion, s.joint.friction_deg, 50e6, 0.0}, 60.0);
  EXPECT_NE(line60.find(fmt::format("{:.9g}", jaeger60)), std::string::npos) << line60;
  std::filesystem::remove_all(dir);
}

// Jaeger's intact strength is measured where no joint slides: at 90 deg, else at 0 deg; a group with neither has
// none ("n/a"), never its own largest peak (which would make Jaeger equal the run at that dip by construction).
TEST(Study, JaegerIsAnchoredAt90Or0DegreesOrNotAtAll) {
  auto groups_of = [](std::vector<double> dips) {
    const auto results = synthetic_dip_results(dips, [](double beta) {
      return beta == 0 ? 52e6 : beta == 90 ? 50e6 : 100e6 - beta * 1e6;
    });
    const auto dir = std::filesystem::temp_directory_path() / "rbdem_test_anchor";
    std::filesystem::create_directories(dir);
    auto groups = write_tables(results, dir);
    std::filesystem::remove_all(dir);
    return groups;
  };
  EXPECT_DOUBLE_EQ(groups_of({0, 30, 60, 90})[0].strength_90_pa, 50e6);
  const auto at0 = groups_of({0, 30, 60});
  EXPECT_DOUBLE_EQ(at0[0].strength_90_pa, 52e6);
  EXPECT_DOUBLE_EQ(at0[0].anisotropy_ratio, 52e6 / 40e6);
  const auto none = groups_of({30, 45, 60});  // the largest peak, 70 MPa at 30 deg, is not an intact strength
  EXPECT_TRUE(std::isnan(none[0].strength_90_pa));
  EXPECT_TRUE(std::isnan(none[0].anisotropy_ratio));
  EXPECT_TRUE(std::isnan(none[0].jaeger_min_pa));
  EXPECT_TRUE(std::isnan(jaeger_for(Scene{}, 30.0, none[0].strength_90_pa)));
}

// Jaeger with two planes of weakness: the weaker plane governs. A second set at 90 deg to the first, as weak as
// the first, makes the first set's trough at 60 deg appear again at 30 deg (the second set then dips 120 deg, 60
// deg from sigma_3); a second set whose joints are far stronger leaves the one-set curve.
TEST(Study, JaegerWithTwoSetsFollowsTheWeakerPlane) {
  const double s90 = 50e6;
  const Scene one;
  Scene two = one;
  two.joint_set2.enabled = true, two.joint_set2.follows_set1 = true, two.joint_set2.dip_deg = 90.0;
  static_cast<MaterialParams&>(two.joint2) = two.joint;
  for (double beta : {0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 90.0}) {
    const double expected = std::min(jaeger_for(one, beta, s90), jaeger_for(one, 90.0 - beta, s90));
    EXPECT_DOUBLE_EQ(jaeger_for(two, beta, s90), expected) << beta;
  }
  EXPECT_DOUBLE_EQ(jaeger_for(two, 30.0, s90), jaeger_for(one, 60.0, s90));
  EXPECT_LT(jaeger_for(two, 30.0, s90), 0.6 * s90);
  two.joint2.cohesion = 1e3 * one.joint.cohesion;
  for (double beta : {0.0, 15.0, 30.0, 45.0, 60.0, 75.0, 90.0})
    EXPECT_DOUBLE_EQ(jaeger_for(two, beta, s90), jaeger_for(one, beta, s90)) << beta;
  // An absolute second dip: a set dipping 150 deg acts as one at 30 deg.
  Scene fixed = one;
  fixed.joint_set.enabled = false;
  fixed.joint_set2.enabled = true, fixed.joint_set2.dip_deg = 150.0;
  static_cast<MaterialParams&>(fixed.joint2) = fixed.joint;
  EXPECT_DOUBLE_EQ(jaeger_for(fixed, 0.0, s90), jaeger_for(one, 30.0, s90));
}

// Jennings' envelope for joints with rock bridges: persistence k mixes the joint's and the rock's interface
// envelopes (cohesion and tan phi) by k and 1 - k; at k = 1 it is the joint's, at k = 0.5 the hand value below.
TEST(Study, JaegerWithRockBridgesUsesJenningsEnvelope) {
  const double s90 = 50e6;
  Scene s;
  const double through = jaeger_for(s, 60.0, s90);
  s.joint_set.persistence = 1.0;
  EXPECT_DOUBLE_EQ(jaeger_for(s, 60.0, s90), through);
  s.joint_set.persistence = 0.5;
  // Bonded interfaces that stick: c = 2 x bond cohesion (3.36 and 7.51 MPa), tan phi of the bonds (30, 40 deg).
  const double c = 0.5 * 2 * 3.36e6 + 0.5 * 2 * 7.51e6;
  const double mu = 0.5 * std::tan(30.0 * std::numbers::pi / 180) + 0.5 * std::tan(40.0 * std::numbers::pi / 180);
  const double b = 60.0 * std::numbers::pi / 180;
  const double hand = 2 * c / ((1 - mu / std::tan(b)) * std::sin(2 * b));
  EXPECT_NEAR(jaeger_for(s, 60.0, s90), hand, 1e-6 * hand);
  EXPECT_NEAR(hand, 42.5e6, 0.1e6);
  s.joint_set.persistence = 0.25;
  EXPECT_DOUBLE_EQ(jaeger_for(s, 60.0, s90), s90);  // the coplanar path is stronger than the intact rock
}

// A confined study with realizations: the slope between sigma_3 = 0 and 10 MPa of the mean peaks, with its standard
// error from their scatter, against a hand computation; one mesh per pressure gives no error.
TEST(Study, EnvelopeSlopeOfMeansWithItsStandardError) {
  const auto dir = std::filesystem::temp_directory_path() / ("rbdem_test_envelope_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  auto result = [](double p, double peak) {
    CaseResult r;
    r.c.beta = 60.0;
    r.summary = {{"confining_pressure_pa", p}, {"peak_stress_pa", peak}};
    return r;
  };
  // sigma_1 at 0: 19, 20, 21 MPa (mean 20, s^2 = 1e12); at 10 MPa: 44, 46 MPa (mean 45, s^2 = 2e12).
  const std::vector<CaseResult> five{result(0, 19e6), result(0, 20e6), result(0, 21e6), result(10e6, 44e6),
                                     result(10e6, 46e6)};
  const auto e = write_envelopes(five, dir);
  ASSERT_EQ(e.size(), 1u);
  EXPECT_EQ(e[0].points, 5);
  EXPECT_NEAR(e[0].slope_0_10, (45e6 - 20e6) / 10e6, 1e-12);
  EXPECT_NEAR(e[0].slope_0_10_se, std::sqrt(1e12 / 3 + 2e12 / 2) / 10e6, 1e-12);
  const auto two = write_envelopes({result(0, 20e6), result(10e6, 45e6)}, dir);
  EXPECT_NEAR(two[0].slope_0_10, 2.5, 1e-12);
  EXPECT_TRUE(std::isnan(two[0].slope_0_10_se));
  std::ifstream csv(dir / "envelope.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_NE(header.find("slope_0_10mpa,slope_0_10mpa_se,"), std::string::npos) << header;
  std::filesystem::remove_all(dir);
}

// Student's t at 0.975 against published values (the table) and past it (the expansion; exact value from the
// regularized incomplete beta function).
TEST(Study, StudentQuantiles) {
  EXPECT_DOUBLE_EQ(student_t975(1), 12.706204736);
  EXPECT_DOUBLE_EQ(student_t975(4), 2.776445105);
  EXPECT_NEAR(student_t975(31), 2.039513446, 1e-7);
  EXPECT_NEAR(student_t975(100), 1.983971519, 1e-7);
  EXPECT_THROW(student_t975(0), std::invalid_argument);
}

// realizations = 3: three cases per dip with mesh.seed 0, 1, 2, and table.csv with the mean, sd and 95 % interval
// of each dip's peak, checked against a hand computation; realizations.csv keeps every realization.
TEST(Study, RealizationsGiveMeanSdAndInterval) {
  const auto dir = std::filesystem::temp_directory_path() / ("rbdem_test_realizations_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "study.toml") << "[study]\ndips = [60, 90]\nrealizations = 3\n"
                                       "[study.set]\n\"mesh.size\" = 0.004\n";
  const StudySpec spec = load_study(dir / "study.toml");
  EXPECT_EQ(spec.realizations, 3);
  const auto cases = expand(spec);
  ASSERT_EQ(cases.size(), 6u);
  EXPECT_EQ(cases[0].id, "beta=60/seed=0");
  EXPECT_EQ(cases[2].id, "beta=60/seed=2");
  EXPECT_EQ(cases[3].point, "beta=90");
  for (int k = 0; k < 6; ++k) {
    EXPECT_EQ(cases[k].scene.mesh.seed, k % 3);
    EXPECT_EQ(cases[k].realization, k % 3);
    EXPECT_EQ(cases[k].group, "");
  }
  // Peaks 18, 20, 25 MPa at 60 deg and 50, 50, 53 MPa at 90 deg.
  const double peaks[6] = {18e6, 20e6, 25e6, 50e6, 50e6, 53e6};
  std::vector<CaseResult> results;
  for (int k = 0; k < 6; ++k) {
    CaseResult r;
    r.c = cases[k];
    r.summary = {{"peak_stress_pa", peaks[k]}, {"strain_at_peak", 1e-4}, {"youngs_modulus_pa", 2e11},
                 {"failure_mode", k == 2 ? "y" : "x"}, {"steps", 10 + k}, {"scene", scene_json(cases[k].scene)},
                 {"cracks", {{"rock_tensile", k}, {"rock_shear", 0}, {"joint_tensile", 0}, {"joint_shear", 0}}}};
    // A signal that one realization of each point leaves undefined (null): 19 and 24 MPa at 60 deg.
    r.summary["crack_damage_stress_pa"] = k % 3 == 0 ? nlohmann::json(nullptr) : nlohmann::json(peaks[k] - 1e6);
    results.push_back(r);
  }
  const auto points = realization_means(results);
  ASSERT_EQ(points.size(), 2u);
  EXPECT_DOUBLE_EQ(points[0].mean.summary["crack_damage_stress_pa"].get<double>(), 21.5e6);  // of the defined ones
  const auto groups = write_tables(results, dir);
  // By hand at 60 deg: mean 21 MPa, sd sqrt((9 + 1 + 16) / 2) = sqrt(13) = 3.605551 MPa,
  // half-width 4.302653 x 3.605551 / sqrt(3) = 8.956686 MPa.
  std::ifstream in(dir / "table.csv");
  std::string header, line;
  std::getline(in, header);
  for (const char* col :
       {",realizations,", ",peak_stress_sd_pa,", ",peak_stress_ci95_pa,", ",peak_stress_ci95_low_pa,"})
    EXPECT_NE(header.find(col), std::string::npos) << col << " missing in " << header;
  std::vector<std::string> rows;
  while (std::getline(in, line)) rows.push_back(line);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].rfind("beta=60,", 0), 0u) << rows[0];
  EXPECT_NE(rows[0].find(",21000000,"), std::string::npos) << rows[0];
  EXPECT_NE(rows[0].find(",3,3605551.28,8956685.9,12043314.1,29956685.9,"), std::string::npos) << rows[0];
  EXPECT_NE(rows[0].find(",x,"), std::string::npos) << rows[0];  // the most frequent failure mode
  EXPECT_NE(rows[0].find(",1,0,0,0,11,"), std::string::npos) << rows[0];  // mean crack counts and steps
  // Jaeger and the group use the means: 51 MPa at 90 deg.
  ASSERT_EQ(groups.size(), 1u);
  EXPECT_DOUBLE_EQ(groups[0].strength_90_pa, 51e6);
  EXPECT_DOUBLE_EQ(groups[0].min_strength_pa, 21e6);
  std::ifstream rin(dir / "realizations.csv");
  std::getline(rin, header);
  EXPECT_EQ(header.rfind("id,group,point,realization,mesh_seed,beta_deg,peak_stress_pa,", 0), 0u) << header;
  rows.clear();
  while (std::getline(rin, line)) rows.push_back(line);
  ASSERT_EQ(rows.size(), 6u);
  EXPECT_EQ(rows[2].rfind("beta=60/seed=2,,beta=60,2,2,60,25000000,", 0), 0u) << rows[2];
  std::filesystem::remove_all(dir);
}

TEST(Study, BadRealizationsAreRefused) {
  const auto dir = std::filesystem::temp_directory_path() / ("rbdem_test_bad_real_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  for (const char* value : {"0", "-2", "2.5", "\"5\"", "1001"}) {
    std::ofstream(dir / "s.toml") << "[study]\nrealizations = " << value << "\n";
    try {
      load_study(dir / "s.toml");
      FAIL() << "accepted realizations = " << value;
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find("study.realizations"), std::string::npos) << e.what();
    }
  }
  Scene user_mesh;
  user_mesh.mesh.file = "x.msh";
  EXPECT_THROW(check_realizations(3, user_mesh), SceneError);
  EXPECT_NO_THROW(check_realizations(1, user_mesh));
  std::filesystem::remove_all(dir);
}

TEST(Calibrate, ShippedTargetsFileLoads) {
  const CalibrationSpec spec = load_calibration(source_dir / "scenes/calibrate_paper.toml");
  EXPECT_EQ(spec.parameters.size(), 2u);
  EXPECT_EQ(spec.targets.size(), 3u);
  EXPECT_DOUBLE_EQ(spec.parameters[0].start, spec.base.rock.cohesion);
  const CalibrationSpec four = load_calibration(source_dir / "scenes/calibrate_four_targets.toml");
  EXPECT_EQ(four.realizations, 3);
  EXPECT_EQ(four.targets.size(), 4u);
  EXPECT_EQ(four.targets[3].label(), "tensile_strength@0");
}

// The command line's --set moves the base scene after [calibrate.set], and a fitted key's start with it (it used
// to be set after the starts were read, so a --set of a fitted key changed nothing); a key the file does not fit
// keeps the override.
TEST(Calibrate, CommandLineOverridesMoveTheStartValues) {
  const auto file = source_dir / "scenes/calibrate_realistic.toml";
  const CalibrationSpec plain = load_calibration(file);
  const CalibrationSpec moved = load_calibration(file, {"rock.cohesion=50e6", "rock.stiffness_weibull_modulus=5",
                                                        "mesh.size=0.004"});
  ASSERT_EQ(moved.parameters[1].keys[0], "rock.cohesion");
  EXPECT_EQ(moved.parameters[1].start, 50e6);
  EXPECT_NE(plain.parameters[1].start, 50e6);
  EXPECT_EQ(moved.parameters[0].start, plain.parameters[0].start);
  EXPECT_EQ(moved.base.rock.stiffness_weibull_modulus, 5.0);
  EXPECT_EQ(moved.base.mesh.size, 0.004);  // over the file's [calibrate.set] mesh.size = 0.003
  EXPECT_EQ(plain.base.mesh.size, 0.003);
}

// A targets file with the given [calibrate] lines, one parameter and the given [[target]] tables.
CalibrationSpec calibration_from(const std::string& calibrate, const std::string& targets) {
  const auto dir = std::filesystem::temp_directory_path() / ("rbdem_cal_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "t.toml") << "[calibrate]\n" << calibrate << "\n[[parameter]]\nname = \"s\"\n"
                                << "keys = [\"rock.cohesion\"]\n" << targets;
  struct Cleanup {
    std::filesystem::path d;
    ~Cleanup() { std::filesystem::remove_all(d); }
  } cleanup{dir};
  return load_calibration(dir / "t.toml");
}

// A misspelt key used to be ignored (the calibration then ran without the target the user meant).
TEST(Calibrate, UnknownKeysAreRefusedNamingTheKey) {
  const std::string target = "[[target]]\nquantity = \"strength\"\nvalue = 5e7\n";
  const auto refused = [](const std::string& calibrate, const std::string& targets, const std::string& words) {
    try {
      calibration_from(calibrate, targets);
      ADD_FAILURE() << "accepted: " << calibrate << targets;
    } catch (const SceneError& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  refused("", "[[target]]\nquantity = \"strength\"\nbeta = 90\nvalu = 5e7\n", "unknown key 'valu'");
  refused("", "[[target]]\nquantity = \"strenght\"\nvalue = 5e7\n", "target quantity 'strenght' unknown");
  refused("realisations = 3", target, "unknown key 'realisations'");
  refused("", "[[target]]\nquantity = \"min_strength\"\nbeta = 60\nvalue = 2e7\n", "takes no beta");
  refused("confining = [5e6]", target, "two different pressures");
  refused("realizations = 0", target, "realizations");
  EXPECT_NO_THROW(calibration_from("", target));
}

TEST(Calibrate, ReadsRealizationsConfiningAndEveryTargetQuantity) {
  std::string targets;
  for (const auto& q : target_quantities())
    targets += fmt::format("[[target]]\nquantity = \"{}\"\n{}value = 1\n", q.name, q.at_dip ? "beta = 60\n" : "");
  const CalibrationSpec spec = calibration_from("realizations = 3\nconfining = [0, 2e6, 4e6]", targets);
  EXPECT_EQ(spec.realizations, 3);
  EXPECT_EQ(spec.confining, (std::vector<double>{0, 2e6, 4e6}));
  ASSERT_EQ(spec.targets.size(), target_quantities().size());
  EXPECT_EQ(spec.targets[0].label(), "strength@60");
  EXPECT_EQ(spec.targets.back().label(), "min_angle");
}

}  // namespace
}  // namespace rbdem::study

namespace rbdem::study {
namespace {

// A case whose run the watchdog stopped has a summary.json with "completed": false: a rerun of the sweep must run
// it again, not count it as done (an interrupted case has no summary.json at all). Nor does a result left by
// another scene (an edited study file, another version's defaults) count.
TEST(Study, CaseStoppedByTheWatchdogDoesNotCountAsDone) {
  namespace fs = std::filesystem;
  const fs::path out = fs::temp_directory_path() / ("rbdem_study_incomplete_" + std::to_string(::getpid()));
  fs::remove_all(out);
  std::vector<Case> cases(3);
  cases[0].id = "done", cases[1].id = "stopped", cases[2].id = "other_scene";
  for (const auto& c : cases) fs::create_directories(out / c.id);
  auto summary = [](bool completed, const Scene& scene) {
    nlohmann::json j;
    j["peak_stress_pa"] = completed ? nlohmann::json(1e7) : nlohmann::json(nullptr);
    j["completed"] = completed;
    j["scene"] = scene_json(scene);
    return j.dump();
  };
  Scene edited = cases[2].scene;
  edited.joint.cohesion *= 1.01;
  std::ofstream(out / "done" / "summary.json") << summary(true, cases[0].scene);
  std::ofstream(out / "stopped" / "summary.json") << summary(false, cases[1].scene);
  std::ofstream(out / "other_scene" / "summary.json") << summary(true, edited);
  const auto found = collect(cases, out);
  ASSERT_EQ(found.size(), 1u);
  EXPECT_EQ(found[0].c.id, "done");
  fs::remove_all(out);
}

// A sweep shares its cores among the running cases: seven dips on 16 cores start with 3, 3, 2, 2, 2, 2 and 2
// threads, and as the queue empties and cases end, the last ones get the cores the others leave.
TEST(Study, CasesShareTheCoresAndTheLastOnesGetTheRest) {
  EXPECT_EQ(share_cores(16, 7, 7), (std::vector<int>{3, 3, 2, 2, 2, 2, 2}));
  EXPECT_EQ(share_cores(16, 7, 3), (std::vector<int>{3, 3, 2}));  // the queue still holds cases: shares are kept
  EXPECT_EQ(share_cores(16, 2, 2), (std::vector<int>{8, 8}));
  EXPECT_EQ(share_cores(16, 1, 1), (std::vector<int>{16}));
  EXPECT_EQ(share_cores(2, 2, 2), (std::vector<int>{1, 1}));   // two cores: one thread per case, as before
  EXPECT_EQ(share_cores(2, 1, 1), (std::vector<int>{2}));
  EXPECT_EQ(share_cores(3, 5, 5), (std::vector<int>{1, 1, 1, 1, 1}));  // never fewer than one
  for (int cores : {1, 2, 5, 16, 64})
    for (std::size_t running = 1; running <= 9; ++running) {
      const std::vector<int> t = share_cores(cores, running, running);
      int sum = 0;
      for (int k : t) sum += k;
      EXPECT_EQ(sum, std::max(cores, int(running))) << cores << " cores, " << running << " cases";
    }
}

}  // namespace
}  // namespace rbdem::study
