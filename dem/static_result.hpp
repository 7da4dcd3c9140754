// The static elastic solve's options and result, dimension-free (Simulation::solve_static, dem/simulation.hpp;
// the 2D solve is dem/static_solve.cpp).
//
// Before any bond breaks the model is piecewise linear: each bond is a parallel bond plus a linear part that acts
// only in compression. The solve finds the exact equilibrium of the intact bonded blocks under the installed
// boundary components (the platens' closure, a jacket's pressure as a load, fixed groups) and any external load,
// with the linear parts' open / stick / slip states found by an active-set iteration.
#pragma once

#include <atomic>
#include <cstdint>
#include <vector>

namespace rbdem {

struct StaticOptions {
  double platen_displacement = 1e-6;        // m, the imposed closure of the top platen
  bool linear_parts_always_closed = false;  // every linear part closed and sticking (no active-set iteration)
  int max_iterations = 30;
  double krylov_tolerance = 1e-10;  // relative residual of the BiCGSTAB solves (states with sliding linear parts)
  // External loads: the generalized force on each block (dof(dim) entries per block: in 2D fx, fy, moment; N, N,
  // N m) in the reference configuration (e.g. a confining pressure, Simulation::pressure_load()). Empty = none.
  std::vector<double> load;
  // false: the platens, if installed, are left out (a specimen held only by its loads, e.g. a disc under diametral
  // forces); then `anchors` name blocks whose dofs get a weak spring against the rigid-body modes (the loads must
  // have no resultant).
  bool platens = true;
  std::vector<int> anchors;
  // Threads for BiCGSTAB's products with the stiffness, read at each solve (null: one). The results do not depend
  // on it.
  const std::atomic<int>* threads = nullptr;
};

struct StaticResult {
  int dim = 2;
  double platen_displacement = 0;          // m, imposed closure of the top platen
  double top_force = 0, bottom_force = 0;  // N, compression positive
  double apparent_modulus = 0;             // Pa: (F / loaded area) / (displacement / H)
  std::vector<double> u;                   // per block, dof(dim) entries: in 2D u_x, u_y (m), theta (rad)
  std::vector<double> fn_b, fs_b, m_b;     // per bond: parallel bond force and moment (compression positive)
  std::vector<double> fs_lin;              // per bond: linear part shear force (stick: elastic; slip: -+ mu F_n)
  std::vector<double> fn_lin;              // per bond: linear part normal force (compression positive; 0 open)
  std::vector<double> platen_fs;           // per block: platen shear force (sticking platens; 0 if frictionless)
  enum LinearState : std::uint8_t { open = 0, stick = 1, slip_positive = 2, slip_negative = 3 };
  std::vector<std::uint8_t> linear_state;  // per bond
  std::size_t open_bonds = 0, sliding_bonds = 0;
  // Linear parts held in their state after changing it twice (an active-set cycle near the open/closed boundary),
  // summed over the iterations in which they would have changed again.
  std::size_t held_bonds = 0;
  int active_set_iterations = 0;
  int krylov_iterations = 0;  // BiCGSTAB iterations over all active-set iterations
  int direct_fallbacks = 0;   // solves that fell back to sparse LU (BiCGSTAB did not converge)
  std::size_t dofs = 0;
  double seconds = 0;
  // Load factor at which the first bond reaches its strength (1 = this displacement), and that bond.
  double first_break_factor = 0;
  int first_break_bond = -1;

  bool empty() const { return u.empty(); }
  std::size_t dof() const { return dim == 2 ? 3 : 6; }
  // Degree of freedom k of every block (in 2D: 0 u_x, 1 u_y, 2 theta).
  std::vector<double> component(std::size_t k) const {
    std::vector<double> out(u.size() / dof());
    for (std::size_t b = 0; b < out.size(); ++b) out[b] = u[dof() * b + k];
    return out;
  }
};

// a x fa + b x fb, field by field (displacements, bond forces, linear-part and platen shear, platen forces and
// displacement): two solutions of the same linear problem superpose when their linear-part states agree.
StaticResult superpose(const StaticResult& a, double fa, const StaticResult& b, double fb);

}  // namespace rbdem
