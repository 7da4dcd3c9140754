// Shared parts of the loading protocols. See protocol.hpp.
#include "dem/driver/protocol.hpp"

#include <algorithm>
#include <cmath>

namespace rbdem {

LateralGauge::LateralGauge(const Topology& topo) : width_(topo.width()) {
  const auto& E = topo.boundary;
  for (std::size_t e = 0; e < E.size(); ++e) {
    if (E.side[e] == Side::left) left_.push_back(E.block[e]);
    if (E.side[e] == Side::right) right_.push_back(E.block[e]);
  }
  if (left_.empty() && right_.empty()) {  // a disc or another curved outline: the rim near the horizontal diameter
    const double yc = 0.5 * (topo.ymin + topo.ymax), xc = 0.5 * (topo.xmin + topo.xmax), band = 0.1 * topo.height();
    for (std::size_t e = 0; e < E.size(); ++e) {
      const int b = E.block[e];
      if (std::abs(topo.blocks.cy[std::size_t(b)] - yc) > band) continue;
      (topo.blocks.cx[std::size_t(b)] < xc ? left_ : right_).push_back(b);
    }
  }
  for (auto* v : {&left_, &right_}) {
    std::sort(v->begin(), v->end());
    v->erase(std::unique(v->begin(), v->end()), v->end());
  }
}

double LateralGauge::strain(const Engine& engine) const {
  const Model& m = engine.model();
  const ModelState& s = engine.state();
  auto mean_shift = [&](const std::vector<int>& blocks, bool& any) {
    double sum = 0;
    int n = 0;
    for (int b : blocks)
      if (m.has_intact_bond(b, s.broken)) sum += s.x[std::size_t(b)] - m.x0[std::size_t(b)], ++n;
    any = n > 0;
    return n > 0 ? sum / n : 0.0;
  };
  bool l = false, r = false;
  const double shift = mean_shift(right_, r) - mean_shift(left_, l);
  return l && r && width_ > 0 ? -shift / width_ : 0.0;
}

double LateralGauge::strain_of(const std::vector<double>& ux) const {
  auto mean = [&](const std::vector<int>& blocks) {
    double sum = 0;
    for (int b : blocks) sum += ux[std::size_t(b)];
    return blocks.empty() ? 0.0 : sum / double(blocks.size());
  };
  return left_.empty() || right_.empty() || !(width_ > 0) ? 0.0 : -(mean(right_) - mean(left_)) / width_;
}

}  // namespace rbdem
