// The Love-Weber stress and diametral loads. See measure.hpp.
#include "dem/measure.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace rbdem {

Region Region::box(std::vector<double> lo, std::vector<double> hi) {
  Region r;
  r.kind = Kind::box, r.lo = std::move(lo), r.hi = std::move(hi);
  return r;
}

Region Region::circle(std::vector<double> centre, double radius) {
  Region r;
  r.kind = Kind::circle, r.centre = std::move(centre), r.radius = radius;
  return r;
}

Region Region::layers(std::vector<int> ids) {
  Region r;
  r.kind = Kind::layers, r.ids = std::move(ids);
  return r;
}

Region Region::blocks(std::vector<int> ids) {
  Region r;
  r.kind = Kind::blocks, r.ids = std::move(ids);
  return r;
}

std::string Region::describe() const {
  switch (kind) {
    case Kind::all: return "the whole specimen";
    case Kind::box: return fmt::format("the box from ({}) to ({}) m", fmt::join(lo, ", "), fmt::join(hi, ", "));
    case Kind::circle: return fmt::format("the circle of radius {} m about ({}) m", radius, fmt::join(centre, ", "));
    case Kind::layers: return fmt::format("the layers {}", fmt::join(ids, ", "));
    case Kind::blocks: return fmt::format("the {} blocks listed", ids.size());
  }
  return "a region";
}

