// The order of a mesh's elements, which is the order of the DEM's blocks and, through them, of its bonds
// (dem/topology.hpp walks the elements in order). gmsh numbers elements in the order its mesher made them, which
// scatters neighbours across the arrays; the engine splits blocks and bonds into contiguous ranges, one per thread,
// so a scattered order puts many bonds across two threads' ranges and fetches most neighbours from far away in
// memory. Sorting the elements along a Hilbert curve through their centroids keeps neighbours near in the arrays
// (mesh.block_order = "hilbert"; docs/performance.md, "The order of the blocks").
#pragma once

#include <array>
#include <cstdint>
#include <string_view>
#include <vector>

#include "mesh/tetmesh.hpp"
#include "mesh/trimesh.hpp"

namespace rbdem {

// The position of the cell (x, y) (or (x, y, z)) of a 2^bits grid along the Hilbert curve that fills it: 0 at the
// origin's cell, consecutive positions are cells that share a side. bits in 1 .. 21, coordinates below 2^bits.
std::uint64_t hilbert_index(std::array<std::uint32_t, 2> cell, int bits);
std::uint64_t hilbert_index(std::array<std::uint32_t, 3> cell, int bits);

// The elements in the order of their centroids along a Hilbert curve through the mesh's bounding cube (2^21 cells
// a side); elements in one cell keep their order. order[k] = the old index of the k-th element.
std::vector<int> hilbert_order(const TriMesh& mesh);
std::vector<int> hilbert_order(const TetMesh& mesh);

// The mesh with its elements in `order` (a permutation: order[k] = the old index of the new element k), their layers
// with them; nodes, interfaces and layer names unchanged, boundary faces pointing at the new indices.
void reorder_elements(TriMesh& mesh, const std::vector<int>& order);
void reorder_elements(TetMesh& mesh, const std::vector<int>& order);

// The block orders mesh.block_order names: "mesh" (as meshed or read: leaves the mesh as it is) and "hilbert".
inline constexpr std::array<std::string_view, 2> block_orders{"mesh", "hilbert"};
// Applies the named order. std::invalid_argument for a name not in block_orders.
void apply_block_order(TriMesh& mesh, std::string_view order);
void apply_block_order(TetMesh& mesh, std::string_view order);

}  // namespace rbdem
