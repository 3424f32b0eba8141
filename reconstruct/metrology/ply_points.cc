#include "reconstruct/metrology/ply_points.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>

#include "calib/core/file_suffix.h"
#include "calib/core/input_error.h"
#include "calib/core/input_file.h"

namespace stereorig {

namespace {

enum class Encoding { kAscii, kLittle, kBig };

struct Property {
  std::string name;
  std::string type;        // scalar type, or the item type of a list
  std::string count_type;  // non-empty for a list
};

int SizeOf(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "float" || t == "int32" || t == "uint32" || t == "float32") return 4;
  if (t == "double" || t == "float64") return 8;
  return 0;
}

double ReadBinary(std::istream& in, const std::string& t, bool swap, const std::string& path) {
  unsigned char b[8];
  const int n = SizeOf(t);
  if (!in.read(reinterpret_cast<char*>(b), n)) throw InputError(path, "truncated PLY body");
  if (swap) std::reverse(b, b + n);
  auto get = [&](auto v) {
    std::memcpy(&v, b, sizeof v);
    return static_cast<double>(v);
  };
  if (t == "char" || t == "int8") return get(int8_t{});
  if (t == "uchar" || t == "uint8") return get(uint8_t{});
  if (t == "short" || t == "int16") return get(int16_t{});
  if (t == "ushort" || t == "uint16") return get(uint16_t{});
  if (t == "int" || t == "int32") return get(int32_t{});
  if (t == "uint" || t == "uint32") return get(uint32_t{});
  if (t == "float" || t == "float32") return get(float{});
  return get(double{});
}

}  // namespace

