// The static elastic start of a 3D failure run: the exact equilibrium of the intact face-bond network under the
// installed platens and loads, the load factor of the first bond failure along it, the model set to a point on
// it, and the exact stability limit of the explicit scheme. The 3D counterpart of dem/static_solve.hpp, on the
// 12 x 12 face-bond stiffness of dem/static3.hpp.
//
// Degrees of freedom: 6 per block, (u_x, u_y, u_z, phi_x, phi_y, phi_z) with phi a small rotation (world axes).
// The linear parts: each is closed (its k_n A and k_s A beside the parallel bond's) or open (no stiffness), found
// by an active-set iteration on the sign of the opening at the face's centroid; a closed one sticks (the linear
// part of an intact bond does not slide unless its material says slip_when_bonded, which the 3D start treats as
// sticking too). Frictionless platens leave three rigid modes, removed by holding u_x and u_y of one bottom block
// and u_y of the bottom block farthest from it in x (rigid constraints only, no stress); sticking platens hold the
// faces on them in shear.
#pragma once

#include "dem/engine3.hpp"
#include "dem/static3.hpp"
#include "dem/static_result.hpp"

namespace rbdem {

// The system is factorised once per stiffness by `solver` (dem/static3.hpp; automatic: CHOLMOD where the build has
// it); an active-set iteration changes the values, not the pattern, and redoes only the numeric factorisation.
StaticResult solve_static(const Engine<3>& engine, const StaticOptions& options,
                          Static3Solver solver = Static3Solver::automatic);

// The smallest lambda >= 0 at which some intact bond reaches its strength under base + lambda x increment (an
// empty base: the unloaded specimen) by FaceBond's failure test on the parallel bond's forces, and that bond; +inf
// when none does. From rest the loads are homogeneous in lambda and solved exactly; from a base (a confined start)
// the margins are convex on either side of the normal stress's cap and their first root is bracketed and bisected.
double first_break_along(const Engine<3>& engine, const StaticResult& base, const StaticResult& increment,
                         int* bond);

// Puts the model into base + lambda x st (an empty base: the unloaded specimen): the blocks displaced and turned,
// moving with the velocity field of the increment whose top platen closes at `velocity`, the linear parts' shear
// histories and the platens' position set, the clock at the time the platen needs for lambda x st.
void apply_static(Engine<3>& engine, const StaticResult& base, const StaticResult& st, double lambda,
                  double velocity);

// 2 / sqrt(lambda_max(M^-1 K)) of the intact model with every linear part closed and the installed platens (power
// iteration, serial: the same to the last bit at any thread count).
double stability_limit(const Engine<3>& engine, int iterations);

}  // namespace rbdem
