// The model's state as dimension-free tables: what scripts (the Python module's sim.blocks, sim.bonds,
// sim.contacts), measurements (dem/measure.hpp) and writers read. Each table is a copy made on request
// (Simulation::block_states() and its siblings), so reading it never disturbs a run. Vectors of `dim` components
// per item are stored item by item (position[dim * b + k]); rotations and moments have rotation_dof(dim)
// components (1 in 2D, 3 in 3D).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace rbdem {

// Rotational degrees of freedom per block in `dim` dimensions: 1 in 2D (about z), 3 in 3D.
constexpr int rotation_dof(int dim) { return dim == 2 ? 1 : 3; }

struct BlockStates {
  int dim = 2;
  std::vector<double> position;          // m, dim per block: the centroid now
  std::vector<double> rotation;          // rad, rotation_dof per block: from the reference configuration (2D: theta)
  std::vector<double> velocity;          // m/s, dim per block
  std::vector<double> angular_velocity;  // rad/s, rotation_dof per block
  std::vector<double> force;             // N, dim per block: the resultant of the last step, before damping
  std::vector<double> moment;            // N m, rotation_dof per block: likewise
  std::size_t size() const { return velocity.size() / std::size_t(dim); }
};

struct BondStates {
  int dim = 2;
  std::vector<std::uint8_t> intact;  // 0 once broken (its row is then zero)
  std::vector<double> point;         // m, dim per bond: where its force acts now (the face's centre, moved)
  std::vector<double> normal;        // -, dim per bond: the face normal now, from block i to block j
  std::vector<double> force;         // N, dim per bond: the force on block j (block i takes its opposite)
  std::vector<double> moment;        // N m, rotation_dof per bond: the couple on block j about the bond point
                                     // (the moment on j about its centroid is (point - x_j) x force + moment)
  std::vector<double> normal_force;  // N, along the normal, tension positive: parallel bond and linear part
  std::vector<double> shear_force;   // N, along the tangent (2D: the normal turned 90 deg anticlockwise)
  std::vector<double> failure_index;  // -: the law's max(sigma / sigma_c, tau / tau_limit); 1 at the strength
  std::vector<double> damage;        // -: 1 - the fraction of the parallel bond's stiffness left (0 intact)
  std::size_t size() const { return intact.size(); }
};

// The pairs of blocks in contact now (touching, not bonded).
struct ContactStates {
  int dim = 2;
  std::vector<int> i, j;             // the blocks, i < j
  std::vector<double> point;         // m, dim per contact: where the force acts
  std::vector<double> normal;        // -, dim per contact, from block i to block j
  std::vector<double> force;         // N, dim per contact: the force on block j (block i takes its opposite)
  std::vector<double> normal_force;  // N, compression positive
  std::vector<double> shear_force;   // N, signed along the tangent (2D: the normal turned 90 deg anticlockwise)
  std::size_t size() const { return i.size(); }
};

// The forces the boundary components put on the blocks now, each at its point: one row per block touching a platen
// (the contact force at the overlap's centroid), per loaded jacket face (the pressure's force at the face's
// midpoint) and per block of a group (its force, or for a fixed or driven group the reaction that holds the block,
// at the centroid, with the moment as a couple). With the bond and contact rows they are every force on a block.
// The whole specimen's Love-Weber stress needs them (dem/measure.hpp): without the loads on its outside, an average
// over every block would miss the stress they carry in.
struct BoundaryLoads {
  int dim = 2;
  std::vector<int> block;      // the block loaded
  std::vector<int> component;  // which component: its index in Simulation::boundaries()
  std::vector<double> point;   // m, dim per load: where the force acts
  std::vector<double> force;   // N, dim per load: the force on the block
  std::vector<double> moment;  // N m, rotation_dof per load: a couple on the block besides (about the point)
  std::size_t size() const { return block.size(); }
};

}  // namespace rbdem