PlyVertices ReadPlyVertices(const std::string& path) {
  RequireInputFile(path, /*pipe_too=*/true);  // a folder is named as one, not as "not a PLY file"
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "cannot be read");
  std::string line;
  if (!std::getline(in, line) || line.rfind("ply", 0) != 0) {
    if (EndsWithIgnoringCase(path, ".stl")) {
      throw InputError(path,
                       "not a PLY file: an STL mesh holds no per-vertex module, so hole filling's points "
                       "(module 255) cannot be told from measured ones; give the cloud (reconstruct --out) or a PLY "
                       "mesh");
    }
    throw InputError(path, "not a PLY file");
  }
  PlyVertices out;
  Encoding enc = Encoding::kAscii;
  long long num_vertices = -1;
  bool in_vertex = false, seen_vertex = false, after_vertex = false;
  std::string element_before_vertex;  // a vertex element that is not the first: its data would be misread
  std::vector<Property> props;
  while (true) {
    if (!std::getline(in, line)) throw InputError(path, "PLY header has no end_header");
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream s(line);
    std::string word;
    s >> word;
    if (word == "end_header") break;
    if (word == "format") {
      std::string f;
      s >> f;
      if (f == "ascii")
        enc = Encoding::kAscii;
      else if (f == "binary_little_endian")
        enc = Encoding::kLittle;
      else if (f == "binary_big_endian")
        enc = Encoding::kBig;
      else
        throw InputError(path, "unknown PLY format '" + f + "'");
    } else if (word == "element") {
      std::string name;
      long long count = 0;
      std::string rest;  // "element vertex 1e12" read a count of 1 and stopped at "e12"
      s >> name >> count;
      if (!s || count < 0 || s >> rest) throw InputError(path, "malformed element line '" + line + "'");
      if (seen_vertex && count > 0) after_vertex = true;  // data after the vertices, not read
      in_vertex = name == "vertex";
      if (name == "face") out.faces = count;
      if (in_vertex) {
        if (seen_vertex) throw InputError(path, "two vertex elements");
        if (!element_before_vertex.empty()) {
          throw InputError(path, "its vertex element comes after '" + element_before_vertex +
                                     "'; this reader needs the vertices first (as every PLY writer of point clouds "
                                     "puts them)");
        }
        seen_vertex = true;
        num_vertices = count;
      } else if (!seen_vertex && element_before_vertex.empty() && count > 0) {
        element_before_vertex = name;  // an empty one holds no data to misread
      }
    } else if (word == "property" && in_vertex) {
      Property p;
      std::string t;
      s >> t;
      if (t == "list") {
        s >> p.count_type >> p.type;
      } else {
        p.type = t;
      }
      s >> p.name;
      if (!SizeOf(p.type) || (!p.count_type.empty() && !SizeOf(p.count_type))) {
        throw InputError(path, "unknown PLY property type in '" + line + "'");
      }
      props.push_back(p);
    }
  }
  if (!seen_vertex || num_vertices < 0) throw InputError(path, "PLY has no vertex element");
  int ix = -1, iy = -1, iz = -1, imodule = -1, inx = -1, iny = -1, inz = -1;
  for (int i = 0; i < static_cast<int>(props.size()); ++i) {
    if (!props[i].count_type.empty()) continue;
    if (props[i].name == "x") ix = i;
    if (props[i].name == "y") iy = i;
    if (props[i].name == "z") iz = i;
    if (props[i].name == "module") imodule = i;
    if (props[i].name == "nx") inx = i;
    if (props[i].name == "ny") iny = i;
    if (props[i].name == "nz") inz = i;
  }
  if (ix < 0 || iy < 0 || iz < 0) throw InputError(path, "PLY vertices have no x, y, z");
  // Normals are all three or none: one or two of them is a broken writer,
  // not a cloud whose normals verify could read.
  const int normal_components = (inx >= 0) + (iny >= 0) + (inz >= 0);
  if (normal_components != 0 && normal_components != 3)
    throw InputError(path, "PLY vertices have some of nx, ny, nz but not all three");
  const bool has_normals = normal_components == 3;
  const bool swap = (enc == Encoding::kBig) == (std::endian::native == std::endian::little);
  // The declared count against what the file can hold, before anything is
  // allocated for it: a header declaring 3000000000 vertices ended in
  // std::bad_alloc and an abort (exit 134), not in the truncated body it is.
  // A vertex takes at least its scalars' bytes (a list at least its count),
  // or in ASCII one character and a separator per property. A pipe, whose
  // size is unknown, is read as it comes, with no more reserved than a
  // million points.
  size_t min_record_bytes = 0;
  for (const Property& p : props)
    min_record_bytes += enc == Encoding::kAscii ? 2 : SizeOf(p.count_type.empty() ? p.type : p.count_type);
  const std::streamoff body_at = in.tellg();
  std::streamoff end_at = -1;
  if (body_at >= 0) {
    in.seekg(0, std::ios::end);
    end_at = in.tellg();
    in.clear();
    in.seekg(body_at);
  }
  size_t reserve = std::min<size_t>(static_cast<size_t>(num_vertices), 1 << 20);
  if (body_at >= 0 && end_at >= body_at) {
    // +1: the last ASCII value needs no separator after it.
    const auto body_bytes = static_cast<unsigned long long>(end_at - body_at) + (enc == Encoding::kAscii ? 1 : 0);
    if (static_cast<unsigned long long>(num_vertices) > body_bytes / min_record_bytes) {
      throw InputError(path, "truncated PLY body: its header declares " + std::to_string(num_vertices) +
                                 " vertices, at least " + std::to_string(min_record_bytes) +
                                 " bytes each, and the file holds " + std::to_string(end_at - body_at) +
                                 " bytes after its header");
    }
    reserve = static_cast<size_t>(num_vertices);
  }
  out.points.reserve(reserve);
  if (imodule >= 0) out.module.reserve(reserve);
  if (has_normals) out.normals.reserve(reserve);
  std::vector<double> v(props.size());
  for (long long k = 0; k < num_vertices; ++k) {
    if (enc == Encoding::kAscii) {
      for (size_t i = 0; i < props.size(); ++i) {
        if (!props[i].count_type.empty()) {
          double n;
          if (!(in >> n)) throw InputError(path, "truncated PLY body");
          for (int j = 0; j < static_cast<int>(n); ++j) {
            double skip;
            in >> skip;
          }
        } else if (!(in >> v[i])) {
          throw InputError(path, "truncated or malformed PLY body at vertex " + std::to_string(k));
        }
      }
    } else {
      for (size_t i = 0; i < props.size(); ++i) {
        if (!props[i].count_type.empty()) {
          const int n = static_cast<int>(ReadBinary(in, props[i].count_type, swap, path));
          for (int j = 0; j < n; ++j) ReadBinary(in, props[i].type, swap, path);
        } else {
          v[i] = ReadBinary(in, props[i].type, swap, path);
        }
      }
    }
    const Eigen::Vector3d p(v[ix], v[iy], v[iz]);
    if (!p.allFinite()) throw InputError(path, "vertex " + std::to_string(k) + " is not finite");
    out.points.push_back(p);
    if (imodule >= 0) out.module.push_back(static_cast<int>(v[imodule]));
    if (has_normals) {
      const Eigen::Vector3d n(v[inx], v[iny], v[inz]);
      if (!n.allFinite()) throw InputError(path, "vertex " + std::to_string(k) + "'s normal is not finite");
      out.normals.push_back(n);
    }
  }
  // With nothing declared after the vertices, anything more is data the
  // header does not count: a vertex count too small would drop points
  // unseen. (Trailing white space of an ASCII file is no data.)
  if (!after_vertex) {
    bool more = false;
    if (enc == Encoding::kAscii) {
      in >> std::ws;
      more = in.peek() != std::char_traits<char>::eof();
    } else {
      // A whole vertex record or more; a stray byte or two (a newline some
      // writers end with) is not a vertex.
      size_t record = 0;
      for (const Property& p : props) record += p.count_type.empty() ? SizeOf(p.type) : SizeOf(p.count_type);
      const std::streamoff at = in.tellg();
      in.seekg(0, std::ios::end);
      more = at >= 0 && in.tellg() - at >= static_cast<std::streamoff>(record);
    }
    if (more) {
      throw InputError(path, "holds more data after its " + std::to_string(num_vertices) +
                                 " vertices than its header declares (a wrong vertex count?)");
    }
  }
  return out;
}

std::vector<Eigen::Vector3d> ReadPlyPoints(const std::string& path) { return ReadPlyVertices(path).points; }

MeasuredPoints ReadMeasuredPlyPoints(const std::string& path) {
  PlyVertices all = ReadPlyVertices(path);
  MeasuredPoints measured;
  if (all.module.empty()) {
    if (all.faces > 0) {
      measured.note =
          "a mesh without a per-vertex module: all " + std::to_string(all.points.size()) +
          " vertices are taken as measured (a stereorig mesh written before its vertices kept their module may hold "
          "hole filling's: verify the cloud, reconstruct --out)";
    }
    measured.points = std::move(all.points);
    measured.normals = std::move(all.normals);
    return measured;
  }
  for (size_t k = 0; k < all.points.size(); ++k) {
    if (all.module[k] == kPlyFilledModule) {
      ++measured.filled_skipped;
    } else {
      measured.points.push_back(all.points[k]);
      if (!all.normals.empty()) measured.normals.push_back(all.normals[k]);
    }
  }
  return measured;
}

}  // namespace stereorig
