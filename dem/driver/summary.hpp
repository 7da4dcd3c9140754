// From a run's record to its result: the headline numbers, the quasi-static verdict, the crack statistics and the
// failure classification. Pure functions of plain data: the record, the crack log and the specimen's tables
// (dem/specimen.hpp), never the engine or files.
#pragma once

#include <string>
#include <vector>

#include "dem/driver/protocol.hpp"
#include "dem/driver/result.hpp"
#include "dem/scene.hpp"
#include "dem/specimen.hpp"

namespace rbdem {

CrackCounts count_cracks(const std::vector<Crack>& cracks);
// The cracks of each material the specimen has (which joint set slipped, which rock cracked).
std::vector<MaterialCracks> count_cracks_by_material(const std::vector<Crack>& cracks, const Specimen& specimen);

// Failure mode from the crack log, in the seed paper's three classes plus one:
//   a joint broken along at least half its length, mostly in shear, with a large resolved shear stress on it
//   (tau / sigma = sin(2 dip) / 2 > 1/4: 15 < dip < 75 deg) -> "shear_slip_along_joints"
//   a joint broken along at least half its length otherwise -> "splitting_along_layers"
//   no joint broken through: rock cracks, by length, mostly tensile -> splitting, "splitting_along_layers" when the
//   layers are steep (dip >= 60 deg, cracks parallel to them) else "splitting_across_layers";
//   mostly shear -> "shear_through_rock"; and "intact" when nothing broke.
// Joints are grouped by interface (joint set) and layer pair; the second set's joints use dip2_deg. In 3D a joint
// is a plane of joint faces (one interface, one orientation, one distance from the origin) and its size is area:
// the resolved shear on a plane of dip beta under the axial load does not depend on its dip direction, so the
// same dips decide. With rock bridges (`bridges`: a non-persistent set), a joint failure whose broken rock length is
// at least half the broken joint length -> "bridge_fracture" (the failure path runs through the bridges as much as
// along the joints).
std::string classify_failure(const std::vector<Crack>& cracks, const Specimen& specimen, double dip_deg,
                             double dip2_deg = 0.0, bool bridges = false);
// The dip (0..90 deg from the horizontal) of a mesh's joints: the length-weighted axial mean direction of its joint
// edges (3D: the dip of the principal axis of its joint faces' area-weighted normals); `fallback` when it has none. The failure classification of a user mesh uses it.
double joint_dip_deg(const Specimen& specimen, double fallback);
// A warning when a user mesh spans more than 1 m or less than 1 mm (`span`: its larger side, m): coordinates are
// read in metres, so a mesh drawn in millimetres becomes a specimen a thousand times too large. Empty otherwise.
std::string mesh_scale_warning(const std::string& file, double span);
// Whether an enabled joint set of the scene has rock bridges (persistence < 1).
bool non_persistent(const Scene& scene);

// Dip (0..90 deg from the horizontal) of the principal axis of the crack positions, weighted by crack length:
// near 90 for axial splitting, near 45 + phi/2 for a shear band, the joint dip for slip along a joint.
double crack_band_angle_deg(const std::vector<Crack>& cracks);
// 3D: the crack band is a plane, the least-squares plane through the crack positions weighted by face area (its
// normal is the principal axis of least spread); its dip (summary.json's crack_band_angle_deg, as in 2D: near 90
// for axial splitting, the joints' dip for slip along them) and dip direction. NaN for fewer than three cracks.
PlaneOrientation crack_band_plane(const std::vector<Crack>& cracks);

// The quasi-static verdict's limit on the platen forces' difference while loading, over their mean.
inline constexpr double quasi_static_force_mismatch_limit = 0.05;

// The result of a completed run: `result` arrives with the record's curve (the peak sample in it), frames, the
// crack log, the counts and the timing filled in; this adds the peak, E50, the quasi-static checks, the crack
// statistics and the failure mode, and the signals of dem/driver/signals.hpp (Poisson's ratio at half the peak,
// the crack initiation and damage stresses, the residual strength; Poisson's ratio and the crack damage stress are
// left undefined where the protocol's lateral strain is not the specimen's width change under axial load, as in
// the Brazilian test). The protocol's stress floor (a confined test's sigma_3) is where the signals' windows start.
void summarize(const Scene& scene, const Specimen& specimen, const LoadingProtocol& protocol,
               const TestRecord& record, TestResult& result);

// The crack statistics of any run, completed or stopped by the watchdog: each crack's orientation, the crack rate
// against strain (50 bins up to the last sample's strain) and the fragments left by the crack log.
void crack_statistics(const Specimen& specimen, TestResult& result);

}  // namespace rbdem
