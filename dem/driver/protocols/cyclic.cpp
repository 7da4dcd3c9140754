// rbdem cyclic: loading-unloading cycles to rising stress levels, as labs measure how the modulus of a rock falls
// with damage. Uniaxial, or confined when loading.confining_pressure > 0 (the jacket and the isotropic start of
// ConfinedPlatenTest); the levels and the unload stress are of the deviator sigma_1 - sigma_3. The top platen closes
// at loading.platen_velocity until the deviator reaches level k = k / cycles x loading.cycle_max_stress, opens at the
// same speed down to loading.cycle_unload_stress, closes again, and so on; after the last cycle it loads to failure
// (loading.cycle_to_failure) or stops when the last loop closes. Each cycle's row (dem/records.hpp, Cycle): the
// unloading and reloading secant moduli (10 % to 90 % of each branch's stress range), the energy the loop
// dissipates (its area in the top platen's stress-strain plane x the specimen's volume: the platen's net work over
// the loop), the engine's damping and friction over the same loop, and the cracks.
#include <cmath>
#include <limits>
#include <optional>

#include <fmt/format.h>

#include "dem/driver/platen_test.hpp"
#include "dem/driver/registry.hpp"

namespace rbdem {

namespace {

constexpr double nan = std::numeric_limits<double>::quiet_NaN();

// A branch of a loop: the strains at which the stress first passes its 10 % and 90 % stresses, interpolated
// linearly between the readings of two steps.
struct Branch {
  double lo_strain = nan, hi_strain = nan;
  void pass(double lo, double hi, double e0, double s0, double e1, double s1) {
    auto crossed = [&](double s) { return s0 != s1 && (s0 - s) * (s1 - s) <= 0.0; };
    auto at = [&](double s) { return e0 + (s - s0) / (s1 - s0) * (e1 - e0); };
    if (std::isnan(lo_strain) && crossed(lo)) lo_strain = at(lo);
    if (std::isnan(hi_strain) && crossed(hi)) hi_strain = at(hi);
  }
  // The secant modulus between the two stresses (NaN when the branch did not pass both).
  double modulus(double lo, double hi) const { return (hi - lo) / (hi_strain - lo_strain); }
};

// The loop of the cycle under way, from the reversal at its level to the reloading branch's return to it.
struct Loop {
  Cycle row;
  double lo = 0, hi = 0;  // Pa, deviator: 10 % and 90 % of the way from the unload stress to the level
  Branch unloading, reloading;
  double area = 0;        // Pa: the integral of the top platen's stress d eps_a since the reversal
  double damped0 = 0;     // J: the engine's damping and friction at the reversal
};

class CyclicProtocol final : public ConfinedPlatenTest {
 public:
  using ConfinedPlatenTest::ConfinedPlatenTest;
  std::string name() const override { return "cyclic"; }
  void start(Simulation& sim, TestRecord& record) override;
  long max_steps(const Simulation& sim, const TestRecord& record) const override;
  void control(Simulation& sim, const Reading& reading, const TestRecord& record) override;
  bool stop(const Simulation& sim, const Reading& reading, const TestRecord& record,
            std::string& reason) const override;
  void results(const Simulation& sim, const TestRecord& record, TestResult& result) const override;

 protected:
  // The explicit run takes over below the first reversal.
  double start_stress_limit() const override { return pressure() + 0.9 * level(0); }

 private:
  int cycles() const { return scene_.loading.cycles; }
  double level(int k) const { return scene_.loading.cycle_max_stress * double(k + 1) / double(cycles()); }
  double unload_stress() const { return scene_.loading.cycle_unload_stress; }
  static double damped(const Simulation& sim) { return sim.energies().damping + sim.energies().friction; }
  void reverse(Simulation& sim, double strain);
  void reload(Simulation& sim, double strain);
  void close_loop(const Simulation& sim);

