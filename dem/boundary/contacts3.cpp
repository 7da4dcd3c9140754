// Contacts between 3D blocks that were never neighbours. See components3.hpp.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <thread>

#include "dem/boundary/components3.hpp"
#include "dem/contact3.hpp"

namespace rbdem {

namespace {

Tet world_tet(const Model<3>& m, const ModelState<3>& s, std::size_t b) {
  const Vec3 x = s.position(b);
  const Quat q = s.rotation(b);
  Tet t;
  for (std::size_t k = 0; k < 4; ++k) t[k] = x + rotate(q, m.shape[b][k]);
  return t;
}

}  // namespace

BlockContacts3::BlockContacts3(const Model<3>& m) {
  const std::size_t nb = m.num_blocks();
  mean_face_.assign(nb, 0.0);
  neighbours_.assign(nb, {});
  double edge = 0;
  for (std::size_t b = 0; b < nb; ++b) {
    const auto& v = m.shape[b];
    double area = 0;
    for (std::size_t f = 0; f < 4; ++f) {
      const Vec3 a = v[f], c = v[(f + 1) % 4], d = v[(f + 2) % 4];
      area += 0.5 * norm(cross(c - a, d - a));
    }
    mean_face_[b] = 0.25 * area;
    edge += norm(v[1] - v[0]);
  }
  skin_ = nb > 0 ? 0.2 * edge / double(nb) : 0.0;  // a fifth of the mean edge, as the 2D broad phase
  for (std::size_t b = 0; b < m.num_bonds(); ++b) {
    neighbours_[std::size_t(m.bi[b])].push_back(m.bj[b]);
    neighbours_[std::size_t(m.bj[b])].push_back(m.bi[b]);
  }
  for (auto& n : neighbours_) std::sort(n.begin(), n.end());
}

bool BlockContacts3::rebuild_due(const Model<3>& m, const ModelState<3>& s) const {
  (void)m;
  if (long(s.cracks.size()) != broken_seen_) return true;
  const double limit = 0.25 * skin_ * skin_;  // half a skin, squared
  for (std::size_t k = 0; k < eligible_.size(); ++k) {
    const std::size_t b = std::size_t(eligible_[k]);
    const double dx = s.x[b] - ref_[3 * k], dy = s.y[b] - ref_[3 * k + 1], dz = s.z[b] - ref_[3 * k + 2];
    if (dx * dx + dy * dy + dz * dz > limit) return true;
  }
  return false;
}

// The blocks that lost a bond (or never had one), their boxes grown by the skin, swept; pairs that share no face,
// in order of (i, j). A pair that was in the list keeps its shear history.
void BlockContacts3::rebuild(const Model<3>& m, const ModelState<3>& s) {
  ++rebuilds_;
  broken_seen_ = long(s.cracks.size());
  std::vector<std::uint8_t> lost(m.num_blocks(), 0);
  for (std::size_t b = 0; b < m.num_blocks(); ++b) lost[b] = m.offset[b] == m.offset[b + 1];  // no bond at all
  for (const Crack& c : s.cracks) lost[std::size_t(m.bi[std::size_t(c.bond)])] = lost[std::size_t(m.bj[std::size_t(c.bond)])] = 1;
  eligible_.clear(), ref_.clear();
  for (std::size_t b = 0; b < lost.size(); ++b)
    if (lost[b]) eligible_.push_back(int(b)), ref_.insert(ref_.end(), {s.x[b], s.y[b], s.z[b]});
  std::vector<Aabb3> box(eligible_.size());
  for (std::size_t k = 0; k < eligible_.size(); ++k) box[k] = aabb_of(world_tet(m, s, std::size_t(eligible_[k])));
  // Swept along the axis the boxes spread most along (the cracked blocks of vertical joints share their x, and a
  // sweep along x would then test every pair of them); the pairs found are the same along any axis.
  int axis = 0;
  double spread[3] = {};
  for (int c = 0; c < 3 && !box.empty(); ++c) {
    double mean = 0;
    for (const Aabb3& b : box) mean += b.lo[c];
    mean /= double(box.size());
    for (const Aabb3& b : box) spread[c] += (b.lo[c] - mean) * (b.lo[c] - mean);
    if (spread[c] > spread[axis]) axis = c;
  }
  std::vector<std::size_t> order(eligible_.size());
  for (std::size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return box[a].lo[axis] != box[b].lo[axis] ? box[a].lo[axis] < box[b].lo[axis] : eligible_[a] < eligible_[b];
  });
  // Each pair under its lower block's place in eligible_ (ascending blocks), so that the lists read in that order,
  // each sorted, are the pairs in order of (i, j) without sorting them all.
  std::vector<std::vector<int>> partners(eligible_.size());
  for (std::size_t a = 0; a < order.size(); ++a) {
    const Aabb3& A = box[order[a]];
    for (std::size_t c = a + 1; c < order.size(); ++c) {
      const Aabb3& C = box[order[c]];
      if (C.lo[axis] - skin_ > A.hi[axis] + skin_) break;  // aabbs_overlap's test along the axis
      if (!aabbs_overlap(A, C, skin_)) continue;
      std::size_t ka = order[a], kc = order[c];
      if (ka > kc) std::swap(ka, kc);
      const int i = eligible_[ka], j = eligible_[kc];
      const auto& n = neighbours_[std::size_t(i)];
      if (std::binary_search(n.begin(), n.end(), j)) continue;  // a face's pair: the bond's linear part
      partners[ka].push_back(j);
    }
  }
  std::vector<std::pair<int, int>> found;
  for (std::size_t k = 0; k < partners.size(); ++k) {
    std::sort(partners[k].begin(), partners[k].end());
    for (const int j : partners[k]) found.emplace_back(eligible_[k], j);
  }
  std::vector<int> pi, pj;
  std::vector<double> fs;
  std::size_t old = 0;
  for (const auto& [i, j] : found) {
    while (old < pi_.size() && std::make_pair(pi_[old], pj_[old]) < std::make_pair(i, j)) ++old;
    const bool kept = old < pi_.size() && pi_[old] == i && pj_[old] == j;
    pi.push_back(i), pj.push_back(j);
    for (int k = 0; k < 3; ++k) fs.push_back(kept ? fs_[3 * old + std::size_t(k)] : 0.0);
  }
  pi_ = std::move(pi), pj_ = std::move(pj), fs_ = std::move(fs);
  records_.resize(pi_.size()), new_fs_.resize(3 * pi_.size()), touching_.resize(pi_.size());
  index_pairs(m.num_blocks());
}

