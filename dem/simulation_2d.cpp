// SimulationImpl<2>: the Simulation interface over the 2D engine. See simulation_impl.hpp.
#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "dem/simulation_impl.hpp"

namespace rbdem {

std::unique_ptr<Simulation> Simulation::create(const Scene& scene, const TriMesh& mesh,
                                               const SimulationOptions& options) {
  return std::make_unique<SimulationImpl<2>>(scene, mesh, options);
}

Specimen describe(const Topology<2>& topo, const TriMesh* mesh, const std::vector<std::uint8_t>& bond_material) {
  Specimen s;
  s.dim = 2;
  s.lo = {topo.xmin, topo.ymin, 0.0}, s.hi = {topo.xmax, topo.ymax, 0.0};
  s.thickness = topo.thickness;
  if (mesh) {
    s.nodes.reserve(2 * mesh->nodes.size());
    for (const auto& p : mesh->nodes) s.nodes.insert(s.nodes.end(), {p[0], p[1]});
    s.cells.reserve(3 * mesh->triangles.size());
    for (const auto& t : mesh->triangles) s.cells.insert(s.cells.end(), {t[0], t[1], t[2]});
  }
  s.layer_names = topo.layer_names, s.interface_names = topo.interface_names;
  const auto& G = topo.blocks;
  for (std::size_t b = 0; b < G.size(); ++b) {
    s.blocks.centroid.insert(s.blocks.centroid.end(), {G.cx[b], G.cy[b]});
    s.blocks.shape.insert(s.blocks.shape.end(), G.shape[b].begin(), G.shape[b].end());
  }
  s.blocks.measure = G.area, s.blocks.mass = G.mass, s.blocks.layer = G.layer;
  const auto& N = topo.bonds;
  s.bonds.i = N.i, s.bonds.j = N.j, s.bonds.kind = N.kind, s.bonds.size = N.length;
  s.bonds.interface = N.interface.empty() ? std::vector<int>(N.size(), -1) : N.interface;
  s.bonds.material = bond_material;
  for (std::size_t b = 0; b < N.size(); ++b) {
    s.bonds.nodes.insert(s.bonds.nodes.end(), {N.node_a[b], N.node_b[b]});
    s.bonds.midpoint.insert(s.bonds.midpoint.end(), {N.mx[b], N.my[b]});
    s.bonds.normal.insert(s.bonds.normal.end(), {N.nx[b], N.ny[b]});
  }
  return s;
}

std::size_t Specimen::count(BondKind k) const {
  return std::size_t(std::count(bonds.kind.begin(), bonds.kind.end(), k));
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

SimulationImpl<2>::SimulationImpl(const Scene& scene, const TriMesh& mesh, const SimulationOptions& options,
                                  const std::function<void(EngineOptions&)>& engine)
    : topology_(build_topology(mesh, scene.specimen.thickness, scene.rock.density)),
      engine_(topology_, scene, engine_options(scene, options, engine)),
      specimen_(describe(topology_, &mesh, engine_.model().material)) {
  engine_.on_crack = [this](const Crack& c) {
    if (on_crack) on_crack(c);
  };
  find_sides();
}

SimulationImpl<2>::SimulationImpl(const Scene& scene, Topology<2> topology, const SimulationOptions& options,
                                  const std::function<void(EngineOptions&)>& engine)
    : topology_(std::move(topology)),
      engine_(topology_, scene, engine_options(scene, options, engine)),
      specimen_(describe(topology_, nullptr, engine_.model().material)) {
  engine_.on_crack = [this](const Crack& c) {
    if (on_crack) on_crack(c);
  };
  find_sides();
}

void SimulationImpl<2>::find_sides() {
  const Topology<2>& topo = topology_;
  const auto& E = topo.boundary;
  for (std::size_t e = 0; e < E.size(); ++e) {
    if (E.side[e] == Side::left) left_.push_back(E.block[e]);
    if (E.side[e] == Side::right) right_.push_back(E.block[e]);
  }
  if (left_.empty() && right_.empty()) {  // a disc or another curved outline: the rim near the horizontal diameter
    const double yc = 0.5 * (topo.ymin + topo.ymax), xc = 0.5 * (topo.xmin + topo.xmax), band = 0.1 * topo.height();
    for (std::size_t e = 0; e < E.size(); ++e) {
      const int b = E.block[e];
      if (std::abs(topo.blocks.cy[std::size_t(b)] - yc) > band) continue;
      (topo.blocks.cx[std::size_t(b)] < xc ? left_ : right_).push_back(b);
    }
  }
  for (auto* v : {&left_, &right_}) {
    std::sort(v->begin(), v->end());
    v->erase(std::unique(v->begin(), v->end()), v->end());
  }
}

double SimulationImpl<2>::lateral_strain() const {
  const Model<2>& m = engine_.model();
  const ModelState<2>& s = engine_.state();
  auto mean_shift = [&](const std::vector<int>& blocks, bool& any) {
    double sum = 0;
    int n = 0;
    for (int b : blocks)
      if (m.has_intact_bond(b, s.broken)) sum += s.x[std::size_t(b)] - m.x0[std::size_t(b)], ++n;
    any = n > 0;
    return n > 0 ? sum / n : 0.0;
  };
  bool l = false, r = false;
  const double shift = mean_shift(right_, r) - mean_shift(left_, l);
  const double width = topology_.width();
  return l && r && width > 0 ? -shift / width : 0.0;
}

double SimulationImpl<2>::lateral_strain_of(const StaticResult& st) const {
  auto mean = [&](const std::vector<int>& blocks) {
    double sum = 0;
    for (int b : blocks) sum += st.u[3 * std::size_t(b)];
    return blocks.empty() ? 0.0 : sum / double(blocks.size());
  };
  const double width = topology_.width();
  return left_.empty() || right_.empty() || !(width > 0) ? 0.0 : -(mean(right_) - mean(left_)) / width;
}

std::string SimulationImpl<2>::non_finite() const {
  const ModelState<2>& s = engine_.state();
  // The first block with a non-finite position or velocity, the scan on the run's threads (the watchdog's check).
  const long n = long(s.num_blocks());
  long first = n;
#pragma omp parallel for schedule(static) num_threads(engine_.threads()) reduction(min : first) if (n > 4096)
  for (long k = 0; k < n; ++k) {
    const std::size_t b = std::size_t(k);
    if (!(std::isfinite(s.x[b]) && std::isfinite(s.y[b]) && std::isfinite(s.theta[b]) && std::isfinite(s.vx[b]) &&
          std::isfinite(s.vy[b]) && std::isfinite(s.omega[b])))
      first = std::min(first, k);
  }
  if (first < n) return fmt::format("block {} has a non-finite position or velocity", first);
  return {};
}

std::vector<double> SimulationImpl<2>::pose() const {
  const ModelState<2>& s = engine_.state();
  std::vector<double> p;
  p.reserve(3 * s.num_blocks());
  p.insert(p.end(), s.x.begin(), s.x.end());
  p.insert(p.end(), s.y.begin(), s.y.end());
  p.insert(p.end(), s.theta.begin(), s.theta.end());
  return p;
}

template <class C>
C& SimulationImpl<2>::install(std::unique_ptr<C> component) {
  C& c = *component;
  engine_.attach(&c);
  boundaries_.push_back(&c);
  components_.push_back(std::move(component));
  return c;
}

Platens& SimulationImpl<2>::add_platens(const PlatenSettings& settings) {
  if (find<Platens>()) throw std::invalid_argument("the simulation has its platens already");
  return install(std::make_unique<PlatensImpl<2>>(engine_.model(), settings));
}

Jacket& SimulationImpl<2>::add_jacket(double pressure) {
  if (find<Jacket>()) throw std::invalid_argument("the simulation has its jacket already");
  return install(std::make_unique<JacketImpl<2>>(engine_.model(), pressure));
}

BlockGroup& SimulationImpl<2>::add_group(const GroupSettings& settings) {
  for (const Boundary* b : boundaries_)
    if (b->name() == settings.name)
      throw std::invalid_argument(fmt::format("a boundary named '{}' exists already: give the group another name",
                                              settings.name));
  return install(std::make_unique<BlockGroupImpl<2>>(engine_, settings));
}

double SimulationImpl<2>::first_break_along(const StaticResult& base, const StaticResult& increment, int* bond) const {
  if (base.empty()) {  // from rest: the increment's own first-break factor
    if (bond) *bond = increment.first_break_bond;
    return increment.first_break_factor;
  }
  return rbdem::first_break_along(engine_, base, increment, bond);
}

void SimulationImpl<2>::apply_static(const StaticResult& base, const StaticResult& increment, double lambda,
                                     double velocity) {
  if (base.empty()) apply_static_state(engine_, increment, lambda, velocity);
  else apply_static_path(engine_, base, increment, lambda, velocity);
}

std::vector<double> SimulationImpl<2>::pressure_load(double pressure) const {
  if (const auto* jacket = dynamic_cast<const JacketImpl<2>*>(find<Jacket>()))
    return jacket->reference_load(engine_.model(), pressure);
  return JacketImpl<2>(engine_.model(), pressure).reference_load(engine_.model(), pressure);
}

Snapshot SimulationImpl<2>::snapshot() const {
  Snapshot s;
  s.dim = 2;
  save_state(engine_.state(), s);
  for (const BoundaryHooks<2>* h : engine_.hooks()) h->save(s);
  return s;
}

void SimulationImpl<2>::restore(const Snapshot& snapshot) {
  if (snapshot.dim != 2)
    throw std::invalid_argument(fmt::format("the snapshot is of a {}D model; this one is 2D", snapshot.dim));
  ModelState<2> state;
  load_state(snapshot, state);
  check_state_fits(state, engine_.model().num_blocks(), engine_.model().num_bonds());
  // The components next, then the engine: a snapshot that does not fit leaves the engine as it was.
  for (BoundaryHooks<2>* h : engine_.hooks()) h->load(snapshot, engine_.model());
  engine_.restore(state);
}

}  // namespace rbdem