  bool started_ = false;      // start() ran (a resumed run has no cycle state: refused)
  double modulus_ = 0;        // Pa: the intact specimen's axial modulus (the static closure solve)
  int next_ = 0;              // the level the platen loads towards; cycles(): the final loading
  bool unloading_ = false;
  // The current loading branch: its highest sigma_1 so far, the step and strain there, the cracks before it.
  double branch_peak_ = -std::numeric_limits<double>::infinity();
  long branch_peak_step_ = 0;
  double branch_peak_strain_ = 0;
  std::size_t branch_cracks_ = 0;
  std::optional<Loop> loop_;  // the loop under way
  bool have_prev_ = false;
  double strain_prev_ = 0, stress_prev_ = 0, top_prev_ = 0;  // the last step's axial strain, sigma_1, top stress
  std::size_t cracks_before_ = 0;             // cracks at the end of the previous cycle
  bool done_ = false;
  std::vector<Cycle> cycles_;
};

void CyclicProtocol::start(Simulation& sim, TestRecord& record) {
  ConfinedPlatenTest::start(sim, record);
  modulus_ = axial_stiffness(sim) * sim.specimen().height() / platens(sim).area();
  started_ = true;
}

// The steps to loading.max_strain, and those of the cycles' unloading and reloading: twice the path of the intact
// specimen (a damaged one is softer).
long CyclicProtocol::max_steps(const Simulation& sim, const TestRecord& record) const {
  const long base = PlatenTest::max_steps(sim, record);
  if (!(modulus_ > 0)) return base;
  double path = 0;  // strain travelled down and back up
  for (int k = 0; k < cycles(); ++k) path += 2.0 * (level(k) - unload_stress()) / modulus_;
  const double per_step = scene_.loading.platen_velocity * record.dt / sim.specimen().height();
  return base + long(std::ceil(2.0 * path / per_step));
}

void CyclicProtocol::control(Simulation& sim, const Reading& r, const TestRecord&) {
  if (!started_)
    throw SceneError("rbdem cyclic keeps its cycles in the run, not in the checkpoint: it cannot resume; run it "
                     "afresh without --resume");
  const double deviator = r.stress - pressure();
  if (have_prev_ && loop_) {
    Loop& l = *loop_;
    // The work is the top platen's (the bottom one is fixed): its stress, not the mean of the two, which differs
    // from it by the specimen's inertia and damping while the platen moves.
    l.area += 0.5 * (top_prev_ + r.stress_top) * (r.strain - strain_prev_);
    const double s0 = stress_prev_ - pressure();
    (unloading_ ? l.unloading : l.reloading).pass(l.lo, l.hi, strain_prev_, s0, r.strain, deviator);
    if (!unloading_ && deviator >= l.row.level) close_loop(sim);
  }
  if (!unloading_ && r.stress > branch_peak_)
    branch_peak_ = r.stress, branch_peak_step_ = sim.steps(), branch_peak_strain_ = r.strain;
  if (!unloading_ && next_ < cycles() && deviator >= level(next_)) reverse(sim, r.strain);
  else if (unloading_ && deviator <= unload_stress()) reload(sim, r.strain);
  strain_prev_ = r.strain, stress_prev_ = r.stress, top_prev_ = r.stress_top, have_prev_ = true;
}

void CyclicProtocol::reverse(Simulation& sim, double strain) {
  sim.find<Platens>()->set_velocity(-scene_.loading.platen_velocity);
  unloading_ = true;
  Loop l;
  l.row.cycle = next_ + 1;
  l.row.level = level(next_);
  l.row.unload_stress = unload_stress();
  l.row.strain_at_level = strain;
  l.row.reversal_step = sim.steps();
  l.lo = unload_stress() + 0.1 * (l.row.level - unload_stress());
  l.hi = unload_stress() + 0.9 * (l.row.level - unload_stress());
  l.damped0 = damped(sim);
  loop_ = l;
}

void CyclicProtocol::reload(Simulation& sim, double strain) {
  sim.find<Platens>()->set_velocity(scene_.loading.platen_velocity);
  unloading_ = false;
  loop_->row.strain_at_unload = strain;
  ++next_;
  branch_peak_ = -std::numeric_limits<double>::infinity();
  branch_cracks_ = sim.cracks().size();
}

void CyclicProtocol::close_loop(const Simulation& sim) {
  Loop& l = *loop_;
  Cycle& c = l.row;
  c.unloading_modulus = l.unloading.modulus(l.lo, l.hi);
  c.reloading_modulus = l.reloading.modulus(l.lo, l.hi);
  c.modulus_loss = 1.0 - c.unloading_modulus / modulus_;
  c.dissipated = l.area * platens(sim).area() * sim.specimen().height();
  c.damped = damped(sim) - l.damped0;
  c.cracks_total = int(sim.cracks().size());
  c.cracks = int(sim.cracks().size() - cracks_before_);
  c.closure_step = sim.steps();
  cracks_before_ = sim.cracks().size();
  cycles_.push_back(c);
  loop_.reset();
  if (next_ >= cycles() && !scene_.loading.cycle_to_failure) done_ = true;
}

// During the cycles the stress falls at every unloading, and a damaged specimen may fail on a reloading branch
// below the run's peak: the post-peak criteria of PlatenTest apply to the peak of the current loading branch, once
// bonds broke on it (a reloading branch starts with the reversal's transients, not with failure).
bool CyclicProtocol::stop(const Simulation& sim, const Reading& r, const TestRecord&, std::string& reason) const {
  if (done_) {
    reason = "cycles_done";
    return true;
  }
  if (r.strain >= scene_.loading.max_strain) {
    reason = "max_strain";
    return true;
  }
  if (unloading_ || sim.cracks().size() == branch_cracks_ || sim.steps() <= branch_peak_step_) return false;
  const double floor = pressure();
  const bool dropped = r.stress - floor < scene_.loading.stop_fraction * (branch_peak_ - floor);
  const bool residual = r.strain > (1.0 + scene_.loading.post_peak_strain) * branch_peak_strain_;
  if (!dropped && !residual) return false;
  reason = dropped ? "post_peak" : "post_peak_strain";
  return true;
}

void CyclicProtocol::results(const Simulation& sim, const TestRecord& record, TestResult& result) const {
  double dissipated = 0;
  for (const Cycle& c : cycles_) dissipated += c.dissipated;
  result.cycles = cycles_;
  // A loop the run ended in (the specimen failed on its reloading branch): its unloading branch is the most damaged
  // state the run measured. Its row has no reloading modulus, loop energy or closure.
  if (loop_ && !unloading_) {
    Cycle c = loop_->row;
    c.unloading_modulus = loop_->unloading.modulus(loop_->lo, loop_->hi);
    c.modulus_loss = 1.0 - c.unloading_modulus / modulus_;
    c.reloading_modulus = c.dissipated = c.damped = nan;
    c.cracks_total = int(sim.cracks().size());
    c.cracks = int(sim.cracks().size() - cracks_before_);
    c.closure_step = -1;
    result.cycles.push_back(c);
  }
  result.own = {{"intact_modulus_pa", modulus_, true},
                {"cycles_completed", double(cycles_.size()), false},
                {"cycle_max_stress_pa", scene_.loading.cycle_max_stress, false},
                {"cycle_unload_stress_pa", unload_stress(), false},
                {"dissipated_total_j", dissipated, true},
                {"deviator_at_peak_pa", record.peak - pressure(), true}};
}

}  // namespace

ProtocolInfo cyclic_protocol() {
  ProtocolInfo p;
  p.name = "cyclic";
  p.description = "loading-unloading cycles to rising levels, then to failure: the modulus against damage";
  p.options = {{"--confining", "loading.confining_pressure",
                "confining pressure sigma_3 [Pa] (loading.confining_pressure); 0: uniaxial"}};
  p.check = [](const Scene& scene) {
    if (scene.specimen.shape == "disc")
      throw SceneError("rbdem cyclic compresses a rectangle between platens: set specimen.shape = \"rectangle\"");
    const LoadingParams& l = scene.loading;
    if (!(l.cycle_unload_stress < l.cycle_max_stress / l.cycles))
      throw SceneError(fmt::format("loading.cycle_unload_stress = {} Pa is not below the first cycle level {} Pa "
                                   "(loading.cycle_max_stress / loading.cycles): lower it, or raise the levels",
                                   l.cycle_unload_stress, l.cycle_max_stress / l.cycles));
    if (l.fast_factor > 1.0)
      throw SceneError("rbdem cyclic sets the platen's speed itself: set loading.fast_factor = 1");
    if (l.mismatch_stop > 0.0)
      throw SceneError("rbdem cyclic sets the platen's speed itself: set loading.mismatch_stop = 0");
    if (l.transit_strain_fraction > 0.0)
      throw SceneError("rbdem cyclic loads at loading.platen_velocity: set loading.transit_strain_fraction = 0");
  };
  p.make = [](const Scene& scene, int curve_points) {
    return std::make_unique<CyclicProtocol>(scene, curve_points);
  };
  p.headline = [](const TestResult& r) {
    if (r.cycles.empty()) return fmt::format("cyclic: no cycle closed; peak {:.2f} MPa", r.peak_stress / 1e6);
    const Cycle &first = r.cycles.front(), &last = r.cycles.back();
    return fmt::format("cyclic: {} cycles to {:.2f} MPa, unloading modulus {:.2f} -> {:.2f} GPa (loss {:.1f} %), "
                       "{} cracks in the cycles; peak {:.2f} MPa",
                       r.cycles.size(), last.level / 1e6, first.unloading_modulus / 1e9, last.unloading_modulus / 1e9,
                       100.0 * last.modulus_loss, last.cracks_total, r.peak_stress / 1e6);
  };
  return p;
}

}  // namespace rbdem
