#include "reconstruct/line_index.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <vector>

#include "calib/core/input_error.h"
#include "reconstruct/footprint_sample.h"
#include "reconstruct/parallel_for.h"

namespace stereorig {

void LineIndexOptions::Check() const {
  if (max_shift_px < 2 || max_shift_px > 64) throw InputError("line_index_max_shift_px", "must be in [2, 64]");
  if (min_component_px < 1) throw InputError("line_index_min_component_px", "must be >= 1");
  if (samples < 4 || samples > 10000) throw InputError("line_index_samples", "must be in [4, 10000]");
  // The vernier fits a row offset between the views, which a window of one
  // row (0) cannot read: on the demo's five scenes 0 left 8 of the 10
  // modules without a point (their lit pixels 76-85 % wrong_line). With 1,
  // 2 or 3 (3 to 7 rows) `score` gave every module its points, std within
  // 0.005 mm of the default 4's and fill within 1.4 points, but for one
  // component decision (3: the ball bar's module 1, 72.3 against 83.3 %).
  if (window_half_height_px < 1 || window_half_height_px > 30)
    throw InputError("line_index_window_half_height_px",
                     "must be in [1, 30] (3 to 61 rows): the vernier fits a row offset between the views, which a "
                     "window of one row (0) cannot read");
  if (!(max_row_offset_px > 0 && max_row_offset_px < 1))
    throw InputError("line_index_max_row_offset_px", "must be in (0, 1)");
  // Below the vernier window's 9 x 9 px the re-read's samples overlap: it
  // costs more and reads little more.
  if (area_per_sample_px != 0 && (area_per_sample_px < 81 || area_per_sample_px > 100000))
    throw InputError("line_index_area_per_sample_px", "must be 0 (off) or in [81, 100000]");
  if (footprint_gap_px < 0 || footprint_gap_px > 16)
    throw InputError("line_index_footprint_gap_px", "must be in [0, 16]");
  if (!(ambiguity_sigmas >= 0 && ambiguity_sigmas <= 5))
    throw InputError("line_index_ambiguity_sigmas", "must be in [0, 5] (0 = off)");
  if (!(seam_spread_px > 0 && seam_spread_px <= 4)) throw InputError("line_index_seam_spread_px", "must be in (0, 4]");
  if (min_seam_px < 1) throw InputError("line_index_min_seam_px", "must be >= 1");
  if (max_seam_gap_px < 0 || max_seam_gap_px > 32) throw InputError("line_index_max_seam_gap_px", "must be in [0, 32]");
  if (!(min_row_offset_step_px > 0 && min_row_offset_step_px < 1))
    throw InputError("line_index_min_row_offset_step_px", "must be in (0, 1)");
  // Below max_row_offset_px it acts as max_row_offset_px (only components
  // that read off are tested).
  if (!(drop_row_offset_px >= 0 && drop_row_offset_px < 1))
    throw InputError("line_index_drop_row_offset_px", "must be in [0, 1) (0 = off)");
}

cv::Mat LabelDisparityComponents(const cv::Mat& disparity_px, const cv::Rect& roi, double max_step_px,
                                 std::vector<std::vector<int>>* components) {
  STEREORIG_CHECK(disparity_px.type() == CV_32FC1 && disparity_px.isContinuous());
  STEREORIG_CHECK(roi.x >= 0 && roi.y >= 0 && roi.width >= 0 && roi.height >= 0 &&
                  roi.x + roi.width <= disparity_px.cols && roi.y + roi.height <= disparity_px.rows);
  const int cols = disparity_px.cols;
  const int x0 = roi.x, x1 = roi.x + roi.width, y0 = roi.y, y1 = roi.y + roi.height;
  components->clear();
  // The walk's own labels over the roi with a one-pixel frame, row stride
  // `stride`: kFree = a valid pixel not yet labelled, kBlocked = invalid or
  // the frame. A neighbour is then one test of its label, with no bounds or
  // validity test (the walk's cost is per pixel: ~40 instructions a pixel
  // with those tests, 5 labellings per capture). Once every valid pixel is
  // labelled, the rows inside the frame are the output's.
  constexpr int kFree = -2, kBlocked = -1;
  const int stride = roi.width + 2;
  std::vector<int> walk(size_t(stride) * size_t(roi.height + 2), kBlocked);
  const float* d_at = disparity_px.ptr<float>(0);  // a pixel is y * cols + x
  for (int y = y0; y < y1; ++y) {
    const float* d = d_at + size_t(y) * size_t(cols);
    int* w = walk.data() + size_t(y - y0 + 1) * size_t(stride) + 1;  // (x0, y)
    for (int x = x0; x < x1; ++x) w[x - x0] = std::isfinite(d[x]) ? kFree : kBlocked;
  }
  // Depth first from each unlabelled valid pixel in raster order, its
  // neighbours pushed left, right, up, down: the order of each component's
  // pixels, which decides a footprint gap pixel's source when it is reached
  // from both sides (footprint_sample.h). Each pixel is pushed once
  // and listed once, so both buffers hold at most the roi's pixels.
  struct Pixel {
    int w, i;  // in `walk`, in the image
  };
  const size_t area = size_t(roi.area());
  std::unique_ptr<Pixel[]> stack(new Pixel[area]);
  std::unique_ptr<int[]> listed(new int[area]);
  for (int y = y0; y < y1; ++y) {
    const int row_w = (y - y0 + 1) * stride + 1 - x0;  // walk index of (x, y) = row_w + x
    for (int x = x0; x < x1; ++x) {
      if (walk[size_t(row_w + x)] != kFree) continue;
      const int seed_w = row_w + x;
      const int label = int(components->size());
      walk[size_t(seed_w)] = label;
      size_t top = 0, n = 0;
      stack[top++] = {seed_w, y * cols + x};
      while (top > 0) {
        const Pixel p = stack[--top];
        listed[n++] = p.i;
        const float d = d_at[p.i];
        // Joins the neighbour at walk offset dw, image offset di, if free
        // and near d.
        auto visit = [&](int dw, int di) {
          int& l = walk[size_t(p.w + dw)];
          if (l != kFree || std::abs(d_at[p.i + di] - d) > max_step_px) return;
          l = label;
          stack[top++] = {p.w + dw, p.i + di};
        };
        visit(-1, -1);
        visit(1, 1);
        visit(-stride, -cols);
        visit(stride, cols);
      }
      components->emplace_back(listed.get(), listed.get() + n);
    }
  }
  // Labels as the image: -1 outside the roi and on invalid pixels.
  cv::Mat labels(disparity_px.size(), CV_32SC1);
  for (int y = 0; y < disparity_px.rows; ++y) {
    int* out = labels.ptr<int>(y);
    if (y < y0 || y >= y1 || roi.width == 0) {
      std::fill(out, out + cols, -1);
      continue;
    }
    std::fill(out, out + x0, -1);
    std::copy_n(walk.data() + size_t(y - y0 + 1) * size_t(stride) + 1, roi.width, out + x0);
    std::fill(out + x1, out + cols, -1);
  }
  return labels;
}

namespace {

struct Vernier {
  double mean_row_offset_px = 0;  // over the sample's successful fits
  double standard_error_px = 1e9;
  double mean_shift_px = 0;  // mean of (fitted - starting disparity) + the shift tried
  int fits = 0;
};

// The tests and the move, on one module's state.
class LineIndexer {
 public:
  LineIndexer(const cv::Mat& left, const cv::Mat& right, const LineIndexOptions& o, const RefineAcceptance& accept,
              DisparityState* state)
      : left_(left),
        right_(right),
        o_(o),
        accept_(accept),
        state_(state),
        cols_(left.cols),
        sampler_(state->disparity_px, state->slope_x, state->slope_y, o.footprint_gap_px, o.samples) {
    tall_ = accept.subpixel;
    tall_.half_height_px = o.window_half_height_px;
    STEREORIG_CHECK(state->disparity_px.type() == CV_32FC1 && state->disparity_px.isContinuous() &&
                    state->disparity_px.cols == cols_);
  }

