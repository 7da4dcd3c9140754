// The explicit RB-DEM engine: set-up, the step stages and diagnostics. See engine.hpp.
#include "dem/engine.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>
#include <omp.h>

#include "dem/fault_injection.hpp"

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
  o.skip_bonded_pairs = scene.numerics.skip_bonded_pairs;
  o.search_free_faces_only = scene.numerics.search_free_faces_only;
  return o;
}

namespace {

// One bond's forces from the kinematics of its two blocks: the parallel bond (total, co-rotated) and the linear
// part (overlap of the compressed part of the edge, incremental shear at the bond centre). `fs` is the linear
// part's shear history in and out; dt = 0 evaluates without advancing it. `keep` (1 - damage) scales the parallel
// bond's forces in the slot; fnb, fsb and mb stay the undamaged (effective) forces the failure index reads.
struct BondEval {
  double fnb, fsb, mb, fnl, fsl;  // forces in the co-rotated frame
  double inv_L;
  BondSlot slot;                  // force on j, moments on i and j
  double px, py;                  // bond point (world)
};

inline void eval_bond(const BondFrame& f, const BlockState& bi, const BlockState& bj, const Engine::KindParams& kp,
                      double dt, double fs, BondEval& out, double keep = 1.0) {
  // Material points of the bond on each block, and the co-rotated frame: the bisector of the two rotated normals,
  // R_i n0 + R_j n0 = 2 cos(dtheta / 2) R_mean n0 (normalised by a series while |dtheta| is small).
  const double rix = bi.cos_t * f.rix - bi.sin_t * f.riy, riy = bi.sin_t * f.rix + bi.cos_t * f.riy;
  const double rjx = bj.cos_t * f.rjx - bj.sin_t * f.rjy, rjy = bj.sin_t * f.rjx + bj.cos_t * f.rjy;
  const double gx = (bj.x + rjx) - (bi.x + rix), gy = (bj.y + rjy) - (bi.y + riy);
  const double dth = bj.theta - bi.theta;
  double nx = (bi.cos_t + bj.cos_t) * f.n0x - (bi.sin_t + bj.sin_t) * f.n0y;
  double ny = (bi.sin_t + bj.sin_t) * f.n0x + (bi.cos_t + bj.cos_t) * f.n0y;
  const double d2 = dth * dth;
  const double inv = std::abs(dth) < 0.05 ? 0.5 * (1.0 + d2 * (0.125 + d2 * (5.0 / 384.0)))
                                          : 1.0 / std::sqrt(nx * nx + ny * ny);
  nx *= inv, ny *= inv;
  const double tx = -ny, ty = nx;
  const double dn = gx * nx + gy * ny, ds = gx * tx + gy * ty;
  // Parallel bond: k A on the normal opening, k A / kappa on the shear, k I = k A L^2 / 12 on the rotation.
  out.fnb = -f.kA * dn;
  out.fsb = -f.kA * kp.inv_kappa * ds;
  out.mb = -f.kA * f.L * f.L * kp.inertia_factor * dth;
  // Linear part, THEORY.md 4b with the potential of contact_law.hpp: F = k t A_o l_c / L = k A (A_o l_c / L^2).
  const double inv_L = 1.0 / f.L;
  const EdgeOverlap eo = edge_overlap(f.L, dn, dth);
  out.fnl = f.kA * eo.area * eo.chord * inv_L * inv_L;
  const double cix = rix + 0.5 * gx, ciy = riy + 0.5 * gy;  // bond point relative to each centroid
  const double cjx = rjx - 0.5 * gx, cjy = rjy - 0.5 * gy;
  out.px = bi.x + cix, out.py = bi.y + ciy;
  if (out.fnl > 0.0) {
    const double vrx = (bj.vx - bj.omega * cjy) - (bi.vx - bi.omega * ciy);
    const double vry = (bj.vy + bj.omega * cjx) - (bi.vy + bi.omega * cix);
    fs -= f.kA * kp.inv_kappa * (eo.chord * inv_L) * (vrx * tx + vry * ty) * dt;  // k_s t l_c ds
    if (kp.slip_bonded) {
      const double limit = kp.mu * out.fnl;
      if (std::abs(fs) > limit) fs = std::copysign(limit, fs);
    }
  } else {
    fs = 0.0;
  }
  out.fsl = fs;
  out.inv_L = inv_L;
  const double flx = out.fnl * nx + fs * tx, fly = out.fnl * ny + fs * ty;
  const double fx = keep * (out.fnb * nx + out.fsb * tx) + flx, fy = keep * (out.fnb * ny + out.fsb * ty) + fly;
  const double lever = cross(eo.s_c * tx, eo.s_c * ty, flx, fly);  // the linear part acts at s_c along the edge
  out.slot.fx = fx, out.slot.fy = fy;
  out.slot.mj = cross(cjx, cjy, fx, fy) + lever + keep * out.mb;
  out.slot.mi = -cross(cix, ciy, fx, fy) - lever - keep * out.mb;
}

// Adds the slot of one CSR entry (2 bond + 1 if the block is the bond's j) to a block's force and moment. Without
// branches: a block's role in its bonds follows no pattern, so an `if` mispredicts, and x + (-1) a is x - a exactly.
inline void add_slot(int e, const BondSlot* slot, double& fx, double& fy, double& m) {
  const BondSlot& s = slot[e >> 1];
  const bool is_j = e & 1;
  const double sign = is_j ? 1.0 : -1.0;
  fx += sign * s.fx, fy += sign * s.fy, m += is_j ? s.mj : s.mi;
}

// The parallel bond's failure test of contact_law.hpp (BondStrength::check) in force units, without divisions:
// with A = L t and I = t L^3 / 12, sigma A = -F_n + beta_m |M| 6 / L and tau A = |F_s|, against the limits
// sigma_c A and (c - min(sigma_n, sigma_c) tan phi_b) A. One evaluation serves the test and the failure index.
struct BondLoad {
  double tension, tension_limit, shear, shear_limit;  // N
};
inline BondLoad bond_load(const BondEval& ev, const BondStrength& st, double A) {
  return {-ev.fnb + st.beta_m * std::abs(ev.mb) * 6.0 * ev.inv_L, st.sigma_c * A, std::abs(ev.fsb),
          st.cohesion * A - std::min(-ev.fnb, st.sigma_c * A) * st.tan_phi};
}

// Fails when the failure index reaches `scale` (1: the strength; a softened bond's largest index so far).
inline BreakMode bond_failure(const BondLoad& q, double scale = 1.0) {
  if (q.tension >= scale * q.tension_limit) return BreakMode::tensile;
  if (q.shear >= scale * q.shear_limit) return BreakMode::shear;
  return BreakMode::none;
}

// The same test as a failure index for softening bonds (docs/model.md, "Softening bonds"): the larger of
// sigma / sigma_c and tau / (c - sigma_n tan phi_b), both of the undamaged forces; 1 at the strength (infinite when
// the shear limit is not positive, where the brittle test breaks too). `tensile` tells which is larger.
inline double failure_index(const BondLoad& q, bool& tensile) {
  const double ft = q.tension / q.tension_limit;
  const double fs = q.shear_limit > 0.0 ? q.shear / q.shear_limit : std::numeric_limits<double>::infinity();
  tensile = ft >= fs;
  return tensile ? ft : fs;
}

// The failure index at which a softening bond of kind kp breaks: r_u = 2 G_f E* / (sigma_c^2 d) = softening kA / L.
inline double rupture_index(const Engine::KindParams& kp, const BondFrame& f) { return kp.softening * f.kA / f.L; }

// Linear softening in the failure index r (the largest reached): the bond carries (1 - D) of its elastic forces,
// falling linearly from the strength at r = 1 to zero at r = r_u. For r_u <= 1 the bond is brittle.
inline double intact_fraction_of(double r, double r_u) {
  if (r <= 1.0) return 1.0;
  if (r >= r_u) return 0.0;
  return (r_u - r) / (r * (r_u - 1.0));
}

}  // namespace

