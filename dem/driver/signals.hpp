// The signals of a compression test read off its curve and crack log (docs/theory.md, section 10; the definitions
// and units in docs/outputs.md): volumetric strain, Poisson's ratio at half the peak, the crack initiation and crack
// damage stresses, the residual strength, each crack's orientation, the crack rate against strain and the fragments
// left at the end. Pure functions of plain data (no engine, no files); summarize() calls them.
//
// Strains are compression positive, as in curve.csv: the axial strain eps_a (platen closure / height) and the lateral
// strain eps_l (width change / width, negative when the specimen widens). In the plane of the model the volumetric
// strain is eps_v = eps_a + eps_l (the out-of-plane strain is zero: plane strain). In 3D eps_l is the cylinder's
// radial strain, the same in both horizontal directions, and eps_v = eps_a + 2 eps_l.
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "dem/driver/record.hpp"
#include "dem/records.hpp"
#include "dem/specimen.hpp"

namespace rbdem {

inline constexpr double undefined_signal = std::numeric_limits<double>::quiet_NaN();

// eps_v = eps_a + eps_l (2D, plane strain) or eps_a + 2 eps_l (3D), compression positive.
inline double volumetric_strain(const CurvePoint& p, int dim = 2) { return p.volumetric_strain(dim); }

// Poisson's ratio at half the peak, tangent: -d eps_l / d eps_a, the least-squares slope of the lateral against the
// axial strain over the pre-peak samples (strain <= strain_at_peak) whose stress lies between 40 and 60 % of the
// peak. With a `floor` (a confined test's sigma_3) the window is on the deviator: floor + [0.4, 0.6] (peak - floor).
// NaN when fewer than two such samples at distinct strains exist or the peak is not above the floor.
double poisson_ratio_at_half_peak(const std::vector<CurvePoint>& curve, double peak, double strain_at_peak,
                                  double floor = 0.0);

// The stress window of poisson_ratio_at_half_peak, as fractions of the peak.
inline constexpr double poisson_window_low = 0.4, poisson_window_high = 0.6;

// Crack initiation stress: the onset of sustained cracking. The pre-peak stress range [0, peak] is cut into bins of
// `resolution` x peak (default 2 %); each crack that broke before the peak counts in the bin of the highest stress
// the curve had reached when it broke (the loading level: the stress is interpolated on the curve at the crack's
// strain and the running maximum taken, so the short stress drops of a crack event do not move it). Sustained
// cracking begins with the first bin of the uninterrupted run of non-empty bins that ends at the highest non-empty
// bin (the peak's bin, unless the last 2 % before the peak broke nothing); sigma_ci is the loading level of the
// first crack in that bin. NaN when no crack broke before the peak. Throws std::invalid_argument for a resolution
// outside (0, 1).
double crack_initiation_stress(const std::vector<CurvePoint>& curve, const std::vector<Crack>& cracks, double peak,
                               double strain_at_peak, double resolution = 0.02);

// Crack damage stress: the stress at the reversal of the volumetric strain, i.e. at the largest eps_v on the
// pre-peak branch (samples with strain <= strain_at_peak), eps_v of the dimension `dim`. NaN when eps_v is largest at
// the last pre-peak sample (no reversal before the peak) or the curve has fewer than three pre-peak samples.
double crack_damage_stress(const std::vector<CurvePoint>& curve, double strain_at_peak, int dim = 2);

// Residual strength: the mean stress of the samples in the last `tail` (default a fifth) of the post-peak strain
// range (strain_at_peak, last strain]. Defined only for a run that continued past the peak until a strain limit
// (stop_reason "post_peak_strain" or "max_strain") and whose post-peak range is at least `min_span` x strain_at_peak
// (default 0.2); NaN otherwise (a run stopped by the stress drop, loading.stop_fraction, ended before any residual
// plateau). Throws std::invalid_argument for a tail outside (0, 1].
double residual_stress(const std::vector<CurvePoint>& curve, double strain_at_peak, const std::string& stop_reason,
                       double tail = 0.2, double min_span = 0.2);


// The orientation of every crack of the log, from its bond's reference normal (Crack::normal).
std::vector<double> crack_orientations_deg(const std::vector<Crack>& cracks);

// The crack rose of a 3D run: the cracks counted by the dip of their face (bins of dip_bin deg over [0, 90], the
// last one closed) and, within each dip bin, by dip direction (bins of dip_direction_bin deg over [0, 360)), with
// the orientation of records.hpp (plane_orientation_deg). A vertical crack's dip direction is folded into [0, 180)
// and a horizontal one's is 0, so in the first dip bin the dip direction says little. Also the broken face area
// per dip bin. An angle within rose_edge_tolerance_deg below a bin's edge counts in the bin above (the faces of a
// joint plane at 60 deg read 60 +- round-off). Throws std::invalid_argument for a bin that does not divide 90 (dip)
// or 360 (dip direction).
inline constexpr double rose_edge_tolerance_deg = 1e-6;
struct CrackRose {
  double dip_bin_deg = 10, dip_direction_bin_deg = 30;
  std::vector<int> by_dip;                 // cracks per dip bin
  std::vector<double> area_by_dip;         // m^2 of broken faces per dip bin
  std::vector<std::vector<int>> counts;    // [dip bin][dip direction bin]
  int total() const;
};
CrackRose crack_rose3(const std::vector<Crack>& cracks, double dip_bin_deg = 10, double dip_direction_bin_deg = 30);

// Cracks per unit axial strain, in `bins` equal strain bins over [0, strain_end]: the acoustic-emission-like rate
// of docs/outputs.md (crack_rate.csv). A crack at strain_end counts in the last bin; none for strain_end <= 0.
// Throws std::invalid_argument for bins < 1.
struct CrackRateBin {
  double strain_low = 0, strain_high = 0;
  int cracks = 0;
  double rate = 0;  // cracks / (strain_high - strain_low)
};
std::vector<CrackRateBin> crack_rate(const std::vector<Crack>& cracks, double strain_end, int bins = 50);

// A fragment: a connected set of blocks joined by intact bonds (union-find over the bonds not in the crack log).
struct Fragment {
  int blocks = 0;
  double measure = 0;            // m^2 (2D: the area in the plane) or m^3 (3D: the volume)
  double cx = 0, cy = 0, cz = 0; // measure-weighted reference centroid, m (cz: 3D only)
};
// The fragments at the end of a run, largest area (3D: volume) first (ties: by lowest block index). Uses the
// specimen's block centroids and measures and its bonds' blocks; a bond is broken when it is the `bond` of an entry of `cracks`. Throws
// std::invalid_argument for a crack or bond that names a block or bond outside the specimen.
std::vector<Fragment> fragments(const Specimen& specimen, const std::vector<Crack>& cracks);

}  // namespace rbdem
