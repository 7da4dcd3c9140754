// Contact detection (broad phase) and contact forces (narrow phase + the linear contact law). See stages.hpp.
//
// Only blocks with a free face (a broken bond or a specimen boundary edge) can meet blocks they are not bonded
// to: a block whose three edges are bonded is enclosed by its neighbours (docs/model.md, "Contacts: broad
// phase"). Candidate pairs among them come from a uniform cell grid with a skin of 0.2 mean edge lengths; the list
// is rebuilt when a free-face block or the platen has moved half a skin, and updated when a bond broke. Shear
// history carries over by pair key. The three savings can be switched off to measure them
// (numerics.search_free_faces_only, numerics.skip_bonded_pairs, numerics.update_after_breaks).
#include <algorithm>
#include <cmath>
#include <cstdint>

#include <omp.h>

#include "dem/contact_geometry.hpp"
#include "dem/boundary/hooks.hpp"
#include "dem/stages/bond_kernel.hpp"
#include "dem/stages/stages.hpp"

namespace rbdem::stages {

namespace {

std::uint64_t pair_key(int i, int j) { return (std::uint64_t(std::uint32_t(i)) << 32) | std::uint32_t(j); }

// A component asks for a rebuild regardless of the blocks (the top platen moved half a skin).
bool boundary_moved(const Model<2>& m, const Hooks& hooks) {
  return std::any_of(hooks.begin(), hooks.end(), [&m](const BoundaryHooks<2>* h) { return h->rebuild_due(m); });
}

// Whether one of thread t's share (of nt, contiguous in eligible order) of the eligible blocks moved half a skin
// since the last rebuild.
bool moved_half_skin(const Model<2>& m, const ModelState<2>& s, int t, int nt) {
  const double lim2 = 0.25 * m.skin * m.skin;
  const int ne = int(s.eligible.size());
  const int lo = int(std::int64_t(ne) * t / nt), hi = int(std::int64_t(ne) * (t + 1) / nt);
  bool moved = false;
  for (int k = lo; k < hi; ++k) {
    const std::size_t b = std::size_t(s.eligible[std::size_t(k)]);
    const double dx = s.x[b] - s.ref_x[std::size_t(k)], dy = s.y[b] - s.ref_y[std::size_t(k)];
    moved = moved || dx * dx + dy * dy > lim2;
  }
  return moved;
}

bool blocks_moved(const Model<2>& m, const ModelState<2>& s, int threads) {
  bool moved = false;
#pragma omp parallel num_threads(threads) reduction(|| : moved) if (s.eligible.size() > 1024)
  moved = moved_half_skin(m, s, omp_get_thread_num(), omp_get_num_threads());
  return moved;
}

}  // namespace

bool pair_overlap(const Model<2>& m, const ModelState<2>& s, const Workspace<2>& w, std::size_t p, Overlap& ov) {
  const ContactPairs& C = s.contacts;
  const int i = C.i[p], j = C.j[p];
  const double ox = C.opening_x[p], oy = C.opening_y[p];  // block j moved back towards i by its opening
  const std::size_t a = std::size_t(i), b = std::size_t(j);
  const double ex = s.x[b] - ox - s.x[a], ey = s.y[b] - oy - s.y[a];
  const double rr = m.radius[a] + m.radius[b];
  if (!(ex * ex + ey * ey < rr * rr)) return false;  // out of reach
  double vi[6], vj[6];
  block_vertices(m, s, w, i, vi);
  block_vertices(m, s, w, j, vj);
  for (int k = 0; k < 3; ++k) vj[2 * k] -= ox, vj[2 * k + 1] -= oy;
  return overlap_polygons(vi, 3, vj, 3, ov);
}

void block_vertices(const Model<2>& m, const ModelState<2>& s, const Workspace<2>& w, int b, double* out) {
  const std::size_t k = std::size_t(b);
  const auto& sh = m.shape[k];
  const double c = w.cos_t[k], sn = w.sin_t[k];
  for (int v = 0; v < 3; ++v) {
    out[2 * v] = s.x[k] + c * sh[2 * v] - sn * sh[2 * v + 1];
    out[2 * v + 1] = s.y[k] + sn * sh[2 * v] + c * sh[2 * v + 1];
  }
}

void rebuild_check_begin(Workspace<2>& w, int threads) { w.moved.assign(std::size_t(std::max(threads, 1)), 0); }

void rebuild_check_share(const Model<2>& m, const ModelState<2>& s, Workspace<2>& w, int t, int nt) {
  w.moved[std::size_t(t)] = moved_half_skin(m, s, t, nt);
}

bool rebuild_due(const Model<2>& m, const ModelState<2>& s, const Workspace<2>& w, const Hooks& hooks) {
  return s.rebuild || boundary_moved(m, hooks) ||
         std::any_of(w.moved.begin(), w.moved.end(), [](std::uint8_t v) { return v != 0; });
}

namespace {

// The cell of a point of the grid g, as (column, row) clamped to [0, 2e9]: a run going unstable (stopped by the
// watchdog a few steps later) may carry huge or non-finite positions here, which must not overflow the conversion
// (NaN fails q >= 0 and maps to 0). Clamping merges cells at the edges, which only adds candidates.
std::pair<long, long> cell_of(const Workspace<2>::BroadGrid& g, double x, double y) {
  auto index = [&g](double v) {
    const double q = v / g.cell;
    return q >= 0 ? (q < 2e9 ? long(q) : 2000000000L) : 0L;
  };
  return {index(x - g.xmin), index(y - g.ymin)};
}
std::uint64_t cell_key(long cx, long cy) { return (std::uint64_t(cx) << 32) | std::uint64_t(cy); }

// Calls visit(entry) for the grid entries in the 3 x 3 cells around the cell (cx, cy). The three cells
// (cx + dx, cy - 1 .. cy + 1) of a column lie next to each other in the sorted entries: one search finds the
// first, and the scan runs on to the last (in the order of the nine cells one by one).
template <class Visit>
void visit_neighbourhood(const Workspace<2>::BroadGrid& g, long cx, long cy, Visit&& visit) {
  for (long dx = -1; dx <= 1; ++dx) {
    if (cx + dx < 0) continue;
    const std::uint64_t first = cell_key(cx + dx, std::max(cy - 1, 0L)), last = cell_key(cx + dx, cy + 1);
    auto it = std::lower_bound(g.entries.begin(), g.entries.end(), first,
                               [](const Workspace<2>::GridEntry& e, std::uint64_t k) { return e.key < k; });
    for (; it != g.entries.end() && it->key <= last; ++it) visit(*it);
  }
}

// The grid's order: by cell, then by block.
bool entry_before(const Workspace<2>::GridEntry& a, const Workspace<2>::GridEntry& b) {
  return a.key != b.key ? a.key < b.key : a.block < b.block;
}

// Whether block a, at its position now, and the grid entry e (a block at its position of the last rebuild) make a
// candidate pair: within the two radii and the skin, and not joined by an intact bond when those are skipped.
bool in_reach(const Model<2>& m, const ModelState<2>& s, const DetectionOptions& o, int a, const Workspace<2>::GridEntry& e) {
  const int b = e.block;
  const double rr = m.radius[a] + m.radius[b] + m.skin;
  const double ex = e.x - s.x[a], ey = e.y - s.y[a];
  if (ex * ex + ey * ey > rr * rr) return false;
  return !(o.skip_bonded_pairs && m.bonded(a, b, s.broken));
}

// The pair (i, j) of the sorted key, with its bond, its law and its shear force: carried over from the old list
// when listed there, else handed over from the bond that just broke, else zero. `at` walks the old list.
void list_pair(const Model<2>& m, const ModelState<2>& s, const ContactPairs& old, std::uint64_t key, std::size_t& at,
               ContactPairs& next, std::size_t q) {
  const int i = int(key >> 32), j = int(key & 0xffffffffu);
  while (at < old.key.size() && old.key[at] < key) ++at;
  int bond = -1;
  for (int e = m.csr_offset[i]; e < m.csr_offset[i + 1]; ++e) {
    const int bb = m.csr_entry[e] >> 1;
    if (m.bi[bb] == j || m.bj[bb] == j) bond = bb;
  }
  double fs = 0.0, ox = 0.0, oy = 0.0;
  if (at < old.key.size() && old.key[at] == key) fs = old.fs[at], ox = old.opening_x[at], oy = old.opening_y[at];
  else if (bond >= 0) fs = s.fs_lin[std::size_t(bond)];  // a bond that just broke hands over its linear shear
  next.key[q] = key, next.i[q] = i, next.j[q] = j, next.bond[q] = bond, next.law[q] = m.pair_law(i, j, bond);
  next.fs[q] = fs, next.fn[q] = 0.0, next.chord[q] = 0.0;
  next.opening_x[q] = ox, next.opening_y[q] = oy;
}

void resize(ContactPairs& C, std::size_t n) {
  C.key.resize(n), C.i.resize(n), C.j.resize(n), C.bond.resize(n), C.law.resize(n), C.fs.resize(n);
  C.fn.resize(n), C.chord.resize(n), C.opening_x.resize(n), C.opening_y.resize(n);
}

// The rebuild: every eligible block's reference position and cell, the components' candidates and the pair list.
void rebuild(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, const DetectionOptions& o, const Hooks& hooks,
             int threads) {
  const std::size_t nb = m.num_blocks();
  auto& eligible = s.eligible;
  eligible.clear();
  double rmax = 0;
  for (std::size_t b = 0; b < nb; ++b)
    if (s.free_face[b] || !o.search_free_faces_only) eligible.push_back(int(b)), rmax = std::max(rmax, m.radius[b]);
  s.ref_x.resize(eligible.size()), s.ref_y.resize(eligible.size());
  for (std::size_t k = 0; k < eligible.size(); ++k) s.ref_x[k] = s.x[eligible[k]], s.ref_y[k] = s.y[eligible[k]];

  // The components' candidates (a platen may travel skin/2 before the next rebuild).
  for (BoundaryHooks<2>* h : hooks) h->on_rebuild(m, s, eligible);

  // Uniform grid over the eligible blocks; pairs from the 3 x 3 neighbourhood of each cell.
  Workspace<2>::BroadGrid& g = w.grid;
  g.entries.clear();
  g.valid = true, g.rmax = rmax, g.cell = 2.0 * rmax + m.skin;
  std::vector<std::uint64_t> keys;
  if (o.contacts && !eligible.empty()) {
    g.xmin = g.ymin = 1e300;
    for (int b : eligible) g.xmin = std::min(g.xmin, s.x[b]), g.ymin = std::min(g.ymin, s.y[b]);
    g.entries.reserve(eligible.size());
    for (int b : eligible) {
      const auto [cx, cy] = cell_of(g, s.x[b], s.y[b]);
      g.entries.push_back({cell_key(cx, cy), b, s.x[b], s.y[b]});
    }
    std::sort(g.entries.begin(), g.entries.end(), entry_before);
    // Pairs from each eligible block's neighbourhood, found in parallel into per-thread lists; the sorted union
    // does not depend on how the blocks were split among threads.
    const int ne = int(eligible.size());
    std::vector<std::vector<std::uint64_t>> found(static_cast<std::size_t>(threads));
#pragma omp parallel num_threads(threads) if (ne > 256)
    {
      auto& mine = found[std::size_t(omp_get_thread_num())];
#pragma omp for schedule(static)
      for (int k = 0; k < ne; ++k) {
        const int a = eligible[std::size_t(k)];
        const auto [cx, cy] = cell_of(g, s.x[a], s.y[a]);
        visit_neighbourhood(g, cx, cy, [&](const Workspace<2>::GridEntry& e) {
          if (e.block > a && in_reach(m, s, o, a, e)) mine.push_back(pair_key(a, e.block));
        });
      }
    }
    for (const auto& list : found) keys.insert(keys.end(), list.begin(), list.end());
    std::sort(keys.begin(), keys.end());
  }

  // The new pair list, each pair on its own (its bond, law and carried-over shear force), in parallel.
  ContactPairs next;
  const auto& old = s.contacts;
  const int n = int(keys.size());
  resize(next, std::size_t(n));
  // Each thread takes a contiguous range of the sorted keys and walks the old (sorted) list beside it.
#pragma omp parallel num_threads(threads) if (n > 256)
  {
    const int t = omp_get_thread_num(), nt = omp_get_num_threads();
    const int lo = int(std::int64_t(n) * t / nt), hi = int(std::int64_t(n) * (t + 1) / nt);
    std::size_t at = lo < hi ? std::size_t(std::lower_bound(old.key.begin(), old.key.end(), keys[std::size_t(lo)]) -
                                           old.key.begin())
                             : 0;
    for (int p = lo; p < hi; ++p) list_pair(m, s, old, keys[std::size_t(p)], at, next, std::size_t(p));
  }
  s.contacts = std::move(next);
}

// After bond breaks, while no block and not the platen moved half a skin: the lists of the last rebuild gain the
// blocks that now have a free face and the pairs they and the broken bonds form, instead of a rebuild. A joining
// block is listed at its position now, which becomes its reference, against the other blocks' references, with a
// rebuild's reach (the two radii and the skin; the platen at its reference). So the lists keep a rebuild's
// guarantee: no pair and no platen contact they leave out can touch before the next rebuild. Only pairs and
// platen contacts that touch exert forces, and the lists are walked in block and key order, so the forces are the
// same as after a rebuild to the last bit; the lists may differ from a rebuild's only in entries that do not
// touch. Returns false, having changed nothing, when a joining block is larger than the grid allows.
bool update_after_breaks(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, const DetectionOptions& o,
                         const Hooks& hooks) {
  Workspace<2>::BroadGrid& g = w.grid;
  std::vector<int> joining;
  for (int k : w.broken_now)
    for (int b : {m.bi[std::size_t(k)], m.bj[std::size_t(k)]})
      if (!std::binary_search(s.eligible.begin(), s.eligible.end(), b)) joining.push_back(b);
  std::sort(joining.begin(), joining.end());
  joining.erase(std::unique(joining.begin(), joining.end()), joining.end());
  for (int b : joining)
    if (m.radius[b] > g.rmax) return false;

  // The eligible blocks and their references, in block order.
  if (!joining.empty()) {
    std::vector<int> eligible;
    std::vector<double> ref_x, ref_y;
    const std::size_t n = s.eligible.size() + joining.size();
    eligible.reserve(n), ref_x.reserve(n), ref_y.reserve(n);
    std::size_t a = 0, c = 0;
    while (a < s.eligible.size() || c < joining.size()) {
      if (c == joining.size() || (a < s.eligible.size() && s.eligible[a] < joining[c])) {
        eligible.push_back(s.eligible[a]), ref_x.push_back(s.ref_x[a]), ref_y.push_back(s.ref_y[a]), ++a;
      } else {
        const int b = joining[c++];
        eligible.push_back(b), ref_x.push_back(s.x[b]), ref_y.push_back(s.y[b]);
      }
    }
    s.eligible = std::move(eligible), s.ref_x = std::move(ref_x), s.ref_y = std::move(ref_y);
  }
  if (!joining.empty())
    for (BoundaryHooks<2>* h : hooks) h->on_join(m, s, joining);
  if (!o.contacts) return true;

  // The joining blocks enter the grid; then each finds its partners among every grid entry (joining ones too).
  for (int b : joining) {
    const auto [cx, cy] = cell_of(g, s.x[b], s.y[b]);
    const Workspace<2>::GridEntry e{cell_key(cx, cy), b, s.x[b], s.y[b]};
    g.entries.insert(std::upper_bound(g.entries.begin(), g.entries.end(), e, entry_before), e);
  }
  std::vector<std::uint64_t> keys;
  for (int a : joining) {
    const auto [cx, cy] = cell_of(g, s.x[a], s.y[a]);
    visit_neighbourhood(g, cx, cy, [&](const Workspace<2>::GridEntry& e) {
      if (e.block != a && in_reach(m, s, o, a, e)) keys.push_back(pair_key(std::min(a, e.block), std::max(a, e.block)));
    });
  }
  // A broken bond's two blocks touch along its edge: listed whether or not they joined now.
  for (int k : w.broken_now) {
    const int i = m.bi[std::size_t(k)], j = m.bj[std::size_t(k)];
    keys.push_back(pair_key(std::min(i, j), std::max(i, j)));
  }
  std::sort(keys.begin(), keys.end());
  keys.erase(std::unique(keys.begin(), keys.end()), keys.end());

  // The old list and the new pairs merged in key order; pairs listed already keep their records.
  const ContactPairs& old = s.contacts;
  const auto listed = [&old](std::uint64_t key) { return std::binary_search(old.key.begin(), old.key.end(), key); };
  keys.erase(std::remove_if(keys.begin(), keys.end(), listed), keys.end());
  const std::size_t n = old.size() + keys.size();
  ContactPairs next;
  resize(next, n);
  std::size_t a = 0, k = 0, at = 0;
  for (std::size_t q = 0; q < n; ++q) {
    if (k < keys.size() && (a == old.size() || keys[k] < old.key[a])) {
      list_pair(m, s, old, keys[k++], at, next, q);
      continue;
    }
    next.key[q] = old.key[a], next.i[q] = old.i[a], next.j[q] = old.j[a], next.bond[q] = old.bond[a];
    next.law[q] = old.law[a], next.fs[q] = old.fs[a], next.fn[q] = old.fn[a], next.chord[q] = old.chord[a];
    next.opening_x[q] = old.opening_x[a], next.opening_y[q] = old.opening_y[a];
    ++a;
  }
  s.contacts = std::move(next);
  return true;
}

}  // namespace

void detect_contacts(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, const DetectionOptions& o,
                     const Hooks& hooks, int threads) {
  const bool top_moved = boundary_moved(m, hooks);
  if (!s.rebuild && !top_moved && !blocks_moved(m, s, threads)) return;
  const bool breaks_only =
      o.update_after_breaks && s.rebuild && !top_moved && w.grid.valid && !w.broken_now.empty();
  if (breaks_only && !blocks_moved(m, s, threads) && update_after_breaks(m, s, w, o, hooks)) {
    ++w.grid.updates;
  } else {
    rebuild(m, s, w, o, hooks, threads);
    ++w.grid.rebuilds;
  }
  s.rebuild = false;
  w.broken_now.clear();
}

// Each pair's narrow phase and contact law run in parallel into the pair's own record; the records are then
// summed into the contact accumulators serially in pair order, so the sums do not depend on the thread count or on
// which thread took which chunk.
void contact_forces_begin(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, const StepContext& c) {
  w.pair_force.resize(s.contacts.size());
  partition(m, w, c.threads);
  const std::size_t chunk = Workspace<2>::kPairChunk;
  w.in_contact.resize((s.contacts.size() + chunk - 1) / chunk);
  for (auto& v : w.in_contact) v.clear();
  w.pair_bounds = {0, int(s.contacts.size())};
  Workspace<2>::reset(w.pair_next);
}

namespace {

// The narrow phase and the contact law of the pairs [lo, hi), the touching ones listed in `touching`.
void contact_forces_of(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, const StepContext& c, int lo, int hi,
                       std::vector<int>& touching) {
  auto& C = s.contacts;
  const double dt = c.dt;
  const bool advance = c.advance;
  Workspace<2>::PairForce* out = w.pair_force.data();
  for (int p = lo; p < hi; ++p) {
    const int i = C.i[p], j = C.j[p];
    Overlap ov;
    const bool touching_now = pair_overlap(m, s, w, std::size_t(p), ov);
    // A pair still joined by its bond (listed only with skip_bonded_pairs = false): the bond's linear part is its
    // contact, so the narrow phase above was the whole of its cost.
    const bool intact = C.bond[p] >= 0 && !s.broken[std::size_t(C.bond[p])];
    if (!touching_now || intact) {
      if (advance) C.fs[p] = 0.0, C.fn[p] = 0.0, C.chord[p] = 0.0, C.opening_x[p] = C.opening_y[p] = 0.0;
      out[p] = Workspace<2>::PairForce{0, 0, 0, 0, 0, false};
      continue;
    }
    const double nx = -ov.nx, ny = -ov.ny;  // from i to j, as for bonds
    const double tx = -ny, ty = nx;
    const double fn = C.law[p].normal_force(ov.area, ov.chord);
    const double cix = ov.px - s.x[i], ciy = ov.py - s.y[i];
    const double cjx = ov.px - s.x[j], cjy = ov.py - s.y[j];
    const double vrx = (s.vx[j] - s.omega[j] * cjy) - (s.vx[i] - s.omega[i] * ciy);
    const double vry = (s.vy[j] + s.omega[j] * cjx) - (s.vy[i] + s.omega[i] * cix);
    const double vt = vrx * tx + vry * ty;
    double fs = C.fs[p], opening = 0.0;
    const double friction =
        C.law[p].update_shear(fn, ov.chord, vt, dt, fs, opening) ? std::abs(fs * vt * dt) : 0.0;
    if (advance) {
      C.fs[p] = fs, C.fn[p] = fn, C.chord[p] = ov.chord;
      if (opening != 0.0) C.opening_x[p] += opening * nx, C.opening_y[p] += opening * ny;  // along the normal
    }
    const double fx = fn * nx + fs * tx, fy = fn * ny + fs * ty;  // on j
    out[p] = Workspace<2>::PairForce{fx, fy, cross(cix, ciy, fx, fy), cross(cjx, cjy, fx, fy), friction, true};
    touching.push_back(p);
  }
}

}  // namespace

void contact_forces_share(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, const StepContext& c, int t, int) {
  // Chunks to whichever thread asks: each pair's work is its own, so any thread may take any chunk.
  const int chunk = Workspace<2>::kPairChunk;
  Workspace<2>::run_pieces(w.pair_bounds, w.pair_next, chunk, t, [&](int lo, int hi) {
    contact_forces_of(m, s, w, c, lo, hi, w.in_contact[std::size_t(lo / chunk)]);
  });
}

void contact_forces_end(ModelState<2>& s, Workspace<2>& w, const StepContext& c) {
  // Most pairs of free-face blocks do not touch: only those that do are summed, the lists in chunk order, which is
  // pair order.
  const auto& C = s.contacts;
  const Workspace<2>::PairForce* out = w.pair_force.data();
  for (const std::vector<int>& list : w.in_contact)
    for (int p : list) {
      const Workspace<2>::PairForce& f = out[p];
      const int i = C.i[p], j = C.j[p];
      w.cfx[j] += f.fx, w.cfy[j] += f.fy, w.cm[j] += f.mj;
      w.cfx[i] -= f.fx, w.cfy[i] -= f.fy, w.cm[i] -= f.mi;
      if (c.advance) s.e_friction += f.friction;
    }
}

// Each pair's narrow phase and contact law run in parallel into the pair's own record; the records are then
// summed into the contact accumulators serially in pair order, so the sums do not depend on the thread count.
void contact_forces(const Model<2>& m, ModelState<2>& s, Workspace<2>& w, const StepContext& c) {
  contact_forces_begin(m, s, w, c);
#pragma omp parallel num_threads(c.threads) if (s.contacts.size() > 64)
  contact_forces_share(m, s, w, c, omp_get_thread_num(), omp_get_num_threads());
  contact_forces_end(s, w, c);
}

}  // namespace rbdem::stages