Engine::Engine(const Topology& topo, const Scene& scene, const EngineOptions& options)
    : topo_(topo), options_(options), thickness_(topo.thickness), width_(topo.width()), height_(topo.height()) {
  const std::size_t nb = topo.blocks.size();
  const auto& G = topo.blocks;
  auto& B = blocks;
  B.state.resize(nb);
  for (std::size_t b = 0; b < nb; ++b) B.state[b] = {G.cx[b], G.cy[b], 0.0, 0.0, 0.0, 0.0, 1.0, 0.0};
  B.x0 = G.cx, B.y0 = G.cy;
  B.fx.assign(nb, 0.0), B.fy.assign(nb, 0.0), B.moment.assign(nb, 0.0);
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
  B.ext_fx.assign(nb, 0.0), B.ext_fy.assign(nb, 0.0), B.ext_m.assign(nb, 0.0);
  for (int b : topo.boundary.block) B.free_face[b] = 1;

  // Materials by kind: rock inside a layer, joint across layers.
  const std::array<const MaterialParams*, 2> mat{&scene.rock, &scene.joint};
  for (int k = 0; k < 2; ++k) {
    kinds_[k].modulus = mat[k]->effective_modulus;
    kinds_[k].kappa = mat[k]->stiffness_ratio;
    kinds_[k].inv_kappa = 1.0 / mat[k]->stiffness_ratio;
    kinds_[k].mu = mat[k]->contact_friction;
    kinds_[k].slip_bonded = mat[k]->slip_when_bonded;
    kinds_[k].inertia_divisor = fault_injected("bond_inertia") ? 6.0 : 12.0;
    kinds_[k].inertia_factor = 1.0 / kinds_[k].inertia_divisor;
    kinds_[k].strength = {mat[k]->tensile_strength, mat[k]->cohesion, std::tan(mat[k]->friction_deg * deg),
                          mat[k]->moment_factor};
    const double sc = mat[k]->tensile_strength;
    kinds_[k].softening = 2.0 * mat[k]->fracture_energy / (sc * sc * thickness_);
  }

  const auto& N = topo.bonds;
  const std::size_t nbond = N.size();
  auto& D = bonds;
  D.i = N.i, D.j = N.j, D.kind = N.kind;
  D.frame.resize(nbond);
  for (std::size_t b = 0; b < nbond; ++b) {
    const double L = N.length[b];
    D.frame[b] = {N.mx[b] - G.cx[N.i[b]], N.my[b] - G.cy[N.i[b]], N.mx[b] - G.cx[N.j[b]], N.my[b] - G.cy[N.j[b]],
                  N.nx[b], N.ny[b], L, kinds_[int(N.kind[b])].modulus / N.d[b] * L * thickness_};
  }
  D.broken.assign(nbond, 0);
  D.fs_lin.assign(nbond, 0.0);
  D.drive.assign(nbond, 0.0);
  D.slot.assign(nbond, BondSlot{0, 0, 0, 0});

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
  for (std::size_t b = 0; b < nb; ++b) platen_kn_[b] = kinds_[0].modulus / (2.0 * B.inradius[b]);
  // L_ref of a platen contact: the block's edge on the platen, else the inradius-based length of a fresh contact.
  platen_lref_.resize(nb);
  for (std::size_t b = 0; b < nb; ++b) platen_lref_[b] = 2.0 * std::sqrt(3.0) * B.inradius[b];
  for (std::size_t e = 0; e < topo.boundary.size(); ++e)
    if (topo.boundary.side[e] == Side::top || topo.boundary.side[e] == Side::bottom)
      platen_lref_[topo.boundary.block[e]] = topo.boundary.length[e];
  top_y_ = top_y0_ = topo.ymax;
  bottom_y_ = topo.ymin;

  double mean_length = 0;
  for (double L : N.length) mean_length += L;
  mean_length = nbond ? mean_length / double(nbond) : 1e-3;
  skin_ = 0.2 * mean_length;

  const int nthreads = options_.threads > 0 ? options_.threads : omp_get_max_threads();
  thread_breaks_.assign(std::size_t(std::max(nthreads, 1)), {});
  thread_onsets_.assign(thread_breaks_.size(), 0);
  nthreads_ = int(thread_breaks_.size());
  rebuild_active();
  rebuild_ = true;
  dt_ = critical_step();
}

