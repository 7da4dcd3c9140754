// Building the constant model data from a topology and a scene. See model.hpp.
#include "dem/model.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include "common/fault_injection.hpp"
#include "dem/materials.hpp"

namespace rbdem {

BondStiffness Model<2>::stiffness(int b) const {
  const std::size_t k = std::size_t(b);
  return law[material[k]].stiffness(frame.K[k], frame.L[k], thickness);
}

LinearContact Model<2>::pair_law(int i, int j, int bond) const {
  if (bond >= 0) {  // a broken bond: the very law its linear part had (the bond's K, K / kappa and L)
    const std::size_t k = std::size_t(bond);
    return {frame.K[k], frame.Ks[k], law[material[k]].mu, frame.inv_L[k], law[material[k]].tan_dilation};
  }
  // Never neighbours: d and L_ref from the blocks' inradii (the bond's d and L for equilateral blocks).
  const bool same_layer = layer[std::size_t(i)] == layer[std::size_t(j)];
  const BondKindLaw& kl = law[same_layer ? block_material[std::size_t(i)] : std::uint8_t(material_joint)];
  const double r = inradius[std::size_t(i)] + inradius[std::size_t(j)];
  const double kn = kl.modulus / r;
  LinearContact c = LinearContact::per_area(kn, kn / kl.kappa, kl.mu, std::sqrt(3.0) * r, thickness);
  c.tan_dilation = kl.tan_dilation;
  return c;
}

bool Model<2>::has_intact_bond(int b, const std::vector<std::uint8_t>& broken) const {
  for (int o = csr_offset[std::size_t(b)]; o < csr_offset[std::size_t(b) + 1]; ++o)
    if (!broken[std::size_t(csr_entry[std::size_t(o)] >> 1)]) return true;
  return false;
}

bool Model<2>::bonded(int i, int j, const std::vector<std::uint8_t>& broken) const {
  for (int o = csr_offset[i]; o < csr_offset[i + 1]; ++o) {
    const int b = csr_entry[o] >> 1;
    if (!broken[std::size_t(b)] && (bi[b] == j || bj[b] == j)) return true;
  }
  return false;
}

namespace {

using MaterialTable = std::array<const MaterialParams*, material_count>;

// The blocks: masses and inertias (rock2's blocks at its density, both with the mass scaling), reference centroids,
// shapes, inradii.
void build_blocks(const Topology<2>& topo, const Scene& scene, double mass_scaling, Model<2>& m) {
  const auto& G = topo.blocks;
  const std::size_t nb = G.size();
  // The topology's masses are at rock.density; blocks of rock2 scale by the density ratio.
  const double rock2_density = scene.rock2.density / scene.rock.density;
  m.mass.resize(nb), m.inv_mass.resize(nb), m.inertia.resize(nb);
  for (std::size_t b = 0; b < nb; ++b) {
    const double scaling = m.block_material[b] == material_rock2 && rock2_density != 1.0 ? mass_scaling * rock2_density
                                                                                        : mass_scaling;
    m.mass[b] = G.mass[b] * scaling;
    m.inv_mass[b] = 1.0 / m.mass[b];
    m.inertia[b] = G.inertia[b] * scaling;
  }
  m.x0 = G.cx, m.y0 = G.cy;
  m.radius = G.radius, m.shape = G.shape, m.layer = G.layer;
  m.inradius.resize(nb);
  for (std::size_t b = 0; b < nb; ++b) {
    const auto& s = G.shape[b];
    double perimeter = 0;
    for (int v = 0; v < 3; ++v)
      perimeter += std::hypot(s[2 * ((v + 1) % 3)] - s[2 * v], s[2 * ((v + 1) % 3) + 1] - s[2 * v + 1]);
    m.inradius[b] = 2.0 * G.area[b] / perimeter;
  }
  m.fixed.assign(nb, 0);
}

// The law of each material (dem/materials.hpp).
void build_laws(const MaterialTable& mat, double thickness, Model<2>& m) {
  constexpr double deg = std::numbers::pi / 180.0;
  for (std::size_t k = 0; k < material_count; ++k) {
    BondKindLaw& kl = m.law[k];
    kl.modulus = mat[k]->effective_modulus;
    kl.kappa = mat[k]->stiffness_ratio;
    kl.mu = mat[k]->contact_friction;
    kl.slip_bonded = mat[k]->slip_when_bonded;
    kl.tan_dilation = std::tan(mat[k]->dilation_deg * deg);
    kl.bond.inertia_divisor = fault_injected("bond_inertia") ? 6.0 : 12.0;
    kl.bond.inv_kappa = 1.0 / mat[k]->stiffness_ratio;
    kl.bond.inertia_factor = 1.0 / kl.bond.inertia_divisor;
    kl.bond.strength = {mat[k]->tensile_strength, mat[k]->cohesion, std::tan(mat[k]->friction_deg * deg),
                        mat[k]->moment_factor};
    const double sc = mat[k]->tensile_strength;
    kl.bond.softening = 2.0 * mat[k]->fracture_energy / (sc * sc * thickness);
  }
}

// The bond frames: lever arms, reference normal, length, the stiffnesses and the strength in force units from the
// bond's law.
void build_frames(const Topology<2>& topo, Model<2>& m) {
  const auto& G = topo.blocks;
  const auto& N = topo.bonds;
  const std::size_t nbond = N.size();
  BondFrames& f = m.frame;
  for (auto* v : {&f.rix, &f.riy, &f.rjx, &f.rjy, &f.n0x, &f.n0y, &f.L, &f.inv_L, &f.K, &f.Ks, &f.KI, &f.A,
                  &f.rupture, &f.mu_bonded, &f.tension_limit, &f.cohesion_A, &f.tan_phi, &f.beta_m})
    v->resize(nbond);
  for (std::size_t b = 0; b < nbond; ++b) {
    const BondKindLaw& kl = m.law[m.material[b]];
    const double L = N.length[b];
    f.rix[b] = N.mx[b] - G.cx[N.i[b]], f.riy[b] = N.my[b] - G.cy[N.i[b]];
    f.rjx[b] = N.mx[b] - G.cx[N.j[b]], f.rjy[b] = N.my[b] - G.cy[N.j[b]];
    f.n0x[b] = N.nx[b], f.n0y[b] = N.ny[b];
    f.L[b] = L, f.inv_L[b] = 1.0 / L;
    f.K[b] = kl.modulus / N.d[b] * L * m.thickness;
    f.Ks[b] = kl.bond.kernel_shear(f.K[b]);
    f.KI[b] = kl.bond.kernel_rotational(f.K[b], L);
    f.A[b] = kl.bond.section(L, m.thickness).A;
    f.rupture[b] = kl.bond.rupture_index(f.K[b], L);
    const BondStrength& st = kl.bond.strength;
    f.mu_bonded[b] = kl.bonded_mu();
    f.tension_limit[b] = st.sigma_c * f.A[b], f.cohesion_A[b] = st.cohesion * f.A[b];
    f.tan_phi[b] = st.tan_phi, f.beta_m[b] = st.beta_m;
  }
}

// Strength heterogeneity: each bond's tensile strength and cohesion times its factor w (weibull_factors,
// dem/materials.hpp, from mesh.strength_seed). A softening bond keeps its fracture energy: r_u ~ 1 / sigma_c^2 scales
// by 1 / w^2.
void apply_heterogeneity(const Scene& scene, Model<2>& m) {
  BondFrames& f = m.frame;
  f.strength_factor =
      weibull_factors(scene, m.material, &MaterialParams::weibull_modulus, std::uint64_t(scene.mesh.strength_seed));
  if (f.strength_factor.empty()) return f.strength_factor.assign(m.num_bonds(), 1.0);
  for (std::size_t b = 0; b < m.num_bonds(); ++b) {
    const double w = f.strength_factor[b];
    f.tension_limit[b] *= w, f.cohesion_A[b] *= w;
    f.rupture[b] /= w * w;
  }
}

// Stiffness heterogeneity: each bond's E* times its factor s (weibull_factors with stiffness_weibull_modulus), from
// its own stream (seeded with mesh.strength_seed + 7777), so that a scene's strengths stay the same whether its
// stiffnesses scatter or not. K, K / kappa and the rotational stiffness scale by s, and so does a softening bond's
// r_u = softening K / L (its fracture energy stays G_f). The broken bond's linear part, the static solve and the
// stability limit read these same K.
void apply_stiffness_heterogeneity(const Scene& scene, Model<2>& m) {
  BondFrames& f = m.frame;
  f.stiffness_factor = weibull_factors(scene, m.material, &MaterialParams::stiffness_weibull_modulus,
                                       std::uint64_t(scene.mesh.strength_seed) + 7777u);
  if (f.stiffness_factor.empty()) return f.stiffness_factor.assign(m.num_bonds(), 1.0);
  for (std::size_t b = 0; b < m.num_bonds(); ++b) {
    const double s = f.stiffness_factor[b];
    f.K[b] *= s, f.Ks[b] *= s, f.KI[b] *= s;
    f.rupture[b] *= s;
  }
}

// The CSR of the force gather (entry = 2 bond + (block is j)) and its padded copy, as wide as the block with the
// most bonds and at least 3 (every block of a triangle mesh).
void build_gather(const Topology<2>& topo, Model<2>& m) {
  const std::size_t nb = m.num_blocks();
  m.csr_offset = topo.bond_offset;
  m.csr_entry.resize(topo.bond_of.size());
  for (std::size_t b = 0; b < nb; ++b)
    for (int o = m.csr_offset[b]; o < m.csr_offset[b + 1]; ++o) {
      const int bond = topo.bond_of[std::size_t(o)];
      m.csr_entry[std::size_t(o)] = 2 * bond + (topo.bonds.j[std::size_t(bond)] == int(b) ? 1 : 0);
    }
  m.gather_width = 3;
  for (std::size_t b = 0; b < nb; ++b)
    m.gather_width = std::max(m.gather_width, m.csr_offset[b + 1] - m.csr_offset[b]);
  const std::size_t width = std::size_t(m.gather_width);
  m.gather.assign(width * nb, 2 * int(m.num_bonds()) + 1);
  for (std::size_t b = 0; b < nb; ++b)
    for (int o = m.csr_offset[b]; o < m.csr_offset[b + 1]; ++o)
      m.gather[width * b + std::size_t(o - m.csr_offset[b])] = m.csr_entry[std::size_t(o)];
}

}  // namespace

Model<2> build_model(const Topology<2>& topo, const Scene& scene, double mass_scaling) {
  Model<2> m;
  m.topology = &topo;
  m.thickness = topo.thickness;
  m.width = topo.width(), m.height = topo.height();
  m.xmin = topo.xmin, m.xmax = topo.xmax, m.ymin = topo.ymin, m.ymax = topo.ymax;
  const MaterialMap materials = assign_materials(topo, scene);
  m.block_material = materials.block;
  build_blocks(topo, scene, mass_scaling, m);
  MaterialTable mat{};
  for (std::size_t k = 0; k < material_count; ++k) mat[k] = &material_params(scene, k);
  build_laws(mat, m.thickness, m);
  m.bi = topo.bonds.i, m.bj = topo.bonds.j, m.kind = topo.bonds.kind, m.material = materials.bond;
  build_frames(topo, m);
  apply_heterogeneity(scene, m);
  apply_stiffness_heterogeneity(scene, m);
  build_gather(topo, m);
  double mean_length = 0;
  for (double L : topo.bonds.length) mean_length += L;
  const std::size_t nbond = m.num_bonds();
  mean_length = nbond ? mean_length / double(nbond) : 1e-3;
  m.skin = 0.2 * mean_length;  // the broad phase's skin: 0.2 mean edge lengths
  return m;
}

}  // namespace rbdem