  using Start = FootprintStart;

  // Pixels of the component's footprint (footprint_sample.h): its valid
  // pixels and, with footprint_gap_px, the empty pixels up to that far
  // along the row from them; at least o.samples of them on the image's
  // lattice where the footprint holds as many (lattice_sampling), else
  // o.samples spread by raster rank. The valid pixels alone are a biased
  // sample: they are the ones whose window passed the matcher's tests at
  // the component's alignment, and at strong speckle those read the vernier
  // nearer 0 on a wrong alignment than the footprint does (simulator's ball
  // bar at speckle 0.4: a component two periods off read +0.11 px on its
  // own pixels, +0.32 on all pixels of its region).
  std::vector<Start> Sample(const std::vector<int>& pixels) {
    if (!o_.lattice_sampling) return sampler_.Sample(pixels);
    return sampler_.SampleLatticeAtLeast(pixels, o_.samples);
  }

  // The whole footprint, one sample per area_per_sample_px.
  std::vector<Start> SampleWhole(const std::vector<int>& pixels) {
    if (!o_.lattice_sampling) return sampler_.Sample(pixels, o_.area_per_sample_px);
    return sampler_.SampleLattice(pixels, std::max(1, int(std::lround(std::sqrt(double(o_.area_per_sample_px))))));
  }

