// rbdem hold: the specimen is loaded to the axial stress sigma_1 = loading.hold_stress and held there by the platen
// servo for loading.hold_steps explicit steps, as a lab holds a specimen at constant stress. Uniaxial, or confined
// when loading.confining_pressure > 0 (ConfinedPlatenTest). The top platen closes at loading.platen_velocity until
// the mean platen stress reaches the target, then the servo of dem/boundary/boundary.hpp (PlatenServo) drives it,
// with the gain and rate limit of hold_servo below. Its own numbers: the worst deviation from the target over the
// hold, the mean stress, the axial strain the specimen gained and the cracks it took while held.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include <fmt/format.h>

#include "dem/driver/platen_test.hpp"
#include "dem/driver/registry.hpp"

namespace rbdem {

// The servo of a stress hold (docs/theory.md, "The platen servo"). The platen's closing speed v = g (sigma* -
// sigma) makes the stress error decay as exp(-t / tau) with tau = A / (g K) where the specimen follows the platen
// quasi-statically (K: its axial stiffness between the platens, A: the loaded area). The specimen answers a platen
// motion within its axial vibration, of angular frequency sqrt(K / M) at the least (M: its mass; the first axial
// mode between the platens is pi times that); the loop stays stable and free of overshoot when the servo is ten
// times slower: tau = 10 sqrt(M / K), g = A / (10 sqrt(K M)). Per step the error then shrinks by dt / tau, far
// below the explicit bound 2. The rate limit `max_velocity` (the test's loading speed) keeps the servo from driving
// the platen faster than the quasi-static loading did.
PlatenServo hold_servo(double stiffness, double mass, double area, double target, double max_velocity) {
  PlatenServo servo;
  servo.target_stress = target;
  servo.gain = area / (10.0 * std::sqrt(stiffness * mass));
  servo.max_velocity = max_velocity;
  return servo;
}

namespace {

constexpr double nan = std::numeric_limits<double>::quiet_NaN();

class HoldProtocol final : public ConfinedPlatenTest {
 public:
  using ConfinedPlatenTest::ConfinedPlatenTest;
  std::string name() const override { return "hold"; }
  void start(Simulation& sim, TestRecord& record) override;
  long max_steps(const Simulation& sim, const TestRecord& record) const override {
    return PlatenTest::max_steps(sim, record) + scene_.loading.hold_steps;
  }
  void control(Simulation& sim, const Reading& reading, const TestRecord& record) override;
  bool stop(const Simulation& sim, const Reading& reading, const TestRecord& record,
            std::string& reason) const override;
  void results(const Simulation& sim, const TestRecord& record, TestResult& result) const override;

 protected:
  // The explicit run takes over below the target, so that the servo takes a moving specimen.
  double start_stress_limit() const override { return 0.9 * target(); }

 private:
  double target() const { return scene_.loading.hold_stress; }

