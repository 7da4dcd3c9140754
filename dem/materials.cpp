// Materials over layers and interfaces. See materials.hpp.
#include "dem/materials.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <numbers>
#include <random>

#include <fmt/format.h>

#include "dem/specimen_mesh.hpp"

namespace rbdem {

namespace {
std::string trim(std::string s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.pop_back();
  std::size_t i = 0;
  while (i < s.size() && std::isspace(static_cast<unsigned char>(s[i]))) ++i;
  return s.substr(i);
}

std::vector<std::string> tokens(const std::string& list) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (start <= list.size()) {
    const std::size_t comma = std::min(list.find(',', start), list.size());
    std::string t = trim(list.substr(start, comma - start));
    if (!t.empty()) out.push_back(std::move(t));
    start = comma + 1;
  }
  return out;
}

std::string listing(const std::vector<std::string>& names) {
  if (names.empty()) return "none";
  std::string s;
  for (std::size_t k = 0; k < names.size(); ++k) s += (k ? ", " : "") + fmt::format("{} '{}'", k, names[k]);
  return s;
}

bool all_digits(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c); });
}
}  // namespace

const MaterialParams& material_params(const Scene& scene, std::size_t id) {
  switch (id) {
    case material_joint: return scene.joint;
    case material_joint2: return scene.joint2;
    case material_rock2: return scene.rock2;
    default: return scene.rock;
  }
}

std::vector<double> weibull_factors(const Scene& scene, const std::vector<std::uint8_t>& bond_material,
                                    double MaterialParams::*modulus, std::uint64_t seed) {
  bool any = false;
  for (std::size_t k = 0; k < material_count; ++k) any = any || material_params(scene, k).*modulus > 0;
  if (!any) return {};
  std::vector<double> w(bond_material.size(), 1.0);
  std::mt19937_64 random(seed);
  for (std::size_t b = 0; b < w.size(); ++b) {
    const double u = (double(random() >> 11) + 0.5) * 0x1.0p-53;  // (0, 1), the same on every platform
    const double m = material_params(scene, bond_material[b]).*modulus;
    if (m > 0) w[b] = std::pow(-std::log1p(-u), 1.0 / m) / std::tgamma(1.0 + 1.0 / m);
  }
  return w;
}

namespace {
// Which mesh this is, for messages: layer numbers and names change with the dip of a generated specimen.
std::string which_mesh(const Scene& scene) {
  if (!scene.mesh.file.empty()) return fmt::format("the mesh (mesh.file = \"{}\")", scene.mesh.file);
  if (!scene.joint_set.enabled) return "the mesh of the unjointed specimen (joint_set.enabled = false)";
  return fmt::format("the mesh at joint_set.dip_deg = {:g} deg", scene.joint_set.dip_deg);
}

// rock2.groups: the layers it names, by name or number.
std::vector<std::uint8_t> rock2_layers_by_name(const Topology<2>& topo, const Scene& scene, std::size_t layers) {
  std::vector<std::uint8_t> rock2_layer(layers, 0);
  for (const std::string& t : tokens(scene.rock2.groups)) {
    const auto named = std::find(topo.layer_names.begin(), topo.layer_names.end(), t);
    if (named != topo.layer_names.end()) {
      rock2_layer[std::size_t(named - topo.layer_names.begin())] = 1;
    } else if (all_digits(t) && t.size() < 9 && std::size_t(std::stoi(t)) < layers) {
      rock2_layer[std::size_t(std::stoi(t))] = 1;
    } else {
      throw SceneError(fmt::format(
          "rock2.groups names layer '{}', which {} does not have; its layers (number and name) are: {}; name one of "
          "them, or a number below {}{}",
          t, which_mesh(scene), listing(topo.layer_names), layers,
          scene.mesh.file.empty() ? "; the layers of a generated specimen change with the dip (the elastic gate and "
                                    "sweeps mesh other dips): beds.pattern states beds by position, the same at "
                                    "every dip"
                                  : ""));
    }
  }
  return rock2_layer;
}

// beds.pattern: each layer takes the bed that holds its area-weighted centroid, measured along the joint normal
// n = (-sin dip, cos dip) from the specimen centre. A layer lies between two joints, so with beds one spacing thick
// its centroid is inside one bed whatever the dip; a corner piece the mesher merged with its neighbour (no joint
// cut there) goes with that neighbour's bed.
std::vector<std::uint8_t> rock2_layers_by_position(const Topology<2>& topo, const Scene& scene, std::size_t layers) {
  const BedSequence beds = bed_sequence(scene);
  std::vector<double> area(layers, 0.0), sx(layers, 0.0), sy(layers, 0.0);
  const auto& G = topo.blocks;
  for (std::size_t b = 0; b < G.size(); ++b) {
    const auto l = std::size_t(G.layer[b]);
    area[l] += G.area[b], sx[l] += G.area[b] * G.cx[b], sy[l] += G.area[b] * G.cy[b];
  }
  const double beta = scene.joint_set.dip_deg * std::numbers::pi / 180.0;
  const double nx = -std::sin(beta), ny = std::cos(beta);
  const double cx = 0.5 * (topo.xmin + topo.xmax), cy = 0.5 * (topo.ymin + topo.ymax);
  std::vector<std::uint8_t> rock2_layer(layers, 0);
  for (std::size_t l = 0; l < layers; ++l) {
    if (!(area[l] > 0)) continue;
    const double s = nx * (sx[l] / area[l] - cx) + ny * (sy[l] / area[l] - cy);
    rock2_layer[l] = beds.rock2[beds.bed_at(s)] ? 1 : 0;
  }
  return rock2_layer;
}
}  // namespace