// Each pair's blocks as places in eligible_ (every pair's blocks are eligible: the rebuild pairs only those).
// False where a pair's block is not eligible (a snapshot that does not hold together).
bool BlockContacts3::index_pairs(std::size_t num_blocks) {
  std::vector<int> place(num_blocks, -1);
  for (std::size_t k = 0; k < eligible_.size(); ++k) place[std::size_t(eligible_[k])] = int(k);
  ki_.resize(pi_.size()), kj_.resize(pi_.size());
  bool ok = true;
  for (std::size_t k = 0; k < pi_.size(); ++k) {
    ki_[k] = place[std::size_t(pi_[k])], kj_[k] = place[std::size_t(pj_[k])];
    ok = ok && ki_[k] >= 0 && kj_[k] >= 0;
  }
  posed_.resize(eligible_.size());
  ready_ = std::make_unique<std::atomic<long>[]>(eligible_.size());  // zero: not this step's
  return ok;
}

BlockContacts3::Force BlockContacts3::contact(const Model<3>& m, const ModelState<3>& s, std::size_t k, double dt,
                                              Vec3& fs) const {
  return contact(m, s, k, world_tet(m, s, std::size_t(pi_[k])), world_tet(m, s, std::size_t(pj_[k])), dt, fs);
}

// The pair k with its blocks' tetrahedra ti, tj at the state s.
BlockContacts3::Force BlockContacts3::contact(const Model<3>& m, const ModelState<3>& s, std::size_t k, const Tet& ti,
                                              const Tet& tj, double dt, Vec3& fs) const {
  Force out;
  const std::size_t i = std::size_t(pi_[k]), j = std::size_t(pj_[k]);
  TetContact c;
  if (!contact_tets(ti, tj, c) || !(c.area > 0) || !(c.volume > 0)) {
    fs = {};
    return out;
  }
  const bool same_layer = m.layer[i] == m.layer[j];
  const FaceKindLaw& law = m.law[same_layer ? 0 : 1];
  const double kn = law.modulus / (m.inradius[i] + m.inradius[j]);
  const double A = std::min(mean_face_[i], mean_face_[j]);
  out.fn = kn * c.volume * c.area / A;
  // The shear history turns with the normal (its normal part dropped, its length kept), then grows with the slip.
  const Vec3 n = c.normal;
  Vec3 t = fs - dot(fs, n) * n;
  const double old = norm(fs), now = norm(t);
  if (now > 0) t = (old / now) * t;
  const Vec3 ri = c.point - s.position(i), rj = c.point - s.position(j);
  const Vec3 v = (s.velocity(j) + cross(s.spin(j), rj)) - (s.velocity(i) + cross(s.spin(i), ri));
  const Vec3 vs = v - dot(v, n) * n;
  const double ks = kn / law.kappa * c.area;  // N/m: the shear stiffness of the contact area
  t -= (ks * dt) * vs;
  const double mag = norm(t), limit = law.mu * out.fn;
  if (mag > limit) {
    t = (mag > 0 ? limit / mag : 0.0) * t;
    out.friction = std::abs(dot(t, vs)) * dt;
  }
  fs = t;
  out.force = out.fn * n + t;
  out.point = c.point;
  out.energy = 0.5 * kn * c.volume * c.volume / A + (ks > 0 ? 0.5 * dot(t, t) / ks : 0.0);
  out.touching = true;
  return out;
}

