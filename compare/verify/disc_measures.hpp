// The Brazilian disc below failure as plain measurements, shared by `rbdem verify` (compare/verify/cases_disc.cpp,
// which adds the tolerances and their sources) and the unit tests (tests/test_measure_fe.cpp).
//
// The DEM disc is measured twice, like for like and as it runs. Before any bond breaks a bond's linear part acts
// in compression only, so the DEM as it runs is a bimodular body (a bonded edge about twice as stiff in
// compression as in tension); the FE disc and the closed forms are linear elastic. With every linear part held
// closed (StaticOptions::linear_parts_always_closed) the DEM is the linear model they describe, and its five
// elastic constants, measured by the same static virtual tests with the linear parts held closed, are the ones the
// FE disc and the closed form use. The DEM as it runs is measured beside it, with its count of open linear parts.
#pragma once

#include <cstddef>
#include <vector>

#include "dem/measure.hpp"
#include "dem/scene.hpp"
#include "mesh/trimesh.hpp"
#include "theory/elasticity.hpp"

namespace rbdem::verify {

// The paper scene as a full disc (point loads need the nodes at the top and bottom, no flattened ends) with the
// given joints and mesh size.
Scene disc_scene(const Scene& base, bool joints, double dip_deg);

// The diametral load P (N) giving the isotropic centre tension 2 P / (pi D t) = 1 MPa.
double unit_disc_load(const Scene& s);

// The DEM disc under +-P at its top and bottom nodes (P > 0 pushes, P < 0 pulls), the block nearest the centre
// anchored against the rigid modes (the load has no resultant), solved statically: the Love-Weber mean stress
// over the blocks whose centroid lies within radius_fraction R of the centre (dem/measure.hpp): with the linear
// parts held closed, from the solution's own forces (static_stress: a closed linear part in tension pulls); as it
// runs, from the engine put into the solved state (average_stress: the laws as the failure runs evaluate them).
struct DemDisc {
  StressTensor mean;
  double cx = 0, cy = 0, R = 0;  // m, the disc read from the blocks
  std::size_t blocks = 0, bonds = 0;
  std::size_t open = 0;  // linear parts open at the solution (0 when held closed)
};
DemDisc dem_disc(const Scene& s, const TriMesh& mesh, double P, double radius_fraction, bool linear_parts_closed);

// One layer angle (between the load and the bedding; dip = 90 - angle) of the layered disc. Stresses are the
// principal tension in Pa for the unit load (unit_disc_load), so they read as Claesson & Bohloli's factor in MPa.
struct DiscAngle {
  double layer_angle_deg = 0, dip_deg = 0;
  double dem_mean = 0;         // the DEM with every linear part closed: the mean over r <= r_avg
  double dem_as_run_mean = 0;  // the DEM as it runs (linear parts in compression only), pushed
  double dem_pulled_mean = 0;  // the same with the forces reversed (sign flipped back); a linear model: = pushed
  std::size_t open_as_run = 0, open_pulled = 0;  // open linear parts of the two as-run solves
  double fe_mean = 0;      // the FE disc (the linear DEM's constants, the same mesh) over the same circle
  double fe_centre = 0;    // the FE's centre value (its fit through the central cells)
  double closed_form = 0;  // Claesson & Bohloli's centre tension with the same constants
  // The DEM's centre value: its mean times the FE's ratio of centre to mean (the curvature of the field over the
  // averaging circle, about 4 % at r_avg = R / 5).
  double dem_centre() const { return dem_mean * fe_centre / fe_mean; }
  double dem_as_run_centre() const { return dem_as_run_mean * fe_centre / fe_mean; }
};

struct LayeredDisc {
  theory::TIConstants constants;  // the linear DEM's, from static virtual tests at dips 0, 45, 90
  double fit_residual = 0;
  std::vector<DiscAngle> angles;
  double mesh_size = 0;                            // m, the scene's mesh.size
  std::size_t blocks = 0, bonds = 0, fe_dofs = 0;  // of the last angle's disc
  double fe_seconds = 0;                           // the FE discs' wall time, all angles
};

// The layered disc of `base` (its joints, mesh size, rock) at the given layer angles, averaged over r <= fraction R.
// Needs the deal.II build (RBDEM_HAVE_CONTINUUM); elsewhere it throws std::runtime_error.
LayeredDisc layered_disc(const Scene& base, const std::vector<double>& layer_angles_deg, double radius_fraction);

// The worst deviation of the linear DEM over the angles: max of |DEM mean / FE mean - 1|,
// |FE centre / closed form - 1| and |DEM centre / closed form - 1|.
double like_for_like_error(const LayeredDisc& d);

}  // namespace rbdem::verify