BondStiffness Engine::stiffness(int b) const {
  const BondFrame& f = bonds.frame[std::size_t(b)];
  const KindParams& kp = kinds_[int(bonds.kind[std::size_t(b)])];
  const double A = f.L * thickness_;
  return {f.kA, f.kA / kp.kappa, f.kA * f.L * f.L / kp.inertia_divisor, f.kA, f.kA / kp.kappa, kp.mu, kp.slip_bonded,
          A, A * f.L * f.L / 12.0, f.L};
}

double Engine::intact_fraction(int b) const {
  const KindParams& kp = kinds_[int(bonds.kind[std::size_t(b)])];
  if (bonds.broken[std::size_t(b)]) return 0.0;
  if (!(kp.softening > 0.0) || !(bonds.drive[std::size_t(b)] > 1.0)) return 1.0;
  const BondFrame& f = bonds.frame[std::size_t(b)];
  return intact_fraction_of(bonds.drive[std::size_t(b)], rupture_index(kp, f));
}

BondForces Engine::bond_forces(int b) const {
  BondForces out;
  if (bonds.broken[std::size_t(b)]) return out;
  const std::size_t k = std::size_t(b);
  const KindParams& kp = kinds_[int(bonds.kind[k])];
  BondEval ev;
  eval_bond(bonds.frame[k], blocks.state[std::size_t(bonds.i[k])], blocks.state[std::size_t(bonds.j[k])], kp, 0.0,
            bonds.fs_lin[k], ev);
  const double keep = intact_fraction(b);
  out.fn_b = keep * ev.fnb, out.fs_b = keep * ev.fsb, out.m_b = keep * ev.mb, out.fn_lin = ev.fnl, out.fs_lin = ev.fsl;
  const double A = bonds.frame[k].L * thickness_;
  kp.strength.check(ev.fnb, ev.fsb, ev.mb, A, A * bonds.frame[k].L * bonds.frame[k].L / 12.0, 0.5 * bonds.frame[k].L,
                    out.sigma, out.tau);
  return out;
}

void Engine::bonded_forces(std::vector<double>& fx, std::vector<double>& fy, std::vector<double>& moment) {
  update_rotations();
  const BlockState* st = blocks.state.data();
  BondSlot* slot = bonds.slot.data();
  for (const auto* list : {&active_, &softened_}) {
    for (int b : *list) {
      const std::size_t k = std::size_t(b);
      BondEval ev;
      eval_bond(bonds.frame[k], st[bonds.i[k]], st[bonds.j[k]], kinds_[int(bonds.kind[k])], 0.0, bonds.fs_lin[k],
                ev, intact_fraction(b));
      slot[k] = ev.slot;
    }
  }
  const std::size_t n = blocks.size();
  fx.resize(n), fy.resize(n), moment.resize(n);
  for (std::size_t b = 0; b < n; ++b) {
    double f_x = blocks.ext_fx[b], f_y = blocks.ext_fy[b], m = blocks.ext_m[b];
    for (int o = csr_offset_[b]; o < csr_offset_[b + 1]; ++o) {
      const int e = csr_entry_[o];
      if (!bonds.broken[std::size_t(e >> 1)]) add_slot(e, slot, f_x, f_y, m);
    }
    fx[b] = f_x, fy[b] = f_y, moment[b] = m;
  }
}

void Engine::set_platen_shear(int block, double fs) {
  const std::size_t b = std::size_t(block);
  (blocks.state[b].y > 0.5 * (top_y_ + bottom_y_) ? top_fs_ : bottom_fs_)[b] = fs;
}

void Engine::refresh() {
  rebuild_active();
  update_rotations();
  rebuild_ = true;
}

