// The bond stage and the bond events. See stages.hpp.
//
// The kernel runs over every bond in bond order (not over a list of intact ones), reading contiguous frame
// arrays: a broken bond writes a zero slot. Bonds whose failure test holds are collected per thread; the events
// (softening, breakage, the crack log) are then handled serially in bond order, so the outcome does not depend on
// the thread count. Softened bonds carry the fraction `keep` of their elastic forces set by the largest failure
// index reached up to the previous step (docs/model.md, "Softening bonds").
#include <algorithm>

#include <omp.h>

#include "dem/stages/bond_kernel.hpp"
#include "dem/stages/stages.hpp"

namespace rbdem::stages {

void bond_forces(const Model& m, ModelState& s, Workspace& w, const StepContext& c) {
  const int n = int(m.num_bonds());
  const bool test = c.advance && s.breakage;
  if (int(w.flagged.size()) < c.threads) w.flagged.resize(std::size_t(c.threads));
  for (auto& v : w.flagged) v.clear();
  const std::uint8_t* broken = s.broken.data();
  double* fs_lin = s.fs_lin.data();
  const double* drive = s.drive.data();
  const double* keep = w.keep.data();
  double *sfx = w.slot_fx.data(), *sfy = w.slot_fy.data(), *smi = w.slot_mi.data(), *smj = w.slot_mj.data();
  const BondFrames& f = m.frame;
#pragma omp parallel num_threads(c.threads)
  {
    auto& mine = w.flagged[std::size_t(omp_get_thread_num())];
#pragma omp for schedule(static) nowait
    for (int b = 0; b < n; ++b) {
      if (broken[b]) {
        sfx[b] = sfy[b] = smi[b] = smj[b] = 0.0;
        continue;
      }
      double fs = fs_lin[b];
      BondEval ev;
      eval_bond(m, s, w, b, c.dt, fs, keep[b], ev);
      sfx[b] = ev.fx, sfy[b] = ev.fy, smi[b] = ev.mi, smj[b] = ev.mj;
      if (!c.advance) continue;
      fs_lin[b] = fs;
      if (!test) continue;
      const BondStrength& st = m.law[int(m.kind[std::size_t(b)])].bond.strength;
      const BondLoad q = BondLoad::of(st, ev.fnb, ev.fsb, ev.mb, f.inv_L[std::size_t(b)], f.A[std::size_t(b)]);
      if (q.failure(drive[b] > 0.0 ? drive[b] : 1.0) != BreakMode::none) mine.push_back(b);
    }
  }
}

void refresh_keep(const Model& m, const ModelState& s, Workspace& w) {
  const std::size_t n = m.num_bonds();
  w.keep.resize(n);
  for (std::size_t b = 0; b < n; ++b)
    w.keep[b] = s.broken[b] ? 0.0 : ParallelBond::intact_fraction(s.drive[b], m.frame.rupture[b]);
}

int bond_events(const Model& m, ModelState& s, Workspace& w, const std::function<void(const Crack&)>& on_crack) {
  int breaks = 0;
  for (const auto& list : w.flagged)
    for (const int b : list) {
      const std::size_t k = std::size_t(b);
      const BondKindLaw& law = m.law[int(m.kind[k])];
      // The positions have not moved since the kernel: the same evaluation gives the same undamaged forces.
      double fs = s.fs_lin[k];
      BondEval ev;
      eval_bond(m, s, w, b, 0.0, fs, 1.0, ev);
      const BondLoad q = BondLoad::of(law.bond.strength, ev.fnb, ev.fsb, ev.mb, m.frame.inv_L[k], m.frame.A[k]);
      const BreakMode mode = law.bond.advance(q, m.frame.rupture[k], s.drive[k]);
      w.keep[k] = ParallelBond::intact_fraction(s.drive[k], m.frame.rupture[k]);
      if (mode == BreakMode::none) continue;
      Crack crack;
      const double L = m.frame.L[k], A = m.frame.A[k];
      law.bond.strength.stresses(ev.fnb, ev.fsb, ev.mb, A, A * L * L / 12.0, 0.5 * L, crack.sigma, crack.tau);
      crack.mode = mode, crack.bond = b, crack.kind = m.kind[k], crack.x = ev.px, crack.y = ev.py;
      crack.time = s.time, crack.strain = s.strain_for_log;
      s.broken[k] = 1;
      w.keep[k] = 0.0;
      w.slot_fx[k] = w.slot_fy[k] = w.slot_mi[k] = w.slot_mj[k] = 0.0;  // the pair's contact carries the linear part
      s.free_face[std::size_t(m.bi[k])] = s.free_face[std::size_t(m.bj[k])] = 1;
      // With skip_bonded_pairs = false the pair is in the contact list already: it takes over the linear shear.
      const int lo = std::min(m.bi[k], m.bj[k]), hi = std::max(m.bi[k], m.bj[k]);
      const std::uint64_t key = (std::uint64_t(std::uint32_t(lo)) << 32) | std::uint32_t(hi);
      const auto at = std::lower_bound(s.contacts.key.begin(), s.contacts.key.end(), key);
      if (at != s.contacts.key.end() && *at == key) s.contacts.fs[std::size_t(at - s.contacts.key.begin())] = s.fs_lin[k];
      s.cracks.push_back(crack);
      if (on_crack) on_crack(crack);
      ++breaks;
    }
  if (breaks > 0) s.rebuild = true;
  return breaks;
}

}  // namespace rbdem::stages
