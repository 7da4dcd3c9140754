// The explicit engine of the 3D model. See engine3.hpp.
#include "dem/engine3.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>

#include <fmt/format.h>
#include <omp.h>

namespace rbdem {

namespace {

// The contiguous share [lo, hi) of n items for thread t of nt: the same split for the same nt, and the shares in
// thread order are the items in order.
std::array<std::size_t, 2> share(std::size_t n, int t, int nt) {
  return {n * std::size_t(t) / std::size_t(nt), n * std::size_t(t + 1) / std::size_t(nt)};
}
// The share of the bonds in whole tiles of the table (the last one may be short), so that each chunk of the bond
// stage is one tile. Which thread computes a bond does not change its numbers.
std::array<std::size_t, 2> bond_share(std::size_t n, int t, int nt) {
  constexpr std::size_t tile = stages::FaceBondTable::kTile;
  const auto [lo, hi] = share((n + tile - 1) / tile, t, nt);
  return {std::min(n, lo * tile), std::min(n, hi * tile)};
}

}  // namespace

Engine<3>::Engine(const TetMesh& mesh, const Scene& scene, const EngineOptions& options)
    : options_(options), model_(build_model(mesh, scene, options.mass_scaling)) {
  const std::size_t nb = model_.num_blocks(), nbond = model_.num_bonds();
  ModelState<3>& s = state_;
  s.x.resize(nb), s.y.resize(nb), s.z.resize(nb);
  for (std::size_t b = 0; b < nb; ++b) s.x[b] = model_.x0[b].x, s.y[b] = model_.x0[b].y, s.z[b] = model_.x0[b].z;
  s.qw.assign(nb, 1.0);
  for (auto* v : {&s.qx, &s.qy, &s.qz, &s.vx, &s.vy, &s.vz, &s.wx, &s.wy, &s.wz, &s.fx, &s.fy, &s.fz, &s.mx, &s.my,
                  &s.mz})
    v->assign(nb, 0.0);
  s.broken.assign(nbond, 0);
  s.fs1.assign(nbond, 0.0), s.fs2.assign(nbond, 0.0), s.drive.assign(nbond, 0.0);
  slot_.resize(nbond);
  refresh_records();
  ext_f_.resize(nb), ext_m_.resize(nb), damping_work_.resize(nb);
  nthreads_ = std::max(options_.threads > 0 ? options_.threads : omp_get_max_threads(), 1);
  const char* adapt = std::getenv("RBDEM_ADAPT_THREADS");
  team_ = TeamSize(nthreads_, options_.adapt_threads && !(adapt && std::string(adapt) == "0"));
  breaks_.assign(std::size_t(nthreads_), {});
  s.dt = critical_step();
}

int Engine<3>::threads() const {
  const int n = team_.size();
  return options_.thread_budget ? std::clamp(options_.thread_budget->load(std::memory_order_relaxed), 1, n) : n;
}

double Engine<3>::critical_step() const {
  const Model<3>& m = model_;
  std::vector<BlockStiffness3> k(m.num_blocks());
  for (std::size_t b = 0; b < m.num_bonds(); ++b) {
    const stages::FaceBondFrame& f = m.frame[b];
    // The parallel bond and the linear part side by side (partly closed, the linear part bends and twists too).
    const double kb = 2 * std::max({f.k.kb1, f.k.kb2, f.k.kt});
    k[std::size_t(m.bi[b])].add(2 * f.k.kn, 2 * f.k.ks, kb, f.ri, f.axes.r[2]);
    k[std::size_t(m.bj[b])].add(2 * f.k.kn, 2 * f.k.ks, kb, f.rj, f.axes.r[2]);
  }
  for (const BoundaryHooks<3>* h : hooks_) h->add_stiffness(m, k);
  double dt = std::numeric_limits<double>::infinity();
  for (std::size_t b = 0; b < m.num_blocks(); ++b) dt = std::min(dt, k[b].critical_step(m.body[b]));
  return dt;
}

void Engine<3>::restore(const ModelState<3>& s) {
  if (s.num_blocks() != model_.num_blocks() || s.num_bonds() != model_.num_bonds())
    throw std::invalid_argument(fmt::format("the state has {} blocks and {} bonds, the model {} and {}: it was "
                                            "written for another scene or mesh", s.num_blocks(), s.num_bonds(),
                                            model_.num_blocks(), model_.num_bonds()));
  state_ = s;
  refresh_records();
}

void Engine<3>::break_bond(int b) { state_.broken.at(std::size_t(b)) = 1; }

void Engine<3>::fix_block(int b, bool fixed) {
  model_.fixed.at(std::size_t(b)) = fixed ? 1 : 0;
  if (fixed) {
    const std::size_t k = std::size_t(b);
    state_.vx[k] = state_.vy[k] = state_.vz[k] = state_.wx[k] = state_.wy[k] = state_.wz[k] = 0.0;
    refresh_record(k);
  }
}

// --- the bond stage ------------------------------------------------------------------------------------------------

void Engine<3>::refresh_record(std::size_t b) {
  const ModelState<3>& s = state_;
  record_[b] = stages::block_record(s.position(b), s.rotation(b), s.velocity(b), s.spin(b));
}

void Engine<3>::refresh_records() {
  record_.resize(state_.num_blocks());
  for (std::size_t b = 0; b < record_.size(); ++b) refresh_record(b);
}

stages::FaceBondOut Engine<3>::bond_now(std::size_t b, double& keep) const {
  using F = stages::FaceBondTable;
  const Model<3>& m = model_;
  const ModelState<3>& s = state_;
  const stages::FaceBondColumns t = stages::FaceBondColumns::of(m.table, b);
  const std::size_t k = stages::FaceBondColumns::lane(b);
  const bool broken = s.broken[b] != 0;
  keep = broken ? 0.0 : stages::intact_fraction(s.drive[b], t(F::rupture, k));
  std::int64_t regular = 1;
  return stages::face_bond_forces<true>(t, k, record_[std::size_t(m.bi[b])], record_[std::size_t(m.bj[b])], 0.0,
                                        s.fs1[b], s.fs2[b], keep, broken ? t(F::mu_broken, k) : t(F::mu_bonded, k),
                                        regular);
}

namespace {

// Bonds per chunk of the kernel, one tile of the table: its per-bond results stay in the first level of the cache
// until the serial pass.
constexpr int kChunk = int(stages::FaceBondTable::kTile);

// What one thread's share of the kernel reads and writes.
struct BondRange {
  const stages::FaceBondTable* table;
  const int *bi, *bj;
  const stages::BlockRecord3* record;
  const double *drive, *fs1, *fs2;
  stages::FaceBondSlot* slot;
  double dt;
};
// One chunk's bonds: 1 where a bond is intact (read before the kernel), and the results: the new shear history, and
// per bond 1 where the branch-free form does not hold (the exact form recomputes it) plus 2 where the failure test's
// load reaches the bond's strength (the law then decides). The flags are 64 bits wide, as the doubles are: a vector
// loop has as many lanes as its narrowest type fits in a register, so one byte or 32-bit integer in the kernel
// spreads each double over eight or two registers, which then spill (it did: 64 lanes for AVX-512).
struct Chunk {
  std::int64_t intact[kChunk];
  double fs1[kChunk], fs2[kChunk];
  std::int64_t flag[kChunk];
};

// Bond b's intact fraction and the linear part's friction; t is its tile and k its lane there, `intact` 0 once it
// is broken.
[[gnu::always_inline]] inline void bond_status(const BondRange& r, const stages::FaceBondColumns& t, std::size_t k,
                                               std::size_t b, std::int64_t intact, double& keep, double& mu) {
  using F = stages::FaceBondTable;
  const double fraction = stages::intact_fraction(r.drive[b], t(F::rupture, k));
  const double mu_broken = t(F::mu_broken, k), mu_bonded = t(F::mu_bonded, k);  // both read: no branch
  keep = intact != 0 ? fraction : 0.0;
  mu = intact != 0 ? mu_bonded : mu_broken;
}

// The doubles of a block record the kernel reads (BlockRecord3 but its padding).
constexpr int kRecord = 13;
using Rows = double[kRecord][kChunk];

// Eight doubles as one value of the vector extension (GCC and Clang; __builtin_shufflevector in both): one AVX-512
// register, two AVX2 or four SSE2 ones.
typedef double V8 __attribute__((vector_size(64)));

// The 8 x 8 transpose of v[0 .. 8) in place, by three rounds of two-source shuffles (elements, pairs, halves):
// 24 shuffles where the element by element copy takes 64 loads and 64 stores.
[[gnu::always_inline]] inline void transpose8(V8 v[8]) {
  V8 t[8];
  for (int i = 0; i < 8; i += 2) {  // t[i] = a0 b0 a2 b2 ..., t[i + 1] = a1 b1 a3 b3 ... of a = v[i], b = v[i + 1]
    t[i] = __builtin_shufflevector(v[i], v[i + 1], 0, 8, 2, 10, 4, 12, 6, 14);
    t[i + 1] = __builtin_shufflevector(v[i], v[i + 1], 1, 9, 3, 11, 5, 13, 7, 15);
  }
  for (int i = 0; i < 8; i += 4)  // v[i + j] = a_j b_j c_j d_j a_j+4 ..., v[i + j + 2] the same for j + 2
    for (int j = 0; j < 2; ++j) {
      v[i + j] = __builtin_shufflevector(t[i + j], t[i + j + 2], 0, 1, 8, 9, 4, 5, 12, 13);
      v[i + j + 2] = __builtin_shufflevector(t[i + j], t[i + j + 2], 2, 3, 10, 11, 6, 7, 14, 15);
    }
  for (int j = 0; j < 4; ++j) {  // the element j and j + 4 of all eight
    t[j] = __builtin_shufflevector(v[j], v[j + 4], 0, 1, 2, 3, 8, 9, 10, 11);
    t[j + 4] = __builtin_shufflevector(v[j], v[j + 4], 4, 5, 6, 7, 12, 13, 14, 15);
  }
  for (int i = 0; i < 8; ++i) v[i] = t[i];
}

// The records of the blocks idx[0 .. n) transposed into rows: the vector lanes then read them contiguously. Eight
// records at a time as two 8 x 8 blocks (a record is 16 doubles, 64-byte aligned), the rest one by one; the same
// values either way.
[[gnu::always_inline]] inline void load_records(const stages::BlockRecord3* record, const int* idx, int n, Rows& rows) {
  int k = 0;
  for (; k + 8 <= n; k += 8) {
    V8 lo[8], hi[8];
    for (int i = 0; i < 8; ++i) {
      const double* p = &record[idx[k + i]].x.x;
      std::memcpy(&lo[i], p, sizeof(V8)), std::memcpy(&hi[i], p + 8, sizeof(V8));
    }
    transpose8(lo), transpose8(hi);
    for (int f = 0; f < 8; ++f) std::memcpy(&rows[f][k], &lo[f], sizeof(V8));
    for (int f = 8; f < kRecord; ++f) std::memcpy(&rows[f][k], &hi[f - 8], sizeof(V8));
  }
  for (; k < n; ++k) {
    const double* p = &record[idx[k]].x.x;
    for (int f = 0; f < kRecord; ++f) rows[f][k] = p[f];
  }
}
[[gnu::always_inline]] inline stages::BlockRecord3 record_at(const Rows& a, int k) {
  return {{a[0][k], a[1][k], a[2][k]},
          {a[3][k], a[4][k], a[5][k], a[6][k]},
          {a[7][k], a[8][k], a[9][k]},
          {a[10][k], a[11][k], a[12][k]}};
}

// The bonds [b0, b0 + n), one tile of the table, in the branch-free form: no branches and no dependence between
// iterations (ivdep: the slots and the chunk's results are written at the bond's own index), so the loop
// vectorises. Not `omp simd`: it would make the kernel's aggregates per-lane arrays before they are inlined away,
// which blocks the vectoriser.
[[gnu::always_inline]] inline void bond_chunk_body(const BondRange& range, std::size_t b0, int n, Chunk& out) {
  const BondRange r = range;  // a local copy: the stores must not make the loop reload its array pointers
  const stages::FaceBondColumns t = stages::FaceBondColumns::of(*r.table, b0);
  alignas(64) Rows ri, rj;
  load_records(r.record, r.bi + b0, n, ri);
  load_records(r.record, r.bj + b0, n, rj);
#pragma GCC ivdep
  for (int k = 0; k < n; ++k) {
    const std::size_t b = b0 + std::size_t(k);
    double keep, mu;
    bond_status(r, t, std::size_t(k), b, out.intact[k], keep, mu);
    std::int64_t regular = 1;
    const stages::FaceBondOut e = stages::face_bond_forces<false>(t, std::size_t(k), record_at(ri, k),
                                                                  record_at(rj, k), r.dt, r.fs1[b], r.fs2[b], keep,
                                                                  mu, regular);
    stages::FaceBondSlot& slot = r.slot[b];
    stages::store(slot.f, e.f), stages::store(slot.mi, e.mi), stages::store(slot.mj, e.mj);
    out.fs1[k] = e.fs1_lin, out.fs2[k] = e.fs2_lin;
    const BondLoad q = stages::face_bond_load(t, std::size_t(k), e.pb);
    const double scale = r.drive[b] > 0.0 ? r.drive[b] : 1.0;
    out.flag[k] = (1 - regular) | ((out.intact[k] & std::int64_t(q.exceeds(scale))) << 1);
  }
}

// Asks the cache for the records of the blocks of bonds [b0, b1) (the next chunk's, while this one computes): a
// bond's blocks are scattered over the block arrays, which outgrow the second level of the cache.
inline void prefetch_records(const BondRange& r, std::size_t b0, std::size_t b1) {
  for (std::size_t b = b0; b < b1; ++b)
    for (const int block : {r.bi[b], r.bj[b]}) {
      const char* p = reinterpret_cast<const char*>(r.record + block);
      __builtin_prefetch(p), __builtin_prefetch(p + 64);
    }
}

// The chunk compiled for AVX-512, AVX2 and the baseline instruction set, one chosen when the program starts. The
// arithmetic is the same in each (no fused multiply-add, no reassociation: dem/CMakeLists.txt), so are the numbers.
[[gnu::target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")]] void bond_chunk(const BondRange& r,
                                                                                      std::size_t b0, int n,
                                                                                      Chunk& out) {
  bond_chunk_body(r, b0, n, out);
}

}  // namespace

// The bonds [b0, b1) chunk by chunk: each one's forces into its slot; with `advance` its linear part's shear history
// and, while breakage is on, the failure test on its undamaged forces (the softening history advanced, a break
// listed). A bond the branch-free kernel does not take (a relative rotation beyond the series) and a bond at its
// strength are computed again in the exact form, which gives the kernel's numbers where both apply.
void Engine<3>::bond_range(std::size_t b0, std::size_t b1, double dt, bool advance, std::vector<Break>* breaks) {
  using F = stages::FaceBondTable;
  ModelState<3>& s = state_;
  const Model<3>& m = model_;
  const BondRange r{&m.table, m.bi.data(), m.bj.data(), record_.data(),
                    s.drive.data(), s.fs1.data(), s.fs2.data(), slot_.data(), dt};
  const bool test = advance && s.breakage;
  Chunk out;
  assert(b0 % kChunk == 0);  // the chunks are the table's tiles
  for (std::size_t c0 = b0; c0 < b1; c0 += kChunk) {
    const stages::FaceBondColumns t = stages::FaceBondColumns::of(m.table, c0);
    const int n = int(std::min<std::size_t>(kChunk, b1 - c0));
    prefetch_records(r, c0 + kChunk, std::min(c0 + 2 * kChunk, b1));
    for (int k = 0; k < n; ++k) out.intact[k] = s.broken[c0 + std::size_t(k)] == 0;
    bond_chunk(r, c0, n, out);
    for (int k = 0; k < n; ++k) {
      const std::size_t b = c0 + std::size_t(k);
      const std::int64_t flag = out.flag[k] & (test ? 3 : 1);
      if (flag) {
        double keep, mu;
        bond_status(r, t, std::size_t(k), b, out.intact[k], keep, mu);
        std::int64_t regular = 1;
        const stages::BlockRecord3& I = record_[std::size_t(m.bi[b])];
        const stages::FaceBondOut e = stages::face_bond_forces<true>(t, std::size_t(k), I,
                                                                     record_[std::size_t(m.bj[b])], dt, s.fs1[b],
                                                                     s.fs2[b], keep, mu, regular);
        if (flag & 1) slot_[b] = {e.f, e.mi, e.mj}, out.fs1[k] = e.fs1_lin, out.fs2[k] = e.fs2_lin;
        if (flag & 2) {
          const BondLoad q = stages::face_bond_load(t, std::size_t(k), e.pb);
          ParallelBond rule;  // its advance reads only `softening`
          rule.softening = t(F::softening, k);
          const BreakMode mode = rule.advance(q, t(F::rupture, k), s.drive[b]);
          const double A = t(F::area, k);
          if (mode != BreakMode::none) breaks->push_back({int(b), mode, I.x + e.ci, q.tension / A, q.shear / A});
        }
      }
      if (advance) s.fs1[b] = out.fs1[k], s.fs2[b] = out.fs2[k];
    }
  }
}

// The bonds broken this step, in bond order (the threads' lists in thread order): broken from the next step on,
// each logged as a crack.
void Engine<3>::log_breaks(const std::vector<std::vector<Break>>& breaks) {
  ModelState<3>& s = state_;
  for (const std::vector<Break>& list : breaks)
    for (const Break& k : list) {
      const std::size_t b = std::size_t(k.bond);
      s.broken[b] = 1;
      Crack c;
      c.time = s.time, c.strain = s.strain_for_log;
      c.position = {k.p.x, k.p.y, k.p.z};
      const Vec3 n = model_.frame[b].axes.r[2];
      c.normal = {n.x, n.y, n.z};
      c.size = model_.frame[b].section.A;
      c.bond = k.bond, c.kind = model_.kind[b], c.mode = k.mode;
      c.sigma = k.sigma, c.tau = k.tau;
      s.cracks.push_back(c);
      if (on_crack) on_crack(s.cracks.back());
    }
}

// --- the block stage -----------------------------------------------------------------------------------------------

void Engine<3>::gather(std::size_t b, Vec3& force, Vec3& moment) const {
  const Model<3>& m = model_;
  for (int o = m.offset[b]; o < m.offset[b + 1]; ++o) {
    const int e = m.gather[std::size_t(o)];
    const stages::FaceBondSlot& sl = slot_[std::size_t(e >> 1)];
    if (e & 1) force += sl.f, moment += sl.mj;
    else force -= sl.f, moment += sl.mi;
  }
  force += ext_f_[b], moment += ext_m_[b];
}

namespace {

// What one thread's share of the block stage reads and writes.
struct BlockRange {
  const RigidBody3* body;
  double *x, *y, *z, *qw, *qx, *qy, *qz, *vx, *vy, *vz, *wx, *wy, *wz;
  double *fx, *fy, *fz, *mx, *my, *mz;
  stages::BlockRecord3* record;
  double* work;
  double dt, alpha;
};
// One chunk of blocks: the gathered force and moment, 1 where a block is fixed, and 1 where the branch-free step
// holds (else the block keeps its state in the lanes and the exact form steps it). 64-bit flags, as Chunk's.
struct BlockChunk {
  double f[6][kChunk];
  std::int64_t fixed[kChunk];
  std::int64_t regular[kChunk];
};

[[gnu::always_inline]] inline RigidState3 rigid_state(const BlockRange& r, std::size_t b) {
  return {{r.x[b], r.y[b], r.z[b]}, {r.vx[b], r.vy[b], r.vz[b]}, {r.qw[b], r.qx[b], r.qy[b], r.qz[b]},
          {r.wx[b], r.wy[b], r.wz[b]}};
}
// Block b's state, its record and its damping's work.
[[gnu::always_inline]] inline void store_block(const BlockRange& r, std::size_t b, const RigidState3& st,
                                               double work) {
  r.x[b] = st.x.x, r.y[b] = st.x.y, r.z[b] = st.x.z;
  r.vx[b] = st.v.x, r.vy[b] = st.v.y, r.vz[b] = st.v.z;
  r.qw[b] = st.q.w, r.qx[b] = st.q.x, r.qy[b] = st.q.y, r.qz[b] = st.q.z;
  r.wx[b] = st.omega.x, r.wy[b] = st.omega.y, r.wz[b] = st.omega.z;
  stages::BlockRecord3& rec = r.record[b];
  rec.x.x = st.x.x, rec.x.y = st.x.y, rec.x.z = st.x.z;
  rec.q.w = st.q.w, rec.q.x = st.q.x, rec.q.y = st.q.y, rec.q.z = st.q.z;
  rec.v.x = st.v.x, rec.v.y = st.v.y, rec.v.z = st.v.z;
  rec.omega.x = st.omega.x, rec.omega.y = st.omega.y, rec.omega.z = st.omega.z;
  r.work[b] = work;
}

// The blocks [b0, b0 + n) in the branch-free step (rigid3::step), their forces, states and records written in the
// lanes: no branches, so the loop vectorises. A fixed block, and one the branch-free step does not take, keeps its
// state here.
[[gnu::always_inline]] inline void block_chunk_body(const BlockRange& range, std::size_t b0, int n, BlockChunk& c) {
  const BlockRange r = range;  // a local copy: the stores must not make the loop reload its array pointers
#pragma GCC ivdep
  for (int k = 0; k < n; ++k) {
    const std::size_t b = b0 + std::size_t(k);
    const Vec3 F{c.f[0][k], c.f[1][k], c.f[2][k]}, M{c.f[3][k], c.f[4][k], c.f[5][k]};
    r.fx[b] = F.x, r.fy[b] = F.y, r.fz[b] = F.z, r.mx[b] = M.x, r.my[b] = M.y, r.mz[b] = M.z;
    const RigidState3 old = rigid_state(r, b);
    RigidState3 st = old;
    std::int64_t regular = 1;
    const double work = rigid3::step<false>(r.body[b], st, F, M, r.dt, r.alpha, regular);
    c.regular[k] = regular;
    const bool hold = (c.fixed[k] != 0) | (regular == 0);
    const RigidState3 next{{hold ? old.x.x : st.x.x, hold ? old.x.y : st.x.y, hold ? old.x.z : st.x.z},
                           {hold ? old.v.x : st.v.x, hold ? old.v.y : st.v.y, hold ? old.v.z : st.v.z},
                           {hold ? old.q.w : st.q.w, hold ? old.q.x : st.q.x, hold ? old.q.y : st.q.y,
                            hold ? old.q.z : st.q.z},
                           {hold ? old.omega.x : st.omega.x, hold ? old.omega.y : st.omega.y,
                            hold ? old.omega.z : st.omega.z}};
    store_block(r, b, next, hold ? 0.0 : work);
  }
}

[[gnu::target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")]] void block_chunk(const BlockRange& r,
                                                                                       std::size_t b0, int n,
                                                                                       BlockChunk& c) {
  block_chunk_body(r, b0, n, c);
}

}  // namespace

bool Engine<3>::block_range(std::size_t b0, std::size_t b1) {
  ModelState<3>& s = state_;
  const BlockRange r{model_.body.data(), s.x.data(), s.y.data(), s.z.data(), s.qw.data(),
                     s.qx.data(), s.qy.data(), s.qz.data(), s.vx.data(), s.vy.data(), s.vz.data(), s.wx.data(),
                     s.wy.data(), s.wz.data(), s.fx.data(), s.fy.data(), s.fz.data(), s.mx.data(), s.my.data(),
                     s.mz.data(), record_.data(), damping_work_.data(), s.dt, options_.damping};
  bool finite = true;
  BlockChunk c;
  for (std::size_t c0 = b0; c0 < b1; c0 += kChunk) {
    const int n = int(std::min<std::size_t>(kChunk, b1 - c0));
    for (int k = 0; k < n; ++k) {
      Vec3 force, moment;
      gather(c0 + std::size_t(k), force, moment);
      c.f[0][k] = force.x, c.f[1][k] = force.y, c.f[2][k] = force.z;
      c.f[3][k] = moment.x, c.f[4][k] = moment.y, c.f[5][k] = moment.z;
      c.fixed[k] = model_.fixed[c0 + std::size_t(k)] != 0;
    }
    block_chunk(r, c0, n, c);
    for (int k = 0; k < n; ++k) {
      const std::size_t b = c0 + std::size_t(k);
      if (!c.regular[k] && !c.fixed[k]) {  // a half angle beyond the series: the exact step
        RigidState3 st = rigid_state(r, b);
        const double work = rigid_step(model_.body[b], st, {c.f[0][k], c.f[1][k], c.f[2][k]},
                                       {c.f[3][k], c.f[4][k], c.f[5][k]}, s.dt, options_.damping);
        store_block(r, b, st, work);
      }
      finite = finite && std::isfinite(s.x[b] + s.y[b] + s.z[b] + s.qw[b] + s.vx[b] + s.vy[b] + s.vz[b]);
    }
  }
  return finite;
}

void Engine<3>::step() {
  ModelState<3>& s = state_;
  const Model<3>& m = model_;
  const int nt_want = threads();
  const double t_start = omp_get_wtime();
  const bool sample = team_.begin(t_start, nt_want);
  for (BoundaryHooks<3>* h : hooks_) h->begin_step(m, s);  // serial: the contacts' rebuild, before the shares
  const double t_begun = omp_get_wtime();
  double mark[3] = {};
  bool finite = true;
  std::exception_ptr error;
  for (auto& list : breaks_) list.clear();
  if (breaks_.size() < std::size_t(nt_want)) breaks_.resize(std::size_t(nt_want));
#pragma omp parallel num_threads(nt_want) reduction(&& : finite)
  {
    const int t = omp_get_thread_num(), nt = omp_get_num_threads();
    if (sample) team_.read(t);
    const auto bonds = bond_share(m.num_bonds(), t, nt);
    bond_range(bonds[0], bonds[1], s.dt, true, &breaks_[std::size_t(t)]);
    const auto blocks = share(m.num_blocks(), t, nt);  // the components' sums start from zero, cleared in parallel
    std::fill(ext_f_.begin() + long(blocks[0]), ext_f_.begin() + long(blocks[1]), Vec3{});
    std::fill(ext_m_.begin() + long(blocks[0]), ext_m_.begin() + long(blocks[1]), Vec3{});
    for (BoundaryHooks<3>* h : hooks_) h->prepare_forces(m, s, s.dt, t, nt);
#pragma omp barrier
#pragma omp master
    {
      mark[0] = omp_get_wtime();
      try {
        for (BoundaryHooks<3>* h : hooks_) s.e_friction += h->add_forces(m, s, ext_f_, ext_m_, s.dt, true);
      } catch (...) {
        error = std::current_exception();
      }
      mark[1] = omp_get_wtime();
    }
#pragma omp barrier
    if (!error) finite = block_range(blocks[0], blocks[1]);
  }
  mark[2] = omp_get_wtime();
  team_.end(mark[2]);
  if (error) std::rethrow_exception(error);
  times_.bonds += mark[0] - t_begun, times_.serial += (t_begun - t_start) + (mark[1] - mark[0]);
  times_.blocks += mark[2] - mark[1], ++times_.steps;
  for (double w : damping_work_) s.e_damping -= w;
  log_breaks(breaks_);
  if (!finite)
    throw InstabilityError(fmt::format("a block's position is no longer finite at step {}: the time step is too "
                                       "large for this scene (lower numerics.dt_safety)", s.steps));
  for (BoundaryHooks<3>* h : hooks_) h->after_step(m, s, s.dt);
  s.time += s.dt;
  ++s.steps;
}

void Engine<3>::evaluate_forces(std::vector<Vec3>& force, std::vector<Vec3>& moment) const {
  const Model<3>& m = model_;
  auto& self = const_cast<Engine<3>&>(*this);  // the slots are a workspace: no state is advanced
  self.bond_range(0, m.num_bonds(), 0.0, false, nullptr);
  std::fill(self.ext_f_.begin(), self.ext_f_.end(), Vec3{}), std::fill(self.ext_m_.begin(), self.ext_m_.end(), Vec3{});
  for (BoundaryHooks<3>* h : hooks_) h->add_forces(m, state_, self.ext_f_, self.ext_m_, 0.0, false);
  force.assign(m.num_blocks(), Vec3{}), moment.assign(m.num_blocks(), Vec3{});
  for (std::size_t b = 0; b < m.num_blocks(); ++b) gather(b, force[b], moment[b]);
}

}  // namespace rbdem
