#include "targets/board_svg.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>

#include <opencv2/imgcodecs.hpp>

#include "calib/core/atomic_file.h"
#include "calib/core/input_error.h"
#include "targets/detect.h"

namespace stereorig {
namespace {

std::string ReadAll(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::map<std::string, std::string> Attributes(const std::string& element) {
  std::map<std::string, std::string> a;
  static const std::regex attr("([a-zA-Z-]+)=\"([^\"]*)\"");
  for (std::sregex_iterator it(element.begin(), element.end(), attr), end; it != end; ++it) a[(*it)[1]] = (*it)[2];
  return a;
}

TEST(BoardSvg, SquaresScaleBarAndPageAreInTrueMillimetres) {
  const Target target = DefaultTarget();
  const std::string path = (std::filesystem::temp_directory_path() / "stereorig_board_svg_test.svg").string();
  const BoardSvg svg = MakeBoardSvg(target);
  WriteFileAtomically(path, svg.text);
  const std::string text = ReadAll(path);
  ASSERT_EQ(text, svg.text);

  // Well-formed XML, by an independent parser.
  const std::string cmd =
      "/usr/bin/python3 -c \"import sys, xml.etree.ElementTree as E; E.parse(sys.argv[1])\" " + path;
  EXPECT_EQ(std::system(cmd.c_str()), 0);

  // The root: width and height in mm, and a viewBox of the same numbers, so
  // a user unit is a millimetre.
  std::smatch m;
  ASSERT_TRUE(std::regex_search(text, m, std::regex("<svg [^>]*>")));
  auto root = Attributes(m.str());
  const double w = std::stod(root["width"]), h = std::stod(root["height"]);
  EXPECT_EQ(root["width"], root["width"].substr(0, root["width"].size() - 2) + "mm");
  EXPECT_EQ(root["height"].substr(root["height"].size() - 2), "mm");
  std::istringstream vb(root["viewBox"]);
  double x0, y0, vw, vh;
  vb >> x0 >> y0 >> vw >> vh;
  EXPECT_EQ(x0, 0);
  EXPECT_EQ(y0, 0);
  EXPECT_DOUBLE_EQ(vw, w);
  EXPECT_DOUBLE_EQ(vh, h);

  // Each face: squares of 9 mm, on a 9 mm lattice, exactly the black ones.
  int expected_black = 0;
  for (int j = -1; j < target.corners_y(); ++j)
    for (int i = -1; i < target.corners_x(); ++i)
      expected_black += target.IsBlack(Face::kFront, (i + 0.5) * 9.0, (j + 0.5) * 9.0);
  for (const char* face : {"front", "back"}) {
    SCOPED_TRACE(face);
    const size_t begin = text.find(std::string("id=\"") + face + "\"");
    ASSERT_NE(begin, std::string::npos);
    const size_t end = text.find(" </g>\n", begin);
    const std::string group = text.substr(begin, end - begin);
    int squares = 0;
    double min_x = 1e9, min_y = 1e9;
    std::vector<std::pair<double, double>> corners;
    static const std::regex square("<rect class=\"square\"[^>]*>");
    for (std::sregex_iterator it(group.begin(), group.end(), square), e; it != e; ++it) {
      auto a = Attributes(it->str());
      EXPECT_DOUBLE_EQ(std::stod(a["width"]), 9.0);
      EXPECT_DOUBLE_EQ(std::stod(a["height"]), 9.0);
      corners.emplace_back(std::stod(a["x"]), std::stod(a["y"]));
      min_x = std::min(min_x, corners.back().first);
      min_y = std::min(min_y, corners.back().second);
      ++squares;
    }
    EXPECT_EQ(squares, expected_black);
    for (const auto& [x, y] : corners) {
      // On the lattice: a whole number of squares from the leftmost/topmost.
      EXPECT_NEAR(std::remainder(x - min_x, 9.0), 0.0, 1e-4);
      EXPECT_NEAR(std::remainder(y - min_y, 9.0), 0.0, 1e-4);
    }
    // The tags' cells are there too, smaller than a square.
    EXPECT_NE(group.find("class=\"tag-cell\""), std::string::npos);
  }

  // The scale bar: 100 mm, and its label says so.
  ASSERT_TRUE(std::regex_search(text, m, std::regex("<rect class=\"scale-bar\"[^>]*>")));
  EXPECT_DOUBLE_EQ(std::stod(Attributes(m.str())["width"]), 100.0);
  EXPECT_NE(text.find("check: this bar is 100.0 mm"), std::string::npos);
  // The page holds the two plates side by side.
  const double plate_w = target.max_x_mm() - target.min_x_mm();
  EXPECT_GT(w, 2 * plate_w);
  std::filesystem::remove(path);
}

TEST(BoardSvg, PlainBoardHasOneFaceAndNoBack) {
  const Target plain = PlainTarget(9, 6, 25.0);
  const BoardSvg svg = MakeBoardSvg(plain);
  EXPECT_NE(svg.text.find("id=\"front\""), std::string::npos);
  EXPECT_EQ(svg.text.find("id=\"back\""), std::string::npos);
  EXPECT_EQ(svg.text.find("tag-cell"), std::string::npos);
  BoardSvgOptions back;
  back.faces = SvgFaces::kBack;
  EXPECT_THROW(MakeBoardSvg(plain, back), InputError);
  // 10x7 squares of 25 mm, alternating: 35 black.
  size_t n = 0, pos = 0;
  while ((pos = svg.text.find("class=\"square\"", pos)) != std::string::npos) ++n, ++pos;
  EXPECT_EQ(n, 35u);
}

// The print, as an independent rasteriser (python3, rects only) sees it,
// is a target the detector reads: the right face, every corner, each where
// the target file puts it. 4 px per mm: a 9 mm square is 36 px.
TEST(BoardSvg, RasterisedPrintIsDetectedWhereTheTargetSaysItsCornersAre) {
  const Target target = DefaultTarget();
  const double px_per_mm = 4.0;
  const std::string dir = std::filesystem::temp_directory_path().string();
  // One python3 run rasterises the three prints (front, back, both).
  const SvgFaces kinds[3] = {SvgFaces::kFront, SvgFaces::kBack, SvgFaces::kBoth};
  std::vector<BoardSvg> svgs;
  std::string cmd =
      "/usr/bin/python3 " STEREORIG_SOURCE_DIR "/targets/testdata/rasterize_svg_rects.py " + std::to_string(px_per_mm);
  for (int k = 0; k < 3; ++k) {
    BoardSvgOptions options;
    options.faces = kinds[k];
    svgs.push_back(MakeBoardSvg(target, options));
    const std::string stem = dir + "/stereorig_raster_test_" + std::to_string(k);
    WriteFileAtomically(stem + ".svg", svgs.back().text);
    cmd += " " + stem + ".svg " + stem + ".png";
  }
  ASSERT_EQ(std::system(cmd.c_str()), 0);
  for (int k = 0; k < 3; ++k) {
    const SvgFaces which = kinds[k];
    const BoardSvg& svg = svgs[k];
    const std::string stem = dir + "/stereorig_raster_test_" + std::to_string(k);
    const cv::Mat grey = cv::imread(stem + ".png", cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(grey.empty());
    std::filesystem::remove(stem + ".png");
    std::filesystem::remove(stem + ".svg");
    const DetectResult r = TargetDetector(target, DetectOptions()).Detect(grey);
    if (which == SvgFaces::kBoth) {
      EXPECT_EQ(r.reason, RejectReason::kBothFaces) << r.message;  // both faces on one sheet
      continue;
    }
    const Face face = which == SvgFaces::kFront ? Face::kFront : Face::kBack;
    ASSERT_EQ(r.faces.size(), 1u) << r.message;
    EXPECT_EQ(r.faces[0].face, face);
    ASSERT_EQ(r.faces[0].quality.num_corners, target.num_corners());
    // Where corner id must be: the plate's top-left on the page, read from the
    // SVG's plate outline, plus the corner's face position; then pixels with
    // (0,0) at the centre of the top-left pixel.
    std::smatch m;
    ASSERT_TRUE(std::regex_search(svg.text, m, std::regex("<rect class=\"plate\"[^>]*>")));
    auto plate = Attributes(m.str());
    const double ox = std::stod(plate["x"]) - target.min_x_mm(), oy = std::stod(plate["y"]) - target.min_y_mm();
    double sum_sq = 0;
    for (size_t i = 0; i < r.faces[0].corner_ids.size(); ++i) {
      const Eigen::Vector3d p = target.CornerInFace(r.faces[0].corner_ids[i]);
      const Eigen::Vector2d expected((ox + p.x()) * px_per_mm - 0.5, (oy + p.y()) * px_per_mm - 0.5);
      sum_sq += (r.faces[0].q_px[i] - expected).squaredNorm();
    }
    // Edges fall on pixel boundaries here (axis-aligned, 4 px per mm), the
    // easy case: a few hundredths of a px; a wrong id would be 36 px off.
    EXPECT_LT(std::sqrt(sum_sq / target.num_corners()), 0.05);
  }
}

}  // namespace
}  // namespace stereorig
