// The explicit RB-DEM engine: set-up, the step stages and diagnostics. See engine.hpp.
#include "dem/engine.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>
#include <omp.h>

#include "dem/contact_geometry.hpp"

namespace rbdem {

namespace {

inline double cross(double ax, double ay, double bx, double by) { return ax * by - ay * bx; }
constexpr double deg = std::numbers::pi / 180.0;

}  // namespace

EngineOptions EngineOptions::from_scene(const Scene& scene) {
  EngineOptions o;
  o.damping = scene.numerics.damping;
  o.mass_scaling = scene.numerics.mass_scaling;
  o.platen_velocity = scene.loading.platen_velocity;
  o.platen_friction = scene.loading.platen_friction;
  o.threads = scene.numerics.threads;
  return o;
}

Engine::Engine(const Topology& topo, const Scene& scene, const EngineOptions& options)
    : topo_(topo), options_(options), thickness_(topo.thickness), width_(topo.width()), height_(topo.height()) {
  const std::size_t nb = topo.blocks.size();
  const auto& G = topo.blocks;
  auto& B = blocks;
  B.x = G.cx, B.y = G.cy, B.x0 = G.cx, B.y0 = G.cy;
  B.theta.assign(nb, 0.0), B.vx.assign(nb, 0.0), B.vy.assign(nb, 0.0), B.omega.assign(nb, 0.0);
  B.fx.assign(nb, 0.0), B.fy.assign(nb, 0.0), B.moment.assign(nb, 0.0);
  B.cos_t.assign(nb, 1.0), B.sin_t.assign(nb, 0.0);
  B.mass.resize(nb), B.inertia.resize(nb);
  for (std::size_t b = 0; b < nb; ++b) {
    B.mass[b] = G.mass[b] * options_.mass_scaling;
    B.inertia[b] = G.inertia[b] * options_.mass_scaling;
  }
  B.radius = G.radius, B.shape = G.shape, B.layer = G.layer;
  B.inradius.resize(nb);
  for (std::size_t b = 0; b < nb; ++b) {
    const auto& s = G.shape[b];
    double perimeter = 0;
    for (int v = 0; v < 3; ++v)
      perimeter += std::hypot(s[2 * ((v + 1) % 3)] - s[2 * v], s[2 * ((v + 1) % 3) + 1] - s[2 * v + 1]);
    B.inradius[b] = 2.0 * G.area[b] / perimeter;
  }
  B.free_face.assign(nb, 0);
  B.fixed.assign(nb, 0);
  for (int b : topo.boundary.block) B.free_face[b] = 1;

  // Materials by kind: rock inside a layer, joint across layers.
  const std::array<const MaterialParams*, 2> mat{&scene.rock, &scene.joint};
  for (int k = 0; k < 2; ++k) {
    modulus_[k] = mat[k]->effective_modulus;
    kappa_[k] = mat[k]->stiffness_ratio;
    strength_[k] = {mat[k]->tensile_strength, mat[k]->cohesion, std::tan(mat[k]->friction_deg * deg),
                    mat[k]->moment_factor};
    contact_law_[k] = {0.0, 0.0, mat[k]->contact_friction};
  }

  const auto& N = topo.bonds;
  const std::size_t nbond = N.size();
  auto& D = bonds;
  D.i = N.i, D.j = N.j, D.n0x = N.nx, D.n0y = N.ny, D.L = N.length, D.d = N.d, D.kind = N.kind;
  D.rix.resize(nbond), D.riy.resize(nbond), D.rjx.resize(nbond), D.rjy.resize(nbond);
  D.A.resize(nbond), D.I.resize(nbond), D.kbnA.resize(nbond), D.kbsA.resize(nbond), D.kbnI.resize(nbond);
  D.linear.resize(nbond);
  for (std::size_t b = 0; b < nbond; ++b) {
    D.rix[b] = N.mx[b] - G.cx[N.i[b]], D.riy[b] = N.my[b] - G.cy[N.i[b]];
    D.rjx[b] = N.mx[b] - G.cx[N.j[b]], D.rjy[b] = N.my[b] - G.cy[N.j[b]];
    const double L = N.length[b];
    D.A[b] = L * thickness_;
    D.I[b] = thickness_ * L * L * L / 12.0;
    const int k = int(N.kind[b]);
    const double kn = modulus_[k] / N.d[b];  // Pa/m
    D.kbnA[b] = kn * D.A[b];
    D.kbsA[b] = kn / kappa_[k] * D.A[b];
    D.kbnI[b] = kn * D.I[b];
    D.linear[b] = {kn, kn / kappa_[k], contact_law_[k].mu};
  }
  D.broken.assign(nbond, 0);
  D.fs_lin.assign(nbond, 0.0);
  for (auto* v : {&D.fn_b, &D.fs_b, &D.m_b, &D.fn_lin, &D.sfx, &D.sfy, &D.smi, &D.smj}) v->assign(nbond, 0.0);

  // CSR with the block's role encoded: entry = 2 bond + (block is j).
  csr_offset_ = topo.bond_offset;
  csr_entry_.resize(topo.bond_of.size());
  for (std::size_t b = 0; b < nb; ++b)
    for (int o = csr_offset_[b]; o < csr_offset_[b + 1]; ++o) {
      const int bond = topo.bond_of[o];
      csr_entry_[o] = 2 * bond + (N.j[bond] == int(b) ? 1 : 0);
    }

  cfx_.assign(nb, 0.0), cfy_.assign(nb, 0.0), cm_.assign(nb, 0.0);
  top_fs_.assign(nb, 0.0), bottom_fs_.assign(nb, 0.0);
  // Platen stiffness: the platen acts as the mirror image of the block, d = 2 x inradius.
  platen_kn_.resize(nb);
  for (std::size_t b = 0; b < nb; ++b) platen_kn_[b] = modulus_[0] / (2.0 * B.inradius[b]);
  top_y_ = top_y0_ = topo.ymax;
  bottom_y_ = topo.ymin;

  double mean_length = 0;
  for (double L : N.length) mean_length += L;
  mean_length = nbond ? mean_length / double(nbond) : 1e-3;
  skin_ = 0.2 * mean_length;

  const int threads = options_.threads > 0 ? options_.threads : omp_get_max_threads();
  thread_breaks_.assign(std::size_t(std::max(threads, 1)), {});
  rebuild_active();
  rebuild_ = true;
  dt_ = critical_step();
}

void Engine::refresh() {
  rebuild_active();
  update_rotations();
  rebuild_ = true;
}

void Engine::rebuild_active() {
  active_.clear();
  for (std::size_t b = 0; b < bonds.i.size(); ++b)
    if (!bonds.broken[b]) active_.push_back(int(b));
}

bool Engine::bonded(int i, int j) const {
  for (int o = csr_offset_[i]; o < csr_offset_[i + 1]; ++o) {
    const int b = csr_entry_[o] >> 1;
    if (!bonds.broken[b] && (bonds.i[b] == j || bonds.j[b] == j)) return true;
  }
  return false;
}

double Engine::critical_step() const {
  // THEORY.md 5: dt_crit = min over blocks of sqrt(m / k_trans) and sqrt(I / k_rot), with k the sums of the
  // normal and shear stiffnesses acting on the block (parallel bond + linear part in compression; platens).
  const std::size_t nb = blocks.x.size();
  std::vector<double> kt(nb, 0.0), kr(nb, 0.0);
  const auto& D = bonds;
  for (std::size_t b = 0; b < D.i.size(); ++b) {
    if (D.broken[b]) continue;
    const double knA = D.kbnA[b] + D.linear[b].kn * D.A[b];
    const double ksA = D.kbsA[b] + D.linear[b].ks * D.A[b];
    const double nx = D.n0x[b], ny = D.n0y[b];
    for (int side = 0; side < 2; ++side) {
      const int blk = side == 0 ? D.i[b] : D.j[b];
      const double rx = side == 0 ? D.rix[b] : D.rjx[b], ry = side == 0 ? D.riy[b] : D.rjy[b];
      const double rn = cross(rx, ry, nx, ny), rt = rx * nx + ry * ny;  // r x n and r x t (t = perp n)
      kt[blk] += knA + ksA;
      kr[blk] += D.kbnI[b] + knA * rn * rn + ksA * rt * rt;
    }
  }
  if (options_.platens)
    for (std::size_t e = 0; e < topo_.boundary.size(); ++e) {
      const Side s = topo_.boundary.side[e];
      if (s != Side::top && s != Side::bottom) continue;
      const int blk = topo_.boundary.block[e];
      const double k = platen_kn_[blk] * thickness_ * topo_.boundary.length[e];
      kt[blk] += k * (1.0 + 1.0 / kappa_[0]);
      const double r = 0.5 * blocks.radius[blk];
      kr[blk] += k * r * r;
    }
  double dt = 1e300;
  for (std::size_t b = 0; b < nb; ++b) {
    if (kt[b] > 0) dt = std::min(dt, std::sqrt(blocks.mass[b] / kt[b]));
    if (kr[b] > 0) dt = std::min(dt, std::sqrt(blocks.inertia[b] / kr[b]));
  }
  return dt;
}

void Engine::update_rotations() {
  const int n = int(blocks.x.size());
#pragma omp parallel for schedule(static) num_threads(thread_breaks_.size())
  for (int b = 0; b < n; ++b) {
    blocks.cos_t[b] = std::cos(blocks.theta[b]);
    blocks.sin_t[b] = std::sin(blocks.theta[b]);
  }
}

void Engine::block_vertices(int b, double* out) const {
  const double c = blocks.cos_t[b], s = blocks.sin_t[b];
  const auto& sh = blocks.shape[b];
  for (int v = 0; v < 3; ++v) {
    out[2 * v] = blocks.x[b] + c * sh[2 * v] - s * sh[2 * v + 1];
    out[2 * v + 1] = blocks.y[b] + s * sh[2 * v] + c * sh[2 * v + 1];
  }
}

void Engine::step() {
  if (steps_ == 0) update_rotations();
  bond_forces();
  process_breaks();
  broad_phase();
  contact_forces();
  platen_forces();
  integrate();
  update_rotations();
  top_y_ -= options_.platen_velocity * dt_;
  time_ += dt_;
  ++steps_;
}

// Stage: every intact bond computes its parallel bond and linear part and writes one slot. Pure per-bond work.
void Engine::bond_forces() {
  auto& D = bonds;
  const auto& Bk = blocks;
  const double t = thickness_, dt = dt_;
  const int n = int(active_.size());
  const bool breakage = breakage_;
  for (auto& v : thread_breaks_) v.clear();
#pragma omp parallel num_threads(thread_breaks_.size())
  {
    auto& breaks = thread_breaks_[std::size_t(omp_get_thread_num())];
#pragma omp for schedule(static)
    for (int k = 0; k < n; ++k) {
      const int b = active_[k];
      const int i = D.i[b], j = D.j[b];
      const double ci = Bk.cos_t[i], si = Bk.sin_t[i], cj = Bk.cos_t[j], sj = Bk.sin_t[j];
      // Material points of the bond on each block, and the co-rotated frame (bisector of the rotated normals).
      const double rix = ci * D.rix[b] - si * D.riy[b], riy = si * D.rix[b] + ci * D.riy[b];
      const double rjx = cj * D.rjx[b] - sj * D.rjy[b], rjy = sj * D.rjx[b] + cj * D.rjy[b];
      const double gx = (Bk.x[j] + rjx) - (Bk.x[i] + rix), gy = (Bk.y[j] + rjy) - (Bk.y[i] + riy);
      double nx = (ci + cj) * D.n0x[b] - (si + sj) * D.n0y[b];
      double ny = (si + sj) * D.n0x[b] + (ci + cj) * D.n0y[b];
      const double inv = 1.0 / std::sqrt(nx * nx + ny * ny);
      nx *= inv, ny *= inv;
      const double tx = -ny, ty = nx;
      const double dn = gx * nx + gy * ny, ds = gx * tx + gy * ty;
      const double dth = Bk.theta[j] - Bk.theta[i];
      // Parallel bond (total, co-rotated).
      const double fnb = -D.kbnA[b] * dn, fsb = -D.kbsA[b] * ds, mb = -D.kbnI[b] * dth;
      // Linear part: overlap of the compressed part of the edge; incremental shear at the bond centre.
      const EdgeOverlap eo = edge_overlap(D.L[b], dn, dth);
      const double fnl = D.linear[b].normal_force(eo.area, t);
      // contact point (centre of the two material points) relative to each centroid
      const double cix = rix + 0.5 * gx, ciy = riy + 0.5 * gy;
      const double cjx = rjx - 0.5 * gx, cjy = rjy - 0.5 * gy;
      const double vrx = (Bk.vx[j] - Bk.omega[j] * cjy) - (Bk.vx[i] - Bk.omega[i] * ciy);
      const double vry = (Bk.vy[j] + Bk.omega[j] * cjx) - (Bk.vy[i] + Bk.omega[i] * cix);
      double fsl = D.fs_lin[b];
      D.linear[b].update_shear(fnl, eo.chord, t, (vrx * tx + vry * ty) * dt, fsl);
      D.fs_lin[b] = fsl;
      D.fn_b[b] = fnb, D.fs_b[b] = fsb, D.m_b[b] = mb, D.fn_lin[b] = fnl;
      if (breakage) {
        double sigma, tau;
        const BondStrength& st = strength_[int(D.kind[b])];
        if (st.check(fnb, fsb, mb, D.A[b], D.I[b], 0.5 * D.L[b], sigma, tau) != BreakMode::none) breaks.push_back(b);
      }
      // Force on j (on i the opposite); the linear part acts at s_c along the edge.
      const double flx = fnl * nx + fsl * tx, fly = fnl * ny + fsl * ty;
      const double fx = fnb * nx + fsb * tx + flx, fy = fnb * ny + fsb * ty + fly;
      const double lever = cross(eo.s_c * tx, eo.s_c * ty, flx, fly);
      D.sfx[b] = fx, D.sfy[b] = fy;
      D.smj[b] = cross(cjx, cjy, fx, fy) + lever + mb;
      D.smi[b] = -cross(cix, ciy, fx, fy) - lever - mb;
    }
  }
}

// Stage: breakage events in bond order (deterministic at any thread count).
void Engine::process_breaks() {
  pending_breaks_.clear();
  for (const auto& v : thread_breaks_)
    for (int b : v) pending_breaks_.push_back({b, BreakMode::none});
  if (pending_breaks_.empty()) return;
  std::sort(pending_breaks_.begin(), pending_breaks_.end());
  auto& D = bonds;
  for (auto& [b, mode] : pending_breaks_) {
    double sigma, tau;
    mode = strength_[int(D.kind[b])].check(D.fn_b[b], D.fs_b[b], D.m_b[b], D.A[b], D.I[b], 0.5 * D.L[b], sigma, tau);
    const int i = D.i[b], j = D.j[b];
    Crack c;
    c.time = time_, c.strain = strain_for_log, c.bond = b, c.kind = D.kind[b], c.mode = mode;
    c.sigma = sigma, c.tau = tau;
    const double ci = blocks.cos_t[i], si = blocks.sin_t[i];
    c.x = blocks.x[i] + ci * D.rix[b] - si * D.riy[b];
    c.y = blocks.y[i] + si * D.rix[b] + ci * D.riy[b];
    D.broken[b] = 1;
    D.fn_b[b] = D.fs_b[b] = D.m_b[b] = D.fn_lin[b] = 0.0;
    D.sfx[b] = D.sfy[b] = D.smi[b] = D.smj[b] = 0.0;  // the pair's contact carries the linear part from now on
    blocks.free_face[i] = blocks.free_face[j] = 1;
    cracks_.push_back(c);
    if (on_crack) on_crack(c);
  }
  rebuild_active();
  rebuild_ = true;
}

bool Engine::needs_rebuild() const {
  if (rebuild_) return true;
  if (std::abs(top_y_ - ref_top_) > 0.5 * skin_) return true;
  const double lim2 = 0.25 * skin_ * skin_;
  for (std::size_t b = 0; b < blocks.x.size(); ++b) {
    if (!blocks.free_face[b]) continue;
    const double dx = blocks.x[b] - ref_x_[b], dy = blocks.y[b] - ref_y_[b];
    if (dx * dx + dy * dy > lim2) return true;
  }
  return false;
}

// Stage: candidate pairs among blocks with a free face (a broken bond or a boundary edge), on a cell grid with
// a skin; pairs joined by an intact bond need no narrow phase. Shear history carries over by pair key.
void Engine::broad_phase() {
  if (!needs_rebuild()) return;
  rebuild_ = false;
  const std::size_t nb = blocks.x.size();
  ref_x_ = blocks.x, ref_y_ = blocks.y, ref_top_ = top_y_;
  std::vector<int> eligible;
  double rmax = 0;
  for (std::size_t b = 0; b < nb; ++b)
    if (blocks.free_face[b]) eligible.push_back(int(b)), rmax = std::max(rmax, blocks.radius[b]);

  // Platen candidates (the platen may travel skin/2 before the next rebuild).
  top_candidates_.clear(), bottom_candidates_.clear();
  if (options_.platens)
    for (int b : eligible) {
      if (blocks.y[b] + blocks.radius[b] > top_y_ - skin_) top_candidates_.push_back(b);
      if (blocks.y[b] - blocks.radius[b] < bottom_y_ + skin_) bottom_candidates_.push_back(b);
    }

  // Uniform grid over the eligible blocks.
  const double cell = 2.0 * rmax + skin_;
  double xmin = 1e300, ymin = 1e300;
  for (int b : eligible) xmin = std::min(xmin, blocks.x[b]), ymin = std::min(ymin, blocks.y[b]);
  std::vector<std::pair<std::uint64_t, int>> cells;
  cells.reserve(eligible.size());
  auto cell_of = [&](int b) {
    return std::pair<long, long>{long((blocks.x[b] - xmin) / cell), long((blocks.y[b] - ymin) / cell)};
  };
  auto cell_key = [](long cx, long cy) { return (std::uint64_t(cx) << 32) | std::uint64_t(cy); };
  for (int b : eligible) {
    const auto [cx, cy] = cell_of(b);
    cells.push_back({cell_key(cx, cy), b});
  }
  std::sort(cells.begin(), cells.end());
  auto find_cell = [&](std::uint64_t key) {
    auto it = std::lower_bound(cells.begin(), cells.end(), std::pair<std::uint64_t, int>{key, -1});
    return it;
  };
  std::vector<std::uint64_t> keys;
  for (int a : eligible) {
    const auto [cx, cy] = cell_of(a);
    for (long dx = -1; dx <= 1; ++dx)
      for (long dy = -1; dy <= 1; ++dy) {
        if (cx + dx < 0 || cy + dy < 0) continue;
        const std::uint64_t key = cell_key(cx + dx, cy + dy);
        for (auto it = find_cell(key); it != cells.end() && it->first == key; ++it) {
          const int b = it->second;
          if (b <= a) continue;
          const double rr = blocks.radius[a] + blocks.radius[b] + skin_;
          const double ex = blocks.x[b] - blocks.x[a], ey = blocks.y[b] - blocks.y[a];
          if (ex * ex + ey * ey > rr * rr) continue;
          if (bonded(a, b)) continue;
          keys.push_back(pair_key(a, b));
        }
      }
  }
  std::sort(keys.begin(), keys.end());

  ContactPairs next;
  const auto& old = contacts;
  std::size_t o = 0;
  for (std::uint64_t key : keys) {
    const int i = int(key >> 32), j = int(key & 0xffffffffu);
    while (o < old.key.size() && old.key[o] < key) ++o;
    int bond = -1;
    for (int e = csr_offset_[i]; e < csr_offset_[i + 1]; ++e) {
      const int bb = csr_entry_[e] >> 1;
      if (bonds.i[bb] == j || bonds.j[bb] == j) bond = bb;
    }
    LinearContact law;
    if (bond >= 0) {
      law = bonds.linear[bond];
    } else {
      const int kind = blocks.layer[i] == blocks.layer[j] ? 0 : 1;
      const double kn = modulus_[kind] / (blocks.inradius[i] + blocks.inradius[j]);
      law = {kn, kn / kappa_[kind], contact_law_[kind].mu};
    }
    double fs = 0.0;
    if (o < old.key.size() && old.key[o] == key) fs = old.fs[o];
    else if (bond >= 0) fs = bonds.fs_lin[bond];  // a bond that just broke hands over its linear shear force
    next.i.push_back(i), next.j.push_back(j), next.bond.push_back(bond), next.law.push_back(law);
    next.fs.push_back(fs), next.fn.push_back(0.0), next.chord.push_back(0.0), next.key.push_back(key);
  }
  contacts = std::move(next);
}

// Stage: polygon contacts, serially in pair order into the contact accumulators.
void Engine::contact_forces() {
  std::fill(cfx_.begin(), cfx_.end(), 0.0);
  std::fill(cfy_.begin(), cfy_.end(), 0.0);
  std::fill(cm_.begin(), cm_.end(), 0.0);
  auto& C = contacts;
  const double t = thickness_;
  for (std::size_t c = 0; c < C.i.size(); ++c) {
    const int i = C.i[c], j = C.j[c];
    const double ex = blocks.x[j] - blocks.x[i], ey = blocks.y[j] - blocks.y[i];
    const double rr = blocks.radius[i] + blocks.radius[j];
    Overlap ov;
    double vi[6], vj[6];
    bool touching = false;
    if (ex * ex + ey * ey < rr * rr) {
      block_vertices(i, vi);
      block_vertices(j, vj);
      touching = overlap_polygons(vi, 3, vj, 3, ov);
    }
    if (!touching) {
      C.fs[c] = 0.0, C.fn[c] = 0.0, C.chord[c] = 0.0;
      continue;
    }
    const double nx = -ov.nx, ny = -ov.ny;  // from i to j, as for bonds
    const double tx = -ny, ty = nx;
    const double fn = C.law[c].normal_force(ov.area, t);
    const double cix = ov.px - blocks.x[i], ciy = ov.py - blocks.y[i];
    const double cjx = ov.px - blocks.x[j], cjy = ov.py - blocks.y[j];
    const double vrx = (blocks.vx[j] - blocks.omega[j] * cjy) - (blocks.vx[i] - blocks.omega[i] * ciy);
    const double vry = (blocks.vy[j] + blocks.omega[j] * cjx) - (blocks.vy[i] + blocks.omega[i] * cix);
    const double ds = (vrx * tx + vry * ty) * dt_;
    double fs = C.fs[c];
    if (C.law[c].update_shear(fn, ov.chord, t, ds, fs)) e_friction_ += std::abs(fs * ds);
    C.fs[c] = fs, C.fn[c] = fn, C.chord[c] = ov.chord;
    const double fx = fn * nx + fs * tx, fy = fn * ny + fs * ty;  // on j
    cfx_[j] += fx, cfy_[j] += fy, cm_[j] += cross(cjx, cjy, fx, fy);
    cfx_[i] -= fx, cfy_[i] -= fy, cm_[i] -= cross(cix, ciy, fx, fy);
  }
}

// Stage: the two platens, as half-planes with the same area law (k_n from the block's mirror image).
void Engine::platen_forces() {
  top_force_ = bottom_force_ = platen_energy_ = 0.0;
  if (!options_.platens) return;
  const double t = thickness_;
  const double mu = options_.platen_friction;
  for (int side = 0; side < 2; ++side) {
    const bool top = side == 0;
    const auto& cand = top ? top_candidates_ : bottom_candidates_;
    auto& fs_hist = top ? top_fs_ : bottom_fs_;
    const double wy = top ? top_y_ : bottom_y_;
    const double my = top ? 1.0 : -1.0;  // into the platen
    const double wall_vy = top ? -options_.platen_velocity : 0.0;
    double total = 0.0;
    for (int b : cand) {
      double v[6];
      block_vertices(b, v);
      Overlap ov;
      if (!overlap_halfplane(v, 3, 0.0, wy, 0.0, my, ov)) {
        fs_hist[b] = 0.0;
        continue;
      }
      const LinearContact law{platen_kn_[b], platen_kn_[b] / kappa_[0], mu};
      const double fn = law.normal_force(ov.area, t);
      // Force on the block: -fn along the normal (out of the platen), shear along t = perp(n).
      const double nx = ov.nx, ny = ov.ny, tx = -ny, ty = nx;
      const double rx = ov.px - blocks.x[b], ry = ov.py - blocks.y[b];
      const double vrx = blocks.vx[b] - blocks.omega[b] * ry, vry = blocks.vy[b] + blocks.omega[b] * rx - wall_vy;
      const double ds = (vrx * tx + vry * ty) * dt_;
      double fs = fs_hist[b];
      if (law.update_shear(fn, ov.chord, t, ds, fs)) e_friction_ += std::abs(fs * ds);
      fs_hist[b] = fs;
      const double fx = -fn * nx + fs * tx, fy = -fn * ny + fs * ty;
      cfx_[b] += fx, cfy_[b] += fy, cm_[b] += cross(rx, ry, fx, fy);
      total += fn;
      const double k = law.kn * t * ov.chord;
      platen_energy_ += 0.5 * (fn * fn + fs * fs * kappa_[0]) / k;
    }
    (top ? top_force_ : bottom_force_) = total;
  }
  e_work_ += top_force_ * options_.platen_velocity * dt_;
}

// Stage: per-block gather in fixed CSR order, Cundall local damping, central difference update.
void Engine::integrate() {
  auto& B = blocks;
  const auto& D = bonds;
  const int n = int(B.x.size());
  const double dt = dt_, alpha = options_.damping;
  double e_damp = 0.0;
  bool finite = true;
#pragma omp parallel for schedule(static) num_threads(thread_breaks_.size()) reduction(+ : e_damp) \
    reduction(&& : finite)
  for (int b = 0; b < n; ++b) {
    double fx = cfx_[b], fy = cfy_[b], m = cm_[b];
    for (int o = csr_offset_[b]; o < csr_offset_[b + 1]; ++o) {
      const int e = csr_entry_[o], bond = e >> 1;
      if (e & 1) fx += D.sfx[bond], fy += D.sfy[bond], m += D.smj[bond];
      else fx -= D.sfx[bond], fy -= D.sfy[bond], m += D.smi[bond];
    }
    B.fx[b] = fx, B.fy[b] = fy, B.moment[b] = m;
    if (B.fixed[b]) continue;
    // Cundall local damping: F_d = -alpha |F| sign(v), per degree of freedom.
    const double dfx = -alpha * std::abs(fx) * ((B.vx[b] > 0) - (B.vx[b] < 0));
    const double dfy = -alpha * std::abs(fy) * ((B.vy[b] > 0) - (B.vy[b] < 0));
    const double dm = -alpha * std::abs(m) * ((B.omega[b] > 0) - (B.omega[b] < 0));
    e_damp -= (dfx * B.vx[b] + dfy * B.vy[b] + dm * B.omega[b]) * dt;
    B.vx[b] += dt * (fx + dfx) / B.mass[b];
    B.vy[b] += dt * (fy + dfy) / B.mass[b];
    B.omega[b] += dt * (m + dm) / B.inertia[b];
    B.x[b] += dt * B.vx[b];
    B.y[b] += dt * B.vy[b];
    B.theta[b] += dt * B.omega[b];
    finite = finite && std::isfinite(B.x[b]) && std::isfinite(B.y[b]) && std::isfinite(B.theta[b]);
  }
  e_damping_ += e_damp;
  if (!finite)
    throw InstabilityError(fmt::format(
        "the run diverged at step {} (t = {:.4g} s): positions are no longer finite. The time step {:.4g} s is "
        "above the stability limit of this scene (critical step estimate {:.4g} s); lower numerics.dt or "
        "numerics.dt_safety",
        steps_, time_, dt_, critical_step()));
}

std::size_t Engine::active_contacts() const {
  return std::size_t(std::count_if(contacts.fn.begin(), contacts.fn.end(), [](double f) { return f > 0; }));
}

Energies Engine::energies() const {
  Energies e;
  const auto& B = blocks;
  for (std::size_t b = 0; b < B.x.size(); ++b)
    e.kinetic += 0.5 * (B.mass[b] * (B.vx[b] * B.vx[b] + B.vy[b] * B.vy[b]) + B.inertia[b] * B.omega[b] * B.omega[b]);
  const auto& D = bonds;
  const double t = thickness_;
  for (std::size_t b = 0; b < D.i.size(); ++b) {
    if (D.broken[b]) continue;
    e.strain += 0.5 * (D.fn_b[b] * D.fn_b[b] / D.kbnA[b] + D.fs_b[b] * D.fs_b[b] / D.kbsA[b] +
                       D.m_b[b] * D.m_b[b] / D.kbnI[b]);
    const double kl = D.linear[b].kn * t * D.L[b];
    e.strain += 0.5 * (D.fn_lin[b] * D.fn_lin[b] / kl + D.fs_lin[b] * D.fs_lin[b] * D.linear[b].kn /
                                                            (D.linear[b].ks * kl));
  }
  for (std::size_t c = 0; c < contacts.i.size(); ++c) {
    if (!(contacts.fn[c] > 0)) continue;
    const auto& law = contacts.law[c];
    const double k = law.kn * t * contacts.chord[c];
    e.strain += 0.5 * (contacts.fn[c] * contacts.fn[c] / k + contacts.fs[c] * contacts.fs[c] * law.kn / (law.ks * k));
  }
  e.strain += platen_energy_;
  e.damping = e_damping_;
  e.friction = e_friction_;
  e.work_platen = e_work_;
  return e;
}

}  // namespace rbdem
