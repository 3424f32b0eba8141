#include "calib/capture_folder.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace stereorig {
namespace {

// A log of `images` images, `accepted` of them accepted and the rest
// rejected for the reasons given, in order.
DetectedCaptures Log(int accepted, const std::vector<std::pair<RejectReason, int>>& rejected) {
  DetectedCaptures d;
  for (int k = 0; k < accepted; ++k) d.log.push_back({k, 0, "", true, Face::kFront, 50, 0, "", RejectReason::kNone});
  for (const auto& [reason, n] : rejected)
    for (int k = 0; k < n; ++k) d.log.push_back({k, 1, "", false, Face::kFront, 0, 0, "why", reason});
  return d;
}

// The user's swapped corners (a 9 x 11 file for an 11 x 9 board): 29 of 200
// images accepted, 59 rejected as ambiguous. Named, with the file's
// corners_x and corners_y. A right file's 13 rejections of 200 (none
// ambiguous), or most rejected with the board out of view (no_chessboard
// only), say nothing of the layout.
TEST(RejectedViewsNote, MostImagesRejectedAsOffTheLayoutNameTheTargetFile) {
  const Target swapped = PlainTarget(9, 11, 9.0);
  const DetectedCaptures d =
      Log(29, {{RejectReason::kNoChessboard, 93}, {RejectReason::kAmbiguous, 59}, {RejectReason::kTooFewCorners, 19}});
  EXPECT_EQ(RejectedViewsNote(d, swapped, "t_swap.yaml"),
            "171 of 200 images rejected (59 ambiguous, 93 no_chessboard, 19 too_few_corners): is t_swap.yaml this "
            "board's target file? It says corners_x 9, corners_y 11 (inner corners along a row, along a column); a "
            "board whose grid differs (or the two swapped) fits no single orientation");
  EXPECT_EQ(
      RejectedViewsNote(Log(187, {{RejectReason::kNoTags, 11}, {RejectReason::kTooFewCorners, 2}}), swapped, "t.yaml"),
      "");
  EXPECT_EQ(RejectedViewsNote(Log(29, {{RejectReason::kNoChessboard, 171}}), swapped, "t.yaml"), "");
  // Half rejected is not most.
  EXPECT_EQ(RejectedViewsNote(Log(100, {{RejectReason::kAmbiguous, 100}}), swapped, "t.yaml"), "");
  EXPECT_NE(RejectedViewsNote(Log(99, {{RejectReason::kGridMismatch, 101}}), swapped, "t.yaml"), "");
}

// A target file hand-edited to corners_x 12 for the 11 x 9 board: its 12th
// column is never among the corners any view found (a double-sided target
// keeps the corners its tags place). Named, with the file's counts. A row
// and a column both; a file whose every row and column showed somewhere,
// or no accepted view, says nothing.
TEST(NeverSeenCornersNote, ARowOrColumnNoViewShowedNamesTheTargetFile) {
  const Target t12 = DoubleSidedTarget(12, 9, 9.0);
  BoardObservation a, b;
  for (int row = 0; row < 9; ++row)
    for (int col = 0; col < 11; ++col) (row < 5 ? a : b).corner_ids.push_back(row * 12 + col);
  const std::vector<BoardObservation> views = {a, b, BoardObservation()};
  EXPECT_EQ(NeverSeenCornersNote(views, t12, "t12.yaml"),
            "t12.yaml says corners_x 12, corners_y 9 (inner corners along a row, along a column), but its column 12 "
            "of corners (1-based) never showed in any of the 2 accepted views: does the board have that many? (the "
            "rig records the file's grid)");
  const Target t12x10 = DoubleSidedTarget(12, 10, 9.0);
  BoardObservation c;  // ids in the 12 x 10 grid: rows 1..9, columns 1..11 seen
  for (int row = 0; row < 9; ++row)
    for (int col = 0; col < 11; ++col) c.corner_ids.push_back(row * 12 + col);
  EXPECT_NE(NeverSeenCornersNote({c}, t12x10, "t.yaml").find("its column 12 and row 10 of corners"), std::string::npos);
  b.corner_ids.push_back(4 * 12 + 11);  // column 12 seen once
  EXPECT_EQ(NeverSeenCornersNote({a, b}, t12, "t12.yaml"), "");
  EXPECT_EQ(NeverSeenCornersNote({BoardObservation()}, t12, "t12.yaml"), "");
  const Target t11 = DoubleSidedTarget(11, 9, 9.0);
  BoardObservation d;
  for (int id = 0; id < 99; id += 12) d.corner_ids.push_back(id);  // the diagonal: every row, every column
  for (int col = 0; col < 11; ++col) d.corner_ids.push_back(col);
  EXPECT_EQ(NeverSeenCornersNote({d}, t11, "t11.yaml"), "");
}

// Most images with no board of the file's grid: for a refused calibration,
// the note asks whether the board was seen and whether the file is its
// (a plain 9 x 6 file against the 11 x 9 board: "too few views: 1 usable"
// and nothing more). Half is not most; other reasons do not count.
TEST(NoBoardFoundNote, MostImagesWithNoBoardAskAboutTheViewAndTheFile) {
  const Target plain = PlainTarget(9, 6, 9.0);
  EXPECT_EQ(NoBoardFoundNote(Log(2, {{RejectReason::kNoChessboard, 198}}), plain, "t9x6.yaml"),
            "198 of 200 images show no board as t9x6.yaml describes it (corners_x 9, corners_y 6, inner corners "
            "along a row, along a column): is the board in view and lit, and is that file this board's target "
            "file?");
  // A double-sided target whose tags are none of the board's: no_tags.
  EXPECT_EQ(NoBoardFoundNote(Log(0, {{RejectReason::kNoTags, 200}}), DefaultTarget(), "tags.yaml"),
            "200 of 200 images show no board as tags.yaml describes it (corners_x 11, corners_y 9, inner corners "
            "along a row, along a column, and its tags): is the board in view and lit, and is that file this "
            "board's target file?");
  EXPECT_EQ(NoBoardFoundNote(Log(100, {{RejectReason::kNoChessboard, 100}}), plain, "t.yaml"), "");
  EXPECT_EQ(NoBoardFoundNote(Log(10, {{RejectReason::kTooFewCorners, 190}}), plain, "t.yaml"), "");
  EXPECT_NE(NoBoardFoundNote(Log(99, {{RejectReason::kNoChessboard, 101}}), plain, "t.yaml"), "");
}

// The note goes only with refusals for too few views, as stages 1 and 2
// word them; a refusal that shows the board was seen gets none.
TEST(NoBoardFoundNote, OnlyRefusalsForTooFewViewsTakeIt) {
  for (const char* problem :
       {"never sees the board (no view with enough corners)", "too few views: 1 usable, need at least 5",
        "too few views with a board pose: 2", "too few views left after outlier rejection: 3",
        "too few views shared by both cameras: 1"})
    EXPECT_TRUE(IsTooFewViewsProblem(problem)) << problem;
  for (const char* problem :
       {"face seen by the wrong module: module1 sees the front face", "corner 12 outside the imager", "observed twice"})
    EXPECT_FALSE(IsTooFewViewsProblem(problem)) << problem;
}

// Stage 2's views left out, named with the board's tilt in each. A ring's
// side views (the commissioning audit's: 85, 74 and 80 deg) read as boards
// seen nearly edge-on; they used to read as "a module's left and right
// swapped?", which a swapped pair's ordinary tilts still do. A mix says
// which is which; a view stage 1 had no pose for gives no tilt.
TEST(StereoViewsLeftOutNotes, NameTheBoardsTiltAndTellEdgeOnViewsFromSwappedImages) {
  CalibrationReport report;
  report.capture_names = {{31, "031"}, {45, "045"}};
  StereoReport module;
  module.module = 1;
  module.module_name = "module1";
  module.views_left_out = {{31, 3}, {45, 2}, {45, 3}};
  module.views_left_out_tilt_deg = {85.2, 74.4, 80.0};
  report.stereo = {module};
  const std::string edge_on =
      "module 1 (module1): stage 2 left out 031/cam3.png (board tilted 85 deg), 045/cam2.png (board tilted 74 deg), "
      "045/cam3.png (board tilted 80 deg): outlier rejection left too few of their corners to fix the board's pose "
      "(boards seen nearly edge-on, their corners foreshortened: usual where a module sees the board from the side, "
      "as in a ring; the module's other views fix it)";
  EXPECT_EQ(StereoViewsLeftOutNotes(report), std::vector<std::string>{edge_on});

  report.stereo[0].views_left_out_tilt_deg = {31.0, 28.5, 40.0};
  const std::vector<std::string> swapped = StereoViewsLeftOutNotes(report);
  ASSERT_EQ(swapped.size(), 1u);
  EXPECT_NE(swapped[0].find("(images of another camera or capture, such as a module's left and right swapped?)"),
            std::string::npos)
      << swapped[0];
  EXPECT_EQ(swapped[0].find("edge-on"), std::string::npos) << swapped[0];

  report.stereo[0].views_left_out_tilt_deg = {85.2, 28.5, std::nan("")};
  const std::vector<std::string> mixed = StereoViewsLeftOutNotes(report);
  ASSERT_EQ(mixed.size(), 1u);
  EXPECT_NE(mixed[0].find("045/cam3.png:"), std::string::npos) << mixed[0];  // no tilt to give
  EXPECT_NE(mixed[0].find("(those tilted 70 deg or more seen nearly edge-on; the others images of another camera"),
            std::string::npos)
      << mixed[0];

  // Judged as printed: 69.6 deg reads "70 deg", and is edge-on.
  report.stereo[0].views_left_out = {{31, 3}};
  report.stereo[0].views_left_out_tilt_deg = {69.6};
  const std::vector<std::string> at_the_bound = StereoViewsLeftOutNotes(report);
  ASSERT_EQ(at_the_bound.size(), 1u);
  EXPECT_NE(at_the_bound[0].find("031/cam3.png (board tilted 70 deg): "), std::string::npos) << at_the_bound[0];
  EXPECT_NE(at_the_bound[0].find("(boards seen nearly edge-on"), std::string::npos) << at_the_bound[0];

  report.stereo[0].views_left_out.clear();
  report.stereo[0].views_left_out_tilt_deg.clear();
  EXPECT_TRUE(StereoViewsLeftOutNotes(report).empty());
}

}  // namespace
}  // namespace stereorig
