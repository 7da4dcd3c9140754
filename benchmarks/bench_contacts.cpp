// The contact narrow phases alone, one core: nanoseconds per pair of the tetrahedron-tetrahedron contact
// (BM_TetContact, dem/contact3.hpp) in three cases, beside the 2D triangle-triangle polygon clipping
// (BM_TriangleContact2D, dem/contact_geometry.hpp):
//   /0 separated:   boxes that overlap (what a broad phase hands over) but a separating axis between the blocks;
//   /1 touching:    a mesh neighbour, face on face (zero volume, the whole face's area);
//   /2 overlapping: a shallow overlap, a penetration of at most 5 % of the edge, of any kind (vertex, edge, face);
// and the quick test that proves pairs apart before it (BM_TetsApart) on the separated pairs of /0.
// Each iteration runs the routine over 4096 pairs drawn once (edges of about 1 mm, random orientations), so that
// neither the branch predictor nor the cache learns one pair.
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "dem/contact3.hpp"
#include "dem/contact_geometry.hpp"

namespace {

using namespace rbdem;

constexpr int kPairs = 4096;

benchmark::Counter per_pair(const benchmark::State& state) {
  return benchmark::Counter(double(kPairs) * double(state.iterations()),
                            benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

Tet random_tet(std::mt19937_64& rng, Vec3 at, double size) {
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  for (;;) {
    Tet t;
    for (Vec3& p : t) p = at + size * Vec3{u(rng), u(rng), u(rng)};
    if (std::abs(signed_volume(t)) > 0.02 * size * size * size) return t;
  }
}

// j is i's mirror image through its face k, so the two share that face (as mesh neighbours do).
Tet mirrored(const Tet& i, int k) {
  const Vec3 a = i[std::size_t((k + 1) % 4)], b = i[std::size_t((k + 2) % 4)], c = i[std::size_t((k + 3) % 4)];
  Vec3 n = cross(b - a, c - a);
  n = (1.0 / norm(n)) * n;
  Tet j = i;
  j[std::size_t(k)] = i[std::size_t(k)] - (2.0 * dot(n, i[std::size_t(k)] - a)) * n;
  return j;
}

std::vector<std::pair<Tet, Tet>> pairs_of(int kind) {
  std::mt19937_64 rng(42 + std::uint64_t(kind));
  std::uniform_real_distribution<double> u(-1e-3, 1e-3);
  std::vector<std::pair<Tet, Tet>> out;
  while (int(out.size()) < kPairs) {
    const Tet i = random_tet(rng, {0, 0, 0}, 1e-3);
    if (kind == 1) {
      out.push_back({i, mirrored(i, int(out.size() % 4))});
      continue;
    }
    const Tet j = random_tet(rng, {u(rng), u(rng), u(rng)}, 1e-3);
    TetContact c;
    const bool touch = contact_tets(i, j, c);
    if (kind == 0 && !touch && aabbs_overlap(aabb_of(i), aabb_of(j))) out.push_back({i, j});
    if (kind == 2 && touch && c.volume > 0 && c.depth < 0.05e-3) out.push_back({i, j});
  }
  return out;
}

void BM_TetContact(benchmark::State& state) {
  const auto pairs = pairs_of(int(state.range(0)));
  double sum = 0;
  for (auto _ : state) {
    for (const auto& [i, j] : pairs) {
      TetContact c;
      if (contact_tets(i, j, c)) sum += c.volume + c.area + c.normal.x;
    }
    benchmark::DoNotOptimize(sum);
  }
  state.counters["ns_per_pair"] = per_pair(state);
}
BENCHMARK(BM_TetContact)->Arg(0)->Arg(1)->Arg(2)->Unit(benchmark::kMicrosecond);

// The quick test a pair list runs before the narrow phase (tets_apart, dem/contact3.hpp) on the separated pairs of
// BM_TetContact/0, their poses prepared once (as a run does once per block and step): the share it proves apart
// and its cost per pair, beside BM_TetContact/0's for the same pairs.
void BM_TetsApart(benchmark::State& state) {
  const auto pairs = pairs_of(0);
  std::vector<std::pair<PosedTet, PosedTet>> posed_pairs;
  for (const auto& [i, j] : pairs) posed_pairs.push_back({posed(i), posed(j)});
  long proved = 0;
  for (auto _ : state) {
    proved = 0;
    for (const auto& [i, j] : posed_pairs) proved += tets_apart(i, j);
    benchmark::DoNotOptimize(proved);
  }
  state.counters["ns_per_pair"] = per_pair(state);
  state.counters["proved_apart"] = double(proved) / double(kPairs);
}
BENCHMARK(BM_TetsApart)->Unit(benchmark::kMicrosecond);

// Two triangles, overlapping or not (about half each), the 2D engine's narrow phase.
void BM_TriangleContact2D(benchmark::State& state) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-0.5e-3, 0.5e-3);
  std::vector<std::array<double, 12>> pairs;
  while (int(pairs.size()) < kPairs) {
    std::array<double, 12> p;
    for (int k = 0; k < 12; ++k) p[std::size_t(k)] = u(rng) + (k >= 6 && k % 2 == 0 ? 0.5e-3 : 0.0);
    for (int t = 0; t < 2; ++t) {  // counter-clockwise
      double* q = p.data() + 6 * t;
      if ((q[2] - q[0]) * (q[5] - q[1]) - (q[3] - q[1]) * (q[4] - q[0]) < 0) std::swap(q[2], q[4]), std::swap(q[3], q[5]);
    }
    pairs.push_back(p);
  }
  double sum = 0;
  for (auto _ : state) {
    for (const auto& p : pairs) {
      Overlap o;
      if (overlap_polygons(p.data(), 3, p.data() + 6, 3, o)) sum += o.area + o.nx;
    }
    benchmark::DoNotOptimize(sum);
  }
  state.counters["ns_per_pair"] = per_pair(state);
}
BENCHMARK(BM_TriangleContact2D)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
