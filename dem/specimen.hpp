// The specimen as the code above the engine reads it: dimension-free tables of its mesh, blocks and bonds, made
// once from the engine's topology (Simulation::specimen()). The summary, the failure classification, the signals
// and the writers (summary.json, result.h5, the Python records) read these tables, never the engine's own types,
// so they serve a model of any dimension. Vectors of `dim` components per item are stored item by item
// (centroid[dim * b + k]).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "dem/records.hpp"

namespace rbdem {

struct Specimen {
  int dim = 2;
  std::array<double, 3> lo{}, hi{};  // m, the bounding box (the first dim components)
  double thickness = 1.0;            // m, the slice's out-of-plane thickness (2D; 1 in 3D)

  // The mesh: node coordinates (dim per node), one cell per block (block_vertices(dim) node indices each), the
  // layer names (physical groups) by layer id and the interface names.
  std::vector<double> nodes;
  std::vector<int> cells;
  std::vector<std::string> layer_names, interface_names;

  struct Blocks {
    std::vector<double> centroid;  // m, dim per block (reference configuration)
    std::vector<double> measure;   // m^2 (2D, in the plane) or m^3: area or volume
    std::vector<double> mass;      // kg, as meshed (before mass scaling)
    std::vector<int> layer;
    std::vector<double> shape;     // m, block_vertices(dim) vertices relative to the centroid, dim each
    std::size_t size() const { return layer.size(); }
  } blocks;

  struct Bonds {
    std::vector<int> i, j;                 // blocks, i < j
    std::vector<int> nodes;                // mesh nodes of the shared face, face vertices (dim) per bond
    std::vector<BondKind> kind;
    std::vector<int> interface;            // index into interface_names, -1 for none
    std::vector<std::uint8_t> material;    // material id (dem/materials.hpp)
    std::vector<double> size;              // m (2D: edge length) or m^2 (face area)
    std::vector<double> midpoint, normal;  // m and -, dim per bond; the normal from i to j
    std::size_t size_of() const { return i.size(); }
  } bonds;

  std::size_t num_blocks() const { return blocks.size(); }
  std::size_t num_bonds() const { return bonds.size_of(); }
  double width() const { return hi[0] - lo[0]; }
  double height() const { return hi[std::size_t(dim - 1)] - lo[std::size_t(dim - 1)]; }
  double centre(int k) const { return 0.5 * (lo[std::size_t(k)] + hi[std::size_t(k)]); }
  std::size_t count(BondKind k) const;
  // Component k of block b's centroid, of bond b's midpoint and normal.
  double centroid(std::size_t b, int k) const { return blocks.centroid[std::size_t(dim) * b + std::size_t(k)]; }
  double midpoint(std::size_t b, int k) const { return bonds.midpoint[std::size_t(dim) * b + std::size_t(k)]; }
  double normal(std::size_t b, int k) const { return bonds.normal[std::size_t(dim) * b + std::size_t(k)]; }
};

}  // namespace rbdem