void BlockContacts3::begin_step(const Model<3>& m, const ModelState<3>& s) {
  if (rebuild_due(m, s)) rebuild(m, s);
  ++generation_;  // every pose of the last step is stale
  cursor_.store(0, std::memory_order_relaxed);  // the threads' pieces start at the first pair
}

// Eligible block k's posed tetrahedron at the step's start, computed once in the step by the first thread that
// asks (the values do not depend on which); a thread that finds it being computed waits for it.
const PosedTet& BlockContacts3::posed_at(const Model<3>& m, const ModelState<3>& s, std::size_t k) const {
  std::atomic<long>& state = ready_[k];
  const long ready = 2 * generation_ + 2;
  long seen = state.load(std::memory_order_acquire);
  if (seen == ready) return posed_[k];
  if (seen != ready - 1 && state.compare_exchange_strong(seen, ready - 1, std::memory_order_acq_rel)) {
    posed_[k] = posed(world_tet(m, s, std::size_t(eligible_[k])));
    state.store(ready, std::memory_order_release);
    return posed_[k];
  }
  while (state.load(std::memory_order_acquire) != ready) std::this_thread::yield();
  return posed_[k];
}

// The pairs that touch lie where the specimen cracked, not spread evenly over the list: pieces of it go to whichever
// thread asks next, so a thread that finished its bonds early takes more. Each pair's record depends on the state
// alone, not on the thread that computed it.
void BlockContacts3::prepare_forces(const Model<3>& m, const ModelState<3>& s, double dt, int thread, int threads) {
  (void)threads;
  constexpr std::size_t kPiece = 16;
  if (thread == 0) prepared_ = true;  // read by add_forces after the engine's barrier
  const std::size_t n = pi_.size();
  for (std::size_t lo = cursor_.fetch_add(kPiece, std::memory_order_relaxed); lo < n;
       lo = cursor_.fetch_add(kPiece, std::memory_order_relaxed))
    for (std::size_t k = lo; k < std::min(n, lo + kPiece); ++k) {
      const PosedTet &a = posed_at(m, s, std::size_t(ki_[k])), &b = posed_at(m, s, std::size_t(kj_[k]));
      Vec3 fs;  // what contact() gives a pair contact_tets rejects: no force, no shear history
      if (tets_apart(a, b)) {
        touching_[k] = 0;
      } else {
        fs = {fs_[3 * k], fs_[3 * k + 1], fs_[3 * k + 2]};
        records_[k] = contact(m, s, k, a.t, b.t, dt, fs);
        touching_[k] = records_[k].touching;
      }
      new_fs_[3 * k] = fs.x, new_fs_[3 * k + 1] = fs.y, new_fs_[3 * k + 2] = fs.z;
    }
}