namespace {

// The region's numbers fit a specimen of dimension d with nb blocks and these layers.
void check_region(const Region& r, int d, std::size_t nb, const std::vector<int>& layer) {
  const auto fail = [&](const std::string& why) {
    throw std::invalid_argument(fmt::format("stress region ({}): {}", r.describe(), why));
  };
  const auto finite = [](const std::vector<double>& v) {
    return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
  };
  if (r.kind == Region::Kind::box) {
    if (r.lo.size() != std::size_t(d) || r.hi.size() != std::size_t(d))
      fail(fmt::format("give lo and hi with {} coordinates each, as the model has", d));
    if (!finite(r.lo) || !finite(r.hi)) fail("its corners must be finite numbers");
    for (int a = 0; a < d; ++a)
      if (r.lo[std::size_t(a)] > r.hi[std::size_t(a)]) fail("lo must not exceed hi in any coordinate");
  } else if (r.kind == Region::Kind::circle) {
    if (r.centre.size() != std::size_t(d)) fail(fmt::format("give its centre with {} coordinates", d));
    if (!finite(r.centre) || !(r.radius > 0) || !std::isfinite(r.radius))
      fail("give a finite centre and a radius > 0");
  } else if (r.kind == Region::Kind::layers) {
    const int top = layer.empty() ? -1 : *std::max_element(layer.begin(), layer.end());
    for (int id : r.ids)
      if (std::find(layer.begin(), layer.end(), id) == layer.end())
        fail(fmt::format("no block is in layer {} (the specimen's layers are 0 .. {})", id, top));
  } else if (r.kind == Region::Kind::blocks) {
    for (int b : r.ids)
      if (b < 0 || std::size_t(b) >= nb)
        fail(fmt::format("block {} is not in the specimen (blocks 0 .. {})", b, nb == 0 ? 0 : nb - 1));
  }
}

// Whether a centroid p (d components) lies in a box or circle region.
bool contains(const Region& r, int d, const double* p) {
  if (r.kind == Region::Kind::box) {
    for (int a = 0; a < d; ++a)
      if (p[a] < r.lo[std::size_t(a)] || p[a] > r.hi[std::size_t(a)]) return false;
    return true;
  }
  const double dx = p[0] - r.centre[0], dy = p[1] - r.centre[1];
  return (d == 2 ? std::hypot(dx, dy) : std::hypot(dx, dy, p[2] - r.centre[2])) <= r.radius;
}

std::vector<int> members(const Region& r, const Specimen& sp, const BlockStates& blocks) {
  const int d = sp.dim;
  const std::size_t nb = sp.num_blocks();
  check_region(r, d, nb, sp.blocks.layer);
  std::vector<int> out;
  if (r.kind == Region::Kind::blocks) {
    out = r.ids;
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
  }
  for (std::size_t b = 0; b < nb; ++b) {
    bool in = true;
    if (r.kind == Region::Kind::layers)
      in = std::find(r.ids.begin(), r.ids.end(), sp.blocks.layer[b]) != r.ids.end();
    else if (r.kind != Region::Kind::all)
      in = contains(r, d, &blocks.position[std::size_t(d) * b]);
    if (in) out.push_back(int(b));
  }
  return out;
}

// The terms of the Love sums in a fixed order: each intact bond's force on j, then its opposite on i; each
// contact's the same way; each boundary load. add(block, r, f) gets r = x_c - x_b and the force f on the block
// (d components each).
template <class Add>
void love_terms(const Simulation& sim, const BlockStates& blocks, const StressSources& src, Add&& add) {
  const Specimen& sp = sim.specimen();
  const std::size_t d = std::size_t(sp.dim);
  double r[3] = {}, f[3] = {};
  const auto term = [&](int block, const double* point, const double* force, double sign) {
    const double* x = &blocks.position[d * std::size_t(block)];
    for (std::size_t a = 0; a < d; ++a) r[a] = point[a] - x[a], f[a] = sign * force[a];
    add(block, r, f);
  };
  if (src.bonds) {
    const BondStates bonds = sim.bond_states();
    for (std::size_t k = 0; k < bonds.size(); ++k) {
      if (!bonds.intact[k]) continue;
      term(sp.bonds.j[k], &bonds.point[d * k], &bonds.force[d * k], 1.0);
      term(sp.bonds.i[k], &bonds.point[d * k], &bonds.force[d * k], -1.0);
    }
  }
  if (src.contacts) {
    const ContactStates contacts = sim.contact_states();
    for (std::size_t k = 0; k < contacts.size(); ++k) {
      term(contacts.j[k], &contacts.point[d * k], &contacts.force[d * k], 1.0);
      term(contacts.i[k], &contacts.point[d * k], &contacts.force[d * k], -1.0);
    }
  }
  if (src.boundaries) {
    const BoundaryLoads loads = sim.boundary_loads();
    for (std::size_t k = 0; k < loads.size(); ++k) term(loads.block[k], &loads.point[d * k], &loads.force[d * k], 1.0);
  }
}

// sym(S) / volume into out (3 x 3 storage): the diagonal as it is, each pair off it as the mean of the two.
void symmetrised(const double* S, int d, double volume, double* out) {
  const double scale = 1.0 / volume;
  for (int a = 0; a < d; ++a) {
    out[3 * a + a] = S[3 * a + a] * scale;
    for (int c = a + 1; c < d; ++c) out[3 * a + c] = out[3 * c + a] = 0.5 * (S[3 * a + c] + S[3 * c + a]) * scale;
  }
}

// What turns a block's measure into its volume: the slice's thickness in 2D (the measure is an area); 1 in 3D, where
// the measure is the volume and Specimen::thickness is the loaded area over the width (dem/simulation_3d.cpp).
double out_of_plane(const Specimen& sp) { return sp.dim == 2 ? sp.thickness : 1.0; }

}  // namespace

std::vector<int> region_blocks(const Simulation& sim, const Region& region) {
  return members(region, sim.specimen(), sim.block_states());
}

