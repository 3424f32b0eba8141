// Sums over a sliding (2 hw + 1) x (2 hh + 1) window, separably: rows are
// added first (AddRow), then each row of column sums is summed along the row
// (SumAlongRow). Plain loops over contiguous floats, which the compiler
// vectorises; each output adds 2 hw + 1 values directly (no running sum), so
// float rounding does not drift along a row.
#pragma once

namespace stereorig {

// acc[x] += in[x], x in [0, width).
void AddRow(const float* in, int width, float* acc);

// out[x] = sum of in[x - half_width .. x + half_width] for x in
// [half_width, width - half_width); the columns nearer the ends are left
// untouched. in and out must not overlap.
void SumAlongRow(const float* in, int width, int half_width, float* out);

}  // namespace stereorig
