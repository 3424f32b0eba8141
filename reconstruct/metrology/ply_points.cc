#include "reconstruct/metrology/ply_points.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>

#include "calib/core/file_suffix.h"
#include "calib/core/input_error.h"
#include "calib/core/input_file.h"
#include "calib/core/number_text.h"

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

// One element of the header: its name, declared count and properties.
struct Element {
  std::string name;
  long long count = 0;
  std::vector<Property> props;
};

// Reads the body's values one at a time, as the header's encoding stores
// them. Read is false at the end of the file; it throws on an ASCII word
// that is not a number, naming where() (the record being read: made only
// then, not for each of millions of records).
class BodyReader {
 public:
  BodyReader(std::istream& in, Encoding enc, const std::string& path)
      : in_(in),
        enc_(enc),
        swap_((enc == Encoding::kBig) == (std::endian::native == std::endian::little)),
        path_(path) {}

  template <typename Where>
  bool Read(const std::string& type, double* v, const Where& where) {
    if (enc_ == Encoding::kAscii) {
      // A word, then strtod: `in >> double` fails on "nan", which read as a
      // truncated body; strtod reads it, for the record's check to name.
      if (!(in_ >> word_)) return false;
      char* end = nullptr;
      *v = std::strtod(word_.c_str(), &end);
      if (end != word_.c_str() + word_.size())
        throw InputError(path_, "malformed PLY body at " + where() + ": '" + word_ + "' is not a number");
      return true;
    }
    unsigned char b[8];
    const int n = SizeOf(type);
    if (!in_.read(reinterpret_cast<char*>(b), n)) return false;
    if (swap_) std::reverse(b, b + n);
    auto get = [&](auto x) {
      std::memcpy(&x, b, sizeof x);
      return static_cast<double>(x);
    };
    if (type == "char" || type == "int8")
      *v = get(int8_t{});
    else if (type == "uchar" || type == "uint8")
      *v = get(uint8_t{});
    else if (type == "short" || type == "int16")
      *v = get(int16_t{});
    else if (type == "ushort" || type == "uint16")
      *v = get(uint16_t{});
    else if (type == "int" || type == "int32")
      *v = get(int32_t{});
    else if (type == "uint" || type == "uint32")
      *v = get(uint32_t{});
    else if (type == "float" || type == "float32")
      *v = get(float{});
    else
      *v = get(double{});
    return true;
  }

 private:
  std::istream& in_;
  Encoding enc_;
  bool swap_;
  const std::string& path_;
  std::string word_;
};

bool IsFaceIndexList(const Element& e, const Property& p) {
  return e.name == "face" && !p.count_type.empty() && (p.name == "vertex_indices" || p.name == "vertex_index");
}

// One record of `e`: its scalars into `values` (a list's items are read and,
// for a face's vertex indices, checked against `num_vertices`; a list's
// other items are skipped). Throws naming the record on a body cut short, a
// list count that is no count, or a face that is no face.
void ReadRecord(BodyReader& body, const Element& e, long long k, long long num_vertices, std::vector<double>* values,
                const std::string& path) {
  auto where = [&] { return e.name + " " + std::to_string(k); };
  auto read = [&](const std::string& type, double* v) {
    if (!body.Read(type, v, where))
      throw InputError(
          path, "truncated PLY body at " + where() + " of the " + std::to_string(e.count) + " its header declares");
  };
  for (size_t i = 0; i < e.props.size(); ++i) {
    const Property& p = e.props[i];
    if (p.count_type.empty()) {
      read(p.type, &(*values)[i]);
      continue;
    }
    double n;
    read(p.count_type, &n);
    if (!(n >= 0 && n == std::floor(n)))
      throw InputError(
          path, "malformed PLY body at " + where() + ": its list '" + p.name + "' has a count of " + NumberText(n));
    const bool face = IsFaceIndexList(e, p);
    // A face is a polygon: fewer than 3 corners is a writer's fault or data
    // read out of step.
    if (face && n < 3)
      throw InputError(path, where() + " has " + NumberText(n) + " vertex indices; a face needs at least 3");
    for (double j = 0; j < n; ++j) {
      double index;
      read(p.type, &index);
      if (face && !(index >= 0 && index < static_cast<double>(num_vertices) && index == std::floor(index)))
        throw InputError(path, where() + " names vertex " + NumberText(index, 17) + ", not one of its " +
                                   std::to_string(num_vertices) + " vertices (0 to " +
                                   std::to_string(num_vertices - 1) + ")");
    }
  }
}

