#include "calib/core/png_image_data.h"

#include <gtest/gtest.h>

namespace stereorig {
namespace {

// Rows of a filter byte and the packed pixels, counted by hand.
TEST(PngImageDataBytes, ARowIsAFilterByteAndItsPackedPixels) {
  EXPECT_EQ(PngImageDataBytes(42, 23, 8, 1, false), 23u * 43u);
  EXPECT_EQ(PngImageDataBytes(752, 582, 8, 1, false), 582u * 753u);  // a capture
  EXPECT_EQ(PngImageDataBytes(9, 5, 1, 1, false), 5u * 3u);          // 9 bits: 2 bytes
  EXPECT_EQ(PngImageDataBytes(3, 2, 16, 4, false), 2u * 25u);        // RGBA, 16-bit: 8 bytes a pixel
  EXPECT_EQ(PngImageDataBytes(5, 1, 4, 1, false), 1u * 4u);          // 20 bits: 3 bytes
}

// At PNG's largest sides (2^31 - 1 px), against values worked out by hand.
// 8-bit grey: 2^31 - 1 rows of 1 + (2^31 - 1) = 2^31 bytes: 2^62 - 2^31.
// libpng's largest (10^6 px a side), 16-bit RGBA: 10^6 rows of 1 + 8 x 10^6
// bytes. 16-bit RGBA, 2^31 - 1 rows: 2^30 px wide, rows of 2^33 + 1 bytes,
// make 2^64 - 2^33 + 2^31 - 1, which fits; one pixel wider, rows of
// 2^33 + 9 bytes, 2^64 + 5 x 2^31 - 9, which does not: saturated, as at
// 2^31 - 1 px wide (about 2^65), interlaced or not.
TEST(PngImageDataBytes, TheLargestHeadersCountExactlyOrSaturate) {
  EXPECT_EQ(PngImageDataBytes(0x7FFFFFFF, 0x7FFFFFFF, 8, 1, false), 4611686016279904256ull);
  EXPECT_EQ(PngImageDataBytes(1000000, 1000000, 16, 4, false), 8000001000000ull);
  EXPECT_EQ(PngImageDataBytes(1u << 30, 0x7FFFFFFF, 16, 4, false), 18446744067267100671ull);
  EXPECT_EQ(PngImageDataBytes((1u << 30) + 1, 0x7FFFFFFF, 16, 4, false), UINT64_MAX);
  EXPECT_EQ(PngImageDataBytes(0x7FFFFFFF, 0x7FFFFFFF, 16, 4, false), UINT64_MAX);
  EXPECT_EQ(PngImageDataBytes(0x7FFFFFFF, 0x7FFFFFFF, 16, 4, true), UINT64_MAX);
}

// Adam7's seven passes, each its own sub-image of rows; a pass without a
// pixel has no row. Counted by hand: an 8 x 8 image's passes are 1x1, 1x1,
// 2x1, 2x2, 4x2, 4x4 and 8x4 px, 64 pixels and 1+1+1+2+2+4+4 = 15 rows.
TEST(PngImageDataBytes, AnInterlacedImageHasSevenPassesOfRows) {
  EXPECT_EQ(PngImageDataBytes(8, 8, 8, 1, true), 64u + 15u);
  EXPECT_EQ(PngImageDataBytes(1, 1, 8, 1, true), 2u);  // pass 1 alone
  // 3 x 2: passes 1 (1x1), 4 (1x1), 6 (1x1) and 7 (3x1); 2, 3 and 5 empty.
  EXPECT_EQ(PngImageDataBytes(3, 2, 8, 1, true), 6u + 4u);
  // 1-bit, 16 x 16: passes of 2x2, 2x2, 4x2, 4x4, 8x4, 8x8 and 16x8 px;
  // a row of up to 8 px packs into 1 byte, pass 7's 16 px into 2.
  EXPECT_EQ(PngImageDataBytes(16, 16, 1, 1, true), 2u * 2 + 2u * 2 + 2u * 2 + 4u * 2 + 4u * 2 + 8u * 2 + 8u * 3);
  // Every pass full (a multiple of 8 on each side): the pixels, and a row
  // for each pass's row: 8 (p1) + 8 + 8 + 16 + 16 + 32 + 32 rows of 64 px.
  EXPECT_EQ(PngImageDataBytes(64, 64, 8, 1, true), 64u * 64u + 8u + 8u + 8u + 16u + 16u + 32u + 32u);
}

}  // namespace
}  // namespace stereorig
