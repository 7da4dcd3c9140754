// Measurements on a DEM state that the continuum reads as stress: the average stress tensor of the blocks in a
// circular region (Love-Weber: sigma = (1/A) sum over the region's blocks of sum over their bonds of (x_c - x_b)
// (x) f_c, with f_c the force the bond applies to the block at its point x_c; symmetrised), and the point forces a
// diametral load puts on a disc's blocks. Used to compare the DEM with the FE twin and with closed forms at a point
// (the centre of a Brazilian disc, docs/theory.md, section 9).
#pragma once

#include <vector>

#include "dem/engine.hpp"

namespace rbdem {

struct StressTensor {
  double xx = 0, yy = 0, xy = 0;  // Pa, tension positive
  double area = 0;                // m^2, of the blocks averaged over
  int blocks = 0;
};

// The average stress of the blocks whose centroids lie within `radius` of (cx, cy), from the bonds' forces in the
// engine's current state (intact bonds; contacts are not counted).
StressTensor average_stress(const Engine<2>& engine, double cx, double cy, double radius);

// The generalized load (3 entries per block) of two opposite point forces P (N) along the vertical diameter of a
// disc: -P at its top point and +P at its bottom point (each shared among the blocks that hold that node), for the
// static solve (StaticOptions::load). Throws std::invalid_argument when the mesh has no node at a point.
std::vector<double> diametral_load(const Engine<2>& engine, const TriMesh& mesh, double force);

}  // namespace rbdem
