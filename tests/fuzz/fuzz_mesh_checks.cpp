// libFuzzer target: bytes -> a TriMesh (nodes and triangles decoded directly, no gmsh) -> check_user_mesh ->
// build_topology. Exercises every check rbdem applies to a user mesh at full speed and fully instrumented, which
// the gmsh-based fuzz_msh cannot (gmsh costs milliseconds per input).
//
// Layout: byte 0 = node count n (1..64); then n nodes of two int16 coordinates (scaled by 1e-4 m, so exact
// duplicates, collinear points and T-junctions are common); then triangles of three bytes (node index mod n) and
// one layer byte, until the input ends.
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "dem/scene.hpp"
#include "dem/specimen_mesh.hpp"
#include "dem/topology.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::size_t n = std::size_t(data[0] % 64) + 1;
  std::size_t pos = 1;
  if (size < pos + 4 * n) return 0;
  rbdem::TriMesh mesh;
  for (std::size_t k = 0; k < n; ++k, pos += 4) {
    std::int16_t x, y;
    std::memcpy(&x, data + pos, 2);
    std::memcpy(&y, data + pos + 2, 2);
    mesh.nodes.push_back({1e-4 * x, 1e-4 * y});
  }
  for (; pos + 4 <= size; pos += 4) {
    mesh.triangles.push_back({int(data[pos] % n), int(data[pos + 1] % n), int(data[pos + 2] % n)});
    mesh.layer.push_back(data[pos + 3] % 2);
  }
  mesh.layer_names = {"layer_0", "layer_1"};
  try {
    rbdem::check_user_mesh(mesh, "fuzz");
    const rbdem::Topology topo = rbdem::build_topology(mesh, 1.0, 2700.0);
    (void)topo;
  } catch (const rbdem::SceneError&) {
  }
  return 0;
}
