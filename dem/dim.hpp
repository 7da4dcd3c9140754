// What differs between a two-dimensional and a three-dimensional model, named once per dimension. The engine's
// types (Topology, Model, ModelState, Engine, the boundary components, SimulationImpl) are templates on `dim` in
// deal.II's style and Dim<dim> is where their sizes and names come from; the code above the Simulation interface
// (dem/simulation.hpp) reads the dimension at run time through the functions below.
//
// Dimension 2 is the paper's slice: triangular blocks with three degrees of freedom (u_x, u_y, theta), bonds on
// shared edges. A three-dimensional model adds Dim<3> (tetrahedra, six degrees of freedom, a rotation stored as a
// unit quaternion, bonds on shared triangular faces) and the specialisations of the engine's types.
#pragma once

#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

namespace rbdem {

template <int dim>
struct Dim;

template <>
struct Dim<2> {
  static constexpr int dof = 3;             // per block: u_x, u_y, theta
  static constexpr int pose = 3;            // per block: x, y (m), theta (rad)
  static constexpr int block_vertices = 3;  // a block is a triangle
  static constexpr int face_vertices = 2;   // a bond's face is an edge
  static constexpr std::array<const char*, 3> pose_names = {"x", "y", "theta"};
  static constexpr std::array<const char*, 3> pose_units = {"m", "m", "rad"};
  static constexpr const char* cell_type = "Triangle";  // XDMF topology of the blocks
  // The world position of the body-frame vector v (dim components) of a block at `pose` (one block's pose
  // components in order): p + R(theta) v.
  static void place(const double* pose, const double* v, double* out) {
    const double c = std::cos(pose[2]), s = std::sin(pose[2]);
    out[0] = pose[0] + c * v[0] - s * v[1];
    out[1] = pose[1] + s * v[0] + c * v[1];
  }
};

// The same at run time, for code above the Simulation interface.
inline void check_dimension(int dim) {
  if (dim != 2)
    throw std::invalid_argument("dimension " + std::to_string(dim) + ": this build models dimension 2");
}
inline int pose_size(int dim) { return check_dimension(dim), Dim<2>::pose; }
inline int dof_per_block(int dim) { return check_dimension(dim), Dim<2>::dof; }
inline int block_vertices(int dim) { return check_dimension(dim), Dim<2>::block_vertices; }
inline const char* pose_name(int dim, int component) { return check_dimension(dim), Dim<2>::pose_names[std::size_t(component)]; }
inline const char* pose_unit(int dim, int component) { return check_dimension(dim), Dim<2>::pose_units[std::size_t(component)]; }
inline const char* cell_type(int dim) { return check_dimension(dim), Dim<2>::cell_type; }
inline void place(int dim, const double* pose, const double* v, double* out) {
  check_dimension(dim);
  Dim<2>::place(pose, v, out);
}

}  // namespace rbdem
