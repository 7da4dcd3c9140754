// The linear contact law: the infinitesimal, no-tension, frictional interface of the linear parallel bond model
// (docs/theory.md, section 7). One law for three users: the linear part of an intact bond (overlap from the
// bond's own kinematics, edge_overlap below), every contact between blocks after a bond broke or between blocks
// that were never neighbours (overlap from polygon clipping, dem/contact_geometry.hpp), and the platens (overlap
// of a block with a half-plane). Small value type, no I/O, history (the shear force) passed in and out.
//
// Normal force: the gradient of Feng, Han and Owen's potential w(A_o) = k_n t A_o^2 / (2 L_ref),
//     F_n = k_n t A_o l_c / L_ref = K A_o l_c / L_ref^2         (N; K = k_n t L_ref, the stiffness of a closed edge)
// with A_o the overlap area per unit thickness (m^2), l_c the contact chord (m), k_n = E*/d (Pa/m). For a whole
// edge in contact l_c = L_ref = L and F_n = k_n L t delta: the linear part of a bond at that edge. Where an edge is
// only partly closed, or a vertex touches a face, the l_c / L_ref factor keeps the force conservative; the plain
// k_n t A_o at the chord midpoint is not, and its non-symmetric tangent made the explicit scheme diverge at 0.6 x
// the linear stability limit (docs/model.md).
// Shear: incremental, dF_s = -k_s t l_c ds = -K_s (l_c / L_ref) ds (K_s = k_s t L_ref), Coulomb limit |F_s| <= mu F_n;
// no shear force without a normal force. mu = +inf never slides (the linear part of a bond whose kind has
// slip_when_bonded = false).
// Dilation (tan_dilation = tan(i) > 0; Patton's sawtooth asperities of angle i): while the contact slides, its
// asperities ride up and hold its faces further apart, by |slip| tan(i). The law gives that opening per step
// (update_shear); the contact keeps the sum as history and its overlap is measured with the faces moved back
// together by it (dem/stages/contacts.cpp, pair_overlap): over a whole edge F_n = K (delta + opening), so a
// constant normal load lifts the faces apart by the opening. The Coulomb coefficient stays mu (the residual stays
// mu F_n); the stiffnesses are unchanged. tan_dilation = 0 is the flat law, bit for bit.
#pragma once

#include <cmath>
#include <cstdint>

namespace rbdem {

// Overlap of the linear part of an intact bond from its kinematics: the edge of length L, centre opening
// delta_n (m, positive when opening) and relative rotation dtheta (rad). Along the edge s in [-L/2, L/2] the
// overlap is u(s) = -delta_n + s dtheta; `area` is the integral of max(u, 0) (m^2), `chord` the compressed
// interval (m), `s_c` the chord's midpoint (m, the contact point, as in the clipped contact).
struct EdgeOverlap {
  double area = 0, chord = 0, s_c = 0;
};
// Written without branches (every case is computed and one is selected) so that the bond kernel vectorises.
inline EdgeOverlap edge_overlap(double L, double delta_n, double dtheta) {
  const double h = 0.5 * L;
  const double u0 = -delta_n - h * dtheta, u1 = -delta_n + h * dtheta;  // overlap at s = -L/2 and s = +L/2
  const bool closed = (u0 >= 0.0) & (u1 >= 0.0), open = (u0 <= 0.0) & (u1 <= 0.0);  // & not &&: no branch
  // Partly compressed: the overlap is a triangle from the zero crossing s0 to the compressed end (dtheta is not 0
  // there; elsewhere s0 is not used).
  const double s0 = delta_n / dtheta;  // u(s0) = 0
  const bool upper = u1 > 0.0;         // the end s = +L/2 is the compressed one
  const double chord = upper ? h - s0 : s0 + h;
  const double area = 0.5 * (upper ? u1 : u0) * chord;
  const double s_c = upper ? 0.5 * (s0 + h) : 0.5 * (s0 - h);
  EdgeOverlap e;
  e.area = closed ? -delta_n * L : (open ? 0.0 : area);
  e.chord = closed ? L : (open ? 0.0 : chord);
  e.s_c = (closed | open) ? 0.0 : s_c;
  return e;
}

// The law of one contact: the stiffnesses of a closed edge of length L_ref, K = k_n t L_ref and K_s = k_s t L_ref (N/m),
// the Coulomb coefficient, and 1 / L_ref. An intact bond's linear part uses the bond's own K (its kA) and L.
struct LinearContact {
  double K = 0;         // N/m, normal stiffness of a closed edge of length L_ref (k_n t L_ref)
  double Ks = 0;        // N/m, shear stiffness of that edge (k_s t L_ref)
  double mu = 0;        // Coulomb coefficient (+inf: never slides)
  double inv_lref = 1;  // 1/m, 1 / L_ref
  double tan_dilation = 0;  // tan(i), the dilation angle (0: a flat interface)

  // From stiffnesses per unit area k_n, k_s (Pa/m), the thickness t and the reference chord L_ref (m).
  static LinearContact per_area(double kn, double ks, double mu, double lref, double t) {
    return {kn * t * lref, ks * t * lref, mu, 1.0 / lref};
  }

  // Normal force (N, compression positive) for an overlap area per unit thickness `area` (m^2) over the chord (m).
  double normal_force(double area, double chord) const { return K * area * chord * inv_lref * inv_lref; }

  // Updates the shear force `fs` (N, along the tangent) for the tangential relative velocity vt (m/s) at the
  // contact point over dt (s), under normal force `fn`. Returns true when the contact slides.
  bool update_shear(double fn, double chord, double vt, double dt, double& fs) const {
    const double trial = trial_shear(chord, vt, dt, fs);
    fs = shear_force(fn, trial);
    return (fn > 0.0) & (std::abs(trial) > mu * fn);
  }
  // The same for a contact that dilates: a step that slides adds its slip times tan(i) to `opening` (m). The slip is
  // the part of the step's tangential displacement the Coulomb limit did not let the spring take,
  // |trial - F_s| / (K_s l_c / L_ref).
  bool update_shear(double fn, double chord, double vt, double dt, double& fs, double& opening) const {
    const double trial = trial_shear(chord, vt, dt, fs);
    fs = shear_force(fn, trial);
    const bool slides = (fn > 0.0) & (std::abs(trial) > mu * fn);
    if (slides && tan_dilation > 0.0) opening += std::abs(trial - fs) / (Ks * chord * inv_lref) * tan_dilation;
    return slides;
  }
  // The same without branches (the bond kernel vectorises it): the elastic trial from the old shear force, then
  // the new shear force (Coulomb-limited, zero without a normal force).
  double trial_shear(double chord, double vt, double dt, double fs) const {
    return fs - Ks * (chord * inv_lref) * vt * dt;
  }
  double shear_force(double fn, double trial) const {
    const double limit = mu * fn;
    const double clamped = std::abs(trial) > limit ? std::copysign(limit, trial) : trial;
    return fn > 0.0 ? clamped : 0.0;
  }

  // Elastic energy (J) stored at normal force fn and shear force fs over the chord: the potential
  // w = k_n t A_o^2 / (2 L_ref) = F_n^2 / (2 K (l_c / L_ref)^2) and F_s^2 / (2 K_s l_c / L_ref).
  double strain_energy(double fn, double fs, double chord) const {
    if (!(fn > 0.0) || !(chord > 0.0)) return 0.0;
    const double c = chord * inv_lref;
    return 0.5 * (fn * fn / (K * c * c) + fs * fs / (Ks * c));
  }
};

}  // namespace rbdem