void Engine::rebuild_active() {
  active_.clear(), softened_.clear();
  for (std::size_t b = 0; b < bonds.i.size(); ++b)
    if (!bonds.broken[b]) (bonds.drive[b] > 0.0 ? softened_ : active_).push_back(int(b));
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
  const std::size_t nb = blocks.size();
  std::vector<double> kt(nb, 0.0), kr(nb, 0.0);
  const auto& D = bonds;
  for (std::size_t b = 0; b < D.size(); ++b) {
    const BondStiffness k = stiffness(int(b));
    const double bond = D.broken[b] ? 0.0 : 1.0;  // a broken bond's pair keeps its linear part as a contact
    const double knA = bond * k.kbnA + k.knA, ksA = bond * k.kbsA + k.ksA;
    const BondFrame& f = D.frame[b];
    for (int side = 0; side < 2; ++side) {
      const int blk = side == 0 ? D.i[b] : D.j[b];
      const double rx = side == 0 ? f.rix : f.rjx, ry = side == 0 ? f.riy : f.rjy;
      const double rn = cross(rx, ry, f.n0x, f.n0y), rt = rx * f.n0x + ry * f.n0y;  // r x n and r x t
      kt[blk] += knA + ksA;
      kr[blk] += bond * k.kbnI + knA * rn * rn + ksA * rt * rt;
    }
  }
  if (options_.platens)
    for (std::size_t e = 0; e < topo_.boundary.size(); ++e) {
      const Side s = topo_.boundary.side[e];
      if (s != Side::top && s != Side::bottom) continue;
      const int blk = topo_.boundary.block[e];
      const double k = platen_kn_[blk] * thickness_ * topo_.boundary.length[e];
      kt[blk] += k * (1.0 + 1.0 / kinds_[0].kappa);
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
  const int n = int(blocks.size());
  auto* st = blocks.state.data();
#pragma omp parallel for schedule(static) num_threads(threads())
  for (int b = 0; b < n; ++b) {
    // Blocks rotate by well under 0.01 rad until they break free; there the Taylor series are exact to round-off
    // (the first omitted terms are below 3e-18 relative) and far cheaper than sin and cos.
    const double q = st[b].theta;
    if (std::abs(q) < 0.01) {
      const double q2 = q * q;
      st[b].sin_t = q * (1.0 - q2 * (1.0 / 6.0 - q2 * (1.0 / 120.0)));
      st[b].cos_t = 1.0 - q2 * (0.5 - q2 * (1.0 / 24.0 - q2 * (1.0 / 720.0)));
    } else {
      st[b].cos_t = std::cos(q);
      st[b].sin_t = std::sin(q);
    }
  }
}

void Engine::block_vertices(int b, double* out) const {
  const BlockState& s = blocks.state[std::size_t(b)];
  const auto& sh = blocks.shape[std::size_t(b)];
  for (int v = 0; v < 3; ++v) {
    out[2 * v] = s.x + s.cos_t * sh[2 * v] - s.sin_t * sh[2 * v + 1];
    out[2 * v + 1] = s.y + s.sin_t * sh[2 * v] + s.cos_t * sh[2 * v + 1];
  }
}

void Engine::step() {
  if (steps_ == 0) update_rotations();
  compute_bond_forces();
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
void Engine::compute_bond_forces() {
  for (auto& v : thread_breaks_) v.clear();
  std::fill(thread_onsets_.begin(), thread_onsets_.end(), 0);
#pragma omp parallel num_threads(threads())
  {
    const std::size_t me = std::size_t(omp_get_thread_num());
    bond_loop<false>(active_, thread_breaks_[me], thread_onsets_[me]);
    bond_loop<true>(softened_, thread_breaks_[me], thread_onsets_[me]);
  }
}

// One list of intact bonds, inside the parallel region of compute_bond_forces. Undamaged bonds (`Softened` false)
// run the brittle kernel: when the failure test holds, a brittle bond breaks and a softening bond starts to soften
// (its drive set, `onsets` counted so that it moves to the softened list). Softened bonds (docs/model.md,
// "Softening bonds") carry the fraction of their forces set by the largest failure index reached up to the
// previous step, and break at r_u.
template <bool Softened>
void Engine::bond_loop(const std::vector<int>& list, std::vector<Crack>& breaks, int& onsets) {
  const BondFrame* frame = bonds.frame.data();
  const int* bi = bonds.i.data();
  const int* bj = bonds.j.data();
  const BondKind* kind = bonds.kind.data();
  double* fs_lin = bonds.fs_lin.data();
  double* drive = bonds.drive.data();
  BondSlot* slot = bonds.slot.data();
  const BlockState* st = blocks.state.data();
  const int* active = list.data();
  const double t = thickness_, dt = dt_;
  const int n = int(list.size());
  const bool breakage = breakage_;
#pragma omp for schedule(static) nowait
  for (int k = 0; k < n; ++k) {
    const int b = active[k];
    const KindParams& kp = kinds_[int(kind[b])];
    BondEval ev;
    if constexpr (Softened)
      eval_bond(frame[b], st[bi[b]], st[bj[b]], kp, dt, fs_lin[b], ev,
                intact_fraction_of(drive[b], rupture_index(kp, frame[b])));
    else
      eval_bond(frame[b], st[bi[b]], st[bj[b]], kp, dt, fs_lin[b], ev);
    fs_lin[b] = ev.fsl;
    slot[b] = ev.slot;
    if (!breakage) continue;
    const double L = frame[b].L, A = L * t;
    // A softened bond tests against its largest index so far; only past it does it compute the index (divisions).
    const BondLoad q = bond_load(ev, kp.strength, A);
    BreakMode mode = bond_failure(q, Softened ? drive[b] : 1.0);
    if (mode != BreakMode::none && kp.softening > 0.0) {
      bool tensile = false;
      const double r = std::max({drive[b], 1.0, failure_index(q, tensile)});
      if (!Softened) ++onsets;
      drive[b] = r;
      mode = r >= std::max(rupture_index(kp, frame[b]), 1.0) ? (tensile ? BreakMode::tensile : BreakMode::shear)
                                                              : BreakMode::none;
    }
    if (mode != BreakMode::none) {
      Crack c;
      kp.strength.check(ev.fnb, ev.fsb, ev.mb, A, A * L * L / 12.0, 0.5 * L, c.sigma, c.tau);
      c.mode = mode, c.bond = b, c.kind = kind[b], c.x = ev.px, c.y = ev.py;
      breaks.push_back(c);
    }
  }
}

// Stage: breakage events in bond order (deterministic at any thread count).
void Engine::process_breaks() {
  std::size_t count = 0;
  for (const auto& v : thread_breaks_) count += v.size();
  if (count == 0) {
    // Bonds that started to soften this step move to the softened list.
    if (std::any_of(thread_onsets_.begin(), thread_onsets_.end(), [](int k) { return k > 0; })) rebuild_active();
    return;
  }
  std::vector<Crack> events;
  events.reserve(count);
  for (const auto& v : thread_breaks_) events.insert(events.end(), v.begin(), v.end());
  std::sort(events.begin(), events.end(), [](const Crack& a, const Crack& b) { return a.bond < b.bond; });
  for (Crack& c : events) {
    const std::size_t b = std::size_t(c.bond);
    c.time = time_, c.strain = strain_for_log;
    bonds.broken[b] = 1;
    bonds.slot[b] = BondSlot{0, 0, 0, 0};  // the pair's contact carries the linear part from now on
    blocks.free_face[std::size_t(bonds.i[b])] = blocks.free_face[std::size_t(bonds.j[b])] = 1;
    // With skip_bonded_pairs = false the pair is in the contact list already: it takes over the linear part's shear.
    const std::uint64_t key = pair_key(std::min(bonds.i[b], bonds.j[b]), std::max(bonds.i[b], bonds.j[b]));
    const auto at = std::lower_bound(contacts.key.begin(), contacts.key.end(), key);
    if (at != contacts.key.end() && *at == key) contacts.fs[std::size_t(at - contacts.key.begin())] = bonds.fs_lin[b];
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
  const int ne = int(eligible_.size());
  bool moved = false;
  const BlockState* st = blocks.state.data();
#pragma omp parallel for schedule(static) num_threads(threads()) reduction(|| : moved) if (ne > 1024)
  for (int k = 0; k < ne; ++k) {
    const BlockState& s = st[eligible_[std::size_t(k)]];
    const double dx = s.x - ref_x_[std::size_t(k)], dy = s.y - ref_y_[std::size_t(k)];
    moved = moved || dx * dx + dy * dy > lim2;
  }
  return moved;
}

// Stage: candidate pairs among blocks with a free face (a broken bond or a boundary edge), on a cell grid with
// a skin; pairs joined by an intact bond need no narrow phase. Shear history carries over by pair key. The two
// savings can be switched off to measure them (numerics.search_free_faces_only, numerics.skip_bonded_pairs).
void Engine::broad_phase() {
  if (!needs_rebuild()) return;
  rebuild_ = false;
  const std::size_t nb = blocks.size();
  const auto& S = blocks.state;
  auto& eligible = eligible_;
  eligible.clear();
  double rmax = 0;
  for (std::size_t b = 0; b < nb; ++b)
    if (blocks.free_face[b] || !options_.search_free_faces_only)
      eligible.push_back(int(b)), rmax = std::max(rmax, blocks.radius[b]);
  ref_x_.resize(eligible.size()), ref_y_.resize(eligible.size());
  for (std::size_t k = 0; k < eligible.size(); ++k) ref_x_[k] = S[eligible[k]].x, ref_y_[k] = S[eligible[k]].y;
  ref_top_ = top_y_;

  // Platen candidates (the platen may travel skin/2 before the next rebuild).
  top_candidates_.clear(), bottom_candidates_.clear();
  if (options_.platens)
    for (int b : eligible) {
      if (S[b].y + blocks.radius[b] > top_y_ - skin_) top_candidates_.push_back(b);
      if (S[b].y - blocks.radius[b] < bottom_y_ + skin_) bottom_candidates_.push_back(b);
    }

  // Uniform grid over the eligible blocks; pairs from the 3 x 3 neighbourhood of each cell.
  std::vector<std::uint64_t> keys;
  if (options_.contacts && !eligible.empty()) {
    const double cell = 2.0 * rmax + skin_;
    double xmin = 1e300, ymin = 1e300;
    for (int b : eligible) xmin = std::min(xmin, S[b].x), ymin = std::min(ymin, S[b].y);
    // Cell indices clamped to [0, 2e9]: a run going unstable (stopped by the watchdog a few steps later) may carry
    // huge or non-finite positions here, which must not overflow the conversion (NaN fails q >= 0 and maps to 0).
    auto index = [cell](double v) {
      const double q = v / cell;
      return q >= 0 ? (q < 2e9 ? long(q) : 2000000000L) : 0L;
    };
    auto cell_of = [&](int b) { return std::pair<long, long>{index(S[b].x - xmin), index(S[b].y - ymin)}; };
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
    std::vector<std::vector<std::uint64_t>> found(static_cast<std::size_t>(threads()));
#pragma omp parallel num_threads(threads()) if (ne > 256)
    {
      auto& mine = found[std::size_t(omp_get_thread_num())];
#pragma omp for schedule(static)
      for (int k = 0; k < ne; ++k) {
        const int a = eligible[std::size_t(k)];
        const auto [cx, cy] = cell_of(a);
        for (long dx = -1; dx <= 1; ++dx)
          for (long dy = -1; dy <= 1; ++dy) {
            if (cx + dx < 0 || cy + dy < 0) continue;
            const std::uint64_t key = cell_key(cx + dx, cy + dy);
            auto it = std::lower_bound(cells.begin(), cells.end(), std::pair<std::uint64_t, int>{key, -1});
            for (; it != cells.end() && it->first == key; ++it) {
              const int b = it->second;
              if (b <= a) continue;
              const double rr = blocks.radius[a] + blocks.radius[b] + skin_;
              const double ex = S[b].x - S[a].x, ey = S[b].y - S[a].y;
              if (ex * ex + ey * ey > rr * rr) continue;
              if (options_.skip_bonded_pairs && bonded(a, b)) continue;
              mine.push_back(pair_key(a, b));
            }
          }
      }
    }
    for (const auto& list : found) keys.insert(keys.end(), list.begin(), list.end());
    std::sort(keys.begin(), keys.end());
  }

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
    if (bond >= 0) {  // a broken bond: the same linear law as its linear part had
      const BondStiffness k = stiffness(bond);
      law = {k.knA / k.A, k.ksA / k.A, k.mu, k.L};
    } else {  // never neighbours: d and L_ref from the blocks' inradii (the bond's d and L for equilateral blocks)
      const KindParams& kp = kinds_[blocks.layer[i] == blocks.layer[j] ? 0 : 1];
      const double kn = kp.modulus / (blocks.inradius[i] + blocks.inradius[j]);
      law = {kn, kn / kp.kappa, kp.mu, std::sqrt(3.0) * (blocks.inradius[i] + blocks.inradius[j])};
    }
    double fs = 0.0;
    if (o < old.key.size() && old.key[o] == key) fs = old.fs[o];
    else if (bond >= 0) fs = bonds.fs_lin[bond];  // a bond that just broke hands over its linear shear force
    next.i.push_back(i), next.j.push_back(j), next.bond.push_back(bond), next.law.push_back(law);
    next.fs.push_back(fs), next.fn.push_back(0.0), next.chord.push_back(0.0), next.key.push_back(key);
  }
  contacts = std::move(next);
}

// Stage: polygon contacts. Each pair's narrow phase and contact law run in parallel into the pair's own record;
// the records are then summed into the contact accumulators serially in pair order, so the sums do not depend on
// the thread count.
void Engine::contact_forces() {
  std::fill(cfx_.begin(), cfx_.end(), 0.0);
  std::fill(cfy_.begin(), cfy_.end(), 0.0);
  std::fill(cm_.begin(), cm_.end(), 0.0);
  auto& C = contacts;
  const auto& S = blocks.state;
  const double t = thickness_, dt = dt_;
  const int n = int(C.i.size());
  pair_force_.resize(C.i.size());
  PairForce* out = pair_force_.data();
#pragma omp parallel for schedule(static) num_threads(threads()) if (n > 64)
  for (int c = 0; c < n; ++c) {
    const int i = C.i[c], j = C.j[c];
    const BlockState &si = S[std::size_t(i)], &sj = S[std::size_t(j)];
    const double ex = sj.x - si.x, ey = sj.y - si.y;
    const double rr = blocks.radius[i] + blocks.radius[j];
    Overlap ov;
    double vi[6], vj[6];
    bool touching = false;
    if (ex * ex + ey * ey < rr * rr) {
      block_vertices(i, vi);
      block_vertices(j, vj);
      touching = overlap_polygons(vi, 3, vj, 3, ov);
    }
    // A pair still joined by its bond (listed only with skip_bonded_pairs = false): the bond's linear part is its
    // contact, so the narrow phase above was the whole of its cost.
    const bool intact = C.bond[c] >= 0 && !bonds.broken[std::size_t(C.bond[c])];
    if (!touching || intact) {
      C.fs[c] = 0.0, C.fn[c] = 0.0, C.chord[c] = 0.0;
      out[c] = PairForce{0, 0, 0, 0, 0};
      continue;
    }
    const double nx = -ov.nx, ny = -ov.ny;  // from i to j, as for bonds
    const double tx = -ny, ty = nx;
    const double fn = C.law[c].normal_force(ov.area, ov.chord, t);
    const double cix = ov.px - si.x, ciy = ov.py - si.y;
    const double cjx = ov.px - sj.x, cjy = ov.py - sj.y;
    const double vrx = (sj.vx - sj.omega * cjy) - (si.vx - si.omega * ciy);
    const double vry = (sj.vy + sj.omega * cjx) - (si.vy + si.omega * cix);
    const double ds = (vrx * tx + vry * ty) * dt;
    double fs = C.fs[c];
    const double friction = C.law[c].update_shear(fn, ov.chord, t, ds, fs) ? std::abs(fs * ds) : 0.0;
    C.fs[c] = fs, C.fn[c] = fn, C.chord[c] = ov.chord;
    const double fx = fn * nx + fs * tx, fy = fn * ny + fs * ty;  // on j
    out[c] = PairForce{fx, fy, cross(cix, ciy, fx, fy), cross(cjx, cjy, fx, fy), friction};
  }
  for (int c = 0; c < n; ++c) {
    const PairForce& p = out[c];
    const int i = C.i[c], j = C.j[c];
    cfx_[j] += p.fx, cfy_[j] += p.fy, cm_[j] += p.mj;
    cfx_[i] -= p.fx, cfy_[i] -= p.fy, cm_[i] -= p.mi;
    e_friction_ += p.friction;
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
      const LinearContact law{platen_kn_[b], platen_kn_[b] / kinds_[0].kappa, mu, platen_lref_[b]};
      const double fn = law.normal_force(ov.area, ov.chord, t);
      const BlockState& s = blocks.state[std::size_t(b)];
      // Force on the block: -fn along the normal (out of the platen), shear along t = perp(n).
      const double nx = ov.nx, ny = ov.ny, tx = -ny, ty = nx;
      const double rx = ov.px - s.x, ry = ov.py - s.y;
      const double vrx = s.vx - s.omega * ry, vry = s.vy + s.omega * rx - wall_vy;
      const double ds = (vrx * tx + vry * ty) * dt_;
      double fs = fs_hist[b];
      if (law.update_shear(fn, ov.chord, t, ds, fs)) e_friction_ += std::abs(fs * ds);
      fs_hist[b] = fs;
      const double fx = -fn * nx + fs * tx, fy = -fn * ny + fs * ty;
      cfx_[b] += fx, cfy_[b] += fy, cm_[b] += cross(rx, ry, fx, fy);
      total += fn;
      platen_energy_ += 0.5 * (fn * fn * law.lref / (law.kn * t * ov.chord * ov.chord) +
                               fs * fs / (law.ks * t * ov.chord));
    }
    (top ? top_force_ : bottom_force_) = total;
  }
  e_work_ += top_force_ * options_.platen_velocity * dt_;
}

// Stage: per-block gather in fixed CSR order, Cundall local damping, central difference update.
void Engine::integrate() {
  auto& B = blocks;
  BlockState* st = B.state.data();
  const BondSlot* slot = bonds.slot.data();
  const int* offset = csr_offset_.data();
  const int* entry = csr_entry_.data();
  const int n = int(B.size());
  const double dt = dt_, alpha = options_.damping;
  double e_damp = 0.0;
  bool finite = true;
#pragma omp parallel for schedule(static) num_threads(threads()) reduction(+ : e_damp) reduction(&& : finite)
  for (int b = 0; b < n; ++b) {
    double fx = cfx_[b] + B.ext_fx[b], fy = cfy_[b] + B.ext_fy[b], m = cm_[b] + B.ext_m[b];
    for (int o = offset[b]; o < offset[b + 1]; ++o) add_slot(entry[o], slot, fx, fy, m);
    B.fx[b] = fx, B.fy[b] = fy, B.moment[b] = m;
    if (B.fixed[b]) continue;
    BlockState& s = st[b];
    // Cundall local damping: F_d = -alpha |F| sign(v), per degree of freedom.
    const double dfx = -alpha * std::abs(fx) * double((s.vx > 0) - (s.vx < 0));
    const double dfy = -alpha * std::abs(fy) * double((s.vy > 0) - (s.vy < 0));
    const double dm = -alpha * std::abs(m) * double((s.omega > 0) - (s.omega < 0));
    e_damp -= (dfx * s.vx + dfy * s.vy + dm * s.omega) * dt;
    const double inv_m = 1.0 / B.mass[b];
    s.vx += dt * (fx + dfx) * inv_m;
    s.vy += dt * (fy + dfy) * inv_m;
    s.omega += dt * (m + dm) / B.inertia[b];
    s.x += dt * s.vx;
    s.y += dt * s.vy;
    s.theta += dt * s.omega;
    finite = finite && std::isfinite(s.x) && std::isfinite(s.y) && std::isfinite(s.theta);
  }
  e_damping_ += e_damp;
  if (!finite)
    throw InstabilityError(fmt::format(
        "the run diverged at step {} (t = {:.4g} s): positions are no longer finite. The time step {:.4g} s is too "
        "large for this scene (block-wise critical step estimate {:.4g} s); lower numerics.dt or numerics.dt_safety",
        steps_, time_, dt_, critical_step()));
}

Engine::Snapshot Engine::snapshot() const {
  Snapshot s;
  s.state = blocks.state, s.fx = blocks.fx, s.fy = blocks.fy, s.moment = blocks.moment;
  s.free_face = blocks.free_face, s.broken = bonds.broken, s.fs_lin = bonds.fs_lin, s.slot = bonds.slot;
  s.drive = bonds.drive;
  s.contacts = contacts, s.cracks = cracks_;
  s.dt = dt_, s.time = time_, s.platen_velocity = options_.platen_velocity, s.strain_for_log = strain_for_log;
  s.steps = steps_, s.breakage = breakage_, s.rebuild = rebuild_;
  s.top_y = top_y_, s.top_force = top_force_, s.bottom_force = bottom_force_, s.ref_top = ref_top_;
  s.e_damping = e_damping_, s.e_friction = e_friction_, s.e_work = e_work_, s.platen_energy = platen_energy_;
  s.eligible = eligible_, s.top_candidates = top_candidates_, s.bottom_candidates = bottom_candidates_;
  s.ref_x = ref_x_, s.ref_y = ref_y_, s.top_fs = top_fs_, s.bottom_fs = bottom_fs_;
  return s;
}

void Engine::restore(const Snapshot& s) {
  const std::size_t nb = blocks.size(), nd = bonds.size();
  const auto& C = s.contacts;
  const std::size_t nc = C.key.size();
  const bool fits = s.state.size() == nb && s.fx.size() == nb && s.fy.size() == nb && s.moment.size() == nb &&
                    s.free_face.size() == nb && s.top_fs.size() == nb && s.bottom_fs.size() == nb &&
                    s.broken.size() == nd && s.fs_lin.size() == nd && s.drive.size() == nd && s.slot.size() == nd &&
                    C.i.size() == nc && C.j.size() == nc && C.bond.size() == nc && C.law.size() == nc && C.fs.size() == nc &&
                    C.fn.size() == nc && C.chord.size() == nc && s.ref_x.size() == s.eligible.size() &&
                    s.ref_y.size() == s.eligible.size();
  if (!fits)
    throw std::invalid_argument(fmt::format("the checkpoint does not fit this model ({} blocks and {} bonds in the "
                                            "checkpoint, {} and {} here): it was written for another scene or mesh",
                                            s.state.size(), s.broken.size(), nb, nd));
  auto in_range = [](const std::vector<int>& v, std::size_t n) {
    return std::all_of(v.begin(), v.end(), [n](int k) { return k >= 0 && std::size_t(k) < n; });
  };
  if (!in_range(C.i, nb) || !in_range(C.j, nb) || !in_range(s.eligible, nb) || !in_range(s.top_candidates, nb) ||
      !in_range(s.bottom_candidates, nb) ||
      !std::all_of(s.cracks.begin(), s.cracks.end(), [nd](const Crack& c) { return c.bond >= 0 && std::size_t(c.bond) < nd; }))
    throw std::invalid_argument("the checkpoint refers to blocks or bonds this model does not have");
  blocks.state = s.state, blocks.fx = s.fx, blocks.fy = s.fy, blocks.moment = s.moment;
  blocks.free_face = s.free_face, bonds.broken = s.broken, bonds.fs_lin = s.fs_lin, bonds.slot = s.slot;
  bonds.drive = s.drive;
  contacts = s.contacts, cracks_ = s.cracks;
  dt_ = s.dt, time_ = s.time, options_.platen_velocity = s.platen_velocity, strain_for_log = s.strain_for_log;
  steps_ = s.steps, breakage_ = s.breakage, rebuild_ = s.rebuild;
  top_y_ = s.top_y, top_force_ = s.top_force, bottom_force_ = s.bottom_force, ref_top_ = s.ref_top;
  e_damping_ = s.e_damping, e_friction_ = s.e_friction, e_work_ = s.e_work, platen_energy_ = s.platen_energy;
  eligible_ = s.eligible, top_candidates_ = s.top_candidates, bottom_candidates_ = s.bottom_candidates;
  ref_x_ = s.ref_x, ref_y_ = s.ref_y, top_fs_ = s.top_fs, bottom_fs_ = s.bottom_fs;
  rebuild_active();
}

std::size_t Engine::active_contacts() const {
  return std::size_t(std::count_if(contacts.fn.begin(), contacts.fn.end(), [](double f) { return f > 0; }));
}

Energies Engine::energies() const {
  Energies e;
  for (std::size_t b = 0; b < blocks.size(); ++b) {
    const BlockState& s = blocks.state[b];
    e.kinetic += 0.5 * (blocks.mass[b] * (s.vx * s.vx + s.vy * s.vy) + blocks.inertia[b] * s.omega * s.omega);
  }
  for (std::size_t b = 0; b < bonds.size(); ++b) {
    if (bonds.broken[b]) continue;
    const BondForces f = bond_forces(int(b));
    const BondStiffness k = stiffness(int(b));
    // A damaged bond stores keep k delta^2 / 2 = f^2 / (2 keep k) in its parallel part (f = keep k delta).
    const double keep = intact_fraction(int(b));
    const double inv_keep = keep > 0.0 ? 1.0 / keep : 0.0;
    e.strain += 0.5 * ((f.fn_b * f.fn_b / k.kbnA + f.fs_b * f.fs_b / k.kbsA + f.m_b * f.m_b / k.kbnI) * inv_keep +
                       f.fn_lin * f.fn_lin / k.knA + f.fs_lin * f.fs_lin / k.ksA);
  }
  const double t = thickness_;
  for (std::size_t c = 0; c < contacts.i.size(); ++c) {
    if (!(contacts.fn[c] > 0)) continue;
    // w = kn t A^2 / (2 L_ref) = fn^2 L_ref / (2 kn t l_c^2); shear fs^2 / (2 ks t l_c)
    const auto& law = contacts.law[c];
    const double l = contacts.chord[c];
    e.strain += 0.5 * (contacts.fn[c] * contacts.fn[c] * law.lref / (law.kn * t * l * l) +
                       contacts.fs[c] * contacts.fs[c] / (law.ks * t * l));
  }
  e.strain += platen_energy_;
  e.damping = e_damping_;
  e.friction = e_friction_;
  e.work_platen = e_work_;
  return e;
}

}  // namespace rbdem
