// SimulationImpl<3>: the Simulation interface over the 3D engine. See simulation_impl3.hpp.
#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "dem/simulation_impl3.hpp"
#include "dem/static_start3.hpp"

namespace rbdem {

std::unique_ptr<Simulation> Simulation::create(const Scene& scene, const TetMesh& mesh,
                                               const SimulationOptions& options) {
  return std::make_unique<SimulationImpl<3>>(scene, mesh, options);
}

Specimen describe(const Model<3>& m, const TetMesh& mesh, double density) {
  Specimen s;
  s.dim = 3;
  s.lo = {m.lo.x, m.lo.y, m.lo.z}, s.hi = {m.hi.x, m.hi.y, m.hi.z};
  // The loaded area over the width: the 2D formulas that read width x thickness as the loaded area hold in 3D.
  s.thickness = m.loaded_area / (m.hi.x - m.lo.x);
  for (const auto& p : mesh.nodes) s.nodes.insert(s.nodes.end(), p.begin(), p.end());
  for (const auto& t : mesh.tets) s.cells.insert(s.cells.end(), t.begin(), t.end());
  s.layer_names = mesh.layer_names, s.interface_names = {"joint_set", "joint_set2"};
  for (std::size_t b = 0; b < m.num_blocks(); ++b) {
    s.blocks.centroid.insert(s.blocks.centroid.end(), {m.x0[b].x, m.x0[b].y, m.x0[b].z});
    for (const Vec3& r : m.shape[b]) s.blocks.shape.insert(s.blocks.shape.end(), {r.x, r.y, r.z});
    s.blocks.measure.push_back(m.block_volume[b]);
    s.blocks.mass.push_back(density * m.block_volume[b]);
  }
  s.blocks.layer = m.layer;
  s.bonds.i = m.bi, s.bonds.j = m.bj, s.bonds.kind = m.kind, s.bonds.interface = m.interface;
  s.bonds.material = m.material;
  for (std::size_t b = 0; b < m.num_bonds(); ++b) {
    const stages::FaceBondFrame& f = m.frame[b];
    s.bonds.nodes.insert(s.bonds.nodes.end(), m.face[b].begin(), m.face[b].end());
    s.bonds.size.push_back(f.section.A);
    const Vec3 c = m.x0[std::size_t(m.bi[b])] + f.ri, n = f.axes.r[2];
    s.bonds.midpoint.insert(s.bonds.midpoint.end(), {c.x, c.y, c.z});
    s.bonds.normal.insert(s.bonds.normal.end(), {n.x, n.y, n.z});
  }
  return s;
}

namespace {

EngineOptions engine_options(const Scene& scene, const SimulationOptions& options,
                             const std::function<void(EngineOptions&)>& adjust) {
  EngineOptions o = EngineOptions::from_scene(scene);
  o.thread_budget = options.thread_budget;
  if (adjust) adjust(o);
  return o;
}

}  // namespace

SimulationImpl<3>::SimulationImpl(const Scene& scene, const TetMesh& mesh, const SimulationOptions& options,
                                  const std::function<void(EngineOptions&)>& engine)
    : engine_(mesh, scene, engine_options(scene, options, engine)),
      specimen_(describe(engine_.model(), mesh, scene.rock.density)) {
  if (engine_.options().contacts) {
    contacts_ = std::make_unique<BlockContacts3>(engine_.model());
    engine_.attach(contacts_.get());
  }
  engine_.on_crack = [this](const Crack& c) {
    if (on_crack) on_crack(c);
  };
  for (const SurfaceFace& f : engine_.model().surface)
    if (f.tag == FaceTag::lateral) lateral_.push_back(f.block);
  std::sort(lateral_.begin(), lateral_.end());
  lateral_.erase(std::unique(lateral_.begin(), lateral_.end()), lateral_.end());
}

double SimulationImpl<3>::stability_limit(int iterations, int) const {
  return rbdem::stability_limit(engine_, iterations);
}

ContactStates SimulationImpl<3>::contact_states() const {
  if (contacts_) return contacts_->states(engine_.model(), engine_.state());
  ContactStates c;
  c.dim = 3;
  return c;
}

std::string SimulationImpl<3>::non_finite() const {
  const ModelState<3>& s = engine_.state();
  for (std::size_t b = 0; b < s.num_blocks(); ++b)
    if (!std::isfinite(s.x[b] + s.y[b] + s.z[b] + s.qw[b] + s.qx[b] + s.qy[b] + s.qz[b] + s.vx[b] + s.vy[b] +
                       s.vz[b] + s.wx[b] + s.wy[b] + s.wz[b]))
      return fmt::format("block {} has a non-finite position or velocity", b);
  return {};
}

std::vector<double> SimulationImpl<3>::pose() const {
  const ModelState<3>& s = engine_.state();
  std::vector<double> p;
  p.reserve(7 * s.num_blocks());
  for (const auto* v : {&s.x, &s.y, &s.z, &s.qw, &s.qx, &s.qy, &s.qz}) p.insert(p.end(), v->begin(), v->end());
  return p;
}

double SimulationImpl<3>::lateral_strain() const {
  const Model<3>& m = engine_.model();
  const ModelState<3>& s = engine_.state();
  double sum = 0;
  int n = 0;
  for (int b : lateral_) {
    if (!m.has_intact_bond(b, s.broken)) continue;
    const std::size_t k = std::size_t(b);
    const double rx = m.x0[k].x - m.axis[0], ry = m.x0[k].y - m.axis[1], r = std::hypot(rx, ry);
    if (!(r > 0)) continue;
    sum += ((s.x[k] - m.x0[k].x) * rx + (s.y[k] - m.x0[k].y) * ry) / (r * r), ++n;
  }
  return n > 0 ? -sum / n : 0.0;
}

double SimulationImpl<3>::lateral_strain_of(const StaticResult& st) const {
  const Model<3>& m = engine_.model();
  double sum = 0;
  int n = 0;
  for (int b : lateral_) {
    const std::size_t k = std::size_t(b);
    const double rx = m.x0[k].x - m.axis[0], ry = m.x0[k].y - m.axis[1], r = std::hypot(rx, ry);
    if (!(r > 0) || st.u.size() < 6 * (k + 1)) continue;
    sum += (st.u[6 * k] * rx + st.u[6 * k + 1] * ry) / (r * r), ++n;
  }
  return n > 0 ? -sum / n : 0.0;
}

template <class C>
C& SimulationImpl<3>::install(std::unique_ptr<C> component) {
  C& c = *component;
  engine_.attach(&c);
  boundaries_.push_back(&c);
  components_.push_back(std::move(component));
  return c;
}

Platens& SimulationImpl<3>::add_platens(const PlatenSettings& settings) {
  if (find<Platens>()) throw std::invalid_argument("the simulation has its platens already");
  return install(std::make_unique<PlatensImpl<3>>(engine_.model(), settings));
}

Jacket& SimulationImpl<3>::add_jacket(double pressure) {
  if (find<Jacket>()) throw std::invalid_argument("the simulation has its jacket already");
  return install(std::make_unique<JacketImpl<3>>(engine_.model(), pressure));
}

BlockGroup& SimulationImpl<3>::add_group(const GroupSettings&) {
  throw SceneError("block groups (rbdem shear's boxes, scripted groups) are not built for 3D specimens: use a 2D "
                   "scene (specimen.dimension = 2)");
}

StaticResult SimulationImpl<3>::solve_static(const StaticOptions& options) const {
  return rbdem::solve_static(engine_, options);
}

double SimulationImpl<3>::first_break_along(const StaticResult& base, const StaticResult& increment, int* bond) const {
  if (base.empty()) {
    if (bond) *bond = increment.first_break_bond;
    return increment.first_break_factor;
  }
  return rbdem::first_break_along(engine_, base, increment, bond);
}

void SimulationImpl<3>::apply_static(const StaticResult& base, const StaticResult& increment, double lambda,
                                     double velocity) {
  rbdem::apply_static(engine_, base, increment, lambda, velocity);
}

std::vector<double> SimulationImpl<3>::pressure_load(double pressure) const {
  if (const auto* jacket = dynamic_cast<const JacketImpl<3>*>(find<Jacket>()))
    return jacket->reference_load(engine_.model(), pressure);
  return JacketImpl<3>(engine_.model(), pressure).reference_load(engine_.model(), pressure);
}

Snapshot SimulationImpl<3>::snapshot() const {
  Snapshot s;
  s.dim = 3;
  save_state(engine_.state(), s);
  for (const BoundaryHooks<3>* h : engine_.hooks()) h->save(s);
  return s;
}

void SimulationImpl<3>::restore(const Snapshot& snapshot) {
  if (snapshot.dim != 3)
    throw std::invalid_argument(fmt::format("the snapshot is of a {}D model; this one is 3D", snapshot.dim));
  ModelState<3> state;
  load_state(snapshot, state, engine_.model().num_blocks(), engine_.model().num_bonds());
  for (BoundaryHooks<3>* h : engine_.hooks()) h->load(snapshot, engine_.model());
  engine_.restore(state);
}

}  // namespace rbdem
