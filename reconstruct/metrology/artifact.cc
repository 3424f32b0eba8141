#include "reconstruct/metrology/artifact.h"

#include <cstdio>
#include <filesystem>
#include <sstream>
#include <utility>

#include "calib/core/input_error.h"
#include "calib/core/input_file.h"
#include "calib/core/rig_file.h"
#include "calib/core/yaml_reader.h"

namespace stereorig {

const char* ArtifactTypeName(ArtifactType type) {
  switch (type) {
    case ArtifactType::kSphere:
      return "sphere";
    case ArtifactType::kBallBar:
      return "ballbar";
    case ArtifactType::kPlate:
      return "plate";
  }
  return "?";
}

std::string ImplausibleMm(double v, const PlausibleMm& range, const std::string& units_note) {
  if (v >= range.min_mm && v <= range.max_mm) return "";
  char buf[256];
  std::snprintf(buf, sizeof buf, "%g mm is not a plausible %s (%g to %g mm)", v, range.what, range.min_mm,
                range.max_mm);
  std::string problem = buf;
  for (const auto& [unit, to_mm] : {std::pair<const char*, double>{"micrometres", 1e-3}, {"metres", 1e3}}) {
    if (v * to_mm >= range.min_mm && v * to_mm <= range.max_mm) {
      std::snprintf(buf, sizeof buf, ": in %s it would be %g mm (%s)", unit, v * to_mm, units_note.c_str());
      problem += buf;
    }
  }
  return problem;
}

namespace {

double Positive(YamlMap& m, const std::string& key) {
  const double v = m.GetDouble(key);
  if (!(v > 0)) throw InputError(m.Where(key), "must be positive");
  return v;
}

double NonNegative(YamlMap& m, const std::string& key) {
  const double v = m.GetDouble(key, 0.0);
  if (v < 0) throw InputError(m.Where(key), "must not be negative");
  return v;
}

// A certificate's expanded uncertainty: not negative, and plausible
// (kCertificateUncertainty), refused as a size is otherwise.
double Uncertainty(YamlMap& m, const std::string& key) {
  const double v = NonNegative(m, key);
  const std::string problem = ImplausibleMm(v, kCertificateUncertainty, "the file's units are mm");
  if (!problem.empty()) throw InputError(m.Where(key), problem);
  return v;
}

// A positive size within `range`; outside it, refused naming the file and
// key, with the unit it looks like when one makes it plausible.
double Size(YamlMap& m, const std::string& key, const PlausibleMm& range) {
  const double v = Positive(m, key);
  const std::string problem = ImplausibleMm(v, range, "the file's units are mm");
  if (!problem.empty()) throw InputError(m.Where(key), problem);
  return v;
}

Artifact Parse(YamlMap m) {
  if (m.GetString("format") != "stereorig-artifact")
    throw InputError(m.Where("format"), "expected 'stereorig-artifact'");
  if (m.GetInt("version") != 1) throw InputError(m.Where("version"), "unsupported version (this build reads 1)");
  if (m.GetString("units") != "mm") throw InputError(m.Where("units"), "expected 'mm'");
  Artifact a;
  a.name = m.GetString("name", "");
  const std::string type = m.GetString("type");
  if (type == "sphere") {
    a.type = ArtifactType::kSphere;
    a.sphere_diameter_mm = Size(m, "diameter_mm", kSphereDiameter);
    a.sphere_diameter_uncertainty_mm = Uncertainty(m, "diameter_uncertainty_mm");
    a.sphere_form_uncertainty_mm = Uncertainty(m, "form_uncertainty_mm");
  } else if (type == "ballbar") {
    a.type = ArtifactType::kBallBar;
    a.sphere_diameter_mm = Size(m, "sphere_diameter_mm", kSphereDiameter);
    a.sphere_diameter_uncertainty_mm = Uncertainty(m, "sphere_diameter_uncertainty_mm");
    a.center_distance_mm = Size(m, "center_distance_mm", kArtifactLength);
    a.center_distance_uncertainty_mm = Uncertainty(m, "center_distance_uncertainty_mm");
    if (a.center_distance_mm <= a.sphere_diameter_mm) {
      throw InputError(m.Where("center_distance_mm"), "must exceed the sphere diameter (the balls would overlap)");
    }
  } else if (type == "plate") {
    a.type = ArtifactType::kPlate;
    a.plate_length_mm = Size(m, "length_mm", kArtifactLength);
    a.plate_width_mm = Size(m, "width_mm", kArtifactLength);
    a.flatness_uncertainty_mm = Uncertainty(m, "flatness_uncertainty_mm");
  } else {
    throw InputError(m.Where("type"), "expected sphere, ballbar or plate, got '" + type + "'");
  }
  a.uncertainty_coverage_factor = m.GetDouble("uncertainty_coverage_factor", a.uncertainty_coverage_factor);
  if (!(a.uncertainty_coverage_factor >= 1 && a.uncertainty_coverage_factor <= 10)) {
    throw InputError(m.Where("uncertainty_coverage_factor"),
                     "must be in [1, 10]: the certificate's k (U = k u, usually 2), not a confidence level");
  }
  if (m.Has("mpe_mm")) {
    YamlMap e = m.GetMap("mpe_mm");
    a.mpe.probing_form_given = e.Has("P_F");
    a.mpe.probing_size_given = e.Has("P_S");
    a.mpe.sphere_spacing_given = e.Has("SD");
    a.mpe.flatness_given = e.Has("F");
    for (const auto& [key, mpe_mm] : {std::pair<const char*, double*>{"P_F", &a.mpe.probing_form_mm},
                                      {"P_S", &a.mpe.probing_size_mm},
                                      {"SD", &a.mpe.sphere_spacing_mm},
                                      {"F", &a.mpe.flatness_mm}}) {
      if (e.Has(key)) *mpe_mm = Size(e, key, kMaximumPermissibleError);
    }
    e.Finish();
  } else {
    m.GetString("mpe_mm", "");  // absent: defaults; mark as read
  }
  m.Finish();
  return a;
}

}  // namespace

// Read here, not by yaml-cpp's LoadFile: a file it cannot open (no read
// permission) it calls a "bad file", which read "not valid YAML: bad file".
// Without a name (it is optional), the file's stem names the artifact: the
// table read "artifact:  (sphere)" and the report "artifact": "".
Artifact ReadArtifactFile(const std::string& path) {
  Artifact a = Parse(YamlMap::LoadString(ReadInputText(path), path));
  if (a.name.empty()) a.name = std::filesystem::path(path).stem().string();
  return a;
}
Artifact ParseArtifactYaml(const std::string& text, const std::string& where) {
  return Parse(YamlMap::LoadString(text, where));
}

std::string ArtifactToYaml(const Artifact& a) {
  std::ostringstream o;
  o << "# stereorig reference artifact (VDI/VDE 2634-2). Units: mm.\n"
    << "format: stereorig-artifact\nversion: 1\nunits: mm\n"
    << "name: \"" << a.name << "\"\n"
    << "type: " << ArtifactTypeName(a.type) << "\n";
  switch (a.type) {
    case ArtifactType::kSphere:
      o << "diameter_mm: " << FormatDouble(a.sphere_diameter_mm) << "\n"
        << "diameter_uncertainty_mm: " << FormatDouble(a.sphere_diameter_uncertainty_mm) << "\n";
      // Only where given: a file without it reads the same in builds that
      // predate the key (which refuse an unknown key).
      if (a.sphere_form_uncertainty_mm > 0) {
        o << "form_uncertainty_mm: " << FormatDouble(a.sphere_form_uncertainty_mm)
          << "   # U of the certified form (P_F)\n";
      }
      break;
    case ArtifactType::kBallBar:
      o << "sphere_diameter_mm: " << FormatDouble(a.sphere_diameter_mm) << "\n"
        << "sphere_diameter_uncertainty_mm: " << FormatDouble(a.sphere_diameter_uncertainty_mm) << "\n"
        << "center_distance_mm: " << FormatDouble(a.center_distance_mm) << "\n"
        << "center_distance_uncertainty_mm: " << FormatDouble(a.center_distance_uncertainty_mm) << "\n";
      break;
    case ArtifactType::kPlate:
      o << "length_mm: " << FormatDouble(a.plate_length_mm) << "\n"
        << "width_mm: " << FormatDouble(a.plate_width_mm) << "\n"
        << "flatness_uncertainty_mm: " << FormatDouble(a.flatness_uncertainty_mm) << "\n";
      break;
  }
  // Only where it is not the default k = 2: a file without the key reads the
  // same here and in builds that predate it (which refuse an unknown key).
  if (a.uncertainty_coverage_factor != 2.0) {
    o << "uncertainty_coverage_factor: " << FormatDouble(a.uncertainty_coverage_factor)
      << "   # k of the expanded uncertainties above (U = k u)\n";
  }
  o << "mpe_mm: {P_F: " << FormatDouble(a.mpe.probing_form_mm) << ", P_S: " << FormatDouble(a.mpe.probing_size_mm)
    << ", SD: " << FormatDouble(a.mpe.sphere_spacing_mm) << ", F: " << FormatDouble(a.mpe.flatness_mm) << "}\n";
  return o.str();
}

}  // namespace stereorig
