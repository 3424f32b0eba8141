// `stereorig match`: the correspondence stage alone on a rectified pair.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "apps/cli_util.h"
#include "apps/command.h"
#include "apps/output_paths.h"
#include "calib/core/input_error.h"
#include "reconstruct/disparity_band.h"
#include "reconstruct/elapsed_ms.h"
#include "reconstruct/grey_image.h"
#include "reconstruct/matcher.h"
#include "reconstruct/parallel_for.h"
#include "reconstruct/pfm.h"

namespace stereorig {

namespace {

// Which ends of the searched range the matches reach, as `reconstruct`
// judges a module's (ModuleReport::RangeEndsReached): from the band the
// half-resolution pass kept; without one (pyramid_levels, the OpenCV
// matchers), from the same clusters of the final disparities. The band, not
// the final disparities alone: on the walkthrough's pair (true 472-549 px in
// [300, 500)) the final ones lay mostly at 332-392 px, a copy of the grid
// ~22 periods off, and only ~1 % at the range's end, where the band pass's
// matches piled up. Only an end the final disparities reach too
// (RangeEndsHeld): the band pass also matches what `reconstruct` crops
// away, the unlit background, and piled up there at an end the object lay
// well clear of (the demo cup's module 0 in [-20, 140): final disparities
// 43-105 px, warned of the far end).
RangeEnds RangeEndsOf(const MatchResult& result, const MatchOptions& options, const std::vector<float>& valid_px) {
  int occupied_min_px = result.occupied_min_disparity_px, occupied_end_px = result.occupied_end_disparity_px;
  if (occupied_end_px <= occupied_min_px)
    if (const std::optional<DisparityBand> band = OccupiedDisparityBand(valid_px, 0))
      occupied_min_px = band->min_px, occupied_end_px = band->max_px;
  const RangeEnds band =
      RangeEndsReached(options.min_disparity_px, options.num_disparities, occupied_min_px, occupied_end_px);
  const RangeEnds held = RangeEndsHeld(valid_px, options.min_disparity_px, options.num_disparities);
  return {.near = band.near && held.near, .far = band.far && held.far};
}

std::string RangeEndsNamed(RangeEnds ends) {
  return ends.near && ends.far ? "both ends"
         : ends.near           ? "the near end (largest disparities)"
         : ends.far            ? "the far end (smallest disparities)"
                               : "";
}

}  // namespace

int RunMatch(int argc, char** argv) {
  CLI::App app{
      "The correspondence stage alone (dense matching, filtering, sub-pixel refinement) on an already rectified "
      "8-bit grey pair. Writes the left view's disparity (x_right = x_left - d) as PFM: little-endian, rows "
      "bottom to top, invalid pixels = +inf.\n"
      "A module's rectified pair, and the disparity range and ROI the runtime derives for it from the measurement "
      "volume (before its per-capture lit-region crop and band pass, which search less), come from "
      "`stereorig reconstruct ... --rectified-out DIR`, which writes DIR/moduleM_left.png and "
      "DIR/moduleM_right.png and prints this command for each module. Matches piling up at an end of the range "
      "(the range misses the object: the laser grid matched whole periods off) are warned of on stderr.\n\n"
      "Exit codes: 0 ok (with a range warning too); 2 bad usage or input.\n\n"
      "Example (the demo rig's module 0 under the default measurement volume):\n"
      "  stereorig reconstruct --rig demo/rig.yaml --capture demo/dataset/scenes/cup/active --out cup.ply "
      "--rectified-out rect\n"
      "  stereorig match --left rect/module0_left.png --right rect/module0_right.png --min-disparity -100 "
      "--num-disparities 274 --roi 0 0 752 582 --out disp.pfm",
      "stereorig match"};
  std::string left_path, right_path, out_path, matcher = "census_sgm";
  MatchOptions options;
  std::vector<int> roi;
  app.add_option("--left", left_path, "rectified left image (8-bit grey PNG)")->required();
  app.add_option("--right", right_path, "rectified right image (8-bit grey PNG, same size)")->required();
  // Whole numbers read by the flag's rule (cli_util.h), in MatchOptions::
  // Check's ranges: 1.5 or 99999999999 said CLI11's bare "Could not convert".
  AddWholeNumberOption(app, "--min-disparity", &options.min_disparity_px, -1024, 2048,
                       "smallest disparity searched, px")
      ->required()
      ->default_str("");  // required: no default to show
  AddWholeNumberOption(app, "--num-disparities", &options.num_disparities, 2, 1024, "number of disparities searched")
      ->required()
      ->default_str("");
  app.add_option("--out", out_path, "output disparity map (.pfm)")->required()->check(NonEmptyPath());
  app.add_option("--roi", roi, "left-image region to match: x y width height, inside the image (default: whole image)")
      ->expected(4)
      ->check(WholeNumberIn(std::numeric_limits<int>::min(), std::numeric_limits<int>::max()));  // each of the four
  app.add_option("--matcher", matcher,
                 "census_sgm (ours), opencv_sgbm_3way (OpenCV's SGBM, then our filters and sub-pixel fit: the "
                 "bench's baseline) or opencv_sgbm_3way_standalone (SGBM with its own sub-pixel fit only)")
      ->capture_default_str();
  AddWholeNumberOption(app, "--pyramid-levels", &options.pyramid_levels, 0, 3,
                       "census_sgm: halvings before the full-range SGM (0 = full-resolution SGM)");
  AddWholeNumberOption(app, "--threads", &options.num_threads, 1, 64,
                       "threads the matching may use at once (1 = this one only)");
  if (auto rc = ParseArgs(app, argc, argv)) return *rc;

  options.matcher = ParseMatcherKind(matcher, "--matcher");
  if (!roi.empty()) options.roi = cv::Rect(roi[0], roi[1], roi[2], roi[3]);
  // An empty or negative size first, in the words of the full check below
  // (MatchOptions::Check would say "non-negative", as if 0 were fine).
  auto roi_refusal = [&](const std::string& image) {
    return InputError("--roi", std::to_string(roi[0]) + " " + std::to_string(roi[1]) + " " + std::to_string(roi[2]) +
                                   " " + std::to_string(roi[3]) + " must have a positive size and lie inside the " +
                                   image);
  };
  if (!roi.empty() && (roi[2] <= 0 || roi[3] <= 0)) throw roi_refusal("image");
  try {
    options.Check();
  } catch (const InputError& e) {  // named by the flag that set it, not by the options field
    for (const auto& [field, flag] : {std::pair{"num_disparities", "--num-disparities"},
                                      {"min_disparity", "--min-disparity"},
                                      {"roi", "--roi"},
                                      {"pyramid_levels", "--pyramid-levels"},
                                      {"num_threads", "--threads"}})
      if (e.where() == field) throw InputError(flag, e.problem());
    throw;
  }
  OutputPaths outputs;  // its folder checked before the matching runs, and that it is neither image
  outputs.Protect(left_path, "the left image (--left)");
  outputs.Protect(right_path, "the right image (--right)");
  outputs.Claim(out_path, "the disparity map (--out)");
  CheckPfmPath(out_path);  // after the claim: "is the left image" says more than "not .pfm" would
  // A cap on the pixels matched, read from the headers before any pixel is
  // decoded: a 249 KB PNG pair declaring 16000 x 16000 px took 5.8 GB and
  // 24 s and wrote a 1 GB PFM (the runtime holds ~23 bytes a pixel), where
  // reconstruct, check and calibrate refuse it by the rig's image size. 50
  // Mpx is twice the largest machine-vision stereo cameras' (~25 Mpx) and
  // bounds match at ~1.2 GB.
  constexpr long long kMaxMatchPixels = 50000000;
  const std::string why_max = "match reads (twice the largest stereo camera's; crop the pair to the region to match)";
  const cv::Mat left = ReadGreyImage(left_path, std::nullopt, kMaxMatchPixels, why_max);
  const cv::Mat right = ReadGreyImage(right_path, std::nullopt, kMaxMatchPixels, why_max);
  if (left.size() != right.size()) throw InputError(right_path, "size differs from the left image");
  // Smaller, the coarse level has no pixel (OpenCV's resize aborted: exit 134).
  if (const MinMatchImage min = MinMatchImageSize(options); left.cols < min.size.width || left.rows < min.size.height)
    throw InputError(left_path, "is " + std::to_string(left.cols) + "x" + std::to_string(left.rows) +
                                    " px (the right image too), smaller than the " + std::to_string(min.size.width) +
                                    "x" + std::to_string(min.size.height) + " px match needs " + min.why);
  // A region partly or wholly outside the image, or empty, is a mistake to
  // name, not one to clip or widen to the whole image without a word.
  const cv::Rect image(0, 0, left.cols, left.rows);
  if (!roi.empty() && (options.roi & image) != options.roi)
    throw roi_refusal(std::to_string(left.cols) + "x" + std::to_string(left.rows) + " image");
  const cv::Rect matched = roi.empty() ? image : options.roi;

  const auto t0 = std::chrono::steady_clock::now();
  const MatchResult result = WorkerPool(options.num_threads).Run([&] { return Match(left, right, options); });
  const double ms = MsSince(t0);
  WritePfm(result.disparity_px, out_path);
  std::vector<float> valid_px;  // in the matched region: outside it nothing is
  for (int y = matched.y; y < matched.y + matched.height; ++y)
    for (int x = matched.x; x < matched.x + matched.width; ++x)
      if (const float d = result.disparity_px.at<float>(y, x); std::isfinite(d)) valid_px.push_back(d);
  const int valid = int(valid_px.size());
  const std::string ends = RangeEndsNamed(RangeEndsOf(result, options, valid_px));
  std::printf("%s: %d valid disparities of %d px%s (%.1f%%) in %.1f ms; wrote %s%s\n", MatcherKindName(options.matcher),
              valid, matched.area(), roi.empty() ? "" : " in --roi", 100.0 * valid / matched.area(), ms,
              out_path.c_str(), ends.empty() ? "" : ("; warning: they reach " + ends + " of the range").c_str());
  const std::string range = "[" + std::to_string(options.min_disparity_px) + ", " +
                            std::to_string(options.min_disparity_px + options.num_disparities) +
                            ") px (--min-disparity, --num-disparities)";
  if (!ends.empty())
    std::fprintf(stderr,
                 "stereorig match: warning: the disparities pile up at %s of the range %s: the range likely misses "
                 "the object (its surface goes on past the range, or the laser grid was matched whole periods off, "
                 "every such disparity wrong); widen or move the range (`stereorig reconstruct --rectified-out` "
                 "prints the range a rig's module needs)\n",
                 ends.c_str(), range.c_str());
  else if (valid == 0)
    std::fprintf(stderr,
                 "stereorig match: hint: no valid disparity: the range %s may miss the scene, or the images hold no "
                 "texture to match (`stereorig reconstruct --rectified-out` prints the range a rig's module needs)\n",
                 range.c_str());
  return kExitOk;
}

}  // namespace stereorig