// What a vertex's coordinate is when it is not a finite number, or "".
std::string NotFinite(double v, const char* axis, long long k) {
  if (std::isnan(v)) return "vertex " + std::to_string(k) + "'s " + axis + " is not a number";
  if (!std::isfinite(v)) return "vertex " + std::to_string(k) + "'s " + axis + " is not finite (" + NumberText(v) + ")";
  return "";
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
  std::vector<Element> elements;
  int vertex_element = -1;
  std::string element_before_vertex;  // a vertex element that is not the first: its data would be misread
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
      // 1.0 is the only PLY version there is: a file claiming another is
      // one this reader cannot vouch for, not one to read as 1.0 and measure.
      std::string version;
      s >> version;
      if (version != "1.0") {
        const std::string gives = version.empty() ? "no PLY version" : "PLY version " + version;
        throw InputError(path, "its format line '" + line + "' gives " + gives + "; this reader reads PLY 1.0 only");
      }
    } else if (word == "element") {
      Element e;
      std::string rest;  // "element vertex 1e12" read a count of 1 and stopped at "e12"
      s >> e.name >> e.count;
      if (!s || e.count < 0 || s >> rest) throw InputError(path, "malformed element line '" + line + "'");
      if (e.name == "face") out.faces = e.count;
      if (e.name == "vertex") {
        if (vertex_element >= 0) throw InputError(path, "two vertex elements");
        if (!element_before_vertex.empty()) {
          throw InputError(path, "its vertex element comes after '" + element_before_vertex +
                                     "'; this reader needs the vertices first (as every PLY writer of point clouds "
                                     "puts them)");
        }
        vertex_element = static_cast<int>(elements.size());
      } else if (vertex_element < 0 && element_before_vertex.empty() && e.count > 0) {
        element_before_vertex = e.name;  // an empty one holds no data to misread
      }
      elements.push_back(e);
    } else if (word == "property" && !elements.empty()) {
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
      elements.back().props.push_back(p);
    }
  }
  if (vertex_element < 0) throw InputError(path, "PLY has no vertex element");
  const long long num_vertices = elements[vertex_element].count;
  const std::vector<Property>& props = elements[vertex_element].props;
  int ix = -1, iy = -1, iz = -1, imodule = -1, inx = -1, iny = -1, inz = -1;
  // A property declared twice is a broken header (which column is x?):
  // named as such, not as the coordinate that is then missing beside it.
  for (int i = 0; i < static_cast<int>(props.size()); ++i) {
    for (int j = 0; j < i; ++j) {
      if (props[j].name == props[i].name)
        throw InputError(path, "its vertex property '" + props[i].name + "' is declared twice");
    }
  }
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
  // `module` is stereorig's (docs/formats.md): a uchar, 255 hole filling's.
  // Another type is another writer's property or a header edited without
  // its data (a float module read the records out of step, and blamed a
  // vertex for not being finite).
  if (imodule >= 0 && props[imodule].type != "uchar" && props[imodule].type != "uint8")
    throw InputError(path, "its vertex property 'module' is " + props[imodule].type +
                               "; stereorig's module is uchar (the measuring module, 255 for hole filling's points)");
  // Normals are all three or none: one or two of them is a broken writer,
  // not a cloud whose normals verify could read.
  const int normal_components = (inx >= 0) + (iny >= 0) + (inz >= 0);
  if (normal_components != 0 && normal_components != 3)
    throw InputError(path, "PLY vertices have some of nx, ny, nz but not all three");
  const bool has_normals = normal_components == 3;
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
  BodyReader body(in, enc, path);
  std::vector<double> v(props.size());
  for (long long k = 0; k < num_vertices; ++k) {
    ReadRecord(body, elements[vertex_element], k, num_vertices, &v, path);
    for (const auto& [i, axis] : {std::pair{ix, "x"}, {iy, "y"}, {iz, "z"}})
      if (const std::string problem = NotFinite(v[i], axis, k); !problem.empty()) throw InputError(path, problem);
    out.points.emplace_back(v[ix], v[iy], v[iz]);
    if (imodule >= 0) out.module.push_back(static_cast<int>(v[imodule]));
    if (has_normals) {
      const Eigen::Vector3d n(v[inx], v[iny], v[inz]);
      if (!n.allFinite()) throw InputError(path, "vertex " + std::to_string(k) + "'s normal is not finite");
      out.normals.push_back(n);
    }
  }
  // The elements after the vertices (a mesh's faces) are read too: a mesh
  // cut short, a face index out of range or a wrong list count (its faces
  // read out of step) was passed as the cloud its vertices are. Their
  // values are not kept; a face's vertex indices are checked.
  std::string read_so_far = std::to_string(num_vertices) + " vertices";
  for (size_t e = vertex_element + 1; e < elements.size(); ++e) {
    if (elements[e].props.empty() || elements[e].count == 0) continue;  // holds no data
    std::vector<double> values(elements[e].props.size());
    for (long long k = 0; k < elements[e].count; ++k) ReadRecord(body, elements[e], k, num_vertices, &values, path);
    read_so_far +=
        " and " + std::to_string(elements[e].count) + " " + elements[e].name + (elements[e].count == 1 ? "" : "s");
  }
  // Anything more is data the header does not count: a vertex count too
  // small would drop points unseen. (Trailing white space of an ASCII file
  // is no data.)
  bool more = false;
  if (enc == Encoding::kAscii) {
    in >> std::ws;
    more = in.peek() != std::char_traits<char>::eof();
  } else {
    // A whole record of the last element or more; a stray byte or two (a
    // newline some writers end with) is not a record.
    size_t record = 0;
    for (const Element& e : elements)
      if (e.count > 0 && !e.props.empty()) {
        record = 0;
        for (const Property& p : e.props) record += p.count_type.empty() ? SizeOf(p.type) : SizeOf(p.count_type);
      }
    const std::streamoff at = in.tellg();  // -1 for a pipe: what follows is not looked at
    if (at >= 0) {
      in.seekg(0, std::ios::end);
      const std::streamoff left = in.tellg() - at;
      in.seekg(at);
      char tail[2] = {};
      const bool newline_only = left <= 2 && in.read(tail, left) &&
                                std::all_of(tail, tail + left, [](char c) { return c == '\r' || c == '\n'; });
      more = left >= static_cast<std::streamoff>(record) && !newline_only;
    }
  }
  if (more) {
    const bool only_vertices = read_so_far.find(" and ") == std::string::npos;
    throw InputError(path, "holds more data after its " + read_so_far + " than its header declares (a wrong " +
                               (only_vertices ? "vertex" : "vertex or face") + " count?)");
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
