// libFuzzer target: bytes -> two tetrahedra -> contact_tets (dem/contact3.hpp). Checks what must hold for any
// finite input: a contact's outputs are finite, its volume, area and depth non-negative and within the smaller
// tetrahedron, its normal and axis unit vectors, a second call gives the same bits, and tets_apart does not call
// the pair apart.
//
// Layout: byte 0 picks the coding of the 24 coordinates that follow (i's four vertices, then j's):
//   0: one signed byte each, / 16 (a coarse lattice: shared vertices, coplanar faces, flat tetrahedra);
//   1: two bytes each (int16), * 1e-4 m, as the mesh fuzz target;
//   2: j's vertices are i's in the order of byte 1's bits, moved by the signed bytes that follow * 2^-40
//      (coincident, touching and round-off-apart pairs);
//   3: eight bytes each, a raw double (NaN, infinities, huge and subnormal values included).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "dem/contact3.hpp"

namespace {

using rbdem::Tet;

bool decode(const std::uint8_t* data, std::size_t size, Tet& i, Tet& j) {
  if (size < 1) return false;
  const int mode = data[0] % 4;
  const std::uint8_t* p = data + 1;
  const std::size_t n = size - 1;
  auto at = [&](int k) -> rbdem::Vec3& { return k < 4 ? i[std::size_t(k)] : j[std::size_t(k - 4)]; };
  if (mode == 0) {
    if (n < 24) return false;
    for (int k = 0; k < 24; ++k) at(k / 3)[k % 3] = double(std::int8_t(p[k])) / 16.0;
  } else if (mode == 1) {
    if (n < 48) return false;
    for (int k = 0; k < 24; ++k) {
      std::int16_t v;
      std::memcpy(&v, p + 2 * k, 2);
      at(k / 3)[k % 3] = 1e-4 * v;
    }
  } else if (mode == 2) {
    if (n < 1 + 12 + 12) return false;
    for (int k = 0; k < 12; ++k) at(k / 3)[k % 3] = double(std::int8_t(p[1 + k])) / 16.0;
    for (int k = 0; k < 4; ++k) {
      const int from = (p[0] >> (2 * k)) & 3;
      for (int c = 0; c < 3; ++c)
        at(4 + k)[c] = i[std::size_t(from)][c] + std::ldexp(double(std::int8_t(p[13 + 3 * k + c])), -40);
    }
  } else {
    if (n < 24 * 8) return false;
    for (int k = 0; k < 24; ++k) std::memcpy(&at(k / 3)[k % 3], p + 8 * k, 8);
  }
  return true;
}

bool same(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }
bool same(rbdem::Vec3 a, rbdem::Vec3 b) { return same(a.x, b.x) && same(a.y, b.y) && same(a.z, b.z); }
bool same(const rbdem::TetContact& a, const rbdem::TetContact& b) {
  return same(a.normal, b.normal) && same(a.area, b.area) && same(a.volume, b.volume) && same(a.point, b.point) &&
         same(a.centroid, b.centroid) && same(a.axis, b.axis) && same(a.depth, b.depth) &&
         a.axis_kind == b.axis_kind && a.axis_index == b.axis_index;
}

bool finite(rbdem::Vec3 v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

void check(const Tet& i, const Tet& j) {
  rbdem::TetContact c, again;
  if (!rbdem::contact_tets(i, j, c)) return;
  if (!rbdem::contact_tets(i, j, again) || !same(c, again)) __builtin_trap();
  // A pair the quick test proves apart has no contact (a pair list skips contact_tets for it).
  if (rbdem::tets_apart(rbdem::posed(i), rbdem::posed(j)) || rbdem::tets_apart(rbdem::posed(j), rbdem::posed(i)))
    __builtin_trap();
  if (!(std::isfinite(c.volume) && std::isfinite(c.area) && std::isfinite(c.depth))) __builtin_trap();
  if (!(finite(c.normal) && finite(c.axis) && finite(c.point) && finite(c.centroid))) __builtin_trap();
  if (!(c.volume >= 0 && c.area >= 0 && c.depth >= 0)) __builtin_trap();
  if (std::abs(rbdem::norm(c.normal) - 1) > 1e-9 || std::abs(rbdem::norm(c.axis) - 1) > 1e-9) __builtin_trap();
  // The overlap lies in both: within the smaller volume, up to the clipping's round-off. Generic pairs are exact to
  // 1e-13 (tests/test_contact3.cpp); built to be hard here (a sliver inside a tetrahedron whose faces cross its
  // own at angles of 1e-8 to 1e-5), the clipped faces' crossing lines carry round-off over those angles, up to
  // about 1e-6 of the pair's extent cubed (docs/theory.md, section 11.9). The bound catches anything worse.
  double extent = 0;
  for (const Tet* t : {&i, &j})
    for (const rbdem::Vec3& p : *t)
      for (int k = 0; k < 3; ++k) extent = std::max(extent, std::abs(p[k] - i[0][k]));
  const double vmax = std::min(std::abs(rbdem::signed_volume(i)), std::abs(rbdem::signed_volume(j)));
  const double bound = vmax + 1e-5 * extent * extent * extent;
  if (std::isfinite(bound) && c.volume > bound) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Tet i, j;
  if (!decode(data, size, i, j)) return 0;
  check(i, j);
  check(j, i);
  return 0;
}
