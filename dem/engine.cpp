// The explicit RB-DEM engine: set-up, the step as a sequence of stages, forces without stepping, diagnostics.
// See engine.hpp.
#include "dem/engine.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <string>

#include <omp.h>

#include "dem/stages/bond_kernel.hpp"

namespace rbdem {

EngineOptions EngineOptions::from_scene(const Scene& scene) {
  EngineOptions o;
  o.damping = scene.numerics.damping;
  o.mass_scaling = scene.numerics.mass_scaling;
  o.threads = scene.numerics.threads;
  o.skip_bonded_pairs = scene.numerics.skip_bonded_pairs;
  o.update_after_breaks = scene.numerics.update_after_breaks;
  o.search_free_faces_only = scene.numerics.search_free_faces_only;
  return o;
}

Engine<2>::Engine(const Topology<2>& topo, const Scene& scene, const EngineOptions& options)
    : options_(options), model_(build_model(topo, scene, options.mass_scaling)) {
  const std::size_t nb = model_.num_blocks(), nbond = model_.num_bonds();
  ModelState<2>& s = state_;
  s.x = model_.x0, s.y = model_.y0;
  s.theta.assign(nb, 0.0), s.vx.assign(nb, 0.0), s.vy.assign(nb, 0.0), s.omega.assign(nb, 0.0);
  s.fx.assign(nb, 0.0), s.fy.assign(nb, 0.0), s.moment.assign(nb, 0.0);
  s.free_face.assign(nb, 0);
  for (int b : topo.boundary.block) s.free_face[std::size_t(b)] = 1;
  s.broken.assign(nbond, 0), s.fs_lin.assign(nbond, 0.0), s.drive.assign(nbond, 0.0);
  s.rebuild = true;

  Workspace<2>& w = work_;
  w.slot.assign(nbond);
  w.cfx.assign(nb, 0.0), w.cfy.assign(nb, 0.0), w.cm.assign(nb, 0.0);

  detection_.contacts = options_.contacts;
  detection_.skip_bonded_pairs = options_.skip_bonded_pairs;
  detection_.update_after_breaks = options_.update_after_breaks;
  detection_.search_free_faces_only = options_.search_free_faces_only;

  nthreads_ = std::max(options_.threads > 0 ? options_.threads : omp_get_max_threads(), 1);
  const char* adapt = std::getenv("RBDEM_ADAPT_THREADS");
  team_ = TeamSize(nthreads_, options_.adapt_threads && !(adapt && std::string(adapt) == "0"));
  w.flagged.assign(std::size_t(nthreads_), {});
  busy_.assign(std::size_t(nthreads_), {});
  refresh();
  s.dt = critical_step();
}

void Engine<2>::attach(BoundaryHooks<2>* hooks) {
  hooks_.push_back(hooks);
  state_.rebuild = true;  // the next broad phase gives the component its candidates
  work_.grid.valid = false;
}

StepContext Engine<2>::context(bool advance) const {
  return {advance ? state_.dt : 0.0, advance, threads()};
}

void Engine<2>::refresh() {
  stages::update_rotations(state_, work_, threads());
  stages::refresh_keep(model_, state_, work_);
  stages::clear_accumulators(work_);  // a step cut short (an exception) may have left forces in them
  state_.rebuild = true;
  work_.grid.valid = false, work_.broken_now.clear();  // the next broad phase starts from the state as it is
}

void Engine<2>::step() {
  // One parallel region per step (docs/performance.md, "A fourth round"): the threads meet at barriers
  // between the stages instead of starting a team for each. A step with bond events or a contact rebuild leaves the
  // region after the bond stage, runs those as before (each on its own team), and opens a second region for the
  // block stages. Every stage does the same work in the same order either way, so the numbers are the same.
  // Where the step's time goes (StepTimes), read on the first thread at the stage boundaries: 0 the start,
  // 1 the bond stage done, 2 the block stages scheduled, 3 the block shares done, 4 their sums done, 5 the
  // region(s) left, 6 the end; `events` the second region's start on a step with events.
  double mark[7] = {}, events = 0;
  mark[0] = omp_get_wtime();
  const StepContext c = context(true);
  ModelState<2>& s = state_;
  Workspace<2>& w = work_;
  const bool sample = team_.begin(mark[0], c.threads);
  stages::bond_forces_begin(model_, w, c);
  stages::rebalance(w);
  stages::rebuild_check_begin(w, c.threads);
  bool finite = true, serial = false;
  std::exception_ptr error;
  // The block stages on thread t of nt: contacts and the components' shares into their records, their sums and the
  // components' ends on the first thread, then the integrator. Returns false when a position is not finite.
  Workspace<2>::Partition& part = w.part;
  const auto block_stages = [&](int t, int nt) {
    const bool timed = nt == part.threads;
    double t0 = omp_get_wtime();
    stages::contact_forces_share(model_, s, w, c, t, nt);
    for (BoundaryHooks<2>* h : hooks_)
      if (h->shares()) h->forces_share(model_, s, w, c, t, nt);
    busy_[std::size_t(t)].phase[1] = omp_get_wtime() - t0;
#pragma omp barrier
#pragma omp master
    {
      mark[3] = omp_get_wtime();
      try {
        stages::contact_forces_end(s, w, c);
        for (BoundaryHooks<2>* h : hooks_) h->forces_end(model_, s, w, c);
      } catch (...) {
        error = std::current_exception();
      }
      mark[4] = omp_get_wtime();
    }
#pragma omp barrier
    if (error) return true;
    t0 = omp_get_wtime();
    int items = 0;
    const bool ok = stages::integrate_share(model_, s, w, options_.damping, t, nt, &items);
    busy_[std::size_t(t)].phase[2] = omp_get_wtime() - t0;
    // The block split follows the integration alone: the contacts go in chunks to any thread.
    if (timed) {
      part.block_seconds[std::size_t(t)] += busy_[std::size_t(t)].phase[2];
      part.block_items[std::size_t(t)] += items;
    }
    return ok;
  };
  const auto begin_block_stages = [&] {
    stages::integrate_begin(model_, w, c.threads);
    stages::contact_forces_begin(model_, s, w, c);
    for (BoundaryHooks<2>* h : hooks_) h->forces_begin(model_, s, w, c);
  };
#pragma omp parallel num_threads(c.threads) reduction(&& : finite)
  {
    const int t = omp_get_thread_num(), nt = omp_get_num_threads();
    if (sample) team_.read(t);
    const double t0 = omp_get_wtime();
    const int bonds = stages::bond_forces_share(model_, s, w, c, t, nt);
    busy_[std::size_t(t)].phase[0] = omp_get_wtime() - t0;
    if (nt == part.threads) {
      part.bond_seconds[std::size_t(t)] += busy_[std::size_t(t)].phase[0];
      part.bond_items[std::size_t(t)] += bonds;
    }
    stages::rebuild_check_share(model_, s, w, t, nt);
#pragma omp barrier
#pragma omp master
    {
      mark[1] = omp_get_wtime();
      serial = stages::events_pending(w) || stages::rebuild_due(model_, s, w, hooks_);
      if (!serial) begin_block_stages();
      mark[2] = omp_get_wtime();
    }
#pragma omp barrier
    if (!serial) finite = block_stages(t, nt);
  }
  if (serial) {
    stages::bond_events(model_, s, w, on_crack, c.threads);
    stages::detect_contacts(model_, s, w, detection_, hooks_, c.threads);
    begin_block_stages();
    events = omp_get_wtime();
#pragma omp parallel num_threads(c.threads) reduction(&& : finite)
    finite = block_stages(omp_get_thread_num(), omp_get_num_threads());
  }
  mark[5] = omp_get_wtime();
  team_.end(mark[5]);
  if (error) std::rethrow_exception(error);
  stages::integrate_end(s, w, finite);  // throws when the run diverged
  for (BoundaryHooks<2>* h : hooks_) h->after_step(model_, s, w, s.dt);
  s.time += s.dt;
  ++s.steps;
  mark[6] = omp_get_wtime();
  StepTimes& T = times_;
  T.bonds += mark[1] - mark[0];
  T.serial += (mark[2] - mark[1]) + (mark[4] - mark[3]);
  T.blocks += (mark[3] - (serial ? events : mark[2])) + (mark[5] - mark[4]);
  if (serial) T.events += events - mark[2], ++T.event_steps;
  T.rest += mark[6] - mark[5];
  ++T.steps;
  if (c.threads == part.threads && !error) {
    for (int k = 0; k < 3; ++k) {
      double sum = 0, most = 0;
      for (int t = 0; t < c.threads; ++t) {
        const double b = busy_[std::size_t(t)].phase[k];
        sum += b, most = std::max(most, b);
      }
      T.busy_mean[k] += sum / c.threads, T.busy_max[k] += most;
    }
    ++T.busy_steps;
  }
}

void Engine<2>::evaluate_forces(std::vector<double>& fx, std::vector<double>& fy, std::vector<double>& moment) {
  const StepContext c = context(false);
  stages::update_rotations(state_, work_, c.threads);
  stages::bond_forces(model_, state_, work_, c);
  stages::detect_contacts(model_, state_, work_, detection_, hooks_, c.threads);
  stages::contact_forces(model_, state_, work_, c);
  for (BoundaryHooks<2>* h : hooks_) {
    h->forces_begin(model_, state_, work_, c);
    if (h->shares()) h->forces_share(model_, state_, work_, c, 0, 1);
  }
  for (BoundaryHooks<2>* h : hooks_) h->forces_end(model_, state_, work_, c);
  stages::gather_forces(model_, work_, fx, fy, moment);
}

void Engine<2>::restore(const ModelState<2>& s) {
  check_state_fits(s, model_.num_blocks(), model_.num_bonds());
  state_ = s;
  refresh();
  state_.rebuild = s.rebuild;  // a snapshot carries its own broad-phase schedule
}

void Engine<2>::edit(const std::function<void(ModelState<2>&)>& change) {
  change(state_);
  check_state_fits(state_, model_.num_blocks(), model_.num_bonds());
  refresh();
}

void Engine<2>::break_bond(int b) {
  edit([&](ModelState<2>& s) {
    const std::size_t k = std::size_t(b);
    s.broken[k] = 1;
    s.free_face[std::size_t(model_.bi[k])] = s.free_face[std::size_t(model_.bj[k])] = 1;
  });
}

void Engine<2>::fix_block(int b, bool fixed) { model_.fixed[std::size_t(b)] = fixed ? 1 : 0; }

void Engine<2>::set_block_mass(int b, double mass, double inertia) {
  const std::size_t k = std::size_t(b);
  model_.mass[k] = mass, model_.inv_mass[k] = 1.0 / mass, model_.inertia[k] = inertia;
}

double Engine<2>::critical_step() const {
  // docs/theory.md, section 8: dt_crit = min over blocks of sqrt(m / k_trans) and sqrt(I / k_rot), with k the sums
  // of the normal and shear stiffnesses acting on the block (parallel bond + linear part in compression; platens).
  const std::size_t nb = model_.num_blocks();
  std::vector<double> kt(nb, 0.0), kr(nb, 0.0);
  const BondFrames& f = model_.frame;
  for (std::size_t b = 0; b < model_.num_bonds(); ++b) {
    const BondStiffness k = model_.stiffness(int(b));
    const double bond = state_.broken[b] ? 0.0 : 1.0;  // a broken bond's pair keeps its linear part as a contact
    const double knA = bond * k.kbnA + k.knA, ksA = bond * k.kbsA + k.ksA;
    for (int side = 0; side < 2; ++side) {
      const int blk = side == 0 ? model_.bi[b] : model_.bj[b];
      const double rx = side == 0 ? f.rix[b] : f.rjx[b], ry = side == 0 ? f.riy[b] : f.rjy[b];
      const double rn = stages::cross(rx, ry, f.n0x[b], f.n0y[b]), rt = rx * f.n0x[b] + ry * f.n0y[b];
      kt[std::size_t(blk)] += knA + ksA;
      kr[std::size_t(blk)] += bond * k.kbnI + knA * rn * rn + ksA * rt * rt;
    }
  }
  for (const BoundaryHooks<2>* h : hooks_) h->add_stiffness(model_, kt, kr);
  double dt = 1e300;
  for (std::size_t b = 0; b < nb; ++b) {
    if (kt[b] > 0) dt = std::min(dt, std::sqrt(model_.mass[b] / kt[b]));
    if (kr[b] > 0) dt = std::min(dt, std::sqrt(model_.inertia[b] / kr[b]));
  }
  return dt;
}

BondForces Engine<2>::bond_forces(int b) const {
  BondForces out;
  const std::size_t k = std::size_t(b);
  if (state_.broken[k]) return out;
  const stages::BondEval ev = stages::eval_bond(model_, state_, work_, b, 0.0, state_.fs_lin[k], 1.0);
  const double keep = work_.keep[k];
  out.fn_b = keep * ev.fnb, out.fs_b = keep * ev.fsb, out.m_b = keep * ev.mb, out.fn_lin = ev.fnl, out.fs_lin = ev.fsl;
  const ParallelBond& law = model_.law[model_.material[k]].bond;
  const ParallelBond::Section sec = law.section(model_.frame.L[k], model_.thickness);
  law.strength.stresses(ev.fnb, ev.fsb, ev.mb, sec.A, sec.I, sec.R, out.sigma, out.tau);
  return out;
}

std::size_t Engine<2>::active_contacts() const {
  return std::size_t(std::count_if(state_.contacts.fn.begin(), state_.contacts.fn.end(), [](double f) { return f > 0; }));
}

Energies Engine<2>::energies() const {
  Energies e;
  const ModelState<2>& s = state_;
  // Each block's kinetic energy, each intact bond's and each contact's stored energy on the run's threads (the
  // driver asks at every curve sample, peak refresh and watchdog check), then each sum serially in block, bond and
  // contact order: the same bits at any thread count.
  const int nblock = int(model_.num_blocks()), nbond = int(model_.num_bonds()), ncontact = int(s.contacts.size());
  std::vector<double> term(std::size_t(nblock + nbond + ncontact));
  double* kinetic = term.data();
  double* bond_energy = kinetic + nblock;
  double* contact_energy = bond_energy + nbond;
#pragma omp parallel num_threads(threads()) if (nblock + nbond + ncontact > 4096)
  {
#pragma omp for schedule(static) nowait
    for (int b = 0; b < nblock; ++b) {
      const std::size_t k = std::size_t(b);
      kinetic[k] = 0.5 * (model_.mass[k] * (s.vx[k] * s.vx[k] + s.vy[k] * s.vy[k]) +
                          model_.inertia[k] * s.omega[k] * s.omega[k]);
    }
#pragma omp for schedule(static) nowait
    for (int b = 0; b < nbond; ++b) {
      const std::size_t k = std::size_t(b);
      if (s.broken[k]) continue;
      // The parallel and linear parts of bond_forces(b), without its stresses.
      const stages::BondEval ev = stages::eval_bond(model_, s, work_, b, 0.0, s.fs_lin[k], 1.0);
      const double keep = work_.keep[k];  // >= 0: the bond is intact
      const double fn_b = keep * ev.fnb, fs_b = keep * ev.fsb, m_b = keep * ev.mb;
      const BondStiffness st = model_.stiffness(b);
      // A damaged bond stores keep k delta^2 / 2 = f^2 / (2 keep k) in its parallel part (f = keep k delta).
      const double inv_keep = keep > 0.0 ? 1.0 / keep : 0.0;
      bond_energy[k] = 0.5 * ((fn_b * fn_b / st.kbnA + fs_b * fs_b / st.kbsA + m_b * m_b / st.kbnI) * inv_keep +
                              ev.fnl * ev.fnl / st.knA + ev.fsl * ev.fsl / st.ksA);
    }
#pragma omp for schedule(static)
    for (int c = 0; c < ncontact; ++c) {
      const std::size_t k = std::size_t(c);
      contact_energy[k] = s.contacts.law[k].strain_energy(s.contacts.fn[k], s.contacts.fs[k], s.contacts.chord[k]);
    }
  }
  for (int b = 0; b < nblock; ++b) e.kinetic += kinetic[b];
  for (int b = 0; b < nbond; ++b)
    if (!s.broken[std::size_t(b)]) e.strain += bond_energy[b];
  for (int c = 0; c < ncontact; ++c) e.strain += contact_energy[c];
  for (const BoundaryHooks<2>* h : hooks_) e.strain += h->stored_energy();
  e.damping = s.e_damping;
  e.friction = s.e_friction;
  for (const BoundaryHooks<2>* h : hooks_) e.work += h->work_done();
  return e;
}

}  // namespace rbdem
