// The mesh cache: a generated specimen mesh (triangles in 2D, tetrahedra in 3D), kept on disk by its scene, so that a run of a scene meshed before
// skips gmsh (docs/performance.md, "The mesh cache").
//
// The key is every scene value the mesh can depend on (the [specimen], [joint_set], [joint_set2] and [mesh]
// sections but mesh.strength_seed, which draws strengths, not the mesh), the build's version and commit, and gmsh's
// API version. A cached mesh is the very object gmsh gave (every coordinate to the bit), so a run from it is the
// run that meshes anew. Only builds of a committed tree use the cache: a build with changes the version does not
// name ("-dirty", or outside git) always meshes. User meshes (mesh.file) are read as before.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "dem/scene.hpp"
#include "mesh/tetmesh.hpp"
#include "mesh/trimesh.hpp"

namespace rbdem {

// The folder of rbdem's caches (this one and the elastic gate's): RBDEM_CACHE_DIR, else $XDG_CACHE_HOME/rbdem,
// else ~/.cache/rbdem ("" without any).
std::filesystem::path cache_dir();
// The 64-bit FNV-1a hash the caches name their files by (and check their contents with).
std::uint64_t fnv1a(std::string_view s);

// make_mesh(scene), through the cache when it applies (see above). RBDEM_MESH_CACHE = off turns the cache off;
// on turns it on for any build.
// `from_cache`, when given, tells whether the mesh came from the cache.
TriMesh make_mesh_cached(const Scene& scene, bool* from_cache = nullptr);
// The same for a 3D scene (specimen.dimension = 3): mesh_scene3(scene) through the cache, every seed of a 3D
// study's realizations a file of its own (mesh.seed is in the key).
TetMesh make_mesh3_cached(const Scene& scene, bool* from_cache = nullptr);

// The text the cache key hashes, and the file a scene's mesh is kept in ("" when the cache does not apply).
std::string mesh_cache_key_text(const Scene& scene);
std::filesystem::path mesh_cache_file(const Scene& scene);

}  // namespace rbdem