std::vector<std::uint8_t> rock2_layers(const Topology<2>& topo, const Scene& scene) {
  const std::size_t layers = std::max<std::size_t>(
      topo.layer_names.size(),
      topo.blocks.layer.empty() ? 0 : std::size_t(1 + *std::max_element(topo.blocks.layer.begin(),
                                                                           topo.blocks.layer.end())));
  return scene.beds.pattern.empty() ? rock2_layers_by_name(topo, scene, layers)
                                    : rock2_layers_by_position(topo, scene, layers);
}

MaterialMap assign_materials(const Topology<2>& topo, const Scene& scene) {
  const std::vector<std::uint8_t> rock2_layer = rock2_layers(topo, scene);
  std::vector<std::uint8_t> joint2_interface(topo.interface_names.size(), 0);
  for (std::size_t f = 0; f < topo.interface_names.size(); ++f)
    if (topo.interface_names[f] == joint_set_group[1]) joint2_interface[f] = 1;
  for (const std::string& t : tokens(scene.joint2.groups)) {
    const auto named = std::find(topo.interface_names.begin(), topo.interface_names.end(), t);
    if (named == topo.interface_names.end())
      throw SceneError(fmt::format("joint2.groups names interface '{}', which the mesh does not have; its interfaces "
                                   "(physical curves) are: {}; name one of them, or draw the curve as a physical "
                                   "curve in the mesh",
                                   t, listing(topo.interface_names)));
    joint2_interface[std::size_t(named - topo.interface_names.begin())] = 1;
  }

  MaterialMap m;
  const auto& G = topo.blocks;
  m.block.resize(G.size());
  for (std::size_t b = 0; b < G.size(); ++b)
    m.block[b] = rock2_layer[std::size_t(G.layer[b])] ? material_rock2 : material_rock;
  const auto& N = topo.bonds;
  m.bond.resize(N.size());
  for (std::size_t k = 0; k < N.size(); ++k) {
    const int f = N.interface.empty() ? -1 : N.interface[k];
    if (N.kind[k] == BondKind::rock)
      m.bond[k] = m.block[std::size_t(N.i[k])];
    else
      m.bond[k] = f >= 0 && joint2_interface[std::size_t(f)] ? material_joint2 : material_joint;
  }
  return m;
}

}  // namespace rbdem