  bool started_ = false;
  PlatenServo servo_;
  long hold_from_ = -1;              // step at which the servo took over (-1: still loading)
  double strain0_ = 0, strain_ = 0;  // axial strain when the hold began, and now
  std::size_t cracks0_ = 0, cracks_ = 0;
  double worst_ = 0, sum_ = 0;       // Pa: the largest |sigma - target| over the hold, the sum of sigma
  long held_ = 0;                    // steps held
  double time_constant_ = 0;         // s, tau = A / (g K)
};

void HoldProtocol::start(Simulation& sim, TestRecord& record) {
  ConfinedPlatenTest::start(sim, record);
  const Specimen& s = sim.specimen();
  const double mass = scene_.numerics.mass_scaling * std::accumulate(s.blocks.mass.begin(), s.blocks.mass.end(), 0.0);
  const double K = axial_stiffness(sim), A = platens(sim).area();
  servo_ = hold_servo(K, mass, A, target(), scene_.loading.platen_velocity);
  time_constant_ = A / (servo_.gain * K);
  // The trace: about 1000 curve samples over the hold (and as densely on the way to it).
  record.sample_every = std::max(1L, long(scene_.loading.hold_steps / 1000));
  started_ = true;
}

void HoldProtocol::control(Simulation& sim, const Reading& r, const TestRecord&) {
  if (!started_)
    throw SceneError("rbdem hold keeps its hold in the run, not in the checkpoint: it cannot resume; run it afresh "
                     "without --resume");
  strain_ = r.strain, cracks_ = sim.cracks().size();
  if (hold_from_ < 0) {
    if (r.stress < target()) return;
    hold_from_ = sim.steps();
    strain0_ = r.strain, cracks0_ = sim.cracks().size();
    sim.find<Platens>()->set_servo(servo_);
    return;
  }
  worst_ = std::max(worst_, std::abs(r.stress - target()));
  sum_ += r.stress;
  ++held_;
}

bool HoldProtocol::stop(const Simulation& sim, const Reading& r, const TestRecord& record,
                        std::string& reason) const {
  if (held_ >= scene_.loading.hold_steps) {
    reason = "hold_done";
    return true;
  }
  if (r.strain >= scene_.loading.max_strain) {
    reason = "max_strain";
    return true;
  }
  return PlatenTest::stop(sim, r, record, reason);  // the specimen failed below the target or under it
}

void HoldProtocol::results(const Simulation& sim, const TestRecord&, TestResult& result) const {
  const bool held = held_ > 0;
  result.own = {{"hold_stress_pa", target(), false},
                {"hold_steps_held", double(held_), false},
                {"hold_start_step", double(hold_from_), false},
                {"hold_max_deviation_pa", held ? worst_ : nan, true},
                {"hold_max_relative_deviation", held ? worst_ / target() : nan, true},
                {"hold_mean_stress_pa", held ? sum_ / double(held_) : nan, true},
                {"hold_strain_change", held ? strain_ - strain0_ : nan, true},
                {"hold_cracks", held ? double(cracks_ - cracks0_) : nan, true},
                {"servo_gain_m_per_s_pa", servo_.gain, false},
                {"servo_max_velocity_m_per_s", servo_.max_velocity, false},
                {"servo_time_constant_s", time_constant_, false},
                {"servo_time_constant_steps", time_constant_ / sim.dt(), false}};
}

}  // namespace

ProtocolInfo hold_protocol() {
  ProtocolInfo p;
  p.name = "hold";
  p.description = "load to loading.hold_stress and hold it there by the platen servo for loading.hold_steps steps";
  p.options = {{"--hold-stress", "loading.hold_stress", "the axial stress to hold [Pa] (loading.hold_stress)"},
               {"--confining", "loading.confining_pressure",
                "confining pressure sigma_3 [Pa] (loading.confining_pressure); 0: uniaxial"}};
  p.check = [](const Scene& scene) {
    if (scene.specimen.shape == "disc")
      throw SceneError("rbdem hold compresses a rectangle between platens: set specimen.shape = \"rectangle\"");
    const LoadingParams& l = scene.loading;
    if (!(l.hold_stress > l.confining_pressure))
      throw SceneError(fmt::format("loading.hold_stress = {} Pa is not above loading.confining_pressure = {} Pa: "
                                   "the servo holds sigma_1 above sigma_3; raise it",
                                   l.hold_stress, l.confining_pressure));
    if (l.fast_factor > 1.0)
      throw SceneError("rbdem hold sets the platen's speed itself: set loading.fast_factor = 1");
    if (l.mismatch_stop > 0.0)
      throw SceneError("rbdem hold sets the platen's speed itself: set loading.mismatch_stop = 0");
    if (l.transit_strain_fraction > 0.0)
      throw SceneError("rbdem hold loads at loading.platen_velocity: set loading.transit_strain_fraction = 0");
  };
  p.make = [](const Scene& scene, int curve_points) { return std::make_unique<HoldProtocol>(scene, curve_points); };
  p.headline = [](const TestResult& r) {
    return fmt::format("hold: {:.2f} MPa held for {:g} steps, worst deviation {:.3f} % ({:.4g} Pa), strain change "
                       "{:.3e}, {:g} cracks",
                       r.own_value("hold_stress_pa") / 1e6, r.own_value("hold_steps_held"),
                       100.0 * r.own_value("hold_max_relative_deviation"), r.own_value("hold_max_deviation_pa"),
                       r.own_value("hold_strain_change"), r.own_value("hold_cracks"));
  };
  return p;
}

}  // namespace rbdem
