// `stereorig target`: the printable target (SVG, true scale), and optionally
// its target file to start from.
#include <cstdio>
#include <vector>

#include "apps/cli_util.h"
#include "apps/command.h"
#include "apps/output_paths.h"
#include "calib/core/atomic_file.h"
#include "calib/core/file_suffix.h"
#include "calib/core/input_error.h"
#include "targets/board_svg.h"
#include "targets/target.h"
#include "targets/target_file.h"

namespace stereorig {

namespace {

// The default target's design at another size, checked as a target file's
// layout is (tags clear of the squares and of each other); a problem is
// named by the flags that chose it.
Target ResizedDefaultTarget(int corners_x, int corners_y, double square_mm, double thickness_mm) {
  try {
    Target::Layout layout = DoubleSidedTarget(corners_x, corners_y, square_mm).layout();
    layout.back_from_front = IdealBackFromFront(corners_x, square_mm, thickness_mm);
    return Target(layout, "");
  } catch (const InputError& e) {
    throw InputError("--corners, --square-mm", e.problem());
  }
}

// --square-mm under 1 mm, refused as the target file's square_size_mm is:
// with the unit it was likely typed in (SmallSquareHint).
CLI::Validator SmallSquareUnitHint() {
  return CLI::Validator(
      [](const std::string& text) {
        double square_mm = 0;
        if (!CLI::detail::lexical_cast(text, square_mm)) return std::string();  // the range check refuses it
        const std::string hint = SmallSquareHint(square_mm);
        return hint.empty() ? hint : text + ": " + hint;
      },
      "", "SmallSquareUnitHint");
}

}  // namespace

int RunTarget(int argc, char** argv) {
  CLI::App app{
      "Write a printable target at true scale: an SVG in millimetres with both faces side by side (front left, "
      "back right), each face's name and tag IDs, markers at corner 0's row and column, and a 100 mm scale bar. "
      "Print at 100 % (actual size, no fit-to-page), then measure the bar and the squares (docs/targets.md).\n\n"
      "Without --target, the embedded default target (11x9 inner corners of 9 mm, tag36h11, front IDs 0-7, back "
      "IDs 100-107, a 5 mm plate), or its design at another size (--corners, --square-mm, --thickness-mm): the same "
      "tags and margins, the back face in register with the front. --write-target saves the target file used, to "
      "edit and measure against: its back_from_front and flatness are the design's until you measure the board.\n\n"
      "Exit codes: 0 ok; 2 bad usage or input.\n\n"
      "Examples:\n"
      "  stereorig target --out board.svg --write-target board.yaml\n"
      "  stereorig target --corners 13 10 --square-mm 12 --thickness-mm 6 --out b12.svg --write-target b12.yaml\n"
      "  stereorig target --target my_board.yaml --face back --out back.svg",
      "stereorig target"};
  std::string target_path, out_path, write_target, faces = "both";
  std::vector<int> corners;
  double square_mm = 0, thickness_mm = 0;
  CLI::Option* target_option =
      app.add_option("--target", target_path, "target file (YAML, docs/targets.md); default: the embedded default");
  CLI::Option* corners_option =
      app.add_option("--corners", corners, "the default's design with X x Y inner corners (default 11 9)")
          ->expected(2)
          ->check(CLI::Range(2, kMaxInnerCorners))
          ->excludes(target_option);
  CLI::Option* square_option =
      app.add_option("--square-mm", square_mm, "the default's design with squares of this edge, mm (default 9)")
          ->check(PositiveValue())        // NaN passes CLI11's range (its comparisons fail)
          ->check(SmallSquareUnitHint())  // before the range: its "not in range 1 to 500" names no unit
          ->check(CLI::Range(1.0, 500.0))
          ->excludes(target_option);
  CLI::Option* thickness_option =
      app.add_option(
             "--thickness-mm", thickness_mm,
             "the default's design on a plate this thick, mm (default 5): the back face's depth behind the front")
          ->check(PositiveValue())  // NaN passes CLI11's range
          ->check(CLI::Range(0.1, 100.0))
          ->excludes(target_option);
  app.add_option("--out", out_path, "SVG to write (atomically)")->required()->check(NonEmptyPath());
  app.add_option("--face", faces, "which faces to draw: both, front or back")
      ->check(CLI::IsMember({"both", "front", "back"}))
      ->capture_default_str();
  app.add_option("--write-target", write_target, "also write the target file used here (YAML)");
  if (auto rc = ParseArgs(app, argc, argv)) return *rc;
  // Neither output may be the --target file. Writing it back was allowed
  // once (what it read, defaults filled in), but a target file is edited
  // and measured by hand: the rewrite dropped its comments ("# MEASURED
  // with calipers") and its layout, with exit 0.
  OutputPaths outputs;
  outputs.Protect(target_path, "the target file (--target)");
  if (!write_target.empty()) outputs.Claim(write_target, "the target file (--write-target)");
  outputs.Claim(out_path, "the SVG (--out)");
  // As every output named by its format (a cloud's .ply, a map's .pfm):
  // --out board.txt wrote an SVG a viewer or print dialog would not open.
  if (!EndsWithIgnoringCase(out_path, ".svg"))
    throw InputError(out_path, "the target output must end in .svg (it is written as SVG)");

  const bool resized = corners_option->count() || square_option->count() || thickness_option->count();
  const Target target = !target_path.empty() ? ReadTargetFile(target_path)
                        : resized
                            ? ResizedDefaultTarget(corners.empty() ? 11 : corners[0], corners.empty() ? 9 : corners[1],
                                                   square_option->count() ? square_mm : 9.0,
                                                   thickness_option->count() ? thickness_mm : 5.0)
                            : DefaultTarget();
  // Named by the flag and the file here: the SVG writer's own refusal
  // ("board svg: ...") named neither.
  if (faces == "back" && !target.double_sided())
    throw InputError("--face", "back: " + target_path + " is a plain (one-sided) board, with no back face");
  BoardSvgOptions options;
  options.faces = faces == "front" ? SvgFaces::kFront : faces == "back" ? SvgFaces::kBack : SvgFaces::kBoth;
  const BoardSvg svg = MakeBoardSvg(target, options);
  AtomicOutputSet written;  // both or neither
  written.Add(out_path, svg.text);
  if (!write_target.empty()) written.Add(write_target, TargetToYaml(target));
  written.Commit();
  std::printf("wrote %s: page %.1f x %.1f mm; print at 100 %% and check that the bar measures %.1f mm\n",
              out_path.c_str(), svg.width_mm, svg.height_mm, options.scale_bar_mm);
  if (!write_target.empty()) std::printf("wrote %s\n", write_target.c_str());
  return kExitOk;
}

}  // namespace stereorig
