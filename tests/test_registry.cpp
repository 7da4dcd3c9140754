// A new test is one protocol and one registration, with nothing else edited: a stress relaxation protocol
// written here, registered at run time, runs through the same run_case, driver, monitors, summary and writers as the
// built-in tests (dem/driver/registry.hpp). Its own numbers reach summary.json; the physics it measures has a closed
// form: an elastic specimen held at a fixed platen closure keeps its stress (the model has no creep).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include "dem/driver/platen_test.hpp"
#include "dem/driver/registry.hpp"
#include "io/run_case.hpp"

namespace rbdem {
namespace {

// The platens close at loading.platen_velocity to `hold_strain`, then stop and hold for `hold_steps` steps. The hold
// begins at a step the platen's speed and the time step fix, so a resumed run holds where the uninterrupted one did.
class RelaxationProtocol final : public PlatenTest {
 public:
  RelaxationProtocol(const Scene& scene, int curve_points) : PlatenTest(scene, curve_points) {}
  std::string name() const override { return "relaxation"; }
  void control(Simulation& sim, const Reading& reading, const TestRecord&) override {
    if (reading.strain >= hold_strain) sim.find<Platens>()->set_velocity(0.0);
  }
  long max_steps(const Simulation& sim, const TestRecord& record) const override {
    const double step_closure = scene_.loading.platen_velocity * record.dt;
    return long(std::ceil(hold_strain * sim.specimen().height() / step_closure)) + hold_steps;
  }
  bool stop(const Simulation&, const Reading&, const TestRecord&, std::string&) const override { return false; }
  void results(const Simulation&, const TestRecord& record, TestResult& result) const override {
    result.own = {{"hold_stress_pa", record.peak, true},
                  {"final_stress_pa", record.curve.empty() ? 0.0 : record.curve.back().stress(), true},
                  {"hold_steps", double(hold_steps), false}};
  }
  static constexpr double hold_strain = 5e-5;
  static constexpr long hold_steps = 4000;
};

ProtocolInfo relaxation_protocol() {
  ProtocolInfo p;
  p.name = "relaxation";
  p.description = "platens closed to a strain and held: stress relaxation";
  p.check = [](const Scene& scene) { refuse_confining_pressure("relaxation", scene); };
  p.make = [](const Scene& scene, int curve_points) { return std::make_unique<RelaxationProtocol>(scene, curve_points); };
  p.headline = [](const TestResult& r) {
    return fmt::format("relaxation: {:.2f} MPa held, {:.2f} MPa after {:g} steps", r.own_value("hold_stress_pa") / 1e6,
                       r.own_value("final_stress_pa") / 1e6, r.own_value("hold_steps"));
  };
  return p;
}

TEST(Registry, ANewProtocolIsOneClassAndOneRegistration) {
  register_protocol(relaxation_protocol());  // the one registration line
  EXPECT_THROW(register_protocol(relaxation_protocol()), std::invalid_argument);  // a name is registered once
  EXPECT_EQ(protocol_info("relaxation").name, "relaxation");

  Scene scene;
  scene.specimen.width = 0.01, scene.specimen.height = 0.02, scene.mesh.size = 0.002;
  scene.joint_set.spacing = 0.006, scene.numerics.threads = 1, scene.numerics.elastic_start = false;
  scene.rock.tensile_strength = scene.rock.cohesion = scene.joint.tensile_strength = scene.joint.cohesion = 1e11;
  const auto dir = std::filesystem::temp_directory_path() / fmt::format("rbdem_test_registry_{}", ::getpid());
  io::CaseOptions co;
  co.out = dir;
  const TestResult r = io::run_case("relaxation", scene, co).result;
  ASSERT_TRUE(r.completed) << r.watchdog_message;
  EXPECT_EQ(r.test, "relaxation");
  EXPECT_EQ(r.crack_counts.total(), 0);
  // Held in equilibrium, an elastic specimen keeps its stress: within 1 % after 4 000 steps.
  const double held = r.own_value("hold_stress_pa"), final = r.own_value("final_stress_pa");
  EXPECT_GT(held, 1e6);
  EXPECT_NEAR(final / held, 1.0, 0.01) << held << " Pa held, " << final << " Pa at the end";
  // The shared writers wrote its run folder, its own numbers in summary.json.
  std::ifstream in(dir / "summary.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  EXPECT_EQ(j["test"], "relaxation");
  EXPECT_EQ(j["hold_stress_pa"].get<double>(), held);
  EXPECT_EQ(j["hold_steps"].get<double>(), 4000.0);
  for (const char* file : {"curve.csv", "cracks.csv", "result.h5", "result.xdmf", "scene.toml"})
    EXPECT_TRUE(std::filesystem::exists(dir / file)) << file;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace rbdem
