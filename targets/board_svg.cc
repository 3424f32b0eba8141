#include "targets/board_svg.h"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <vector>

#include "calib/core/input_error.h"

namespace stereorig {

void BoardSvgOptions::Check() const {
  const std::string where = "board svg";
  if (!(page_margin_mm >= 0)) throw InputError(where, "page_margin_mm must not be negative");
  if (!(face_gap_mm >= 0)) throw InputError(where, "face_gap_mm must not be negative");
  if (!(scale_bar_mm > 0)) throw InputError(where, "scale_bar_mm must be positive");
}

namespace {

// Numbers with 4 decimals (0.1 um): exact enough, and stable text.
std::string Mm(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.4f", std::abs(v) < 5e-5 ? 0.0 : v);
  std::string s(buf);
  while (s.back() == '0') s.pop_back();
  if (s.back() == '.') s.pop_back();
  return s;
}

void Rect(std::ostringstream& o, const char* cls, double x, double y, double w, double h) {
  o << "  <rect class=\"" << cls << "\" x=\"" << Mm(x) << "\" y=\"" << Mm(y) << "\" width=\"" << Mm(w) << "\" height=\""
    << Mm(h) << "\"/>\n";
}

void Text(std::ostringstream& o, double x, double y, double size_mm, const std::string& text,
          const char* anchor = "start") {
  o << "  <text x=\"" << Mm(x) << "\" y=\"" << Mm(y) << "\" font-size=\"" << Mm(size_mm)
    << "\" font-family=\"sans-serif\" text-anchor=\"" << anchor << "\" fill=\"#000\">" << text << "</text>\n";
}

void Line(std::ostringstream& o, double x0, double y0, double x1, double y1, double width_mm, const char* colour) {
  o << "  <line x1=\"" << Mm(x0) << "\" y1=\"" << Mm(y0) << "\" x2=\"" << Mm(x1) << "\" y2=\"" << Mm(y1)
    << "\" stroke=\"" << colour << "\" stroke-width=\"" << Mm(width_mm) << "\"/>\n";
}

// One face with its plate's top-left corner at page (ox, oy).
void DrawFace(std::ostringstream& o, const Target& target, Face face, double ox, double oy) {
  const Target::Layout& l = target.layout();
  const double s = l.square_size_mm;
  // page = (ox, oy) + (face - plate min)
  const double dx = ox - target.min_x_mm(), dy = oy - target.min_y_mm();
  const double w = target.max_x_mm() - target.min_x_mm(), h = target.max_y_mm() - target.min_y_mm();
  o << " <g class=\"face\" id=\"" << FaceName(face) << "\">\n";
  // The plate outline: the cut line, light grey, outside the squares.
  o << "  <rect class=\"plate\" x=\"" << Mm(ox) << "\" y=\"" << Mm(oy) << "\" width=\"" << Mm(w) << "\" height=\""
    << Mm(h) << "\" fill=\"none\" stroke=\"#b0b0b0\" stroke-width=\"0.2\"/>\n";
  o << "  <g fill=\"#000\" shape-rendering=\"crispEdges\">\n";
  for (int j = -1; j < l.corners_y; ++j) {
    for (int i = -1; i < l.corners_x; ++i) {
      if (target.IsBlack(face, (i + 0.5) * s, (j + 0.5) * s)) Rect(o, "square", dx + i * s, dy + j * s, s, s);
    }
  }
  // Tags: runs of black cells along each cell row, one rect per run.
  for (const TagPlacement& t : l.faces[static_cast<int>(face)].tags) {
    const TagBits bits = RenderTagBits(l.tag_family, t.id);
    const double cell = l.tag_size_mm / bits.width_at_border;
    const double x0 = t.center_x_mm - 0.5 * cell * bits.total_width, y0 = t.center_y_mm - 0.5 * cell * bits.total_width;
    for (int r = 0; r < bits.total_width; ++r) {
      for (int c = 0; c < bits.total_width;) {
        if (!bits.black[r * bits.total_width + c]) {
          ++c;
          continue;
        }
        int end = c;
        while (end < bits.total_width && bits.black[r * bits.total_width + end]) ++end;
        Rect(o, "tag-cell", dx + x0 + c * cell, dy + y0 + r * cell, (end - c) * cell, cell);
        c = end;
      }
    }
  }
  o << "  </g>\n";
  // Markers outside the plate: corner 0's column (above) and row (left),
  // with the face frame's x and y directions.
  const double tick = 4.0, gap = 1.0;
  Line(o, dx, oy - gap, dx, oy - gap - tick, 0.3, "#000");
  Line(o, ox - gap, dy, ox - gap - tick, dy, 0.3, "#000");
  Text(o, dx + 1.0, oy - gap - 1.0, 2.5, "x &#8594; (corner 0 column)");
  o << "  <text x=\"" << Mm(ox - gap - 1.0) << "\" y=\"" << Mm(dy + 1.0) << "\" font-size=\"2.5\" "
    << "font-family=\"sans-serif\" fill=\"#000\" transform=\"rotate(90 " << Mm(ox - gap - 1.0) << " " << Mm(dy + 1.0)
    << ")\">y &#8594; (corner 0 row)</text>\n";
  std::ostringstream title;
  title << (target.double_sided() ? (face == Face::kFront ? "FRONT face" : "BACK face") : "plain board") << ": "
        << l.corners_x << "x" << l.corners_y << " inner corners, squares " << Mm(s) << " mm";
  if (target.double_sided()) {
    title << ", " << l.tag_family << " IDs";
    for (const TagPlacement& t : l.faces[static_cast<int>(face)].tags) title << " " << t.id;
  }
  Text(o, ox, oy + h + 5.0, 3.0, title.str());
  o << " </g>\n";
}

}  // namespace

BoardSvg MakeBoardSvg(const Target& target, const BoardSvgOptions& options) {
  options.Check();
  std::vector<Face> faces;
  if (options.faces != SvgFaces::kBack) faces.push_back(Face::kFront);
  if (options.faces != SvgFaces::kFront && target.double_sided()) faces.push_back(Face::kBack);
  if (options.faces == SvgFaces::kBack && !target.double_sided()) {
    throw InputError("board svg", "a plain (one-sided) board has no back face");
  }
  const double plate_w = target.max_x_mm() - target.min_x_mm(), plate_h = target.max_y_mm() - target.min_y_mm();
  const double m = options.page_margin_mm;
  const double top = m + 8.0;   // room for the markers above the plates
  const double left = m + 8.0;  // and to their left
  const double faces_w = faces.size() * plate_w + (faces.size() - 1) * (options.face_gap_mm + 8.0);
  const double bar_y = top + plate_h + 14.0;
  BoardSvg out;
  out.width_mm = left + std::max(faces_w, options.scale_bar_mm + 60.0) + m;
  out.height_mm = bar_y + 12.0 + m;

  std::ostringstream o;
  o << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
    << "<!-- stereorig target. Print at 100 % (actual size, no fit-to-page); check the scale bar. -->\n"
    << "<svg xmlns=\"http://www.w3.org/2000/svg\" version=\"1.1\" width=\"" << Mm(out.width_mm) << "mm\" height=\""
    << Mm(out.height_mm) << "mm\" viewBox=\"0 0 " << Mm(out.width_mm) << " " << Mm(out.height_mm) << "\">\n"
    << " <rect x=\"0\" y=\"0\" width=\"" << Mm(out.width_mm) << "\" height=\"" << Mm(out.height_mm)
    << "\" fill=\"#fff\"/>\n";
  for (size_t f = 0; f < faces.size(); ++f) {
    DrawFace(o, target, faces[f], left + f * (plate_w + options.face_gap_mm + 8.0), top);
  }
  // The scale bar: a black bar with 10 mm ticks.
  const double bar = options.scale_bar_mm;
  o << " <g class=\"scale\">\n";
  o << "  <rect class=\"scale-bar\" x=\"" << Mm(left) << "\" y=\"" << Mm(bar_y) << "\" width=\"" << Mm(bar)
    << "\" height=\"2\" fill=\"#000\"/>\n";
  for (int k = 0; k * 10.0 <= bar + 1e-9; ++k)
    Line(o, left + k * 10.0, bar_y - 2.0, left + k * 10.0, bar_y, 0.2, "#000");
  char label[96];
  std::snprintf(label, sizeof(label), "check: this bar is %.1f mm", bar);
  Text(o, left + bar + 4.0, bar_y + 2.0, 3.0, label);
  o << " </g>\n</svg>\n";
  out.text = o.str();
  return out;
}

}  // namespace stereorig