  // About `samples` of `sample`, every k-th (k = size / samples, at least
  // 1: `samples` to 2 x `samples` of them).
  std::vector<Start> Probe(const std::vector<Start>& sample) const {
    const size_t every = std::max<size_t>(1, sample.size() / size_t(o_.samples));
    return every == 1 ? sample : ThinByRank(sample, double(every));
  }

  // The row offset of the tall-window fit over `sample`, each started from
  // its disparity + shift.
  Vernier Read(const std::vector<Start>& sample, double shift) const {
    std::vector<RowOffsetResult> fits(sample.size());
    ParallelForChunks(int(sample.size()), o_.num_threads, [&](int begin, int end) {
      for (int k = begin; k < end; ++k) {
        const Start& s = sample[size_t(k)];
        fits[size_t(k)] = RefineDisparityAndRowOffset(left_, right_, s.i % cols_, s.i / cols_, s.d + shift, s.slope_x,
                                                      s.slope_y, tall_);
      }
    });
    double sum = 0, sum2 = 0, sum_shift = 0;
    int n = 0;
    for (size_t k = 0; k < sample.size(); ++k) {  // in the samples' order
      const RowOffsetResult& r = fits[k];
      if (!r.ok) continue;
      sum += r.row_offset_px, sum2 += r.row_offset_px * r.row_offset_px;
      sum_shift += r.disparity_px - sample[k].d;
      ++n;
    }
    Vernier v;
    v.fits = n;
    if (n >= 4) {
      v.mean_row_offset_px = sum / n;
      v.mean_shift_px = sum_shift / n;
      v.standard_error_px = std::sqrt(std::max(0.0, sum2 / n - v.mean_row_offset_px * v.mean_row_offset_px) / (n - 1));
    }
    return v;
  }

  // Mean ZNCC of the matcher's own refinement from disparity + shift.
  double MeanZncc(const std::vector<Start>& sample, double shift) const {
    std::vector<double> zncc(sample.size());
    ParallelForChunks(int(sample.size()), o_.num_threads, [&](int begin, int end) {
      for (int k = begin; k < end; ++k) {
        const Start& s = sample[size_t(k)];
        const SubpixelResult r = RefineDisparity(left_, right_, s.i % cols_, s.i / cols_, s.d + shift, s.slope_x,
                                                 s.slope_y, accept_.subpixel);
        zncc[size_t(k)] = r.ok ? r.zncc : 0.0;
      }
    });
    double sum = 0;
    for (double z : zncc) sum += z;  // in the samples' order
    return sum / double(sample.size());
  }

