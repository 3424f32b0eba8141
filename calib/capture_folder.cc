#include "calib/capture_folder.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <opencv2/core.hpp>
#include <optional>
#include <tuple>

#include "calib/core/capture_image_name.h"
#include "calib/core/input_error.h"
#include "calib/core/input_file.h"
#include "calib/core/number_text.h"
#include "calib/core/png_reader.h"
#include "calib/core/printable_text.h"
#include "calib/layout_file.h"
#include "targets/target_file.h"

namespace stereorig {

namespace fs = std::filesystem;

namespace {

// Where a captures folder's captures are: `dir`, or its calibration/
// sub-folder if it has one (a dataset written by `stereorig simulate`).
fs::path CapturesRoot(const fs::path& dir) { return fs::is_directory(dir / "calibration") ? dir / "calibration" : dir; }

// A dataset written by `stereorig simulate` without a calibration/ folder
// (--calibration-captures 0): its spec.yaml and truth/ say what it is
// (docs/formats.md "Datasets"). Its sub-folders (scenes/, truth/) are no
// captures: taken as such, the run stopped on "truth/cam0.png: missing".
bool IsDatasetWithoutCaptures(const fs::path& dir) {
  return !fs::exists(dir / "calibration") && fs::is_regular_file(dir / "spec.yaml") && fs::is_directory(dir / "truth");
}

// Whether `folder` holds a camK.png (any K).
bool HoldsCameraImage(const fs::path& folder) {
  for (const auto& e : fs::directory_iterator(folder))
    if (CameraIndexOfImageName(e.path().filename().string())) return true;
  return false;
}

std::string Lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return std::tolower(c); });
  return text;
}

// Whether a file's name is a capture image's, however misnamed: a picture
// (.png, .jpg, .tif, .bmp, .pgm in any case) or a name starting with "cam" in
// any case (Cam0.png, cam_0.png, cam00.png); not a camera model
// (camK.cameramodel, which --export-cameramodels writes).
bool LooksLikeCaptureImage(const std::string& file_name) {
  const std::string name = Lower(file_name);
  const std::string ext = fs::path(name).extension().string();
  if (ext == ".cameramodel") return false;
  for (const char* picture : {".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp", ".pgm"})
    if (ext == picture) return true;
  return name.rfind("cam", 0) == 0;
}

