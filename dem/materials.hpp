// Which material each bond and block gets: the scene's rock, joint, joint2 and rock2 over the mesh's layers and
// interfaces.
//
//   rock bond (inside one layer)   rock2 when its layer is listed in rock2.groups, else rock
//   joint bond                     joint2 when it lies on the second generated joint set (the interface
//                                  "joint_set2") or on an interface listed in joint2.groups, else joint
//   block                          rock2 when its layer is listed in rock2.groups, else rock (density)
//
// rock2.groups lists layer names or layer numbers (0-based layer ids, the order `rbdem mesh` prints);
// joint2.groups lists interface (physical curve) names. A name the mesh lacks is a SceneError that lists what the
// mesh has.
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

// The scene's parameters of material `id`.
const MaterialParams& material_params(const Scene& scene, std::size_t id);

}  // namespace rbdem