  // Re-refines every pixel of `pixels` near disparity + shift: the period
  // varies over a curved surface, so from starts 2 px either side (the
  // other alignments are a period away), keeping the best correlation.
  void Move(const std::vector<int>& pixels, double shift) {
    changed_ = true;
    // Each pixel reads and writes only its own state.
    ParallelForChunks(int(pixels.size()), o_.num_threads, [&](int begin, int end) {
      for (int k = begin; k < end; ++k) MovePixel(pixels[size_t(k)], shift);
    });
  }

  // Move() for pixel i.
  void MovePixel(int i, double shift) {
    const int y = i / cols_, x = i % cols_;
    float& d = state_->disparity_px.at<float>(y, x);
    if (!std::isfinite(d)) return;
    SubpixelResult r;
    for (int k = -2; k <= 2; ++k) {
      const SubpixelResult rk =
          RefineDisparity(left_, right_, x, y, d + shift + k, SlopeX(i), SlopeY(i), accept_.subpixel);
      if (rk.ok && (!r.ok || rk.zncc > r.zncc)) r = rk;
    }
    const PixelStatus why = Accept(left_, right_, x, y, SlopeX(i), SlopeY(i), r, accept_);
    if (why != PixelStatus::kPoint) {
      DropPoint(x, y, why, state_);
      return;
    }
    d = float(r.disparity_px);
    state_->confidence.at<float>(y, x) = float(std::clamp(r.zncc, 0.0, 1.0));
    state_->status.at<uint8_t>(y, x) = uint8_t(PixelStatus::kPoint);
  }

  // Drops every pixel of `pixels` (PixelStatus::kWrongLine).
  void Drop(const std::vector<int>& pixels) {
    for (int i : pixels) {
      const int y = i / cols_, x = i % cols_;
      if (!std::isfinite(state_->disparity_px.at<float>(y, x))) continue;
      changed_ = true;
      DropPoint(x, y, PixelStatus::kWrongLine, state_);
    }
  }

  enum class Outcome { kKept, kMoved, kDropped };

  // Whether Move or Drop has changed the map.
  bool changed() const { return changed_; }

  // The reading at the alignment the last TestComponent left its component
  // on; fits == 0 when it read none or dropped the component.
  const VernierReading& last_reading() const { return last_reading_; }

  // One component's vernier test.
  // offset_px: the row offset a correct match reads (0 on a well rectified pair).
  Outcome TestComponent(const std::vector<int>& pixels, double offset_px) {
    last_reading_ = VernierReading{};
    const Outcome outcome = TestComponentReading(pixels, offset_px);
    if (outcome == Outcome::kDropped) last_reading_ = VernierReading{};
    if (last_reading_.fits > 0) last_reading_.pixels = int(pixels.size());
    return outcome;
  }

 private:
  void Note(const Vernier& v) { last_reading_ = {v.mean_row_offset_px, v.standard_error_px, v.fits, 0}; }

