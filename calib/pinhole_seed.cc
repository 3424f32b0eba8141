#include "calib/pinhole_seed.h"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <optional>

namespace stereorig {

namespace {

// OpenCV's estimate with the principal point at the image's centre (the seed
// before windows were considered; kept as the fallback).
double CentredFocal(const std::vector<const BoardObservation*>& views, const TargetGeometry& target, int width,
                    int height) {
  std::vector<std::vector<cv::Point3f>> objects;
  std::vector<std::vector<cv::Point2f>> images;
  for (const BoardObservation* v : views) {
    std::vector<cv::Point3f> o;
    std::vector<cv::Point2f> q;
    for (size_t k = 0; k < v->corner_ids.size(); ++k) {
      const Eigen::Vector3d p = target.CornerInFace(v->corner_ids[k]);
      o.emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), 0.f);
      q.emplace_back(static_cast<float>(v->q_px[k].x()), static_cast<float>(v->q_px[k].y()));
    }
    objects.push_back(o);
    images.push_back(q);
  }
  const cv::Mat K = cv::initCameraMatrix2D(objects, images, cv::Size(width, height));
  const double f = 0.5 * (K.at<double>(0, 0) + K.at<double>(1, 1));
  return std::isfinite(f) && f > 0 ? f : width;  // a 53 deg lens if the estimate fails
}

// Board plane (mm) -> normalised pixels `(q - centre) / scale`, scaled to
// unit Frobenius norm so that every view weighs alike; nullopt if OpenCV
// finds none.
std::optional<Eigen::Matrix3d> NormalisedHomography(const BoardObservation& v, const TargetGeometry& target,
                                                    const Eigen::Vector2d& centre_px, double scale_px) {
  std::vector<cv::Point2d> board, image;
  for (size_t k = 0; k < v.corner_ids.size(); ++k) {
    const Eigen::Vector3d p = target.CornerInFace(v.corner_ids[k]);
    const Eigen::Vector2d q = (v.q_px[k] - centre_px) / scale_px;
    board.emplace_back(p.x(), p.y());
    image.emplace_back(q.x(), q.y());
  }
  if (board.size() < 4) return std::nullopt;
  const cv::Mat h = cv::findHomography(board, image, 0);
  if (h.empty()) return std::nullopt;
  Eigen::Matrix3d H;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) H(r, c) = h.at<double>(r, c);
  if (!H.allFinite() || H.norm() == 0) return std::nullopt;
  return H / H.norm();
}

// The coefficients of (B11, B13, B23, B33) in hi' B hj.
Eigen::RowVector4d BilinearRow(const Eigen::Vector3d& hi, const Eigen::Vector3d& hj) {
  return {hi(0) * hj(0) + hi(1) * hj(1), hi(0) * hj(2) + hi(2) * hj(0), hi(1) * hj(2) + hi(2) * hj(1), hi(2) * hj(2)};
}

// Zhang's closed form in normalised pixels; nullopt without a real solution.
std::optional<PinholeSeed> ClosedForm(const std::vector<const BoardObservation*>& views, const TargetGeometry& target,
                                      const Eigen::Vector2d& centre_px, double scale_px) {
  std::vector<Eigen::RowVector4d> rows;
  for (const BoardObservation* v : views) {
    const std::optional<Eigen::Matrix3d> H = NormalisedHomography(*v, target, centre_px, scale_px);
    if (!H) continue;
    const Eigen::Vector3d h1 = H->col(0), h2 = H->col(1);
    rows.push_back(BilinearRow(h1, h2));
    rows.push_back(BilinearRow(h1, h1) - BilinearRow(h2, h2));
  }
  if (rows.size() < 4) return std::nullopt;  // 4 unknowns up to scale: 2 views at least
  Eigen::MatrixX4d A(rows.size(), 4);
  for (size_t i = 0; i < rows.size(); ++i) A.row(static_cast<Eigen::Index>(i)) = rows[i];
  const Eigen::Vector4d b = Eigen::JacobiSVD<Eigen::MatrixX4d>(A, Eigen::ComputeFullV).matrixV().col(3);
  const double b11 = b(0), b13 = b(1), b23 = b(2), b33 = b(3);
  if (b11 == 0) return std::nullopt;
  // Both unchanged by b's sign, which the SVD leaves free.
  const Eigen::Vector2d c(-b13 / b11, -b23 / b11);
  const double f2 = (b33 - (b13 * b13 + b23 * b23) / b11) / b11;
  if (!(f2 > 0) || !std::isfinite(f2) || !c.allFinite()) return std::nullopt;
  return PinholeSeed{scale_px * std::sqrt(f2), centre_px + scale_px * c};
}

// RMS over every view of the corners' distances, px, from their
// reprojection through `seed` after each view's pose is solved alone (PnP);
// infinity if a pose cannot be.
double PerViewReprojectionRms(const std::vector<const BoardObservation*>& views, const TargetGeometry& target,
                              const PinholeSeed& seed) {
  const cv::Matx33d K(seed.focal_px, 0, seed.principal_point_px.x(), 0, seed.focal_px, seed.principal_point_px.y(), 0,
                      0, 1);
  double sum_sq = 0;
  size_t count = 0;
  for (const BoardObservation* v : views) {
    std::vector<cv::Point3d> board;
    std::vector<cv::Point2d> image;
    for (size_t k = 0; k < v->corner_ids.size(); ++k) {
      const Eigen::Vector3d p = target.CornerInFace(v->corner_ids[k]);
      board.emplace_back(p.x(), p.y(), p.z());
      image.emplace_back(v->q_px[k].x(), v->q_px[k].y());
    }
    cv::Mat rvec, tvec;
    if (!cv::solvePnP(board, image, K, cv::noArray(), rvec, tvec, false, cv::SOLVEPNP_IPPE)) return INFINITY;
    std::vector<cv::Point2d> projected;
    cv::projectPoints(board, rvec, tvec, K, cv::noArray(), projected);
    for (size_t k = 0; k < image.size(); ++k) {
      const cv::Point2d d = projected[k] - image[k];
      sum_sq += d.dot(d);
      ++count;
    }
  }
  return count ? std::sqrt(sum_sq / count) : INFINITY;
}

}  // namespace

PinholeSeed EstimatePinholeSeed(const std::vector<const BoardObservation*>& views, const TargetGeometry& target,
                                int width_px, int height_px, double given_focal_px) {
  const Eigen::Vector2d centre_px(0.5 * (width_px - 1), 0.5 * (height_px - 1));
  std::vector<PinholeSeed> candidates;
  if (const std::optional<PinholeSeed> closed = ClosedForm(views, target, centre_px, std::max(width_px, height_px)))
    candidates.push_back(*closed);
  candidates.push_back({CentredFocal(views, target, width_px, height_px), centre_px});
  for (int k = -2; k <= 8; ++k) candidates.push_back({width_px * std::pow(2.0, 0.5 * k), centre_px});
  if (given_focal_px > 0)
    for (PinholeSeed& c : candidates) c.focal_px = given_focal_px;
  PinholeSeed best = candidates.back();
  double best_rms = INFINITY;
  for (const PinholeSeed& c : candidates) {
    const double rms = PerViewReprojectionRms(views, target, c);
    if (rms < best_rms) best_rms = rms, best = c;
  }
  return best;
}

}  // namespace stereorig
