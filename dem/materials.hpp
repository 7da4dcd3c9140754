// Which material each bond and block gets: the scene's rock, joint, joint2 and rock2 over the mesh's layers and
// interfaces.
//
//   rock bond (inside one layer)   rock2 when its layer is rock2 (below), else rock
//   joint bond                     joint2 when it lies on the second generated joint set (the interface
//                                  "joint_set2") or on an interface listed in joint2.groups, else joint
//   block                          rock2 when its layer is rock2, else rock (density)
//
// A layer is rock2 when rock2.groups lists it (layer names or layer numbers: 0-based layer ids, the order
// `rbdem mesh` prints, which change with the dip) or, with beds.pattern, when the bed along the joint normal that
// holds the layer's centroid is rock2 (the same physical beds at every dip). joint2.groups lists interface
// (physical curve) names. A name the mesh lacks is a SceneError that lists what the mesh has and names the dip.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "dem/scene.hpp"
#include "dem/topology.hpp"

namespace rbdem {

// Material ids: the index of each material's law in Model::law.
enum Material : std::uint8_t { material_rock = 0, material_joint = 1, material_joint2 = 2, material_rock2 = 3 };
inline constexpr std::size_t material_count = 4;
inline constexpr std::array<const char*, material_count> material_name{"rock", "joint", "joint2", "rock2"};

struct MaterialMap {
  std::vector<std::uint8_t> bond;   // material id per bond
  std::vector<std::uint8_t> block;  // material id per block (material_rock or material_rock2)
};

MaterialMap assign_materials(const Topology<2>& topo, const Scene& scene);

// 1 for each layer id that is rock2, 0 for rock (rock2.groups or beds.pattern, as above).
std::vector<std::uint8_t> rock2_layers(const Topology<2>& topo, const Scene& scene);

// The scene's parameters of material `id`.
const MaterialParams& material_params(const Scene& scene, std::size_t id);

// Heterogeneity: one factor per bond from a Weibull distribution of mean 1, w = (-ln(1 - u))^(1/m) / Gamma(1 + 1/m)
// with m the `modulus` (weibull_modulus for the strengths, stiffness_weibull_modulus for E*) of the bond's material
// (`bond_material`, ids as above); one uniform u in (0, 1) per bond in bond order from a 64-bit Mersenne twister
// seeded with `seed`, drawn for every bond so that a material's factors do not depend on which others scatter; 1
// where m = 0. Empty when no material scatters.
std::vector<double> weibull_factors(const Scene& scene, const std::vector<std::uint8_t>& bond_material,
                                    double MaterialParams::*modulus, std::uint64_t seed);

}  // namespace rbdem