StressTensor average_stress(const Simulation& sim, const Region& region, const StressSources& sources) {
  const Specimen& sp = sim.specimen();
  const BlockStates blocks = sim.block_states();
  const std::vector<int> in_region = members(region, sp, blocks);
  if (in_region.empty())
    throw std::invalid_argument(fmt::format("stress region ({}): it holds no block centroid; enlarge it or move it "
                                            "onto the specimen",
                                            region.describe()));
  StressTensor out;
  out.dim = sp.dim;
  std::vector<char> inside(sp.num_blocks(), 0);
  double measure = 0;  // summed in block order, then times the thickness once (2D)
  for (int b : in_region) inside[std::size_t(b)] = 1, measure += sp.blocks.measure[std::size_t(b)];
  out.blocks = in_region.size();
  out.volume = measure * out_of_plane(sp);
  double S[9] = {};
  const int d = sp.dim;
  love_terms(sim, blocks, sources, [&](int b, const double* r, const double* f) {
    if (!inside[std::size_t(b)]) return;
    for (int a = 0; a < d; ++a)
      for (int c = 0; c < d; ++c) S[3 * a + c] += r[a] * f[c];
  });
  symmetrised(S, d, out.volume, out.s.data());
  return out;
}

StressTensor static_stress(const Simulation& sim, const StaticResult& state, const Region& region) {
  const Specimen& sp = sim.specimen();
  const std::size_t nbond = sp.bonds.size_of();
  if (sp.dim != 2 || state.dim != 2 || state.fn_lin.size() != nbond || state.fn_b.size() != nbond)
    throw std::invalid_argument(fmt::format("static stress: the solution has {} bond forces for the {} bonds of this "
                                            "{}D specimen; pass a 2D solution of this simulation's solve_static",
                                            state.fn_lin.size(), nbond, sp.dim));
  const std::vector<int> in_region = members(region, sp, sim.block_states());
  if (in_region.empty())
    throw std::invalid_argument(fmt::format("stress region ({}): it holds no block centroid; enlarge it or move it "
                                            "onto the specimen",
                                            region.describe()));
  StressTensor out;
  std::vector<char> inside(sp.num_blocks(), 0);
  double measure = 0;
  for (int b : in_region) inside[std::size_t(b)] = 1, measure += sp.blocks.measure[std::size_t(b)];
  out.blocks = in_region.size();
  out.volume = measure * sp.thickness;
  double S[9] = {};
  // Bond k pushes block j along its normal n by its compression and along t = (-n_y, n_x) by its shear; block i
  // takes the opposite. Each term is (x_c - x_block) f, the bond's point the edge's midpoint.
  const auto add = [&](int block, const double* point, double fx, double fy) {
    if (!inside[std::size_t(block)]) return;
    const double* x = &sp.blocks.centroid[2 * std::size_t(block)];
    const double r[2] = {point[0] - x[0], point[1] - x[1]}, f[2] = {fx, fy};
    for (int a = 0; a < 2; ++a)
      for (int c = 0; c < 2; ++c) S[3 * a + c] += r[a] * f[c];
  };
  for (std::size_t k = 0; k < nbond; ++k) {  // a broken bond's forces are zero
    const double nx = sp.bonds.normal[2 * k], ny = sp.bonds.normal[2 * k + 1];
    const double fn = state.fn_b[k] + state.fn_lin[k], fs = state.fs_b[k] + state.fs_lin[k];
    const double fx = fn * nx - fs * ny, fy = fn * ny + fs * nx;
    add(sp.bonds.j[k], &sp.bonds.midpoint[2 * k], fx, fy);
    add(sp.bonds.i[k], &sp.bonds.midpoint[2 * k], -fx, -fy);
  }
  symmetrised(S, 2, out.volume, out.s.data());
  return out;
}

BlockStresses block_stresses(const Simulation& sim, const StressSources& sources) {
  const Specimen& sp = sim.specimen();
  const BlockStates blocks = sim.block_states();
  const std::size_t nb = sp.num_blocks(), d = std::size_t(sp.dim);
  std::vector<double> S(9 * nb, 0.0);
  love_terms(sim, blocks, sources, [&](int b, const double* r, const double* f) {
    double* s = &S[9 * std::size_t(b)];
    for (std::size_t a = 0; a < d; ++a)
      for (std::size_t c = 0; c < d; ++c) s[3 * a + c] += r[a] * f[c];
  });
  BlockStresses out;
  out.dim = sp.dim;
  out.stress.resize(d * d * nb), out.volume.resize(nb);
  for (std::size_t b = 0; b < nb; ++b) {
    out.volume[b] = sp.blocks.measure[b] * out_of_plane(sp);
    double sym[9];
    symmetrised(&S[9 * b], sp.dim, out.volume[b], sym);
    for (std::size_t a = 0; a < d; ++a)
      for (std::size_t c = 0; c < d; ++c) out.stress[d * (d * b + a) + c] = sym[3 * a + c];
  }
  return out;
}

