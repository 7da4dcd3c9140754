// The signals of a compression test. See signals.hpp.
#include "dem/driver/signals.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <stdexcept>

#include <fmt/format.h>

namespace rbdem {

namespace {

// The mean stress on the curve at axial strain e (linear interpolation between the samples that bracket it; the
// curve is in order of strain). Outside the curve: its first or last stress.
double stress_at_strain(const std::vector<CurvePoint>& curve, double e) {
  if (curve.empty()) return 0.0;
  if (e <= curve.front().strain) return curve.front().stress();
  for (std::size_t k = 1; k < curve.size(); ++k) {
    const CurvePoint &a = curve[k - 1], &b = curve[k];
    if (b.strain >= e) {
      const double span = b.strain - a.strain;
      const double f = span > 0 ? (e - a.strain) / span : 1.0;
      return a.stress() + f * (b.stress() - a.stress());
    }
  }
  return curve.back().stress();
}

}  // namespace

double poisson_ratio_at_half_peak(const std::vector<CurvePoint>& curve, double peak, double strain_at_peak,
                                  double floor) {
  if (!(peak > floor)) return undefined_signal;
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (const auto& p : curve) {
    if (p.strain > strain_at_peak) break;
    const double s = p.stress() - floor;
    if (s < poisson_window_low * (peak - floor) || s > poisson_window_high * (peak - floor)) continue;
    n += 1, sx += p.strain, sy += p.lateral_strain, sxx += p.strain * p.strain, sxy += p.strain * p.lateral_strain;
  }
  const double det = n * sxx - sx * sx;
  // det = n^2 var(strain): zero (to round-off) when fewer than two distinct strains lie in the window.
  if (n < 2 || !(det > 1e-12 * sxx * n)) return undefined_signal;
  return -(n * sxy - sx * sy) / det;
}

double crack_initiation_stress(const std::vector<CurvePoint>& curve, const std::vector<Crack>& cracks, double peak,
                               double strain_at_peak, double resolution) {
  if (!(resolution > 0 && resolution < 1))
    throw std::invalid_argument(fmt::format("crack_initiation_stress: resolution {} is not in (0, 1)", resolution));
  if (!(peak > 0) || curve.empty()) return undefined_signal;
  // The loading level of each pre-peak crack: the running maximum of the stress up to its strain. Cracks are in
  // order of breakage, hence of strain.
  const int nbins = int(std::ceil(1.0 / resolution - 1e-9));
  std::vector<double> first_level(std::size_t(nbins), undefined_signal);
  double level = 0;
  std::size_t k = 0;
  bool any = false;
  for (const auto& c : cracks) {
    if (c.strain > strain_at_peak) break;
    for (; k < curve.size() && curve[k].strain <= c.strain; ++k) level = std::max(level, curve[k].stress());
    const double s = std::max(level, stress_at_strain(curve, c.strain));
    const int b = std::clamp(int(s / (resolution * peak)), 0, nbins - 1);
    if (std::isnan(first_level[std::size_t(b)])) first_level[std::size_t(b)] = s;
    any = true;
  }
  if (!any) return undefined_signal;
  // The uninterrupted run of non-empty bins that ends at the highest non-empty bin (normally the peak's: a
  // crack-free stretch just below the peak does not erase the run).
  int last = nbins - 1;
  while (last > 0 && std::isnan(first_level[std::size_t(last)])) --last;
  int first = last;
  while (first > 0 && !std::isnan(first_level[std::size_t(first - 1)])) --first;
  return first_level[std::size_t(first)];
}

double crack_damage_stress(const std::vector<CurvePoint>& curve, double strain_at_peak, int dim) {
  std::size_t n = 0, best = 0;
  for (std::size_t k = 0; k < curve.size() && curve[k].strain <= strain_at_peak; ++k, ++n)
    if (volumetric_strain(curve[k], dim) > volumetric_strain(curve[best], dim)) best = k;
  if (n < 3 || best + 1 >= n) return undefined_signal;
  return curve[best].stress();
}

double residual_stress(const std::vector<CurvePoint>& curve, double strain_at_peak, const std::string& stop_reason,
                       double tail, double min_span) {
  if (!(tail > 0 && tail <= 1))
    throw std::invalid_argument(fmt::format("residual_stress: tail {} is not in (0, 1]", tail));
  if (stop_reason != "post_peak_strain" && stop_reason != "max_strain") return undefined_signal;
  if (curve.empty()) return undefined_signal;
  const double end = curve.back().strain, span = end - strain_at_peak;
  if (!(span > 0) || span < min_span * strain_at_peak) return undefined_signal;
  const double from = end - tail * span;
  double sum = 0;
  int n = 0;
  for (const auto& p : curve)
    if (p.strain > strain_at_peak && p.strain >= from) sum += p.stress(), ++n;
  return n > 0 ? sum / n : undefined_signal;
}

std::vector<double> crack_orientations_deg(const std::vector<Crack>& cracks) {
  std::vector<double> out;
  out.reserve(cracks.size());
  for (const auto& c : cracks) out.push_back(edge_orientation_deg(c.normal[0], c.normal[1]));
  return out;
}

int CrackRose::total() const {
  int n = 0;
  for (const int c : by_dip) n += c;
  return n;
}

CrackRose crack_rose3(const std::vector<Crack>& cracks, double dip_bin_deg, double dip_direction_bin_deg) {
  auto divides = [](double bin, double range) {
    const double n = range / bin;
    return bin > 0 && std::abs(n - std::round(n)) < 1e-9;
  };
  if (!divides(dip_bin_deg, 90.0) || !divides(dip_direction_bin_deg, 360.0))
    throw std::invalid_argument(fmt::format("crack_rose3: bins of {} deg (dip) and {} deg (dip direction) must "
                                            "divide 90 and 360",
                                            dip_bin_deg, dip_direction_bin_deg));
  CrackRose rose;
  rose.dip_bin_deg = dip_bin_deg, rose.dip_direction_bin_deg = dip_direction_bin_deg;
  const int nd = int(std::lround(90.0 / dip_bin_deg)), na = int(std::lround(360.0 / dip_direction_bin_deg));
  rose.by_dip.assign(std::size_t(nd), 0);
  rose.area_by_dip.assign(std::size_t(nd), 0.0);
  rose.counts.assign(std::size_t(nd), std::vector<int>(std::size_t(na), 0));
  // A mesh face on a joint plane of dip 60 deg reads 60 +- 1e-14: the faces of one plane must share a bin, so an
  // angle within rose_edge_tolerance_deg below an edge counts in the bin above it.
  auto bin = [](double angle, double width, int bins) {
    return std::size_t(std::clamp(int(std::floor((angle + rose_edge_tolerance_deg) / width)), 0, bins - 1));
  };
  for (const auto& c : cracks) {
    const PlaneOrientation o = plane_orientation_deg(c.normal);
    const std::size_t d = bin(o.dip_deg, dip_bin_deg, nd);  // 90 deg: the last bin
    const std::size_t a = bin(o.dip_direction_deg, dip_direction_bin_deg, na);
    ++rose.by_dip[d], rose.area_by_dip[d] += c.size, ++rose.counts[d][a];
  }
  return rose;
}

std::vector<CrackRateBin> crack_rate(const std::vector<Crack>& cracks, double strain_end, int bins) {
  if (bins < 1) throw std::invalid_argument(fmt::format("crack_rate: {} bins (at least 1)", bins));
  std::vector<CrackRateBin> out;
  if (!(strain_end > 0)) return out;
  const double w = strain_end / bins;
  out.resize(std::size_t(bins));
  for (int b = 0; b < bins; ++b) out[std::size_t(b)].strain_low = b * w, out[std::size_t(b)].strain_high = (b + 1) * w;
  out.back().strain_high = strain_end;
  for (const auto& c : cracks) {
    if (c.strain < 0 || c.strain > strain_end) continue;
    const int b = std::min(bins - 1, int(c.strain / w));
    ++out[std::size_t(b)].cracks;
  }
  for (auto& b : out) b.rate = b.cracks / (b.strain_high - b.strain_low);
  return out;
}

std::vector<Fragment> fragments(const Specimen& specimen, const std::vector<Crack>& cracks) {
  const std::size_t nb = specimen.num_blocks(), nbond = specimen.num_bonds();
  std::vector<char> broken(nbond, 0);
  for (const auto& c : cracks) {
    if (c.bond < 0 || std::size_t(c.bond) >= nbond)
      throw std::invalid_argument(
          fmt::format("fragments: crack of bond {} but the specimen has {} bonds", c.bond, nbond));
    broken[std::size_t(c.bond)] = 1;
  }
  std::vector<int> parent(nb);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int a) {
    while (parent[std::size_t(a)] != a) a = parent[std::size_t(a)] = parent[std::size_t(parent[std::size_t(a)])];
    return a;
  };
  for (std::size_t b = 0; b < nbond; ++b) {
    const int i = specimen.bonds.i[b], j = specimen.bonds.j[b];
    if (i < 0 || j < 0 || std::size_t(i) >= nb || std::size_t(j) >= nb)
      throw std::invalid_argument(
          fmt::format("fragments: bond {} joins blocks {} and {} but there are {} blocks", b, i, j, nb));
    if (broken[b]) continue;
    const int ri = find(i), rj = find(j);
    if (ri != rj) parent[std::size_t(std::max(ri, rj))] = std::min(ri, rj);  // the root is the lowest block
  }
  std::vector<int> slot(nb, -1);
  std::vector<Fragment> out;
  for (std::size_t b = 0; b < nb; ++b) {
    const int r = find(int(b));
    if (slot[std::size_t(r)] < 0) slot[std::size_t(r)] = int(out.size()), out.emplace_back();
    Fragment& f = out[std::size_t(slot[std::size_t(r)])];
    const double a = specimen.blocks.measure[b];
    f.blocks += 1, f.measure += a, f.cx += a * specimen.centroid(b, 0), f.cy += a * specimen.centroid(b, 1);
    if (specimen.dim == 3) f.cz += a * specimen.centroid(b, 2);
  }
  for (auto& f : out)
    if (f.measure > 0) f.cx /= f.measure, f.cy /= f.measure, f.cz /= f.measure;
  // Fragments were created in order of their lowest block: a stable sort keeps that order among equal measures.
  std::stable_sort(out.begin(), out.end(),
                   [](const Fragment& a, const Fragment& b) { return a.measure > b.measure; });
  return out;
}

}  // namespace rbdem
