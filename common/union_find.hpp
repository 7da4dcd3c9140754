// Disjoint sets of indices 0 .. n-1 and the key of an unordered pair of indices: the node splits of the FE models
// with the joints (continuum/fe_joints.cpp in 2D, continuum/fe_joints3_mesh.cpp in 3D) group elements into classes
// and look up edges and faces by their two ends.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <numeric>
#include <vector>

namespace rbdem {

struct UnionFind {
  std::vector<unsigned> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
  unsigned find(unsigned i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];  // path halving
    return i;
  }
  void unite(unsigned a, unsigned b) {
    a = find(a), b = find(b);
    if (a != b) parent[std::max(a, b)] = std::min(a, b);  // the smaller index stays the root: deterministic
  }
};

// The same key for (a, b) and (b, a), for non-negative indices below 2^32.
inline std::uint64_t unordered_pair_key(int a, int b) {
  return (std::uint64_t(std::uint32_t(std::min(a, b))) << 32) | std::uint32_t(std::max(a, b));
}

}  // namespace rbdem
