// The stress inside a DEM specimen, as the continuum reads it: the Love-Weber average stress tensor of a set of
// blocks (docs/theory.md, section 10.6), of the whole specimen, of a region (a box, a circle,
// layers, a list of blocks) and of each block; and the point forces a diametral load puts on a disc's blocks.
//
// Love-Weber: a block b of measure V_b (2D: its area times the thickness) carries the average stress
//   sigma_b = 1/V_b sum over the forces f_c on b of sym((x_c - x_b) (x) f_c)
// with x_b its centroid now, x_c the point where f_c acts now and sym(A) = (A + A^T) / 2. The forces are every force
// the engine sums into the block: its bonds' (parallel bond and linear part), its contacts' and the boundary
// components' (platens, jacket, groups: Simulation::boundary_loads()). A region's stress is the volume-weighted mean
// over its blocks, sigma = 1/V sum_b V_b sigma_b with V = sum_b V_b. Sign: tension positive, as the FE twin
// (continuum/): a specimen between platens at the platen stress p (compression positive, Platens::stress()) has
// sigma_yy = -p. The couples of the bonds and of a group's moment balance the antisymmetric part of the sum and do not
// enter sigma.
//
// Summed over the whole specimen, sum_b sum_c (x_c - x_b) (x) f_c = sum over the boundary loads of x_c (x) f_c
// - sum_b x_b (x) F_b (a force between two blocks acts at one point on both, with opposite signs; F_b is block b's
// resultant): in static equilibrium the whole specimen's stress is the boundary loads' moment alone, between
// frictionless platens exactly the platen stress. Regions inside the specimen need only the bonds and the contacts
// (no block of theirs is loaded from outside).
//
// Also here: the force network of the state (the bonds' and contacts' forces between their blocks), which each
// frame of result.h5 stores.
//
// Everything is read from the simulation's tables (dem/state_tables.hpp), so it serves a model of any dimension.
// Bad input (a region of another dimension, an empty region, a block or layer not in the specimen) throws
// std::invalid_argument naming it.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "dem/engine.hpp"
#include "dem/records.hpp"
#include "dem/simulation.hpp"

namespace rbdem {

// A symmetric stress tensor of a dim-dimensional model, stored 3 x 3 (the first dim rows and columns used).
struct StressTensor {
  int dim = 2;
  std::array<double, 9> s{};  // Pa, tension positive: component (a, b) at s[3 a + b]
  double volume = 0;          // m^3 of the blocks averaged over (2D: area x thickness)
  std::size_t blocks = 0;     // blocks averaged over
  double operator()(int a, int b) const { return s[std::size_t(3 * a + b)]; }
  double xx() const { return s[0]; }
  double yy() const { return s[4]; }
  double xy() const { return s[1]; }
};

// Which blocks a measurement averages over, by their centroids now (box, circle) or by what they are (layers,
// blocks).
struct Region {
  enum class Kind { all, box, circle, layers, blocks };
  Kind kind = Kind::all;
  std::vector<double> lo, hi;      // m, box: its corners, dim components each (a centroid on a face is inside)
  std::vector<double> centre;      // m, circle (3D: sphere): dim components
  double radius = 0;               // m, circle: centroids at distance <= radius are inside
  std::vector<int> ids;            // layers: layer ids (Specimen::blocks.layer); blocks: block indices

  static Region whole() { return {}; }
  static Region box(std::vector<double> lo, std::vector<double> hi);
  static Region circle(std::vector<double> centre, double radius);
  static Region layers(std::vector<int> ids);
  static Region blocks(std::vector<int> ids);
  std::string describe() const;  // for messages: "the box [0, 0.01] x [0, 0.02] m", ...
};

// Which forces enter the sums (all by default: the whole specimen needs the boundary loads).
struct StressSources {
  bool bonds = true, contacts = true, boundaries = true;
};

// The blocks of `region` now, ascending. Throws std::invalid_argument for a region that does not fit the specimen
// (wrong dimension, lo > hi, radius <= 0, a layer or block not in it).
std::vector<int> region_blocks(const Simulation& sim, const Region& region);

// The Love-Weber average stress of the region's blocks now. Throws std::invalid_argument as region_blocks, and
// when the region holds no block.
StressTensor average_stress(const Simulation& sim, const Region& region = Region::whole(),
                            const StressSources& sources = {});

// The Love-Weber average stress of a static solution (Simulation::solve_static) over the region's blocks, from the
// solution's own bond forces: the parallel bonds and the linear parts in the states the solve found, in the
// reference configuration. Held closed (StaticOptions::linear_parts_always_closed), a linear part carries tension
// too: this is the stress of the linear model the solve solved. average_stress above evaluates the laws as they
// run on the state the engine holds (Simulation::apply_static), where an open linear part carries nothing; the two
// agree wherever the linear parts' states agree. Bonds only (no contacts, no loads): keep the region clear of the
// loaded blocks. 2D. Throws std::invalid_argument as average_stress, and for a solution of another specimen.
StressTensor static_stress(const Simulation& sim, const StaticResult& state, const Region& region);

// The Love-Weber stress of each block now: dim x dim components per block (row-major, symmetric; Pa, tension
// positive) and its volume.
struct BlockStresses {
  int dim = 2;
  std::vector<double> stress;  // Pa, dim * dim per block: component (a, b) of block k at stress[dim (dim k + a) + b]
  std::vector<double> volume;  // m^3 per block
  std::size_t size() const { return volume.size(); }
};
BlockStresses block_stresses(const Simulation& sim, const StressSources& sources = {});

// The force network now (dem/records.hpp): the intact bonds' forces, then the contacts', each between its two
// blocks (what result.h5 stores with each frame).
ForceNetwork force_network(const Simulation& sim);

// The generalized load (3 entries per block) of two opposite point forces P (N) along the vertical diameter of a
// disc: -P at its top point and +P at its bottom point (each shared among the blocks that hold that node), for the
// static solve (StaticOptions::load). Throws std::invalid_argument when the mesh has no node at a point.
std::vector<double> diametral_load(const Engine<2>& engine, const TriMesh& mesh, double force);

}  // namespace rbdem
