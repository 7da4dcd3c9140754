// The integrator: per-block gather of the bond slots (fixed CSR order, Model::gather) and the contact and boundary
// forces, Cundall's local damping, and the central difference update of x, y, theta (docs/theory.md, section 8).
// It sees forces and masses, never a law. See stages.hpp.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include <omp.h>

#include <fmt/format.h>

#include "dem/engine.hpp"
#include "dem/stages/records.hpp"
#include "dem/stages/stages.hpp"

namespace rbdem::stages {

namespace {

// cos and sin of the blocks [lo, hi). Blocks rotate by well under 0.01 rad until they break free; there the
// Taylor series are exact to round-off (the first omitted terms are below 3e-18 relative) and far cheaper than sin
// and cos. The series run over every block in vector lanes; the few blocks past 0.01 rad then take sin and cos.
[[gnu::always_inline]] inline void rotations_of(const double* theta, double* c, double* sn, int lo, int hi) {
  int large = 0;
#pragma omp simd reduction(| : large)
  for (int b = lo; b < hi; ++b) {
    const double q = theta[b], q2 = q * q;
    sn[b] = q * (1.0 - q2 * (1.0 / 6.0 - q2 * (1.0 / 120.0)));
    c[b] = 1.0 - q2 * (0.5 - q2 * (1.0 / 24.0 - q2 * (1.0 / 720.0)));
    large |= int(!(std::abs(q) < 0.01));
  }
  if (large == 0) return;
  for (int b = lo; b < hi; ++b)
    if (!(std::abs(theta[b]) < 0.01)) c[b] = std::cos(theta[b]), sn[b] = std::sin(theta[b]);
}

// What follows a block's new position: cos and sin of its rotation, then its block record (records.hpp).
struct RecordArrays {
  const double *x, *y, *th, *vx, *vy, *om;
  double *c, *sn;
  Workspace<2>::Record* rec;
  RecordArrays(const ModelState<2>& s, Workspace<2>& w)
      : x(s.x.data()), y(s.y.data()), th(s.theta.data()), vx(s.vx.data()), vy(s.vy.data()), om(s.omega.data()),
        c(w.cos_t.data()), sn(w.sin_t.data()), rec(w.record.data()) {}
  // The blocks [lo, hi).
  [[gnu::always_inline]] inline void update(int lo, int hi) const {
    rotations_of(th, c, sn, lo, hi);
    const RecordFields fields = {x, y, th, vx, vy, om, c, sn};
    pack_records(fields, rec, lo, hi);
  }
};

// RecordArrays::update compiled as the kernels.
[[gnu::target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")]] void rotations_and_records(
    const RecordArrays& a, int lo, int hi) {
  a.update(lo, hi);
}

}  // namespace

void update_rotations(const ModelState<2>& s, Workspace<2>& w, int threads) {
  const int n = int(s.num_blocks());
  w.cos_t.resize(std::size_t(n)), w.sin_t.resize(std::size_t(n)), w.record.resize(std::size_t(n));
  const RecordArrays arrays(s, w);
#pragma omp parallel num_threads(threads)
  {
    const int t = omp_get_thread_num(), nt = omp_get_num_threads();
    rotations_and_records(arrays, int(std::int64_t(n) * t / nt), int(std::int64_t(n) * (t + 1) / nt));
  }
}

void update_rotations_of(const ModelState<2>& s, Workspace<2>& w, const std::vector<int>& blocks) {
  const RecordArrays arrays(s, w);
  for (int b : blocks) arrays.update(b, b + 1);
}

void partition(const Model<2>& m, Workspace<2>& w, int threads) {
  Workspace<2>::Partition& p = w.part;
  if (p.threads == threads) return;
  const int nb = int(m.num_blocks()), nbond = int(m.num_bonds());
  const int grain = Workspace<2>::Partition::kBlockGrain;
  p.threads = threads;
  p.block.assign(std::size_t(threads) + 1, nb), p.bond.assign(std::size_t(threads) + 1, nbond);
  p.block[0] = p.bond[0] = 0;
  for (int t = 1; t < threads; ++t) {
    const int b = std::min(nb, int(std::lround(double(nb) * t / threads / grain)) * grain);
    p.block[std::size_t(t)] = b;
    // The bonds numbered from the blocks below b (bi is ascending).
    p.bond[std::size_t(t)] = int(std::lower_bound(m.bi.begin(), m.bi.end(), b) - m.bi.begin());
  }
  w.damping_work.assign(std::size_t((nb + grain - 1) / grain), 0.0);
  p.bond_seconds.assign(std::size_t(threads), 0.0), p.block_seconds.assign(std::size_t(threads), 0.0);
  p.bond_items.assign(std::size_t(threads), 0.0), p.block_items.assign(std::size_t(threads), 0.0);
  p.bond_next.assign(std::size_t(threads), {}), p.block_next.assign(std::size_t(threads), {});
  p.steps = 0;
}

namespace {

// Moves the boundaries `bounds` (over `total` items, multiples of `grain`) half way to where the threads' own
// ranges would have taken equal times at each thread's measured rate (`items` run in `seconds`, its own and those
// it took from others); no thread gets less than half or more than one and a half times an equal share.
void shift_bounds(std::vector<int>& bounds, const std::vector<double>& seconds, const std::vector<double>& items,
                  int grain) {
  const std::size_t nt = seconds.size();
  const int total = bounds.back();
  std::vector<double> rate(nt);
  double sum = 0.0;
  for (std::size_t t = 0; t < nt; ++t) {
    if (!(seconds[t] > 0.0) || !(items[t] > 0.0)) return;  // nothing measured: keep the split
    rate[t] = items[t] / seconds[t], sum += rate[t];
  }
  const double equal = double(total) / double(nt);
  double at = 0.0;
  for (std::size_t t = 0; t + 1 < nt; ++t) {
    const double now = bounds[t + 1] - bounds[t], balanced = total * rate[t] / sum;
    at += std::clamp(0.5 * (now + balanced), 0.5 * equal, 1.5 * equal);
    const int b = int(std::lround(at / grain)) * grain;
    bounds[t + 1] = std::clamp(b, bounds[t], total);
  }
}

}  // namespace

void rebalance(Workspace<2>& w) {
  Workspace<2>::Partition& p = w.part;
  if (p.threads < 2 || ++p.steps < Workspace<2>::Partition::kRebalanceSteps) return;
  shift_bounds(p.bond, p.bond_seconds, p.bond_items, 1);
  shift_bounds(p.block, p.block_seconds, p.block_items, Workspace<2>::Partition::kBlockGrain);
  for (std::vector<double>* v : {&p.bond_seconds, &p.block_seconds, &p.bond_items, &p.block_items})
    std::fill(v->begin(), v->end(), 0.0);
  p.steps = 0;
}

namespace {

// What the per-block gather reads: the contact and boundary accumulators, which it resets, Model::gather and the
// bond slots. Plain pointers, so that the stores of the integration loop do not make it reload them.
struct GatherArrays {
  double *cfx, *cfy, *cm;
  const int* entry;
  int width;
  const double *slot_fx, *slot_fy, *slot_m;
  GatherArrays(const Model<2>& m, Workspace<2>& w)
      : cfx(w.cfx.data()), cfy(w.cfy.data()), cm(w.cm.data()), entry(m.gather.data()), width(m.gather_width),
        slot_fx(w.slot.fx.data()), slot_fy(w.slot.fy.data()), slot_m(w.slot.m.data()) {}
};

// What the integration reads and writes besides.
struct BlockArrays {
  GatherArrays g;
  RecordArrays records;
  double *fx, *fy, *mz, *vx, *vy, *om, *x, *y, *th;
  const double *inv_mass, *inertia;
  const int* fixed;
  BlockArrays(const Model<2>& m, ModelState<2>& s, Workspace<2>& w)
      : g(m, w), records(s, w), fx(s.fx.data()), fy(s.fy.data()), mz(s.moment.data()), vx(s.vx.data()),
        vy(s.vy.data()), om(s.omega.data()), x(s.x.data()), y(s.y.data()), th(s.theta.data()),
        inv_mass(m.inv_mass.data()), inertia(m.inertia.data()), fixed(m.fixed.data()) {}
};

struct Force {
  double fx, fy, m;
};

// Block b's force and moment: its accumulators, which it resets, plus its gather entries in CSR order. Each entry
// (2 bond + 1 if the block is the bond's j) adds its slot without a branch: a block's role in its bonds follows no
// pattern, so an `if` mispredicts, and x + (-1) a is x - a exactly; the padding entries add the zero slot.
// `Triangles`: the width is 3 and the three entries are written out, since the vectoriser takes no inner loop;
// else a loop over Model::gather_width entries, in the same order. integrate() and gather_forces() both read the
// blocks through this.
template <bool Triangles>
[[gnu::always_inline]] inline Force take_block_forces(const GatherArrays& r, int b) {
  const auto term = [&r](int e) {
    const double sign = (e & 1) ? 1.0 : -1.0;
    return Force{sign * r.slot_fx[e >> 1], sign * r.slot_fy[e >> 1], r.slot_m[e]};
  };
  Force f{r.cfx[b], r.cfy[b], r.cm[b]};
  r.cfx[b] = r.cfy[b] = r.cm[b] = 0.0;
  if constexpr (Triangles) {
    const Force t0 = term(r.entry[3 * b]), t1 = term(r.entry[3 * b + 1]), t2 = term(r.entry[3 * b + 2]);
    return {((f.fx + t0.fx) + t1.fx) + t2.fx, ((f.fy + t0.fy) + t1.fy) + t2.fy, ((f.m + t0.m) + t1.m) + t2.m};
  } else {
    for (int k = 0; k < r.width; ++k) {
      const Force t = term(r.entry[std::size_t(r.width) * std::size_t(b) + std::size_t(k)]);
      f.fx += t.fx, f.fy += t.fy, f.m += t.m;
    }
    return f;
  }
}

// The blocks [g0, g1) of one grain (at most kBlockGrain): gather, local damping, central difference, without
// branches, so that `omp simd` vectorises it (the flags it reads are int, not bytes, for the same reason). Fixed
// blocks compute too and keep their state. Each block's damping work goes to work[b - g0], for the caller to sum in
// block order. Returns false when a position is not finite.
template <bool Triangles>
[[gnu::always_inline]] inline bool block_grain_body(const BlockArrays& arrays, double dt, double alpha, int g0,
                                                    int g1, double* work) {
  const BlockArrays r = arrays;  // a local copy: the stores must not make the loop reload its array pointers
  int finite = 1;
  // Vector lanes for triangles only: with a loop inside (any width) the loop does not vectorise.
#pragma omp simd reduction(& : finite) if (Triangles)
  for (int b = g0; b < g1; ++b) {
    const Force f = take_block_forces<Triangles>(r.g, b);
    const double fx = f.fx, fy = f.fy, mz = f.m;
    r.fx[b] = fx, r.fy[b] = fy, r.mz[b] = mz;
    const bool free = r.fixed[b] == 0;
    const double vx0 = r.vx[b], vy0 = r.vy[b], om0 = r.om[b], x0 = r.x[b], y0 = r.y[b], th0 = r.th[b];
    double vx = vx0, vy = vy0, om = om0;
    // Cundall local damping: F_d = -alpha |F| sign(v), per degree of freedom.
    const double dfx = -alpha * std::abs(fx) * double((vx > 0) - (vx < 0));
    const double dfy = -alpha * std::abs(fy) * double((vy > 0) - (vy < 0));
    const double dm = -alpha * std::abs(mz) * double((om > 0) - (om < 0));
    work[b - g0] = free ? (dfx * vx + dfy * vy + dm * om) * dt : 0.0;
    vx += dt * (fx + dfx) * r.inv_mass[b];
    vy += dt * (fy + dfy) * r.inv_mass[b];
    om += dt * (mz + dm) / r.inertia[b];
    const double x = free ? x0 + dt * vx : x0, y = free ? y0 + dt * vy : y0, th = free ? th0 + dt * om : th0;
    r.vx[b] = free ? vx : vx0, r.vy[b] = free ? vy : vy0, r.om[b] = free ? om : om0;
    r.x[b] = x, r.y[b] = y, r.th[b] = th;
    // std::isfinite, as a comparison the vectoriser takes (false for NaN too)
    constexpr double big = std::numeric_limits<double>::max();
    finite &= int(std::abs(x) <= big) & int(std::abs(y) <= big) & int(std::abs(th) <= big);
  }
  return finite != 0;
}

// One grain's integration, then its new cos and sin and its block records while they are in the cache. Compiled
// for AVX-512, AVX2 and the baseline, as the bond kernel (bonds.cpp), with the same numbers in each. Blocks with
// more than three bonds (models built from other polygons, as in some tests) take the loop.
[[gnu::target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")]] bool block_grain(const BlockArrays& r, double dt,
                                                                                       double alpha, int g0, int g1,
                                                                                       double* work) {
  const bool ok = r.g.width == 3 ? block_grain_body<true>(r, dt, alpha, g0, g1, work)
                                 : block_grain_body<false>(r, dt, alpha, g0, g1, work);
  r.records.update(g0, g1);
  return ok;
}

}  // namespace

void integrate_begin(const Model<2>& m, Workspace<2>& w, int threads) {
  partition(m, w, threads);
  Workspace<2>::reset(w.part.block_next);
}

bool integrate_share(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, double damping, int t, int,
                     int* items) {
  const int grain = Workspace<2>::Partition::kBlockGrain;
  const BlockArrays arrays(m, s, w);
  double work[Workspace<2>::Partition::kBlockGrain];
  bool ok = true;
  Workspace<2>::Partition& p = w.part;
  // Any team runs every piece: one of another size than the partition's (inside another parallel region) too.
  const int ran = Workspace<2>::run_pieces(p.block, p.block_next, Workspace<2>::Partition::kBlockPiece, t,
                                           [&](int lo, int hi) {
    for (int g0 = lo; g0 < hi; g0 += grain) {
      const int g1 = std::min(g0 + grain, hi);
      ok = block_grain(arrays, s.dt, damping, g0, g1, work) && ok;
      double e_damp = 0.0;
      for (int b = g0; b < g1; ++b) e_damp -= work[b - g0];
      w.damping_work[std::size_t(g0 / grain)] = e_damp;
    }
  });
  if (items) *items = ran;
  return ok;
}

void integrate_end(ModelState<2>& s, Workspace<2>& w, bool finite) {
  double e_damp = 0.0;
  for (double e : w.damping_work) e_damp += e;
  s.e_damping += e_damp;
  if (!finite)
    throw InstabilityError(fmt::format(
        "the run diverged at step {} (t = {:.4g} s): positions are no longer finite. The time step {:.4g} s is too "
        "large for this scene; lower numerics.dt or numerics.dt_safety",
        s.steps, s.time, s.dt));
}

void integrate(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, double damping, int threads) {
  integrate_begin(m, w, threads);
  bool finite = true;
#pragma omp parallel num_threads(threads) reduction(&& : finite)
  finite = integrate_share(m, s, w, damping, omp_get_thread_num(), omp_get_num_threads(), nullptr);
  integrate_end(s, w, finite);
}

void clear_accumulators(Workspace<2>& w) {
  std::fill(w.cfx.begin(), w.cfx.end(), 0.0);
  std::fill(w.cfy.begin(), w.cfy.end(), 0.0);
  std::fill(w.cm.begin(), w.cm.end(), 0.0);
}

void gather_forces(const Model<2>& m, Workspace<2>& w, std::vector<double>& fx, std::vector<double>& fy,
                   std::vector<double>& moment) {
  const std::size_t n = m.num_blocks();
  fx.resize(n), fy.resize(n), moment.resize(n);
  const GatherArrays gather(m, w);
  for (std::size_t b = 0; b < n; ++b) {
    const Force f = take_block_forces<false>(gather, int(b));
    fx[b] = f.fx, fy[b] = f.fy, moment[b] = f.m;
  }
}

}  // namespace rbdem::stages