// The files of `folder` that look like capture images (LooksLikeCaptureImage),
// and those one sub-folder deeper ("sub/cam0.png"), sorted by name.
std::vector<std::string> CaptureImageLikeFiles(const fs::path& folder) {
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(folder)) {
    const std::string name = e.path().filename().string();
    if (e.is_directory()) {
      for (const auto& f : fs::directory_iterator(e.path()))
        if (!f.is_directory() && LooksLikeCaptureImage(f.path().filename().string()))
          files.push_back(name + "/" + f.path().filename().string());
    } else if (LooksLikeCaptureImage(name)) {
      files.push_back(name);
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

// A sub-folder of the captures holding images, none named camK.png
// (Cam0.png, cam0.PNG, left.png, or images one folder deeper).
struct MisnamedCapture {
  fs::path folder;
  std::vector<std::string> files;  // its image-like files (CaptureImageLikeFiles)
};

// The capture sub-folders of `root` (a folder), sorted by name. Not a
// hidden folder (.thumbs, a viewer's), nor one holding no image at all
// (the camera models calibrate --export-cameramodels wrote beside the
// captures): each was taken for a capture and stopped a re-run on
// "models/cam0.png: missing". Those are added to `skipped`, if given,
// sorted. A folder holding images but no camK.png (Cam0.png) is added to
// `misnamed`, if given, for the caller to refuse: skipped, it silently
// lost a night's capture. A folder holding some cameras' images but not
// all is a capture still, refused for the missing ones.
std::vector<fs::path> CaptureSubfolders(const fs::path& root, std::vector<fs::path>* skipped = nullptr,
                                        std::vector<MisnamedCapture>* misnamed = nullptr) {
  std::vector<fs::path> captures;
  for (const auto& e : fs::directory_iterator(root)) {
    if (!e.is_directory()) continue;
    const bool hidden = e.path().filename().string().rfind('.', 0) == 0;
    if (!hidden && HoldsCameraImage(e.path())) {
      captures.push_back(e.path());
      continue;
    }
    std::vector<std::string> files = hidden ? std::vector<std::string>{} : CaptureImageLikeFiles(e.path());
    if (!files.empty()) {
      if (misnamed) misnamed->push_back({e.path(), std::move(files)});
    } else if (skipped) {
      skipped->push_back(e.path());
    }
  }
  std::sort(captures.begin(), captures.end());
  if (skipped) std::sort(skipped->begin(), skipped->end());
  if (misnamed)
    std::sort(misnamed->begin(), misnamed->end(), [](const auto& a, const auto& b) { return a.folder < b.folder; });
  return captures;
}

// Throws InputError naming the first of `misnamed` (CaptureSubfolders) and
// its files, and the others' folders, unless it is empty.
void RefuseMisnamedCaptures(const std::vector<MisnamedCapture>& misnamed) {
  if (misnamed.empty()) return;
  constexpr size_t kFilesNamed = 6;
  const MisnamedCapture& first = misnamed.front();
  std::string files;
  for (size_t i = 0; i < first.files.size() && i < kFilesNamed; ++i) files += (i ? ", " : "") + first.files[i];
  if (first.files.size() > kFilesNamed) files += " and " + std::to_string(first.files.size() - kFilesNamed) + " more";
  std::string others;
  for (size_t i = 1; i < misnamed.size(); ++i) others += (i > 1 ? ", " : "") + misnamed[i].folder.string();
  throw InputError(first.folder.string(),
                   "holds " + files +
                       " but no camK.png: each capture holds one image per camera named cam0.png, cam1.png, ... "
                       "(lower case, no leading zero, in the capture's own folder); rename them, or move the "
                       "folder out of the captures" +
                       (others.empty() ? "" : " (so too: " + others + ")"));
}

}  // namespace

std::string SkippedFoldersNote(const std::vector<std::string>& skipped_folders) {
  if (skipped_folders.empty()) return "";
  std::string folders;
  for (const std::string& folder : skipped_folders) folders += (folders.empty() ? "" : ", ") + folder;
  return "skipped: " + folders + " (not captures: hidden, or holding no image)";
}

namespace {

std::string SizeText(const std::pair<int, int>& size_px) {
  return std::to_string(size_px.first) + "x" + std::to_string(size_px.second);
}

// Each camera's image size (cameras[c] named camC, 0x0 if none of its
// images could be read), from the headers of its images in `captures` (of
// `dir`). Throws InputError unless each camera's images are of one size,
// naming the odd ones out: those of a size other than most of the camera's
// images have, or, where no size has most, every size with its files. An
// image that is missing or no PNG is left to the detection loop, which
// names it. The first image read used to set the size, and a first image
// of the wrong size had the error name a right one.
std::vector<CameraImager> CameraImageSizes(const std::string& dir, const std::vector<fs::path>& captures,
                                           int num_cameras) {
  std::vector<CameraImager> cameras(num_cameras);
  for (int c = 0; c < num_cameras; ++c) {
    cameras[c].name = "cam" + std::to_string(c);
    std::map<std::pair<int, int>, std::vector<std::string>> images_of_size;
    int images = 0;
    for (const fs::path& capture : captures) {
      const fs::path image = capture / CameraImageName(c);
      if (!fs::is_regular_file(image)) continue;
      std::optional<PngReader> png;
      try {
        png = PngReader::Open(image.string());
      } catch (const InputError&) {
      }
      if (!png) continue;
      images_of_size[{int(png->width_px()), int(png->height_px())}].push_back(image.string());
      ++images;
    }
    if (images_of_size.size() == 1) std::tie(cameras[c].width_px, cameras[c].height_px) = images_of_size.begin()->first;
    if (images_of_size.size() < 2) continue;
    const auto most = std::max_element(images_of_size.begin(), images_of_size.end(),
                                       [](const auto& a, const auto& b) { return a.second.size() < b.second.size(); });
    const std::string camera = "cam" + std::to_string(c);
    if (2 * most->second.size() > size_t(images)) {
      // The first image not of the majority's size is the error's file;
      // the others are listed after it.
      std::string first_path, first_size, others;
      for (const auto& [size, paths] : images_of_size) {
        if (size == most->first) continue;
        for (const std::string& path : paths) {
          if (first_path.empty()) {
            first_path = path;
            first_size = SizeText(size);
          } else {
            others += (others.empty() ? "" : ", ") + path + " " + SizeText(size);
          }
        }
      }
      throw InputError(first_path, "image of the wrong size: " + first_size + ", but " +
                                       std::to_string(most->second.size()) + " of " + camera + "'s " +
                                       std::to_string(images) + " images are " + SizeText(most->first) +
                                       (others.empty() ? "" : " (also of another size: " + others + ")"));
    }
    std::string sizes;
    for (const auto& [size, paths] : images_of_size) {
      sizes += (sizes.empty() ? "" : "; ") + SizeText(size) + ":";
      for (const std::string& path : paths) sizes += " " + path;
    }
    throw InputError(dir, camera + "'s images differ in size, and no size is most of them: " + sizes +
                              " (images of another camera among them?)");
  }
  return cameras;
}

// Throws InputError if a module of `modules` pairs cameras whose images
// (`cameras`, from the captures in `dir`; 0x0 not known) differ in size.
// Calibrated, such a rig was written, exit 0, and refused by every
// reconstruction after ("its two cameras' imagers differ in size (not
// supported)": the runtime matches a module's rows), as the simulator
// refuses such a spec. From the headers, before the detection (minutes on a
// real rig), which it used to follow.
void RefuseModulesOfTwoImagerSizes(const std::string& dir, const std::vector<ModuleLayout>& modules,
                                   const std::vector<CameraImager>& cameras) {
  for (const ModuleLayout& m : modules) {
    const CameraImager &left = cameras[m.left_camera], &right = cameras[m.right_camera];
    if (left.width_px == 0 || right.width_px == 0) continue;  // no image read: the detection loop names it
    if (left.width_px == right.width_px && left.height_px == right.height_px) continue;
    throw InputError(dir, m.name + "'s cameras differ in imager size: " + left.name + "'s images are " +
                              SizeText({left.width_px, left.height_px}) + ", " + right.name + "'s " +
                              SizeText({right.width_px, right.height_px}) +
                              "; a module's two cameras need one (stereorig reconstruct matches their rows): window "
                              "both alike, or images of another camera among them?");
  }
}

// The capture index of each of `captures` (sorted, CaptureSubfolders): a
// numeric name's number (007 is 7); the other names, in their sorted order,
// the indices after the largest number (all of them from 0 when no name is
// a number). A named folder among numbered ones (a retake `003b`, a
// `final_pose` beside `001`..`007`) is so a capture of its own: its place
// among all the folders used to be its index and often a numbered folder's.
// Throws InputError for a number past an int (a time stamp, 20261207153000:
// std::stoi aborted the run), and for two folders of one number (003 and
// 0003): their views were merged into one capture, a board pose each camera
// saw twice ("observed twice", or a night checked as one capture fewer).
std::vector<int> CaptureIndices(const std::vector<fs::path>& captures) {
  constexpr size_t kMaxDigits = 9;  // any number of 9 digits fits an int, and so does it plus the named folders
  std::vector<int> indices(captures.size(), -1);
  std::map<int, fs::path> folder_of;
  int largest_number = -1;
  for (size_t n = 0; n < captures.size(); ++n) {
    const std::string name = captures[n].filename().string();
    if (!std::all_of(name.begin(), name.end(), [](unsigned char c) { return std::isdigit(c) != 0; })) continue;
    const std::string digits = name.substr(std::min(name.find_first_not_of('0'), name.size()));
    if (digits.size() > kMaxDigits)
      throw InputError(captures[n].string(), "a capture folder's number must be under 10^" +
                                                 std::to_string(kMaxDigits) +
                                                 " (it is the capture's index): rename it (000, 001, ...)");
    const int index = digits.empty() ? 0 : std::stoi(digits);
    if (const auto [it, added] = folder_of.emplace(index, captures[n]); !added)
      throw InputError(captures[n].string(), "is capture " + std::to_string(index) + ", as " + it->second.string() +
                                                 " is (a folder's number is its capture's index, 003 and 0003 "
                                                 "alike): rename one (000, 001, ...)");
    indices[n] = index;
    largest_number = std::max(largest_number, index);
  }
  int next = largest_number + 1;
  for (int& index : indices)
    if (index < 0) index = next++;
  return indices;
}

}  // namespace

std::vector<std::string> CaptureFolderImages(const std::string& dir) {
  std::vector<std::string> images;
  if (!fs::is_directory(dir) || IsDatasetWithoutCaptures(dir)) return images;
  for (const fs::path& capture : CaptureSubfolders(CapturesRoot(dir))) {
    for (const auto& e : fs::directory_iterator(capture)) {
      if (CameraIndexOfImageName(e.path().filename().string())) images.push_back(e.path().string());
    }
  }
  std::sort(images.begin(), images.end());
  return images;
}

void RequireCapturesFolder(const std::string& dir) {
  if (fs::is_directory(dir)) return;
  throw InputError(dir, fs::exists(dir) ? "is a file, not a captures folder" : "no such captures folder");
}

DetectedCaptures DetectCaptureFolder(const std::string& dir_in, const Target& target, int num_cameras,
                                     const CaptureFolderOptions& per_folder) {
  STEREORIG_CHECK(per_folder.rig_cameras.empty() || int(per_folder.rig_cameras.size()) == num_cameras);
  RequireCapturesFolder(dir_in);
  if (IsDatasetWithoutCaptures(dir_in))
    throw InputError(dir_in,
                     "is a simulated dataset (spec.yaml, truth/) with no target captures: a dataset's are in its "
                     "calibration/ folder, which this one lacks (simulated with --calibration-captures 0?)");
  const fs::path dir = CapturesRoot(dir_in);
  std::vector<fs::path> skipped;
  std::vector<MisnamedCapture> misnamed;
  const std::vector<fs::path> captures = CaptureSubfolders(dir, &skipped, &misnamed);
  RefuseMisnamedCaptures(misnamed);
  if (captures.empty()) {
    std::vector<std::string> skipped_names;
    for (const fs::path& folder : skipped) skipped_names.push_back(folder.string());
    const std::string note = SkippedFoldersNote(skipped_names);
    throw InputError(dir.string(),
                     "holds no capture folders (expected NNN/camK.png)" + (note.empty() ? "" : "; " + note));
  }

  const std::vector<int> indices = CaptureIndices(captures);
  if (per_folder.rig_cameras.empty())
    RefuseModulesOfTwoImagerSizes(dir.string(), per_folder.modules,
                                  CameraImageSizes(dir.string(), captures, num_cameras));

  DetectedCaptures out;
  for (const fs::path& folder : skipped) out.skipped_folders.push_back(folder.string());
  out.num_captures = static_cast<int>(captures.size());
  out.cameras.resize(num_cameras);
  for (int c = 0; c < num_cameras; ++c) {
    out.cameras[c].name = "cam" + std::to_string(c);
    if (!per_folder.rig_cameras.empty()) {
      out.cameras[c].width_px = per_folder.rig_cameras[c].width_px;
      out.cameras[c].height_px = per_folder.rig_cameras[c].height_px;
    }
  }
  const TargetDetector detector(target, per_folder.detect);
  for (size_t n = 0; n < captures.size(); ++n) {
    const std::string name = captures[n].filename().string();
    const int capture = indices[n];
    if (per_folder.incomplete_set_aside) {
      std::vector<std::string> missing;
      for (int c = 0; c < num_cameras; ++c) {
        // Empty counts as missing: a trigger or a write that failed leaves
        // a file of 0 bytes as often as none (it refused the night).
        const fs::path image = captures[n] / CameraImageName(c);
        std::error_code error;
        if (!fs::exists(image) || (fs::is_regular_file(image) && fs::file_size(image, error) == 0 && !error))
          missing.push_back(image.string());
      }
      if (!missing.empty()) {
        out.missing_images.insert(out.missing_images.end(), missing.begin(), missing.end());
        --out.num_captures;
        if (per_folder.progress)
          std::fprintf(stderr, "%s\n",
                       PrintableText("detect " + name + ": set aside, an image missing or empty").c_str());
        continue;
      }
    }
    out.capture_names[capture] = name;
    std::string line = "detect " + name + ":";
    for (int c = 0; c < num_cameras; ++c) {
      const fs::path image = captures[n] / CameraImageName(c);
      if (!fs::exists(image))
        throw InputError(image.string(), "missing (each capture needs camK.png for every camera)");
      RequireInputFile(image.string());  // a folder named cam0.png
      // Not a PNG though so named (a JPEG): its decoder would complain first.
      std::optional<PngReader> png = PngReader::Open(image.string());
      if (!png) throw InputError(image.string(), "is not a PNG file, though named .png");
      // Held to what the runtime reads (reconstruct/grey_image.h), from the
      // header, before decoding: imread's own conversion to grey would take
      // a 16-bit image's high byte (a 12-bit camera's image in the low bits
      // turns nearly black, and then no board is found) and let a colour
      // capture through that `reconstruct` refuses. The channels are
      // imread's (IMREAD_UNCHANGED), as png_reader.h gives them; the bits the
      // file's own, so that 1-, 2- and 4-bit grey (which the decoder scales
      // to 8) is refused here as by the runtime.
      if (png->channels() != 1 || png->stored_bit_depth() != 8)
        throw InputError(image.string(),
                         "must be an 8-bit single-channel (grey) image, as `stereorig reconstruct` "
                         "reads too (this one has " +
                             std::to_string(png->channels()) + " channel(s) of " +
                             std::to_string(png->stored_bit_depth()) + " bits)");
      // The size from the header too, before the pixels are allocated and
      // decoded: an image of another camera, or a huge one, is refused
      // without paying for it.
      const int width_px = int(png->width_px()), height_px = int(png->height_px());
      CameraImager& spec = out.cameras[c];
      if (spec.width_px == 0) {
        spec.width_px = width_px;
        spec.height_px = height_px;
      } else if (spec.width_px != width_px || spec.height_px != height_px) {
        const std::string size = std::to_string(width_px) + "x" + std::to_string(height_px);
        const std::string expected = std::to_string(spec.width_px) + "x" + std::to_string(spec.height_px);
        if (!per_folder.rig_cameras.empty())
          throw InputError(image.string(), size + ", but the rig's cam" + std::to_string(c) + " is " + expected +
                                               " (an image of another camera, or captures from another rig?)");
        throw InputError(image.string(), "image of the wrong size: " + size + ", but cam" + std::to_string(c) +
                                             "'s other images are " + expected);
      }
      cv::Mat grey(height_px, width_px, CV_8UC1);
      png->Read(grey.data, grey.step);
      DetectResult r;
      try {
        r = detector.Detect(grey);
      } catch (const cv::Exception& e) {
        // A detector failure on one image (e.g. OpenCV refusing a degenerate
        // grid) loses that view, not the calibration; the log says so.
        r.reason = RejectReason::kNoChessboard;
        r.message = std::string("detector failed: ") + e.what();
      }
      ImageDetectionLog log{capture, c, image.string(), false, Face::kFront, 0, 0, r.message, r.reason};
      if (r.reason == RejectReason::kNone && !r.faces.empty()) {
        const FaceDetection& f = r.faces[0];
        // A corner reported outside the image cannot be a real detection
        // (the detector extrapolated it): drop it, and say so.
        BoardObservation obs{capture, c, f.face, {}, {}};
        for (size_t i = 0; i < f.corner_ids.size(); ++i) {
          const Eigen::Vector2d& q = f.q_px[i];
          if (q.x() < -0.5 || q.y() < -0.5 || q.x() > grey.cols - 0.5 || q.y() > grey.rows - 0.5) {
            ++log.num_outside;
            continue;
          }
          obs.corner_ids.push_back(f.corner_ids[i]);
          obs.q_px.push_back(q);
        }
        log.accepted = true;
        log.face = f.face;
        log.num_corners = static_cast<int>(obs.corner_ids.size());
        log.reason.clear();
        log.reject = RejectReason::kNone;
        line += " cam" + std::to_string(c) + " " + FaceName(f.face) + " " + std::to_string(log.num_corners);
        if (log.num_outside) line += " (" + std::to_string(log.num_outside) + " outside the image dropped)";
        out.observations.push_back(std::move(obs));
      } else {
        line += " cam" + std::to_string(c) + " -(" + RejectReasonName(r.reason) + ")";
      }
      out.log.push_back(log);
    }
    if (per_folder.progress) std::fprintf(stderr, "%s\n", PrintableText(line).c_str());
  }
  return out;
}

std::string RejectedViewsNote(const DetectedCaptures& detected, const Target& target, const std::string& target_path) {
  std::map<std::string, int> by_reason;
  int rejected = 0;
  for (const ImageDetectionLog& log : detected.log) {
    if (log.accepted) continue;
    ++rejected;
    ++by_reason[RejectReasonName(log.reject)];
  }
  const int images = static_cast<int>(detected.log.size());
  int off_layout = 0;
  for (const RejectReason r : {RejectReason::kAmbiguous, RejectReason::kGridMismatch})
    if (const auto it = by_reason.find(RejectReasonName(r)); it != by_reason.end()) off_layout += it->second;
  if (2 * rejected <= images || 10 * off_layout < images) return "";
  std::string reasons;
  for (const auto& [reason, n] : by_reason) reasons += (reasons.empty() ? "" : ", ") + std::to_string(n) + " " + reason;
  return std::to_string(rejected) + " of " + std::to_string(images) + " images rejected (" + reasons + "): is " +
         target_path + " this board's target file? It says corners_x " + std::to_string(target.corners_x()) +
         ", corners_y " + std::to_string(target.corners_y()) +
         " (inner corners along a row, along a column); a board whose grid differs (or the two swapped) fits no "
         "single orientation";
}

std::string NoBoardFoundNote(const DetectedCaptures& detected, const Target& target, const std::string& target_path) {
  const int images = static_cast<int>(detected.log.size());
  // No board of the file's: no chessboard of its grid (a plain target), or
  // none of its tags (a double-sided one: targets/detect.h).
  const int no_board = static_cast<int>(std::count_if(detected.log.begin(), detected.log.end(), [](const auto& log) {
    return !log.accepted && (log.reject == RejectReason::kNoChessboard || log.reject == RejectReason::kNoTags);
  }));
  if (2 * no_board <= images) return "";
  return std::to_string(no_board) + " of " + std::to_string(images) + " images show no board as " + target_path +
         " describes it (corners_x " + std::to_string(target.corners_x()) + ", corners_y " +
         std::to_string(target.corners_y()) + ", inner corners along a row, along a column" +
         (target.double_sided() ? ", and its tags" : "") +
         "): is the board in view and lit, and is that file this board's target file?";
}

namespace {

// "" if every index in [0, n) was seen, else "column 12" or "columns 1, 12"
// (1-based).
std::string NeverSeen(const std::vector<bool>& seen, const std::string& what) {
  std::vector<int> never;
  for (size_t i = 0; i < seen.size(); ++i)
    if (!seen[i]) never.push_back(static_cast<int>(i) + 1);
  if (never.empty()) return "";
  std::string out = what + (never.size() > 1 ? "s " : " ");
  for (size_t i = 0; i < never.size(); ++i) out += (i ? ", " : "") + std::to_string(never[i]);
  return out;
}

}  // namespace

std::string NeverSeenCornersNote(const std::vector<BoardObservation>& observations, const Target& target,
                                 const std::string& target_path) {
  const int nx = target.corners_x(), ny = target.corners_y();
  std::vector<bool> column_seen(nx, false), row_seen(ny, false);
  int views = 0;
  for (const BoardObservation& o : observations) {
    if (o.corner_ids.empty()) continue;
    ++views;
    for (int id : o.corner_ids) {
      if (id < 0 || id >= nx * ny) continue;
      column_seen[id % nx] = true;
      row_seen[id / nx] = true;
    }
  }
  if (views == 0) return "";
  const std::string columns = NeverSeen(column_seen, "column"), rows = NeverSeen(row_seen, "row");
  if (columns.empty() && rows.empty()) return "";
  const std::string never = columns + (columns.empty() || rows.empty() ? "" : " and ") + rows;
  return target_path + " says corners_x " + std::to_string(nx) + ", corners_y " + std::to_string(ny) +
         " (inner corners along a row, along a column), but its " + never + " of corners (1-based) never showed in " +
         "any of the " + std::to_string(views) +
         " accepted views: does the board have that many? (the rig records the file's grid)";
}

std::string CamerasLeftOutNote(const std::string& dir, int num_cameras) {
  std::map<int, int> captures_of;  // camera index -> captures holding its image
  for (const std::string& image : CaptureFolderImages(dir)) {
    const std::optional<int> camera = CameraIndexOfImageName(fs::path(image).filename().string());
    if (camera && *camera >= num_cameras) ++captures_of[*camera];
  }
  if (captures_of.empty()) return "";
  std::string images;
  for (const auto& [camera, captures] : captures_of)
    images += (images.empty() ? "" : ", ") + CameraImageName(camera) + " (in " + std::to_string(captures) +
              (captures == 1 ? " capture)" : " captures)");
  return dir + " holds " + images + ", but the layout names cameras 0 to " + std::to_string(num_cameras - 1) +
         " only: the rig leaves them out (name them in a module of the layout to calibrate them)";
}

bool IsTooFewViewsProblem(const std::string& problem) {
  return problem.find("never sees the board") != std::string::npos ||
         problem.find("too few views") != std::string::npos;
}

namespace {

// One line per camera whose views stage 1 found repeating a board pose
// (IntrinsicsReport::repeated_pose_captures), naming them by folder: they
// count as views of their own, the sigmas taking them as independent.
// Eight copies of one capture calibrated, exit 0, a baseline 10.8 mm off;
// stage 1 refuses too few distinct poses, and a few repeats among enough
// are legitimate (a board left still between two captures), so a warning.
std::vector<std::string> RepeatedPosesNotes(const CalibrationReport& report) {
  std::vector<std::string> notes;
  for (const IntrinsicsReport& r : report.intrinsics) {
    if (r.repeated_pose_captures.empty()) continue;
    std::string groups;
    for (const std::vector<int>& captures : r.repeated_pose_captures) {
      groups += groups.empty() ? "" : "; ";
      for (size_t i = 0; i < captures.size(); ++i) groups += (i ? ", " : "") + report.CaptureName(captures[i]);
    }
    notes.push_back("camera " + std::to_string(r.camera) + " (" + r.camera_name +
                    ") sees one board pose again in captures " + groups +
                    " (corners apart by their noise alone): a frame delivered again, or the board left still? "
                    "Each counts as a view of its own, and the sigmas take their corners as independent: too small");
  }
  return notes;
}

}  // namespace

std::vector<std::string> StereoViewsLeftOutNotes(const CalibrationReport& report) {
  std::vector<std::string> notes;
  for (const StereoReport& s : report.stereo) {
    if (s.views_left_out.empty()) continue;
    std::string views;
    int edge_on = 0;
    for (size_t k = 0; k < s.views_left_out.size(); ++k) {
      const auto& [capture, camera] = s.views_left_out[k];
      views += (views.empty() ? "" : ", ") + report.CaptureName(capture) + "/" + CameraImageName(camera);
      const double tilt_deg = k < s.views_left_out_tilt_deg.size() ? s.views_left_out_tilt_deg[k] : std::nan("");
      if (std::isfinite(tilt_deg)) {
        char text[48];
        std::snprintf(text, sizeof text, " (board tilted %.0f deg)", tilt_deg);
        views += text;
        edge_on += SeenEdgeOn(tilt_deg);
      }
    }
    const int n = int(s.views_left_out.size());
    // A swapped pair's images show ordinary tilts (each is a real view, of
    // the other camera); a ring's side views show the board nearly edge-on.
    const std::string why =
        edge_on == n   ? "boards seen nearly edge-on, their corners foreshortened: usual where a module sees the "
                         "board from the side, as in a ring; the module's other views fix it"
        : edge_on == 0 ? "images of another camera or capture, such as a module's left and right swapped?"
                       : "those tilted " + std::to_string(int(kEdgeOnTiltDeg)) + " deg or more" +
                             " seen nearly edge-on; the others images of another camera or capture, such as a module's "
                             "left and right swapped?";
    notes.push_back("module " + std::to_string(s.module) + " (" + s.module_name + "): stage 2 left out " + views +
                    ": outlier rejection left too few of their corners to fix the board's pose (" + why + ")");
  }
  return notes;
}

FolderCalibration CalibrateCaptureFolder(const std::string& captures_dir, const std::string& target_path,
                                         const std::vector<ModuleLayout>& modules, const CalibrationOptions& options) {
  options.Check();
  const Target target = ReadTargetFile(target_path);
  CalibrationInput input;
  input.target = TargetGeometryFromTarget(target);
  input.modules = modules;
  input.source = captures_dir;
  const int num_cameras = LayoutCameraCount(input.modules);
  CaptureFolderOptions per_folder;  // calibrate's: no rig yet
  per_folder.progress = options.progress;
  per_folder.modules = input.modules;
  DetectedCaptures detected = DetectCaptureFolder(captures_dir, target, num_cameras, per_folder);
  input.cameras = detected.cameras;
  input.observations = std::move(detected.observations);
  input.capture_names = std::move(detected.capture_names);
  FolderCalibration out;
  out.num_captures = detected.num_captures;
  out.skipped_folders = detected.skipped_folders;
  out.num_views = static_cast<int>(input.observations.size());
  if (options.progress) {
    std::fprintf(stderr, "calibrate: %d captures, %d accepted views\n", out.num_captures, out.num_views);
  }
  // Warnings on a terminal: their paths' control bytes escaped (the report
  // keeps the text as it is, JSON-escaped).
  const std::string rejected_note = RejectedViewsNote(detected, target, target_path);
  if (!rejected_note.empty()) std::fprintf(stderr, "calibrate: warning: %s\n", PrintableText(rejected_note).c_str());
  const std::string never_seen_note = NeverSeenCornersNote(input.observations, target, target_path);
  if (!never_seen_note.empty())
    std::fprintf(stderr, "calibrate: warning: %s\n", PrintableText(never_seen_note).c_str());
  const std::string left_out_note = CamerasLeftOutNote(captures_dir, num_cameras);
  if (!left_out_note.empty()) std::fprintf(stderr, "calibrate: warning: %s\n", PrintableText(left_out_note).c_str());
  try {
    out.result = Calibrate(input, options);
  } catch (const InputError& e) {
    const std::string note = !rejected_note.empty()              ? rejected_note
                             : IsTooFewViewsProblem(e.problem()) ? NoBoardFoundNote(detected, target, target_path)
                                                                 : "";
    // The folders skipped too: a capture hidden by mistake (.005) is
    // likely why the views were too few.
    const std::string skipped_note = SkippedFoldersNote(out.skipped_folders);
    if (note.empty() && skipped_note.empty()) throw;
    std::string problem = e.problem();
    for (const std::string& n : {note, skipped_note})
      if (!n.empty()) problem += "; " + n;
    throw InputError(e.where(), problem);
  }
  // The calibration's own warnings (a Horn-only solve that stopped short),
  // printed as these are; the report keeps every warning printed, beside the
  // figures they qualify.
  for (const std::string& note : out.result.report.warnings)
    std::fprintf(stderr, "calibrate: warning: %s\n", PrintableText(note).c_str());
  // The skipped folders as the command named them on stdout: the report
  // says what the rig was calibrated without.
  for (const std::string& note :
       {rejected_note, never_seen_note, left_out_note, SkippedFoldersNote(out.skipped_folders)})
    if (!note.empty()) out.result.report.warnings.push_back(note);
  std::vector<std::string> stage_notes = RepeatedPosesNotes(out.result.report);
  for (const std::string& note : StereoViewsLeftOutNotes(out.result.report)) stage_notes.push_back(note);
  for (const std::string& note : stage_notes) {
    std::fprintf(stderr, "calibrate: warning: %s\n", PrintableText(note).c_str());
    out.result.report.warnings.push_back(note);
  }
  // Calibrate records the board (in the rig it built), not its file's name.
  // Absolute, so that the check's messages name it from wherever they run.
  if (std::optional<CalibrationTarget>& board = out.result.rig.provenance().target)
    board->file = std::filesystem::absolute(target_path).lexically_normal().string();
  return out;
}

}  // namespace stereorig
