// The 3D model's constant data from a TetMesh and a scene. See model3.hpp.
#include "dem/model3.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>

#include "dem/geometry3.hpp"
#include "dem/materials.hpp"

namespace rbdem {

double FaceKindLaw::bonded_mu() const { return slip_bonded ? mu : std::numeric_limits<double>::infinity(); }

FaceBond Model<3>::bond_law(std::size_t b) const {
  FaceBond l = law[material[b]].bond;
  const double w = strength_factor[b];
  l.strength.sigma_c *= w, l.strength.cohesion *= w;
  return l;
}

bool Model<3>::has_intact_bond(int block, const std::vector<std::uint8_t>& broken) const {
  for (int o = offset[std::size_t(block)]; o < offset[std::size_t(block) + 1]; ++o)
    if (!broken[std::size_t(gather[std::size_t(o)] >> 1)]) return true;
  return false;
}

namespace {

Vec3 node(const TetMesh& m, int k) {
  const auto& p = m.nodes[std::size_t(k)];
  return {p[0], p[1], p[2]};
}

void build_laws(const Scene& scene, Model<3>& m) {
  constexpr double deg = std::numbers::pi / 180.0;
  for (std::size_t k = 0; k < material_count; ++k) {
    const MaterialParams& p = material_params(scene, k);
    FaceKindLaw& l = m.law[k];
    l.modulus = p.effective_modulus, l.kappa = p.stiffness_ratio, l.mu = p.contact_friction;
    l.slip_bonded = p.slip_when_bonded;
    l.bond.inv_kappa = 1.0 / p.stiffness_ratio;
    l.bond.strength = {p.tensile_strength, p.cohesion, std::tan(p.friction_deg * deg), p.moment_factor};
    l.bond.softening = 2.0 * p.fracture_energy / (p.tensile_strength * p.tensile_strength);
  }
}

void build_blocks(const TetMesh& mesh, double density, Model<3>& m) {
  const std::size_t n = mesh.num_tets();
  m.body.resize(n), m.x0.resize(n), m.shape.resize(n), m.block_volume.resize(n), m.inradius.resize(n);
  m.layer = mesh.layer, m.fixed.assign(n, 0);
  double inf = std::numeric_limits<double>::infinity();
  m.lo = {inf, inf, inf}, m.hi = {-inf, -inf, -inf};
  for (const auto& p : mesh.nodes)
    for (int k = 0; k < 3; ++k) m.lo[k] = std::min(m.lo[k], p[std::size_t(k)]), m.hi[k] = std::max(m.hi[k], p[std::size_t(k)]);
  for (std::size_t t = 0; t < n; ++t) {
    const auto& q = mesh.tets[t];
    const Tet T{node(mesh, q[0]), node(mesh, q[1]), node(mesh, q[2]), node(mesh, q[3])};
    const TetBody body = tet_body(T, density);
    if (!(body.volume > 0))
      throw SceneError(fmt::format("tetrahedron {} of the mesh has no volume: remesh the specimen (mesh.size) or fix "
                                   "the mesh file", t));
    m.body[t] = {body.mass, body.inertia.moments, body.inertia.rotation};
    m.x0[t] = body.centroid, m.block_volume[t] = body.volume;
    double surface = 0;
    for (int f = 0; f < 4; ++f)
      surface += face_of({T[std::size_t(f)], T[std::size_t((f + 1) % 4)], T[std::size_t((f + 2) % 4)]}).area;
    m.inradius[t] = 3.0 * body.volume / surface;
    for (int k = 0; k < 4; ++k) m.shape[t][std::size_t(k)] = T[std::size_t(k)] - body.centroid;
    m.volume += body.volume;
  }
  m.axis = {0.5 * (m.lo.x + m.hi.x), 0.5 * (m.lo.y + m.hi.y)};
}

void build_bonds(const TetMesh& mesh, Model<3>& m) {
  const std::vector<SharedFace> faces = shared_faces(mesh);
  const std::size_t n = faces.size();
  m.bi.resize(n), m.bj.resize(n), m.kind.resize(n), m.material.resize(n), m.interface.resize(n), m.face.resize(n);
  m.frame.resize(n), m.rupture.resize(n);
  for (std::size_t b = 0; b < n; ++b) {
    const SharedFace& f = faces[b];
    const int i = std::min(f.tets[0], f.tets[1]), j = std::max(f.tets[0], f.tets[1]);
    m.bi[b] = i, m.bj[b] = j, m.face[b] = f.nodes;
    m.kind[b] = f.joint ? BondKind::joint : BondKind::rock;
    m.interface[b] = f.joint ? f.set : -1;
    m.material[b] = !f.joint ? material_rock : (f.set == 1 ? material_joint2 : material_joint);
    const FaceKindLaw& l = m.law[m.material[b]];
    const Tri tri{node(mesh, f.nodes[0]), node(mesh, f.nodes[1]), node(mesh, f.nodes[2])};
    m.frame[b] = stages::face_bond_frame(m.x0[std::size_t(i)], m.x0[std::size_t(j)], tri, l.bond, l.modulus,
                                         l.bonded_mu());
    if (!(m.frame[b].k.kn > 0) || !std::isfinite(m.frame[b].k.kn))
      throw SceneError(fmt::format("the face between tetrahedra {} and {} gives a bond without a finite positive "
                                   "stiffness (a degenerate tetrahedron): remesh the specimen", i, j));
    m.rupture[b] = l.bond.rupture_index(m.frame[b].k.kn, m.frame[b].section.A);
  }
  // The gather: each block's bonds in bond order.
  const std::size_t nb = m.num_blocks();
  m.offset.assign(nb + 1, 0);
  for (std::size_t b = 0; b < n; ++b) ++m.offset[std::size_t(m.bi[b]) + 1], ++m.offset[std::size_t(m.bj[b]) + 1];
  for (std::size_t k = 0; k < nb; ++k) m.offset[k + 1] += m.offset[k];
  m.gather.resize(2 * n);
  std::vector<int> next(m.offset.begin(), m.offset.end() - 1);
  for (std::size_t b = 0; b < n; ++b) {
    m.gather[std::size_t(next[std::size_t(m.bi[b])]++)] = int(2 * b);
    m.gather[std::size_t(next[std::size_t(m.bj[b])]++)] = int(2 * b + 1);
  }
}

// Weibull strength factors as in 2D (weibull_factors, dem/materials.hpp, from mesh.strength_seed); a softening bond
// keeps its fracture energy.
void apply_heterogeneity(const Scene& scene, Model<3>& m) {
  m.strength_factor =
      weibull_factors(scene, m.material, &MaterialParams::weibull_modulus, std::uint64_t(scene.mesh.strength_seed));
  if (m.strength_factor.empty()) return m.strength_factor.assign(m.num_bonds(), 1.0);
  for (std::size_t b = 0; b < m.num_bonds(); ++b) m.rupture[b] /= m.strength_factor[b] * m.strength_factor[b];
}

// The bond stage's table from the frames, the laws and the strength factors.
void build_table(Model<3>& m) {
  using F = stages::FaceBondTable;
  F& t = m.table;
  t.resize(m.num_bonds());
  for (std::size_t b = 0; b < m.num_bonds(); ++b) {
    const stages::FaceBondFrame& f = m.frame[b];
    const FaceKindLaw& law = m.law[m.material[b]];
    const BondStrength& st = law.bond.strength;
    const FaceSection& s = f.section;
    const double w = m.strength_factor[b];
    const double values[F::count] = {
        f.ri.x, f.ri.y, f.ri.z, f.rj.x, f.rj.y, f.rj.z,
        f.axes.r[0].x, f.axes.r[0].y, f.axes.r[0].z, f.axes.r[1].x, f.axes.r[1].y, f.axes.r[1].z,
        f.axes.r[2].x, f.axes.r[2].y, f.axes.r[2].z,
        f.k.kn, f.k.ks, f.k.kb1, f.k.kb2, f.k.kt,
        s.A, 1.0 / s.A,
        s.y1[0], s.y1[1], s.y1[2], s.y2[0], s.y2[1], s.y2[2],
        st.beta_m * s.A / s.I1, st.beta_m * s.A / s.I2, st.beta_m * s.A * s.r_max / s.J,
        st.sigma_c * w * s.A, st.cohesion * w * s.A, st.tan_phi,
        f.mu, law.mu, law.bond.softening, m.rupture[b]};
    for (int k = 0; k < F::count; ++k) t.at(F::Field(k), b) = values[k];
  }
}

void build_surface(const TetMesh& mesh, Model<3>& m) {
  for (const BoundaryFace& bf : mesh.boundary) {
    const Tri tri{node(mesh, bf.nodes[0]), node(mesh, bf.nodes[1]), node(mesh, bf.nodes[2])};
    const Face f = face_of(tri);
    const Vec3 c = m.x0[std::size_t(bf.tet)];
    SurfaceFace s{bf.tet, bf.tag, f.area, f.J, f.centroid - c, f.normal, {tri[0] - c, tri[1] - c, tri[2] - c}};
    if (dot(s.normal, s.r) < 0) s.normal = -s.normal;  // outward: away from the block's centroid
    m.surface.push_back(s);
    if (bf.tag == FaceTag::top) m.loaded_area += f.area;
  }
}

}  // namespace

Model<3> build_model(const TetMesh& mesh, const Scene& scene, double mass_scaling) {
  if (mesh.num_tets() < 2) throw SceneError("the 3D mesh has fewer than two tetrahedra: lower mesh.size");
  Model<3> m;
  m.mesh = &mesh;
  build_laws(scene, m);
  build_blocks(mesh, scene.rock.density * mass_scaling, m);
  build_bonds(mesh, m);
  apply_heterogeneity(scene, m);
  build_table(m);
  build_surface(mesh, m);
  if (!(m.loaded_area > 0))
    throw SceneError("the 3D mesh has no faces on its top (z = highest): the platens need a flat top and bottom");
  return m;
}

}  // namespace rbdem
