#include "targets/tag_detect.h"

extern "C" {
#include <apriltag/apriltag.h>
}

#include "calib/core/input_error.h"

namespace stereorig {

void TagDetectOptions::Check() const {
  if (!(decimate >= 1.0)) throw InputError("tag detection", "decimate must be >= 1");
  if (!(blur_sigma_px >= 0.0)) throw InputError("tag detection", "blur_sigma_px must not be negative");
  if (max_bit_errors < 0 || max_bit_errors > 2) throw InputError("tag detection", "max_bit_errors must be 0, 1 or 2");
  if (!(min_decision_margin >= 0.0)) throw InputError("tag detection", "min_decision_margin must not be negative");
}

std::array<Eigen::Vector2d, 4> TagCornersInFace(const Target& target, const TagPlacement& tag) {
  const double h = 0.5 * target.layout().tag_size_mm;
  const double x = tag.center_x_mm, y = tag.center_y_mm;
  return {Eigen::Vector2d(x - h, y + h), Eigen::Vector2d(x + h, y + h), Eigen::Vector2d(x + h, y - h),
          Eigen::Vector2d(x - h, y - h)};
}

struct TagDetector::Impl {
  TagFamilyPtr family;
  apriltag_detector_t* detector = nullptr;
  ~Impl() {
    if (detector) apriltag_detector_destroy(detector);
  }
};

TagDetector::TagDetector(const Target& target, const TagDetectOptions& options)
    : target_(target), options_(options), impl_(std::make_unique<Impl>()) {
  options_.Check();
  if (!target_.double_sided()) return;
  impl_->family = CreateTagFamily(target_.layout().tag_family);
  STEREORIG_CHECK(impl_->family != nullptr);  // Target validated the name
  impl_->detector = apriltag_detector_create();
  apriltag_detector_add_family_bits(impl_->detector, impl_->family.get(), options_.max_bit_errors);
  impl_->detector->quad_decimate = static_cast<float>(options_.decimate);
  impl_->detector->quad_sigma = static_cast<float>(options_.blur_sigma_px);
  impl_->detector->refine_edges = true;
  impl_->detector->nthreads = 1;
}

TagDetector::~TagDetector() = default;

std::vector<TagDetection> TagDetector::Detect(const cv::Mat& grey, int* num_foreign) const {
  STEREORIG_CHECK(grey.type() == CV_8UC1);
  if (num_foreign) *num_foreign = 0;
  std::vector<TagDetection> out;
  if (!impl_->detector) return out;
  // libapriltag reads the buffer only; the cast drops const for its C API.
  image_u8_t im{grey.cols, grey.rows, static_cast<int32_t>(grey.step[0]), const_cast<uint8_t*>(grey.ptr<uint8_t>())};
  zarray_t* detections = apriltag_detector_detect(impl_->detector, &im);
  for (int i = 0; i < zarray_size(detections); ++i) {
    apriltag_detection_t* d = nullptr;
    zarray_get(detections, i, &d);
    if (d->hamming > options_.max_bit_errors || d->decision_margin < options_.min_decision_margin) continue;
    Face face;
    if (!target_.FaceOfTag(d->id, &face)) {
      if (num_foreign) ++*num_foreign;
      continue;
    }
    TagDetection t;
    t.id = d->id;
    t.face = face;
    t.bit_errors = d->hamming;
    t.decision_margin = d->decision_margin;
    // libapriltag puts (0,0) at the top-left corner of the top-left pixel
    // (measured on rendered truth: its corners sit +0.5 px off in x and y,
    // see detect_test.cc), mrcal at that pixel's centre: shift by -0.5.
    for (int k = 0; k < 4; ++k) t.q_px[k] = Eigen::Vector2d(d->p[k][0] - 0.5, d->p[k][1] - 0.5);
    out.push_back(t);
  }
  apriltag_detections_destroy(detections);
  return out;
}

}  // namespace stereorig
