// Contact detection (broad phase) and contact forces (narrow phase + the linear contact law). See stages.hpp.
//
// Only blocks with a free face (a broken bond or a specimen boundary edge) can meet blocks they are not bonded
// to: a block whose three edges are bonded is enclosed by its neighbours (docs/model.md, "Contacts: broad
// phase"). Candidate pairs among them come from a uniform cell grid with a skin of 0.2 mean edge lengths; the list
// is rebuilt when a free-face block or the platen has moved half a skin, or a bond broke. Shear history carries
// over by pair key. The two savings can be switched off to measure them (numerics.search_free_faces_only,
// numerics.skip_bonded_pairs).
#include <algorithm>
#include <cmath>
#include <cstdint>

#include <omp.h>

#include "dem/contact_geometry.hpp"
#include "dem/stages/bond_kernel.hpp"
#include "dem/stages/stages.hpp"

namespace rbdem::stages {

namespace {

std::uint64_t pair_key(int i, int j) { return (std::uint64_t(std::uint32_t(i)) << 32) | std::uint32_t(j); }

// The first pair whose lower block is b or above.
int first_pair_of(const ContactPairs& C, int b) {
  return int(std::lower_bound(C.key.begin(), C.key.end(), std::uint64_t(std::uint32_t(b)) << 32) - C.key.begin());
}

// A rebuild regardless of the blocks: a bond broke, or the top platen moved half a skin.
bool rebuild_forced(const Model& m, const ModelState& s) {
  return s.rebuild || std::abs(s.top_y - s.ref_top) > 0.5 * m.skin;
}

// Whether one of thread t's share (of nt, contiguous in eligible order) of the eligible blocks moved half a skin
// since the last rebuild.
bool moved_half_skin(const Model& m, const ModelState& s, int t, int nt) {
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

bool needs_rebuild(const Model& m, const ModelState& s, int threads) {
  if (rebuild_forced(m, s)) return true;
  bool moved = false;
#pragma omp parallel num_threads(threads) reduction(|| : moved) if (s.eligible.size() > 1024)
  moved = moved_half_skin(m, s, omp_get_thread_num(), omp_get_num_threads());
  return moved;
}

}  // namespace

void block_vertices(const Model& m, const ModelState& s, const Workspace& w, int b, double* out) {
  const std::size_t k = std::size_t(b);
  const auto& sh = m.shape[k];
  const double c = w.cos_t[k], sn = w.sin_t[k];
  for (int v = 0; v < 3; ++v) {
    out[2 * v] = s.x[k] + c * sh[2 * v] - sn * sh[2 * v + 1];
    out[2 * v + 1] = s.y[k] + sn * sh[2 * v] + c * sh[2 * v + 1];
  }
}

void rebuild_check_begin(Workspace& w, int threads) { w.moved.assign(std::size_t(std::max(threads, 1)), 0); }

void rebuild_check_share(const Model& m, const ModelState& s, Workspace& w, int t, int nt) {
  w.moved[std::size_t(t)] = moved_half_skin(m, s, t, nt);
}

bool rebuild_due(const Model& m, const ModelState& s, const Workspace& w) {
  return rebuild_forced(m, s) || std::any_of(w.moved.begin(), w.moved.end(), [](std::uint8_t v) { return v != 0; });
}

void detect_contacts(const Model& m, ModelState& s, const DetectionOptions& o, int threads) {
  if (!needs_rebuild(m, s, threads)) return;
  s.rebuild = false;
  const std::size_t nb = m.num_blocks();
  auto& eligible = s.eligible;
  eligible.clear();
  double rmax = 0;
  for (std::size_t b = 0; b < nb; ++b)
    if (s.free_face[b] || !o.search_free_faces_only) eligible.push_back(int(b)), rmax = std::max(rmax, m.radius[b]);
  s.ref_x.resize(eligible.size()), s.ref_y.resize(eligible.size());
  for (std::size_t k = 0; k < eligible.size(); ++k) s.ref_x[k] = s.x[eligible[k]], s.ref_y[k] = s.y[eligible[k]];
  s.ref_top = s.top_y;

  // Platen candidates (the platen may travel skin/2 before the next rebuild).
  s.top_candidates.clear(), s.bottom_candidates.clear();
  if (o.platens)
    for (int b : eligible) {
      if (s.y[b] + m.radius[b] > s.top_y - m.skin) s.top_candidates.push_back(b);
      if (s.y[b] - m.radius[b] < m.ymin + m.skin) s.bottom_candidates.push_back(b);
    }

  // Uniform grid over the eligible blocks; pairs from the 3 x 3 neighbourhood of each cell.
  std::vector<std::uint64_t> keys;
  if (o.contacts && !eligible.empty()) {
    const double cell = 2.0 * rmax + m.skin;
    double xmin = 1e300, ymin = 1e300;
    for (int b : eligible) xmin = std::min(xmin, s.x[b]), ymin = std::min(ymin, s.y[b]);
    // Cell indices clamped to [0, 2e9]: a run going unstable (stopped by the watchdog a few steps later) may carry
    // huge or non-finite positions here, which must not overflow the conversion (NaN fails q >= 0 and maps to 0).
    auto index = [cell](double v) {
      const double q = v / cell;
      return q >= 0 ? (q < 2e9 ? long(q) : 2000000000L) : 0L;
    };
    auto cell_of = [&](int b) { return std::pair<long, long>{index(s.x[b] - xmin), index(s.y[b] - ymin)}; };
    auto cell_key = [](long cx, long cy) { return (std::uint64_t(cx) << 32) | std::uint64_t(cy); };
    std::vector<std::pair<std::uint64_t, int>> cells;
    cells.reserve(eligible.size());
    for (int b : eligible) {
      const auto [cx, cy] = cell_of(b);
      cells.push_back({cell_key(cx, cy), b});
    }
    std::sort(cells.begin(), cells.end());
    // Pairs from each eligible block's 3 x 3 cell neighbourhood, found in parallel into per-thread lists; the
    // sorted union does not depend on how the blocks were split among threads.
    const int ne = int(eligible.size());
    std::vector<std::vector<std::uint64_t>> found(static_cast<std::size_t>(threads));
#pragma omp parallel num_threads(threads) if (ne > 256)
    {
      auto& mine = found[std::size_t(omp_get_thread_num())];
#pragma omp for schedule(static)
      for (int k = 0; k < ne; ++k) {
        const int a = eligible[std::size_t(k)];
        const auto [cx, cy] = cell_of(a);
        // The three cells (cx + dx, cy - 1 .. cy + 1) of a column lie next to each other in the sorted list: one
        // search finds the first, and the scan runs on to the last (in the order of the nine cells one by one).
        for (long dx = -1; dx <= 1; ++dx) {
          if (cx + dx < 0) continue;
          const std::uint64_t first = cell_key(cx + dx, std::max(cy - 1, 0L)), last = cell_key(cx + dx, cy + 1);
          auto it = std::lower_bound(cells.begin(), cells.end(), std::pair<std::uint64_t, int>{first, -1});
          for (; it != cells.end() && it->first <= last; ++it) {
            const int b = it->second;
            if (b <= a) continue;
            const double rr = m.radius[a] + m.radius[b] + m.skin;
            const double ex = s.x[b] - s.x[a], ey = s.y[b] - s.y[a];
            if (ex * ex + ey * ey > rr * rr) continue;
            if (o.skip_bonded_pairs && m.bonded(a, b, s.broken)) continue;
            mine.push_back(pair_key(a, b));
          }
        }
      }
    }
    for (const auto& list : found) keys.insert(keys.end(), list.begin(), list.end());
    std::sort(keys.begin(), keys.end());
  }

  // The new pair list, each pair on its own (its bond, law and carried-over shear force), in parallel.
  ContactPairs next;
  const auto& old = s.contacts;
  const int n = int(keys.size());
  next.i.resize(std::size_t(n)), next.j.resize(std::size_t(n)), next.bond.resize(std::size_t(n));
  next.law.resize(std::size_t(n)), next.fs.resize(std::size_t(n));
  next.fn.assign(std::size_t(n), 0.0), next.chord.assign(std::size_t(n), 0.0);
  next.key = std::move(keys);
  const std::vector<std::uint64_t>& sorted = next.key;
  // Each thread takes a contiguous range of the sorted keys and walks the old (sorted) list beside it.
#pragma omp parallel num_threads(threads) if (n > 256)
  {
    const int t = omp_get_thread_num(), nt = omp_get_num_threads();
    const int lo = int(std::int64_t(n) * t / nt), hi = int(std::int64_t(n) * (t + 1) / nt);
    std::size_t at = lo < hi ? std::size_t(std::lower_bound(old.key.begin(), old.key.end(), sorted[std::size_t(lo)]) -
                                           old.key.begin())
                             : 0;
    for (int p = lo; p < hi; ++p) {
      const std::uint64_t key = sorted[std::size_t(p)];
      const int i = int(key >> 32), j = int(key & 0xffffffffu);
      while (at < old.key.size() && old.key[at] < key) ++at;
      int bond = -1;
      for (int e = m.csr_offset[i]; e < m.csr_offset[i + 1]; ++e) {
        const int bb = m.csr_entry[e] >> 1;
        if (m.bi[bb] == j || m.bj[bb] == j) bond = bb;
      }
      double fs = 0.0;
      if (at < old.key.size() && old.key[at] == key) fs = old.fs[at];
      else if (bond >= 0) fs = s.fs_lin[std::size_t(bond)];  // a bond that just broke hands over its linear shear
      const std::size_t q = std::size_t(p);
      next.i[q] = i, next.j[q] = j, next.bond[q] = bond, next.law[q] = m.pair_law(i, j, bond), next.fs[q] = fs;
    }
  }
  s.contacts = std::move(next);
}

// Each pair's narrow phase and contact law run in parallel into the pair's own record; the records are then
// summed into the contact accumulators serially in pair order, so the sums do not depend on the thread count.
void contact_forces_begin(const Model& m, ModelState& s, Workspace& w, const StepContext& c) {
  w.pair_force.resize(s.contacts.size());
  partition(m, w, c.threads);
  if (int(w.in_contact.size()) < c.threads) w.in_contact.resize(std::size_t(c.threads));
  for (auto& v : w.in_contact) v.clear();
}

void contact_forces_share(const Model& m, ModelState& s, Workspace& w, const StepContext& c, int t, int nt) {
  auto& C = s.contacts;
  const double dt = c.dt;
  const bool advance = c.advance;
  Workspace::PairForce* out = w.pair_force.data();
  // Each thread takes the pairs whose lower block it integrates (the keys are sorted by it): it reads the blocks it
  // moved itself. The ranges are contiguous and in thread order.
  const auto [b0, b1] = w.share(w.part.block, t, nt);
  const int lo = first_pair_of(C, b0), hi = first_pair_of(C, b1);
  std::vector<int>& mine = w.in_contact[std::size_t(t)];
  for (int p = lo; p < hi; ++p) {
    const int i = C.i[p], j = C.j[p];
    const double ex = s.x[j] - s.x[i], ey = s.y[j] - s.y[i];
    const double rr = m.radius[i] + m.radius[j];
    Overlap ov;
    double vi[6], vj[6];
    bool touching = false;
    if (ex * ex + ey * ey < rr * rr) {
      block_vertices(m, s, w, i, vi);
      block_vertices(m, s, w, j, vj);
      touching = overlap_polygons(vi, 3, vj, 3, ov);
    }
    // A pair still joined by its bond (listed only with skip_bonded_pairs = false): the bond's linear part is its
    // contact, so the narrow phase above was the whole of its cost.
    const bool intact = C.bond[p] >= 0 && !s.broken[std::size_t(C.bond[p])];
    if (!touching || intact) {
      if (advance) C.fs[p] = 0.0, C.fn[p] = 0.0, C.chord[p] = 0.0;
      out[p] = Workspace::PairForce{0, 0, 0, 0, 0, false};
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
    double fs = C.fs[p];
    const double friction = C.law[p].update_shear(fn, ov.chord, vt, dt, fs) ? std::abs(fs * vt * dt) : 0.0;
    if (advance) C.fs[p] = fs, C.fn[p] = fn, C.chord[p] = ov.chord;
    const double fx = fn * nx + fs * tx, fy = fn * ny + fs * ty;  // on j
    out[p] = Workspace::PairForce{fx, fy, cross(cix, ciy, fx, fy), cross(cjx, cjy, fx, fy), friction, true};
    mine.push_back(p);
  }
}

void contact_forces_end(ModelState& s, Workspace& w, const StepContext& c) {
  // Most pairs of free-face blocks do not touch: only those that do are summed, the lists in thread order, which
  // is pair order.
  const auto& C = s.contacts;
  const Workspace::PairForce* out = w.pair_force.data();
  for (const std::vector<int>& list : w.in_contact)
    for (int p : list) {
      const Workspace::PairForce& f = out[p];
      const int i = C.i[p], j = C.j[p];
      w.cfx[j] += f.fx, w.cfy[j] += f.fy, w.cm[j] += f.mj;
      w.cfx[i] -= f.fx, w.cfy[i] -= f.fy, w.cm[i] -= f.mi;
      if (c.advance) s.e_friction += f.friction;
    }
}

// Each pair's narrow phase and contact law run in parallel into the pair's own record; the records are then
// summed into the contact accumulators serially in pair order, so the sums do not depend on the thread count.
void contact_forces(const Model& m, ModelState& s, Workspace& w, const StepContext& c) {
  contact_forces_begin(m, s, w, c);
#pragma omp parallel num_threads(c.threads) if (s.contacts.size() > 64)
  contact_forces_share(m, s, w, c, omp_get_thread_num(), omp_get_num_threads());
  contact_forces_end(s, w, c);
}

}  // namespace rbdem::stages
