// libFuzzer target: bytes -> a .msh file -> read_msh (header check, gmsh import, our mesh checks) ->
// build_topology. A SceneError is a normal rejection; anything else is a bug. gmsh itself is not instrumented
// (the Debian library); its allocations still go through ASan. See docs/reliability.md.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "dem/scene.hpp"
#include "dem/specimen_mesh.hpp"
#include "dem/topology.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const std::filesystem::path file =
      std::filesystem::temp_directory_path() / ("rbdem_fuzz_" + std::to_string(getpid()) + ".msh");
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  }
  try {
    const rbdem::TriMesh mesh = rbdem::read_msh(file);
    const rbdem::Topology topo = rbdem::build_topology(mesh, 1.0, 2700.0);
    (void)topo;
  } catch (const rbdem::SceneError&) {
  }
  return 0;
}