  Outcome TestComponentReading(const std::vector<int>& pixels, double offset_px) {
    std::vector<Start> sample = Sample(pixels);
    // On the lattice, with area_per_sample_px, the whole footprint is read
    // from the start (the matcher sets it only where growing's noise floor
    // bites: strong speckle).
    if (o_.lattice_sampling && o_.area_per_sample_px > 0) {
      std::vector<Start> whole = SampleWhole(pixels);
      if (whole.size() > sample.size()) sample = std::move(whole);
    }
    if (int(sample.size()) < 4) return Outcome::kKept;
    Vernier here = Read(sample, 0.0);
    here.mean_row_offset_px -= offset_px;
    if (here.fits < 4) return Outcome::kKept;
    Note(here);
    // Read as right without the other alignments: within max_row_offset_px
    // and, with ambiguity_sigmas, by that many standard errors; without it,
    // also anything within 3 standard errors (as before session 6: at
    // speckle 0.4 a component one or two periods off read within that).
    auto read_as_right = [&] {
      const double here_abs = std::abs(here.mean_row_offset_px);
      return o_.ambiguity_sigmas > 0 ? here_abs + o_.ambiguity_sigmas * here.standard_error_px <= o_.max_row_offset_px
                                     : here_abs <= std::max(o_.max_row_offset_px, 3 * here.standard_error_px);
    };
    if (o_.quick_keep && read_as_right()) return Outcome::kKept;
    // Not conclusive from `samples` pixels (by raster rank): with
    // area_per_sample_px, read the whole footprint (one sample per that
    // area) before moving or dropping it; the other alignments are then read
    // over it too. On the lattice it was read whole above.
    if (o_.area_per_sample_px > 0 && !o_.lattice_sampling) {
      std::vector<Start> whole = SampleWhole(pixels);
      if (whole.size() > sample.size()) {
        Vernier whole_here = Read(whole, 0.0);
        whole_here.mean_row_offset_px -= offset_px;
        if (whole_here.fits >= 4) {
          sample = std::move(whole);
          here = whole_here;
          Note(here);
          if (read_as_right()) return Outcome::kKept;
        }
      }
    }
    // Off, and the alignment the vernier points to cannot be read: the
    // right line is out of reach (outside the right image, typically).
    const bool droppable = o_.drop_row_offset_px > 0 && std::abs(here.mean_row_offset_px) >
                                                            std::max(o_.drop_row_offset_px, 3 * here.standard_error_px);
    auto unreadable = [&] {
      if (!droppable) return Outcome::kKept;
      Drop(pixels);
      return Outcome::kDropped;
    };
    // The other alignments: on each side, the shift whose refinement
    // correlates best. Their row offsets step by about the same amount per
    // period (the vernier): fit dy(k) = a + b k over k = -1, 0, +1 and move
    // to the alignment nearest its zero crossing.
    // On the lattice, the shift is found from `samples` to 2 x `samples`
    // of them (Probe): it is the best of 2 x (max_shift_px - 1) mean
    // correlations, which differ by far more than their noise; the row
    // offset there is read from all.
    const std::vector<Start> probe = o_.lattice_sampling ? Probe(sample) : sample;
    Vernier side[2];
    for (int j = 0; j < 2; ++j) {
      const int sign = j == 0 ? -1 : 1;
      double best_z = -2, side_shift = 0;
      for (int s = 2; s <= o_.max_shift_px; ++s) {
        const double z = MeanZncc(probe, sign * s);
        if (z > best_z) best_z = z, side_shift = sign * s;
      }
      side[j] = Read(sample, side_shift);
      side[j].mean_row_offset_px -= offset_px;
    }
    double sw = 0, sk = 0, skk = 0, sd = 0, skd = 0;
    const Vernier* points[3] = {&side[0], &here, &side[1]};
    for (int k = -1; k <= 1; ++k) {
      const Vernier& v = *points[k + 1];
      if (v.fits < 4) continue;
      const double w = 1.0 / (v.standard_error_px * v.standard_error_px + 1e-4);
      sw += w, sk += w * k, skk += w * k * k, sd += w * v.mean_row_offset_px, skd += w * k * v.mean_row_offset_px;
    }
    const double det = sw * skk - sk * sk;
    if (!(det > 0)) return unreadable();  // neither other alignment could be read
    const double a = (skk * sd - sk * skd) / det, b = (sw * skd - sk * sd) / det;
    if (std::abs(b) < o_.min_row_offset_step_px) {  // no vernier to read
      if (o_.ambiguity_sigmas <= 0) return Outcome::kKept;
      // It read off (above) and the other alignments do not say which is
      // right: unknown, so dropped.
      Drop(pixels);
      return Outcome::kDropped;
    }
    const double zero_crossing = std::clamp(-a / b, -1.0, 1.0);
    const int k = int(std::lround(zero_crossing));
    // The reading's uncertainty in alignments: the standard error of the
    // intercept over the step. Nearer than ambiguity_sigmas of it to the
    // midpoint between two alignments, neither is known: drop rather than
    // keep or move a component that may be a period off.
    if (o_.ambiguity_sigmas > 0 &&
        std::abs(zero_crossing - k) + o_.ambiguity_sigmas * here.standard_error_px / std::abs(b) > 0.5) {
      Drop(pixels);
      return Outcome::kDropped;
    }
    if (k == 0) return Outcome::kKept;
    if (points[k + 1]->fits < 4) return unreadable();
    Move(pixels, points[k + 1]->mean_shift_px);
    Note(*points[k + 1]);
    return Outcome::kMoved;
  }

