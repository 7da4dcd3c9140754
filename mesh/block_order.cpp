// Element orders. See block_order.hpp.
#include "mesh/block_order.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>

namespace rbdem {

namespace {

constexpr int kOrderBits = 21;  // 21 bits a coordinate: 63 bits of index in 3D

// The Hilbert index of a cell of a 2^bits grid in N dimensions, by Skilling's transform of the coordinates into the
// "transposed" index (J. Skilling, Programming the Hilbert curve, AIP Conf. Proc. 707, 2004), whose bits, read
// across the coordinates from the highest level down, are the index.
template <std::size_t N>
std::uint64_t hilbert(std::array<std::uint32_t, N> x, int bits) {
  if (bits < 1 || bits > 21) throw std::invalid_argument("hilbert_index: bits must lie in 1 .. 21");
  const std::uint32_t top = std::uint32_t(1) << (bits - 1);
  for (std::uint32_t c : x)
    if (c >= 2 * top) throw std::invalid_argument("hilbert_index: a coordinate lies outside the 2^bits grid");
  for (std::uint32_t q = top; q > 1; q >>= 1) {  // undo the rotations and reflections, level by level
    const std::uint32_t low = q - 1;
    for (std::size_t i = 0; i < N; ++i) {
      if (x[i] & q) {
        x[0] ^= low;  // reflect
      } else {
        const std::uint32_t t = (x[0] ^ x[i]) & low;  // exchange the low bits of x[0] and x[i]
        x[0] ^= t;
        x[i] ^= t;
      }
    }
  }
  for (std::size_t i = 1; i < N; ++i) x[i] ^= x[i - 1];  // Gray code
  std::uint32_t t = 0;
  for (std::uint32_t q = top; q > 1; q >>= 1)
    if (x[N - 1] & q) t ^= q - 1;
  for (std::size_t i = 0; i < N; ++i) x[i] ^= t;
  std::uint64_t index = 0;
  for (int b = bits - 1; b >= 0; --b)
    for (std::size_t i = 0; i < N; ++i) index = (index << 1) | ((x[i] >> b) & 1u);
  return index;
}

// The order of the elements' centroids along the Hilbert curve through their bounding cube; ties keep the
// elements' order.
template <std::size_t N, std::size_t V>
std::vector<int> order_of(const std::vector<std::array<double, N>>& nodes,
                          const std::vector<std::array<int, V>>& elements) {
  std::vector<std::array<double, N>> points(elements.size());
  for (std::size_t e = 0; e < elements.size(); ++e)
    for (std::size_t i = 0; i < N; ++i) {
      double s = 0;
      for (int v : elements[e]) s += nodes[std::size_t(v)][i];
      points[e][i] = s / double(V);
    }
  std::array<double, N> lo, hi;
  lo.fill(std::numeric_limits<double>::infinity());
  hi.fill(-std::numeric_limits<double>::infinity());
  for (const auto& p : points)
    for (std::size_t i = 0; i < N; ++i) lo[i] = std::min(lo[i], p[i]), hi[i] = std::max(hi[i], p[i]);
  double extent = 0;
  for (std::size_t i = 0; i < N; ++i) extent = std::max(extent, hi[i] - lo[i]);
  const double cells = double((std::uint32_t(1) << kOrderBits) - 1);
  const double scale = extent > 0 ? cells / extent : 0.0;
  std::vector<std::uint64_t> key(points.size());
  for (std::size_t e = 0; e < points.size(); ++e) {
    std::array<std::uint32_t, N> cell;
    for (std::size_t i = 0; i < N; ++i)
      cell[i] = std::uint32_t(std::clamp(std::floor((points[e][i] - lo[i]) * scale), 0.0, cells));
    key[e] = hilbert(cell, kOrderBits);
  }
  std::vector<int> order(points.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return key[a] < key[b]; });
  return order;
}

template <class T>
std::vector<T> permuted(const std::vector<T>& v, const std::vector<int>& order) {
  std::vector<T> out;
  out.reserve(order.size());
  for (int e : order) out.push_back(v[std::size_t(e)]);
  return out;
}

// The elements and their layers in `order`, once it is checked to be a permutation.
template <class Element>
void permute(std::vector<Element>& elements, std::vector<int>& layer, const std::vector<int>& order) {
  std::vector<char> seen(elements.size(), 0);
  bool ok = order.size() == elements.size();
  for (std::size_t k = 0; ok && k < order.size(); ++k) {
    const int e = order[k];
    ok = e >= 0 && std::size_t(e) < seen.size() && !seen[std::size_t(e)];
    if (ok) seen[std::size_t(e)] = 1;
  }
  if (!ok) throw std::invalid_argument("reorder_elements: the order must name every element once");
  elements = permuted(elements, order);
  if (layer.size() == order.size()) layer = permuted(layer, order);
}

bool is_hilbert(std::string_view order) {
  if (order == "hilbert") return true;
  if (order == "mesh") return false;
  throw std::invalid_argument("unknown block order '" + std::string(order) + "': use \"mesh\" or \"hilbert\"");
}

}  // namespace

std::uint64_t hilbert_index(std::array<std::uint32_t, 2> cell, int bits) { return hilbert(cell, bits); }
std::uint64_t hilbert_index(std::array<std::uint32_t, 3> cell, int bits) { return hilbert(cell, bits); }

std::vector<int> hilbert_order(const TriMesh& mesh) { return order_of(mesh.nodes, mesh.triangles); }
std::vector<int> hilbert_order(const TetMesh& mesh) { return order_of(mesh.nodes, mesh.tets); }

void reorder_elements(TriMesh& mesh, const std::vector<int>& order) { permute(mesh.triangles, mesh.layer, order); }

void reorder_elements(TetMesh& mesh, const std::vector<int>& order) {
  permute(mesh.tets, mesh.layer, order);
  std::vector<int> new_index(order.size());
  for (std::size_t k = 0; k < order.size(); ++k) new_index[std::size_t(order[k])] = int(k);
  for (auto& f : mesh.boundary) f.tet = new_index[std::size_t(f.tet)];
}

void apply_block_order(TriMesh& mesh, std::string_view order) {
  if (is_hilbert(order)) reorder_elements(mesh, hilbert_order(mesh));
}

void apply_block_order(TetMesh& mesh, std::string_view order) {
  if (is_hilbert(order)) reorder_elements(mesh, hilbert_order(mesh));
}

}  // namespace rbdem
