#include "reconstruct/pfm.h"

#include <bit>
#include <cstring>
#include <fstream>
#include <sstream>

#include "calib/core/atomic_file.h"
#include "calib/core/file_suffix.h"
#include "calib/core/input_error.h"

namespace stereorig {
namespace {

constexpr bool kHostLittleEndian = std::endian::native == std::endian::little;

float ByteSwap(float v) {
  uint32_t u;
  std::memcpy(&u, &v, 4);
  u = __builtin_bswap32(u);
  std::memcpy(&v, &u, 4);
  return v;
}

}  // namespace

std::string EncodePfm(const cv::Mat& image_f32) {
  STEREORIG_CHECK(image_f32.type() == CV_32FC1);
  const int w = image_f32.cols, h = image_f32.rows;
  std::string out = "Pf\n" + std::to_string(w) + " " + std::to_string(h) + "\n-1\n";
  const size_t header = out.size();
  out.resize(header + size_t(w) * h * 4);
  char* dst = out.data() + header;
  for (int r = h - 1; r >= 0; --r) {  // bottom row first
    const float* row = image_f32.ptr<float>(r);
    for (int c = 0; c < w; ++c) {
      const float v = kHostLittleEndian ? row[c] : ByteSwap(row[c]);
      std::memcpy(dst, &v, 4);
      dst += 4;
    }
  }
  return out;
}

cv::Mat DecodePfm(const std::string& bytes, const std::string& where) {
  // The header is three whitespace-separated tokens after the magic, each
  // line ended by a single whitespace character before the binary data.
  size_t pos = 0;
  auto token = [&](const char* what) {
    while (pos < bytes.size() && std::isspace(static_cast<unsigned char>(bytes[pos]))) ++pos;
    const size_t start = pos;
    while (pos < bytes.size() && !std::isspace(static_cast<unsigned char>(bytes[pos]))) ++pos;
    if (start == pos) throw InputError(where, std::string("PFM header ends before the ") + what);
    return bytes.substr(start, pos - start);
  };
  const std::string magic = token("magic");
  if (magic == "PF") throw InputError(where, "colour PFM (PF) is not supported; disparity maps are grey (Pf)");
  if (magic != "Pf") throw InputError(where, "not a PFM file (magic '" + magic + "', expected 'Pf')");
  int w = 0, h = 0;
  double scale = 0;
  try {
    w = std::stoi(token("width"));
    h = std::stoi(token("height"));
    scale = std::stod(token("scale"));
  } catch (const std::logic_error&) {
    throw InputError(where, "PFM header has a non-numeric width, height or scale");
  }
  if (w <= 0 || h <= 0 || w > 1 << 16 || h > 1 << 16) throw InputError(where, "PFM has a bad size");
  if (scale == 0) throw InputError(where, "PFM scale is 0 (its sign must give the byte order)");
  ++pos;  // the single whitespace byte that ends the header
  const size_t need = size_t(w) * h * 4;
  if (bytes.size() < pos + need) throw InputError(where, "PFM data is shorter than width*height floats");
  const bool file_little = scale < 0;
  cv::Mat image(h, w, CV_32FC1);
  const char* src = bytes.data() + pos;
  for (int r = h - 1; r >= 0; --r) {
    float* row = image.ptr<float>(r);
    for (int c = 0; c < w; ++c) {
      float v;
      std::memcpy(&v, src, 4);
      src += 4;
      row[c] = file_little == kHostLittleEndian ? v : ByteSwap(v);
    }
  }
  return image;
}

void WritePfm(const cv::Mat& image_f32, const std::string& path) {
  CheckPfmPath(path);
  WriteFileAtomically(path, EncodePfm(image_f32));
}

void CheckPfmPath(const std::string& path) {
  if (!EndsWithIgnoringCase(path, ".pfm"))
    throw InputError(path, "disparity output must end in .pfm (it is written as PFM)");
}

cv::Mat ReadPfm(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "cannot open");
  std::ostringstream ss;
  ss << in.rdbuf();
  return DecodePfm(ss.str(), path);
}

}  // namespace stereorig