  float SlopeX(int i) const { return state_->slope_x.at<float>(i / cols_, i % cols_); }
  float SlopeY(int i) const { return state_->slope_y.at<float>(i / cols_, i % cols_); }

  const cv::Mat& left_;
  const cv::Mat& right_;
  const LineIndexOptions& o_;
  const RefineAcceptance& accept_;
  DisparityState* state_;
  const int cols_;
  SubpixelOptions tall_;
  FootprintSampler sampler_;
  bool changed_ = false;
  VernierReading last_reading_;
};

}  // namespace

std::map<std::pair<int, int>, std::vector<float>> SeamDifferences(const cv::Mat& labels, const cv::Mat& disparity_px,
                                                                  const cv::Mat& slope_x, const cv::Mat& slope_y,
                                                                  const cv::Rect& roi, int max_gap_px) {
  STEREORIG_CHECK(labels.type() == CV_32SC1 && disparity_px.type() == CV_32FC1 && labels.size() == disparity_px.size());
  STEREORIG_CHECK(slope_x.size() == disparity_px.size() && slope_y.size() == disparity_px.size());
  std::map<std::pair<int, int>, std::vector<float>> seams;
  // From pixel p (label a) to the next labelled pixel q (label b) along its
  // row or column, `step` px on: d_q - (d_p + slope_p * step).
  auto record = [&](int a, int b, float d_p, float d_q, float slope_p, int step) {
    const float diff = d_q - (d_p + slope_p * step);
    if (a < b)
      seams[{a, b}].push_back(diff);
    else
      seams[{b, a}].push_back(-diff);
  };
  // One raster scan: the last labelled pixel along the current row, and
  // along each column (its row, -1 = none yet). Each pixel's next labelled
  // pixel is met once, so each pair is recorded once, whatever the gap.
  std::vector<int> last_y(size_t(std::max(0, roi.width)), -1);
  for (int y = roi.y; y < roi.y + roi.height; ++y) {
    const int* label = labels.ptr<int>(y);
    const float* d = disparity_px.ptr<float>(y);
    int last_x = -1;
    for (int x = roi.x; x < roi.x + roi.width; ++x) {
      const int b = label[x];
      if (b < 0) continue;
      if (last_x >= 0 && x - last_x <= max_gap_px + 1 && label[last_x] != b)
        record(label[last_x], b, d[last_x], d[x], slope_x.ptr<float>(y)[last_x], x - last_x);
      last_x = x;
      int& above = last_y[size_t(x - roi.x)];
      if (above >= 0 && y - above <= max_gap_px + 1) {
        const int a = labels.ptr<int>(above)[x];
        if (a != b) record(a, b, disparity_px.ptr<float>(above)[x], d[x], slope_y.ptr<float>(above)[x], y - above);
      }
      above = y;
    }
  }
  return seams;
}

int CorrectLineIndex(const cv::Mat& left, const cv::Mat& right, const cv::Rect& roi, const LineIndexOptions& o,
                     const RefineAcceptance& accept, DisparityState* state, DisparityComponents* labelled,
                     std::vector<VernierReading>* readings) {
  if (!o.enabled) return 0;
  DisparityComponents own;
  if (!labelled) labelled = &own;
  labelled->labels = LabelDisparityComponents(state->disparity_px, roi, 1.0, &labelled->pixels);
  const std::vector<std::vector<int>>& components = labelled->pixels;
  LineIndexer indexer(left, right, o, accept, state);
  int moved = 0;
  for (const std::vector<int>& pixels : components) {
    if (int(pixels.size()) < o.min_component_px) continue;
    // Up to two moves: a component can be two periods off.
    for (int round = 0; round < 2; ++round) {
      if (indexer.TestComponent(pixels, 0.0) != LineIndexer::Outcome::kMoved) break;
      ++moved;
    }
    // The last test's reading: after two moves, the alignment moved to.
    if (readings && indexer.last_reading().fits > 0) readings->push_back(indexer.last_reading());
  }
  labelled->matches_disparity = !indexer.changed();
  return moved;
}

int JoinAcrossPeriodJumps(const cv::Mat& left, const cv::Mat& right, const cv::Rect& roi, const LineIndexOptions& o,
                          const RefineAcceptance& accept, DisparityState* state, DisparityComponents* labelled) {
  if (!o.enabled) return 0;
  DisparityComponents own;
  if (!labelled) labelled = &own;
  if (!labelled->matches_disparity)
    labelled->labels = LabelDisparityComponents(state->disparity_px, roi, 1.0, &labelled->pixels);
  // Moves below change the map.
  labelled->matches_disparity = false;
  const cv::Mat& labels = labelled->labels;
  const std::vector<std::vector<int>>& components = labelled->pixels;
  std::map<std::pair<int, int>, std::vector<float>> seams =
      SeamDifferences(labels, state->disparity_px, state->slope_x, state->slope_y, roi, o.max_seam_gap_px);
  // Longest seams first; each component moves at most once.
  std::vector<std::pair<size_t, std::pair<int, int>>> order;
  for (const auto& [key, diffs] : seams) order.push_back({diffs.size(), key});
  std::sort(order.rbegin(), order.rend());
  LineIndexer indexer(left, right, o, accept, state);
  std::vector<bool> done(components.size(), false);
  int moved = 0;
  for (const auto& [length, key] : order) {
    if (int(length) < o.min_seam_px) break;
    std::vector<float>& diffs = seams[key];
    std::nth_element(diffs.begin(), diffs.begin() + diffs.size() / 2, diffs.end());
    const double median = diffs[diffs.size() / 2];
    // A smooth surface has no jump: one of about a period (not a depth
    // edge's arbitrary step, which the spread of the seam shows) means one
    // side has the wrong line. Both ways of joining them give one
    // alignment; keep the one whose size-weighted row offset (vernier) is
    // nearer 0.
    if (std::abs(median) < 3 || std::abs(median) > o.max_shift_px) continue;
    int spread = 0;
    for (float d : diffs) spread += std::abs(d - median) > o.seam_spread_px;
    if (spread > int(diffs.size()) / 4) continue;
    const auto [a, b] = key;
    if (done[a] || done[b] || int(std::min(components[a].size(), components[b].size())) < o.min_component_px) continue;
    const auto sample_a = indexer.Sample(components[a]), sample_b = indexer.Sample(components[b]);
    if (int(std::min(sample_a.size(), sample_b.size())) < 4) continue;
    // a moves by +median to meet b, or b by -median to meet a.
    const Vernier a0 = indexer.Read(sample_a, 0.0), a1 = indexer.Read(sample_a, median);
    const Vernier b0 = indexer.Read(sample_b, 0.0), b1 = indexer.Read(sample_b, -median);
    if (std::min({a0.fits, a1.fits, b0.fits, b1.fits}) < 4) continue;
    const double na = double(components[a].size()), nb = double(components[b].size());
    // Both sides end on one alignment either way: the right one reads a row
    // offset of ~0. The vernier's reading has regional biases of ~0.1 px
    // (surface curvature in the window), so when the two readings are
    // within max_row_offset_px of each other the larger component, which
    // SGM and growing made of more evidence, keeps its alignment.
    double cost_move_a = std::abs((na * a1.mean_row_offset_px + nb * b0.mean_row_offset_px) / (na + nb));
    double cost_move_b = std::abs((na * a0.mean_row_offset_px + nb * b1.mean_row_offset_px) / (na + nb));
    if (std::abs(cost_move_a - cost_move_b) < o.max_row_offset_px) {
      cost_move_a = na < nb ? 0 : 1;
      cost_move_b = 1 - cost_move_a;
    }
    if (cost_move_a <= cost_move_b) {
      indexer.Move(components[a], a1.mean_shift_px);
      done[a] = true;
    } else {
      indexer.Move(components[b], b1.mean_shift_px);
      done[b] = true;
    }
    ++moved;
  }
  return moved;
}

}  // namespace stereorig
