// The bond stage and the bond events. See stages.hpp.
//
// The kernel runs over every bond in bond order (not over a list of intact ones), reading contiguous frame
// arrays: a broken bond writes a zero slot. Bonds whose failure test holds are collected per thread; the events
// (softening, breakage, the crack log) are then handled serially in bond order, so the outcome does not depend on
// the thread count. Softened bonds carry the fraction `keep` of their elastic forces set by the largest failure
// index reached up to the previous step (docs/model.md, "Softening bonds").
#include <algorithm>
#include <cstdint>

#include <omp.h>

#include "dem/stages/bond_kernel.hpp"
#include "dem/stages/records.hpp"
#include "dem/stages/stages.hpp"

namespace rbdem::stages {

namespace {

// What one thread's share of the kernel reads and writes.
struct KernelRange {
  BondArrays a;
  const Workspace<2>::Record* rec;  // the blocks' kinematics, read in place of a's block arrays
  const double *tension_limit, *cohesion_A, *tan_phi, *beta_m, *inv_L;  // the strength in force units
  const double *drive, *keep;
  double* fs_lin;
  double *slot_fx, *slot_fy, *slot_m;
  int* flag;
  double dt;
  double arm;         // the law's moment lever A R / I x L (ParallelBond::moment_arm)
  int advance, test;  // 0 or 1 (int, not bool: the vectoriser does not take one-bit values from memory)
  int lo, hi;
};

// Bonds per chunk of the kernel: their blocks' records are transposed into bond-ordered rows first (records.hpp),
// which the kernel's loop then reads contiguously from the first level of the cache.
constexpr int kChunk = 64;

// The kernel over the bonds [b0, b0 + n), n at most kChunk: no branches, so `omp simd` vectorises it; broken bonds
// compute too and write a zero slot. `Damaged`: some bond carries only part of its elastic forces (a softening bond
// past its strength), else every factor is 1 and the kernel skips the multiplications. flag[b] = 1 where the
// failure test held; returns whether it held anywhere.
template <bool Damaged>
[[gnu::always_inline]] inline bool bond_chunk(const KernelRange& r, int b0, int n) {
  alignas(64) double ri[Workspace<2>::kRecordFields][kChunk], rj[Workspace<2>::kRecordFields][kChunk];
  load_records(r.rec, r.a.bi + b0, n, ri);
  load_records(r.rec, r.a.bj + b0, n, rj);
  int any = 0;
#pragma omp simd reduction(| : any)
  for (int k = 0; k < n; ++k) {
    const int b = b0 + k;
    const double factor = r.keep[b];  // read always: a read under a condition would not vectorise
    const bool alive = factor >= 0.0;  // broken bonds are marked -1 (refresh_keep)
    const BlockKin I{ri[0][k], ri[1][k], ri[2][k], ri[3][k], ri[4][k], ri[5][k], ri[6][k], ri[7][k]};
    const BlockKin J{rj[0][k], rj[1][k], rj[2][k], rj[3][k], rj[4][k], rj[5][k], rj[6][k], rj[7][k]};
    const BondEval ev = eval_bond(r.a, b, I, J, r.dt, r.fs_lin[b], Damaged ? factor : 1.0);
    r.slot_fx[b] = alive ? ev.fx : 0.0;
    r.slot_fy[b] = alive ? ev.fy : 0.0;
    r.slot_m[2 * b] = alive ? ev.mi : 0.0;
    r.slot_m[2 * b + 1] = alive ? ev.mj : 0.0;
    r.fs_lin[b] = (alive & (r.advance != 0)) ? ev.fsl : r.fs_lin[b];
    // The law's failure test (BondLoad::exceeds) at the bond's scale: a pre-filter, the events apply the law itself.
    const BondLoad q = BondLoad::of(r.tension_limit[b], r.cohesion_A[b], r.tan_phi[b], r.beta_m[b], ev.fnb, ev.fsb,
                                    ev.mb, r.inv_L[b], r.arm);
    const double scale = r.drive[b] > 0.0 ? r.drive[b] : 1.0;
    const int flag = (r.test != 0) & alive & q.exceeds(scale);
    r.flag[b] = flag;
    any |= flag;
  }
  return any != 0;
}

template <bool Damaged>
[[gnu::always_inline]] inline bool bond_range_body(const KernelRange& range) {
  const KernelRange r = range;  // a local copy: the stores must not make the loop reload its array pointers
  bool any = false;
  for (int b0 = r.lo; b0 < r.hi; b0 += kChunk) any = bond_chunk<Damaged>(r, b0, std::min(kChunk, r.hi - b0)) || any;
  return any;
}

// The kernel compiled for AVX-512, AVX2 and the baseline instruction set, one chosen when the program starts. The
// arithmetic is the same in each (no fused multiply-add, no reassociation: dem/CMakeLists.txt), so are the numbers.
[[gnu::target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")]] bool bond_range_intact(const KernelRange& r) {
  return bond_range_body<false>(r);
}
[[gnu::target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")]] bool bond_range_damaged(const KernelRange& r) {
  return bond_range_body<true>(r);
}

}  // namespace

void bond_forces_begin(const Model<2>& m, Workspace<2>& w, const StepContext& c) {
  partition(m, w, c.threads);
  Workspace<2>::reset(w.part.bond_next);
  if (int(w.flagged.size()) < c.threads) w.flagged.resize(std::size_t(c.threads));
  for (auto& v : w.flagged) v.clear();
  w.flag.resize(m.num_bonds());
}

int bond_forces_share(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, const StepContext& c, int t, int nt) {
  const bool test = c.advance && s.breakage;
  const BondFrames& f = m.frame;
  KernelRange range{BondArrays(m, s, w), w.record.data(), f.tension_limit.data(), f.cohesion_A.data(),
                    f.tan_phi.data(), f.beta_m.data(), f.inv_L.data(), s.drive.data(), w.keep.data(),
                    s.fs_lin.data(), w.slot.fx.data(), w.slot.fy.data(), w.slot.m.data(), w.flag.data(), c.dt,
                    m.law[0].bond.moment_arm(), int(c.advance), int(test), 0, 0};
  // The flagged bonds of the pieces this thread ran, in the order it ran them (bond_events sorts them). Any team
  // runs every piece: one of another size than the partition's (inside another parallel region) too.
  (void)nt;
  auto& mine = w.flagged[std::size_t(t)];
  return Workspace<2>::run_pieces(w.part.bond, w.part.bond_next, Workspace<2>::Partition::kBondPiece, t,
                                  [&](int lo, int hi) {
    range.lo = lo, range.hi = hi;
    if (!(w.damaged > 0 ? bond_range_damaged(range) : bond_range_intact(range))) return;
    for (int b = lo; b < hi; ++b)
      if (w.flag[std::size_t(b)]) mine.push_back(b);
  });
}

void bond_forces(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, const StepContext& c) {
  bond_forces_begin(m, w, c);
#pragma omp parallel num_threads(c.threads)
  bond_forces_share(m, s, w, c, omp_get_thread_num(), omp_get_num_threads());
}

void refresh_keep(const Model<2>& m, const ModelState<2>& s, Workspace<2>& w) {
  const std::size_t n = m.num_bonds();
  w.keep.resize(n);
  w.damaged = 0;
  for (std::size_t b = 0; b < n; ++b) {
    w.keep[b] = s.broken[b] ? -1.0 : ParallelBond::intact_fraction(s.drive[b], m.frame.rupture[b]);
    if (!s.broken[b] && s.drive[b] > 0.0) ++w.damaged;
  }
}

int bond_events(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, const std::function<void(const Crack&)>& on_crack,
                int threads) {
  w.events.clear();
  for (const auto& list : w.flagged) w.events.insert(w.events.end(), list.begin(), list.end());
  std::sort(w.events.begin(), w.events.end());  // the threads took the pieces in any order: bond order again
  const int n = int(w.events.size());
  if (n == 0) return 0;
  // The positions have not moved since the kernel, and an event changes only its own bond: each flagged bond's
  // evaluation gives the same undamaged forces as in the kernel, whatever the events before it did.
  w.event_forces.resize(std::size_t(n));
#pragma omp parallel for schedule(static) num_threads(threads) if (n > 64)
  for (int e = 0; e < n; ++e) {
    const int b = w.events[std::size_t(e)];
    const BondEval ev = eval_bond(m, s, w, b, 0.0, s.fs_lin[std::size_t(b)], 1.0);
    w.event_forces[std::size_t(e)] = {ev.fnb, ev.fsb, ev.mb, ev.px, ev.py};
  }
  int breaks = 0;
  for (int e = 0; e < n; ++e) {
    const int b = w.events[std::size_t(e)];
    const std::size_t k = std::size_t(b);
    const BondKindLaw& law = m.law[m.material[k]];
    const Workspace<2>::EventForces& ev = w.event_forces[std::size_t(e)];
    const BondLoad q = BondLoad::of(m.frame.tension_limit[k], m.frame.cohesion_A[k], m.frame.tan_phi[k],
                                    m.frame.beta_m[k], ev.fn, ev.fs, ev.m, m.frame.inv_L[k], law.bond.moment_arm());
    const bool was_damaged = s.drive[k] > 0.0;
    const BreakMode mode = law.bond.advance(q, m.frame.rupture[k], s.drive[k]);
    w.keep[k] = ParallelBond::intact_fraction(s.drive[k], m.frame.rupture[k]);
    if (!was_damaged && s.drive[k] > 0.0) ++w.damaged;
    if (mode == BreakMode::none) continue;
    Crack crack;
    const ParallelBond::Section sec = law.bond.section(m.frame.L[k], m.thickness);
    law.bond.strength.stresses(ev.fn, ev.fs, ev.m, sec.A, sec.I, sec.R, crack.sigma, crack.tau);
    crack.mode = mode, crack.bond = b, crack.kind = m.kind[k];
    crack.position = {ev.px, ev.py, 0.0};
    crack.normal = {m.frame.n0x[k], m.frame.n0y[k], 0.0};
    crack.size = m.frame.L[k];
    crack.time = s.time, crack.strain = s.strain_for_log;
    if (s.drive[k] > 0.0) --w.damaged;
    s.broken[k] = 1;
    w.keep[k] = -1.0;
    w.slot.zero(k);  // the pair's contact carries the linear part from now on
    s.free_face[std::size_t(m.bi[k])] = s.free_face[std::size_t(m.bj[k])] = 1;
    // With skip_bonded_pairs = false the pair is in the contact list already: it takes over the linear shear.
    const int lo = std::min(m.bi[k], m.bj[k]), hi = std::max(m.bi[k], m.bj[k]);
    const std::uint64_t key = (std::uint64_t(std::uint32_t(lo)) << 32) | std::uint32_t(hi);
    const auto at = std::lower_bound(s.contacts.key.begin(), s.contacts.key.end(), key);
    if (at != s.contacts.key.end() && *at == key) s.contacts.fs[std::size_t(at - s.contacts.key.begin())] = s.fs_lin[k];
    w.broken_now.push_back(b);
    s.cracks.push_back(crack);
    if (on_crack) on_crack(crack);
    ++breaks;
  }
  if (breaks > 0) s.rebuild = true;
  return breaks;
}

}  // namespace rbdem::stages