double BlockContacts3::add_forces(const Model<3>& m, const ModelState<3>& s, std::vector<Vec3>& force,
                                  std::vector<Vec3>& moment, double dt, bool advance) {
  // Prepared: begin_step rebuilt the list when due and the step's threads computed each pair's record. Otherwise
  // (a caller that steps without the engine's hooks, or evaluates only) all of it here.
  const bool prepared = advance && prepared_;
  prepared_ = false;
  if (advance && !prepared && rebuild_due(m, s)) rebuild(m, s);
  double energy = 0, friction = 0;
  auto add = [&](std::size_t k, const Force& f) {
    const std::size_t i = std::size_t(pi_[k]), j = std::size_t(pj_[k]);
    force[j] += f.force, force[i] -= f.force;
    moment[j] += cross(f.point - s.position(j), f.force);
    moment[i] -= cross(f.point - s.position(i), f.force);
    energy += f.energy, friction += f.friction;
  };
  if (prepared) {  // every pair's new history is in new_fs_, and a record only where touching_ says so
    fs_.swap(new_fs_);
    for (std::size_t k = 0; k < pi_.size(); ++k)
      if (touching_[k]) add(k, records_[k]);
  } else {
    for (std::size_t k = 0; k < pi_.size(); ++k) {
      Vec3 fs{fs_[3 * k], fs_[3 * k + 1], fs_[3 * k + 2]};
      const Force f = contact(m, s, k, dt, fs);
      if (advance) fs_[3 * k] = fs.x, fs_[3 * k + 1] = fs.y, fs_[3 * k + 2] = fs.z;
      if (f.touching) add(k, f);
    }
  }
  if (!advance) return 0.0;
  energy_ = energy;
  return friction;
}

void BlockContacts3::loads(const Model<3>&, const ModelState<3>&, int, BoundaryLoads&) const {}

ContactStates BlockContacts3::states(const Model<3>& m, const ModelState<3>& s) const {
  ContactStates out;
  out.dim = 3;
  for (std::size_t k = 0; k < pi_.size(); ++k) {
    Vec3 fs{fs_[3 * k], fs_[3 * k + 1], fs_[3 * k + 2]};
    const Force f = contact(m, s, k, 0.0, fs);
    if (!f.touching) continue;
    out.i.push_back(pi_[k]), out.j.push_back(pj_[k]);
    out.point.insert(out.point.end(), {f.point.x, f.point.y, f.point.z});
    const Vec3 n = (f.fn > 0 ? 1.0 / f.fn : 0.0) * (f.force - fs);
    out.normal.insert(out.normal.end(), {n.x, n.y, n.z});
    out.force.insert(out.force.end(), {f.force.x, f.force.y, f.force.z});
    out.normal_force.push_back(f.fn), out.shear_force.push_back(norm(fs));
  }
  return out;
}

void BlockContacts3::save(Snapshot& s) const {
  s.add("contacts3/i", Extent::free, pi_);
  s.add("contacts3/j", Extent::free, pj_);
  s.add("contacts3/fs", Extent::free, fs_);
  s.add("contacts3/eligible", Extent::free, eligible_);
  s.add("contacts3/ref", Extent::free, ref_);
  s.add("contacts3/broken_seen", Extent::scalar, broken_seen_);
  s.add("contacts3/energy", Extent::scalar, energy_);
}

void BlockContacts3::load(const Snapshot& s, const Model<3>& m) {
  const auto& i = s.get<std::vector<int>>("contacts3/i");
  const auto& j = s.get<std::vector<int>>("contacts3/j");
  const auto& fs = s.get<std::vector<double>>("contacts3/fs");
  const auto& eligible = s.get<std::vector<int>>("contacts3/eligible");
  const auto& ref = s.get<std::vector<double>>("contacts3/ref");
  const int nb = int(m.num_blocks());
  auto in_range = [nb](const std::vector<int>& v) {
    return std::all_of(v.begin(), v.end(), [nb](int b) { return b >= 0 && b < nb; });
  };
  if (i.size() != j.size() || fs.size() != 3 * i.size() || ref.size() != 3 * eligible.size() || !in_range(i) ||
      !in_range(j) || !in_range(eligible))
    throw std::invalid_argument("the snapshot's 3D contacts do not fit this model (another scene or mesh)");
  pi_ = i, pj_ = j, fs_ = fs, eligible_ = eligible, ref_ = ref;
  records_.resize(pi_.size()), new_fs_.resize(3 * pi_.size()), touching_.resize(pi_.size());
  if (!index_pairs(m.num_blocks()))
    throw std::invalid_argument("the snapshot's 3D contacts pair blocks it does not list as searched (a damaged file)");
  prepared_ = false, cursor_.store(0, std::memory_order_relaxed);
  broken_seen_ = s.get<long>("contacts3/broken_seen");
  energy_ = s.get<double>("contacts3/energy");
}

}  // namespace rbdem
