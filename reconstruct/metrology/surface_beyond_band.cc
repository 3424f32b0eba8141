#include "reconstruct/metrology/surface_beyond_band.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

namespace stereorig {

namespace {

// Cells of the shape's surface, rows x cols (columns wrapping round where
// `wrap`: a sphere's azimuth): per cell, the points in the band (`on`) and
// those beyond it within kBeyondBandWidths bands (`beyond`); cells
// `ignored` are judged neither way (a ball bar's shaft).
struct Cells {
  int rows = 0, cols = 0;
  bool wrap = false;
  std::vector<int> on;
  std::vector<std::vector<int>> beyond;
  std::vector<char> ignored;
  Cells(int r, int c, bool w) : rows(r), cols(c), wrap(w), on(r * c, 0), beyond(r * c), ignored(r * c, 0) {}
  // The 8 cells around.
  std::vector<int> Around(int cell) const {
    std::vector<int> out;
    const int row = cell / cols, col = cell % cols;
    for (int dr = -1; dr <= 1; ++dr)
      for (int dc = -1; dc <= 1; ++dc) {
        if ((dr == 0 && dc == 0) || row + dr < 0 || row + dr >= rows) continue;
        if (!wrap && (col + dc < 0 || col + dc >= cols)) continue;
        out.push_back((row + dr) * cols + (col + dc + cols) % cols);
      }
    return out;
  }
};

// A cell holds the surface where the band has at least a quarter of a
// typical measured cell's points (the median over cells with any): a cap's
// edge cells, cut by it, still count. Fewer than 3 points is no surface.
constexpr double kSurfaceFractionOfTypical = 0.25;
constexpr double kOverlaidFractionOfTypical = 0.5;
constexpr int kMinPointsPerCell = 3;

// A part of the surface measured off lies along the surface, as a layer:
// across a cell its offsets spread by the cell's width times its tilt (a
// patch a grid period off, 7 mm along the camera's ray, by under 1 mm; the
// demo's sphere moved radially by noise, 0.1 mm interquartile). Something
// sticking out of it (a stand, a mount's rod) runs across the layers and
// spreads over the whole window beyond the band: 2.8-5.5 mm interquartile
// in the cells of a walkthrough's stand. A cell's points beyond the band
// are a layer where their offsets' interquartile range is within this
// fraction of the band.
constexpr double kLayerSpreadOfBand = 0.25;
constexpr double kLayerEdgeOfBand = 0.1;

// A group of cells is surrounded by measured surface where, of the cells
// around it, at least half are measured at all (hold points in the band:
// a patch at the edge of what was seen borders cells nobody measured,
// which say nothing) and at least this fraction of those hold the
// surface. A mount where the artifact is hidden borders unmeasured cells.
constexpr double kSurroundedFraction = 2.0 / 3.0;
constexpr double kMeasuredAroundFraction = 0.5;

// A part measured off is a piece of the surface: many points. False matches
// come in clumps of a few (a correlation window's neighbours: 4 in a
// walkthrough's cloud), and in a sparse cloud (a 2500-point cap, ~5 points a
// cell) a clump is as many points as a cell of surface holds: 200 such
// outliers left 5 of 6 clouds NOT JUDGED for 4 points. A part has at least
// this many, five clumps; the demo's cells hold ~40, so a part one cell
// wide is still found.
constexpr int kMinPointsPerPart = 20;

double InterquartileRange(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[(3 * v.size()) / 4] - v[v.size() / 4];
}

// The points beyond the band in groups of adjacent cells that hold no
// surface but a layer beyond it (as many points as a cell of surface holds,
// lying along it), each group surrounded by cells that hold the surface.
// off_mm: a point's signed distance to the surface (a layer's spread is
// taken signed: points either side of the surface are not one layer).
SurfaceBeyondBand Judge(const Cells& cells, double band_mm, const std::function<double(int)>& off_mm, bool overlaid) {
  std::vector<int> measured;
  for (size_t c = 0; c < cells.on.size(); ++c)
    if (cells.on[c] > 0 && !cells.ignored[c]) measured.push_back(cells.on[c]);
  SurfaceBeyondBand out;
  if (measured.empty()) return out;
  std::nth_element(measured.begin(), measured.begin() + measured.size() / 2, measured.end());
  const double enough = std::max<double>(kMinPointsPerCell, kSurfaceFractionOfTypical * measured[measured.size() / 2]);
  auto surface = [&](int cell) { return cells.on[cell] >= enough; };
  // `overlaid`: a layer counts over cells that hold the surface too. One
  // module's part measured off where another module holds the surface
  // (their overlap) passed. The caller passes it only where the points
  // beyond the band face as the surface does (their normals), so clutter
  // facing otherwise (a table under a sphere) is not among them; over the
  // surface a layer is a part where it is at least half as dense as a
  // typical cell of surface (a patch a module measured off holds as many
  // points as the cells it left; the surface's quarter bar would take a
  // sparse strip of clutter).
  const double overlaid_enough = std::max(enough, kOverlaidFractionOfTypical * measured[measured.size() / 2]);
  std::vector<char> layer(cells.on.size(), 0);
  std::vector<double> median_off_mm(cells.on.size(), 0);
  for (size_t c = 0; c < cells.on.size(); ++c) {
    const bool over_surface = cells.on[c] >= enough;
    if (cells.ignored[c] || (over_surface && !overlaid) ||
        static_cast<double>(cells.beyond[c].size()) < (over_surface ? overlaid_enough : enough))
      continue;
    std::vector<double> offs;
    for (int i : cells.beyond[c]) offs.push_back(off_mm(i));
    layer[c] = InterquartileRange(offs) <= kLayerSpreadOfBand * band_mm;
    std::nth_element(offs.begin(), offs.begin() + offs.size() / 2, offs.end());
    median_off_mm[c] = offs[offs.size() / 2];
  }
  auto displaced = [&](int cell) { return layer[cell] != 0; };
  const int n = static_cast<int>(cells.on.size());
  std::vector<char> seen(n, 0);
  out.nearest_mm = std::numeric_limits<double>::infinity();
  std::vector<int> found;  // the points of the groups kept, with repeats
  for (int start = 0; start < n; ++start) {
    if (seen[start] || !displaced(start)) continue;
    std::vector<int> group = {start}, rim;
    seen[start] = 1;
    for (size_t k = 0; k < group.size(); ++k)
      for (int next : cells.Around(group[k])) {
        if (seen[next]) continue;
        // One layer runs on continuously: a neighbour's offset within a
        // cell's spread (clumps of false matches at other offsets in
        // adjacent cells are not one part).
        if (displaced(next) &&
            std::abs(median_off_mm[next] - median_off_mm[group[k]]) <= kLayerSpreadOfBand * band_mm) {
          seen[next] = 1;
          group.push_back(next);
        } else if (!cells.ignored[next] && std::find(rim.begin(), rim.end(), next) == rim.end()) {
          rim.push_back(next);
        }
      }
    const auto held = std::count_if(rim.begin(), rim.end(), surface);
    const auto measured_around = std::count_if(rim.begin(), rim.end(), [&](int c) { return cells.on[c] > 0; });
    if (measured_around == 0 || measured_around < kMeasuredAroundFraction * static_cast<double>(rim.size()) ||
        held < kSurroundedFraction * static_cast<double>(measured_around))
      continue;
    // The group's points, and those of its layer beyond it: the layer runs
    // on through cells that also hold some surface (a patch's edge, the
    // cells about a sphere's pole that a patch covers but for a strip),
    // taken where they hold as many of its points as a cell of surface
    // holds, and into the cells around those. A layer point is within the
    // group's range of offsets, widened by a tenth of the band for the
    // noise's extremes (a 0.05 mm noise's are 0.25 mm out).
    double lo_mm = std::numeric_limits<double>::infinity(), hi_mm = -lo_mm;
    for (int cell : group)
      for (int i : cells.beyond[cell]) {
        lo_mm = std::min(lo_mm, off_mm(i));
        hi_mm = std::max(hi_mm, off_mm(i));
      }
    auto in_layer = [&](int i) {
      return off_mm(i) >= lo_mm - kLayerEdgeOfBand * band_mm && off_mm(i) <= hi_mm + kLayerEdgeOfBand * band_mm;
    };
    auto layer_points = [&](int cell) {
      return std::count_if(cells.beyond[cell].begin(), cells.beyond[cell].end(), in_layer);
    };
    std::vector<int> region = group;
    std::vector<char> in_region(n, 0);
    for (int cell : group) in_region[cell] = 1;
    for (size_t k = 0; k < region.size(); ++k)
      for (int next : cells.Around(region[k])) {
        if (in_region[next] || cells.ignored[next] || static_cast<double>(layer_points(next)) < enough) continue;
        in_region[next] = 1;
        region.push_back(next);
      }
    std::vector<int> around = region;
    for (int cell : region)
      for (int next : cells.Around(cell))
        if (!in_region[next] && !cells.ignored[next]) around.push_back(next);
    std::vector<int> part;
    for (int cell : around)
      for (int i : cells.beyond[cell])
        if (in_layer(i)) part.push_back(i);
    std::sort(part.begin(), part.end());
    part.erase(std::unique(part.begin(), part.end()), part.end());
    if (static_cast<int>(part.size()) < kMinPointsPerPart) continue;
    double mean_mm = 0;
    for (int i : part) mean_mm += off_mm(i) / static_cast<double>(part.size());
    out.part_mean_off_mm.push_back(mean_mm);
    found.insert(found.end(), part.begin(), part.end());
  }
  // Each point once: two groups may share a cell around them.
  std::sort(found.begin(), found.end());
  found.erase(std::unique(found.begin(), found.end()), found.end());
  out.points = static_cast<int>(found.size());
  for (int i : found) {
    out.nearest_mm = std::min(out.nearest_mm, std::abs(off_mm(i)));
    out.farthest_mm = std::max(out.farthest_mm, std::abs(off_mm(i)));
  }
  if (!out.found()) out.nearest_mm = 0;
  return out;
}

// A sphere's directions from its centre in equal-area cells: rows equal in
// cos(polar angle) about z, columns in azimuth; 648 cells of ~8 deg, ~7 mm^2
// of a 38.1 mm sphere (~40 points of the demo's clouds).
constexpr int kRows = 18, kCols = 36;

int CellOf(const Eigen::Vector3d& u) {
  const int row = std::clamp(static_cast<int>((u.z() + 1) / 2 * kRows), 0, kRows - 1);
  const double azimuth = std::atan2(u.y(), u.x()) + M_PI;  // [0, 2 pi]
  const int col = std::clamp(static_cast<int>(azimuth / (2 * M_PI) * kCols), 0, kCols - 1);
  return row * kCols + col;
}

Eigen::Vector3d CellCentre(int cell) {
  const double z = -1 + 2 * (cell / kCols + 0.5) / kRows;
  const double azimuth = 2 * M_PI * (cell % kCols + 0.5) / kCols - M_PI;
  const double s = std::sqrt(std::max(0.0, 1 - z * z));
  return {s * std::cos(azimuth), s * std::sin(azimuth), z};
}

// A plate's face in square cells over its outline, this many along its
// longer side (6.5 mm cells on the demo's 130 mm plate, ~40 points each).
constexpr int kPlateCellsAlong = 20;

// A part of a sphere measured off keeps the surface's orientation to within
// its slope error (a patch a grid period off is the surface shifted along
// the camera's ray: a few degrees), so its normals lie within this angle of
// the radial direction; a table below the sphere, where it lands in the
// window (within ~35 degrees of the nadir), faces up: 145 degrees or more
// from radial.
constexpr double kCosFacingOut = 0.866;  // 30 degrees

}  // namespace

SurfaceBeyondBand SphereSurfaceBeyondBand(const std::vector<Eigen::Vector3d>& pts,
                                          const std::vector<Eigen::Vector3d>& normals, const Eigen::Vector3d& center_mm,
                                          double radius_mm, double band_mm, const Eigen::Vector3d& axis,
                                          double cos_cone) {
  Cells cells(kRows, kCols, /*wrap=*/true);
  for (int c = 0; c < kRows * kCols; ++c) cells.ignored[c] = CellCentre(c).dot(axis) > cos_cone;
  auto off_mm = [&](int i) { return (pts[i] - center_mm).norm() - radius_mm; };
  for (int i = 0; i < static_cast<int>(pts.size()); ++i) {
    const Eigen::Vector3d d = pts[i] - center_mm;
    const double n = d.norm();
    if (!(n > 0) || d.dot(axis) > cos_cone * n) continue;
    const double off = std::abs(off_mm(i));
    if (off < band_mm) {
      ++cells.on[CellOf(d / n)];
    } else if (off <= kBeyondBandWidths * band_mm) {
      // Facing otherwise than out of the sphere (a table, a stand's side;
      // no direction written): not the sphere's surface measured off.
      if (!normals.empty() && !(normals[i].norm() > 0 && normals[i].dot(d / n) >= kCosFacingOut * normals[i].norm()))
        continue;
      cells.beyond[CellOf(d / n)].push_back(i);
    }
  }
  // Without normals a layer over the surface may be anything facing any
  // way (a table below the sphere, in the cells ~30 degrees from the nadir
  // that the sphere's own surface holds too): such cells count only where
  // the normals left it out.
  return Judge(cells, band_mm, off_mm, /*overlaid=*/!normals.empty());
}

SurfaceBeyondBand PlateSurfaceBeyondBand(const std::vector<Eigen::Vector3d>& pts,
                                         const std::vector<Eigen::Vector3d>& normals, const Eigen::Vector3d& normal,
                                         double offset_mm, int face_side, const PlaneOutline& outline, double margin_mm,
                                         double band_mm) {
  const double length_mm = outline.length_mm() - 2 * margin_mm, width_mm = outline.width_mm() - 2 * margin_mm;
  const double cell_mm = std::max(length_mm, width_mm) / kPlateCellsAlong;
  if (!(cell_mm > 0) || !(std::min(length_mm, width_mm) > 0)) return {};
  const int cols = std::max(1, static_cast<int>(std::ceil(length_mm / cell_mm)));
  const int rows = std::max(1, static_cast<int>(std::ceil(width_mm / cell_mm)));
  Cells cells(rows, cols, /*wrap=*/false);
  auto off_mm = [&](int i) { return normal.dot(pts[i]) - offset_mm; };
  for (int i = 0; i < static_cast<int>(pts.size()); ++i) {
    if (!outline.InsideEroded(pts[i], margin_mm)) continue;
    const Eigen::Vector3d d = pts[i] - outline.mean;
    const int col = std::clamp(static_cast<int>((outline.u.dot(d) - outline.u0_mm - margin_mm) / cell_mm), 0, cols - 1);
    const int row = std::clamp(static_cast<int>((outline.v.dot(d) - outline.v0_mm - margin_mm) / cell_mm), 0, rows - 1);
    const double off = std::abs(off_mm(i));
    if (off < band_mm) {
      ++cells.on[row * cols + col];
    } else if (off <= kBeyondBandWidths * band_mm) {
      // Measured from the plate's other side: its far face, not the face.
      if (face_side != 0 && !normals.empty() && normals[i].dot(normal) * face_side < 0) continue;
      cells.beyond[row * cols + col].push_back(i);
    }
  }
  // Without normals a plate thicker than the band seen from both sides puts
  // its far face over the face's cells: a layer over them counts only where
  // the normals leave that far face out.
  return Judge(cells, band_mm, off_mm, /*overlaid=*/face_side != 0 && !normals.empty());
}

}  // namespace stereorig