ForceNetwork force_network(const Simulation& sim) {
  const Specimen& sp = sim.specimen();
  const std::size_t d = std::size_t(sp.dim);
  const BondStates bonds = sim.bond_states();
  const ContactStates contacts = sim.contact_states();
  // The intact bonds in bond order, then the contacts: each link's row is known from the count of intact bonds
  // before it, so the rows are filled on the run's threads (a frame is taken at every peak refresh).
  std::vector<std::size_t> row(bonds.size());
  std::size_t n = 0;
  for (std::size_t k = 0; k < bonds.size(); ++k) row[k] = n, n += bonds.intact[k] ? 1 : 0;
  const std::size_t first_contact = n;
  n += contacts.size();
  ForceNetwork net;
  net.i.resize(n), net.j.resize(n), net.kind.resize(n), net.force.resize(d * n), net.normal_force.resize(n);
  const auto link = [&](std::size_t r, int i, int j, std::uint8_t kind, const double* force, double normal) {
    net.i[r] = i, net.j[r] = j, net.kind[r] = kind;
    for (std::size_t a = 0; a < d; ++a) net.force[d * r + a] = float(force[a]);
    net.normal_force[r] = float(normal);
  };
  const std::size_t nbond = bonds.size(), ncontact = contacts.size();
#pragma omp parallel num_threads(sim.threads()) if (n > 4096)
  {
#pragma omp for schedule(static) nowait
    for (std::size_t k = 0; k < nbond; ++k)
      if (bonds.intact[k]) link(row[k], sp.bonds.i[k], sp.bonds.j[k], 0, &bonds.force[d * k], bonds.normal_force[k]);
    // The contact table's normal force is compression positive; the network's is tension positive, as the bonds'.
#pragma omp for schedule(static)
    for (std::size_t k = 0; k < ncontact; ++k)
      link(first_contact + k, contacts.i[k], contacts.j[k], 1, &contacts.force[d * k], -contacts.normal_force[k]);
  }
  return net;
}

std::vector<double> diametral_load(const Engine<2>& engine, const TriMesh& mesh, double force) {
  const Model<2>& m = engine.model();
  const Topology<2>& topo = engine.topology();
  const double tol = 1e-9 * topo.width();
  const double xc = 0.5 * (topo.xmin + topo.xmax);
  std::vector<double> load(3 * m.num_blocks(), 0.0);
  for (const auto& [y, fy] : {std::pair{topo.ymax, -force}, std::pair{topo.ymin, force}}) {
    int node = -1;
    for (std::size_t n = 0; n < mesh.nodes.size(); ++n)
      if (std::abs(mesh.nodes[n][0] - xc) <= tol && std::abs(mesh.nodes[n][1] - y) <= tol) node = int(n);
    if (node < 0)
      throw std::invalid_argument("diametral load: the mesh has no node at the disc's top or bottom point");
    std::vector<int> holders;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
      for (int v : mesh.triangles[t])
        if (v == node) holders.push_back(int(t));
    for (int b : holders) {  // the force shared among the blocks at the node, applied at the node
      const double share = fy / double(holders.size());
      const double rx = mesh.nodes[std::size_t(node)][0] - m.x0[std::size_t(b)];
      load[3 * std::size_t(b) + 1] += share;
      load[3 * std::size_t(b) + 2] += rx * share;
    }
  }
  return load;
}

}  // namespace rbdem
