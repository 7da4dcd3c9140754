// Block records: each block's kinematics in one 64-byte record, for the bond kernel (bonds.cpp).
//
// The kernel reads eight fields of each of its two blocks per bond, at indices that follow no pattern. Read from
// eight arrays, that is sixteen gathers per bond, which the vector units do element by element. Read as records,
// eight bonds' blocks are eight aligned 64-byte loads and an 8 x 8 transpose in registers (24 shuffles), which
// leaves each field in one vector, in bond order. The same transpose, run the other way, writes the records from
// the state's arrays (pack_records). The records copy values and do no arithmetic, so the forces are the same as
// when read from the arrays.
#pragma once

#include <cstring>

#include "dem/stages/stages.hpp"

namespace rbdem::stages {

// Eight doubles in one vector (GCC's vector extension: one register with AVX-512, two or four on narrower targets,
// so the same code serves every clone of the kernel).
using Lane8 = double __attribute__((vector_size(64)));

[[gnu::always_inline]] inline Lane8 load8(const double* p) {
  Lane8 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
[[gnu::always_inline]] inline void store8(double* p, Lane8 v) { std::memcpy(p, &v, sizeof v); }

// Transposes the 8 x 8 matrix whose rows are r[0..7]: afterwards r[f][q] is the old r[q][f].
[[gnu::always_inline]] inline void transpose8(Lane8 (&r)[8]) {
  // Pairs of rows interleaved: t[2p] holds the even columns of rows 2p and 2p + 1, t[2p + 1] the odd ones.
  Lane8 t[8];
  for (int p = 0; p < 4; ++p) {
    t[2 * p] = __builtin_shufflevector(r[2 * p], r[2 * p + 1], 0, 8, 2, 10, 4, 12, 6, 14);
    t[2 * p + 1] = __builtin_shufflevector(r[2 * p], r[2 * p + 1], 1, 9, 3, 11, 5, 13, 7, 15);
  }
  // Pairs of pairs: u holds, for rows 0-3 (u[0..3]) and 4-7 (u[4..7]), columns {0, 4}, {2, 6}, {1, 5}, {3, 7}.
  Lane8 u[8];
  for (int h = 0; h < 2; ++h) {
    const Lane8 *a = t + 4 * h, *b = t + 4 * h + 2;
    u[4 * h + 0] = __builtin_shufflevector(a[0], b[0], 0, 1, 8, 9, 4, 5, 12, 13);
    u[4 * h + 1] = __builtin_shufflevector(a[0], b[0], 2, 3, 10, 11, 6, 7, 14, 15);
    u[4 * h + 2] = __builtin_shufflevector(a[1], b[1], 0, 1, 8, 9, 4, 5, 12, 13);
    u[4 * h + 3] = __builtin_shufflevector(a[1], b[1], 2, 3, 10, 11, 6, 7, 14, 15);
  }
  // Halves: the low halves of u[k] and u[k + 4] make column c, the high halves column c + 4.
  constexpr int column[4] = {0, 2, 1, 3};
  for (int k = 0; k < 4; ++k) {
    r[column[k]] = __builtin_shufflevector(u[k], u[k + 4], 0, 1, 2, 3, 8, 9, 10, 11);
    r[column[k] + 4] = __builtin_shufflevector(u[k], u[k + 4], 4, 5, 6, 7, 12, 13, 14, 15);
  }
}

// The arrays a block record copies, in its order (Workspace<2>::Record).
using RecordFields = const double* [Workspace<2>::kRecordFields];

// The records rec[lo, hi) from the arrays `field`.
[[gnu::always_inline]] inline void pack_records(const RecordFields& field, Workspace<2>::Record* rec, int lo, int hi) {
  int b = lo;
  for (; b + 8 <= hi; b += 8) {
    Lane8 v[8];
#pragma GCC unroll 8
    for (int f = 0; f < 8; ++f) v[f] = load8(field[f] + b);
    transpose8(v);
#pragma GCC unroll 8
    for (int q = 0; q < 8; ++q) store8(rec[b + q].f, v[q]);
  }
  for (; b < hi; ++b)
    for (int f = 0; f < 8; ++f) rec[b].f[f] = field[f][b];
}

// Fields f of the records of blocks index[0..n) into out[f][0..n) (out's rows 64-byte aligned, n at most Chunk).
template <int Chunk>
[[gnu::always_inline]] inline void load_records(const Workspace<2>::Record* rec, const int* index, int n,
                                                double (&out)[Workspace<2>::kRecordFields][Chunk]) {
  int k = 0;
  for (; k + 8 <= n; k += 8) {
    Lane8 v[8];
#pragma GCC unroll 8
    for (int q = 0; q < 8; ++q) v[q] = load8(rec[index[k + q]].f);
    transpose8(v);
#pragma GCC unroll 8
    for (int f = 0; f < 8; ++f) store8(&out[f][k], v[f]);
  }
  for (; k < n; ++k)
    for (int f = 0; f < 8; ++f) out[f][k] = rec[index[k]].f[f];
}

}  // namespace rbdem::stages
