// A reference artifact with certified dimensions (VDI/VDE 2634 Part 2): a
// sphere (probing error), a ball bar (sphere-spacing error) or a flat plate
// (flatness), read from an artifact file (docs/verify-and-check.md).
#pragma once

#include <string>

namespace stereorig {

enum class ArtifactType { kSphere, kBallBar, kPlate };
const char* ArtifactTypeName(ArtifactType type);

// Maximum permissible errors, mm. The default is the seed's +-1.5 mm.
struct MaximumPermissibleErrors {
  double probing_form_mm = 1.5;    // P_F
  double probing_size_mm = 1.5;    // |P_S|
  double sphere_spacing_mm = 1.5;  // |SD|
  double flatness_mm = 1.5;        // F
  // Which of them the artifact file's mpe_mm gives; the others are the
  // default above, which verify says (a certificate without mpe_mm was
  // judged against 1.5 mm with nothing saying so).
  bool probing_form_given = false, probing_size_given = false, sphere_spacing_given = false, flatness_given = false;
  // Whether the MPE of `figure` ("P_F", "P_S", "SD", "F") is the file's.
  bool Given(const std::string& figure) const {
    if (figure == "P_F") return probing_form_given;
    if (figure == "P_S") return probing_size_given;
    if (figure == "SD") return sphere_spacing_given;
    return figure == "F" && flatness_given;
  }
};

// The certificate's uncertainties (*_uncertainty_mm) are expanded
// uncertainties U, as calibration certificates state them (ISO/IEC 17025,
// GUM): U = k u with the coverage factor k the certificate gives, usually 2
// (~95%). verify combines their standard uncertainties U / k with the fit's
// (vdi2634.h). An absent uncertainty reads 0: the reference taken as exact.
struct Artifact {
  std::string name;  // e.g. a serial number
  ArtifactType type = ArtifactType::kSphere;
  double sphere_diameter_mm = 0;              // sphere, and each ball of a ball bar
  double sphere_diameter_uncertainty_mm = 0;  // U of the certified diameter
  double sphere_form_uncertainty_mm = 0;      // sphere: U of its certified form (P_F's reference)
  double center_distance_mm = 0;              // ball bar
  double center_distance_uncertainty_mm = 0;  // U of the certified centre distance
  double plate_length_mm = 0;                 // plate
  double plate_width_mm = 0;
  double flatness_uncertainty_mm = 0;  // U of the plate's certified flatness
  // k of every U above (`uncertainty_coverage_factor`, optional; default 2,
  // in [1, 10]: a confidence level such as 0.95 is not a coverage factor).
  double uncertainty_coverage_factor = 2;
  MaximumPermissibleErrors mpe;
  // The certificate's standard uncertainty (k = 1) of a certified value.
  double StandardUncertaintyMm(double expanded_uncertainty_mm) const {
    return expanded_uncertainty_mm / uncertainty_coverage_factor;
  }
};

// Throws InputError naming the file and key (missing fields for the type,
// unknown keys, non-positive sizes, ...).
Artifact ReadArtifactFile(const std::string& path);

// The plausible range of a length, mm, and what it is of ("sphere
// diameter"): a sphere a rig like this measures (VDI/VDE 2634-2 sizes it at
// 0.1-0.2 of the volume's diagonal), a ball bar's length or a plate's side.
// Outside it a value is a typo or another unit: 38100 (um for 38.1 mm) read
// as a 38 m sphere, 1e300 was judged against a 61.6 mm cloud, whose refusal
// then blamed the cloud, and an MPE of 1e308 passed every figure.
struct PlausibleMm {
  double min_mm, max_mm;
  const char* what;
};
inline constexpr PlausibleMm kSphereDiameter{1, 1000, "sphere diameter"};
inline constexpr PlausibleMm kArtifactLength{1, 10000, "artifact length"};
// A maximum permissible error: 1 um is below what any optical rig claims,
// 100 mm is beyond a sphere's form error that would still be a sphere.
inline constexpr PlausibleMm kMaximumPermissibleError{0.001, 100, "maximum permissible error"};
// A certificate's expanded uncertainty (*_uncertainty_mm): 0 is an exact
// reference; over 100 mm it is no certificate of an artifact a rig like this
// measures (1e308 printed a 300-digit figure, 2000 - um typed as mm - was
// taken as 2 m).
inline constexpr PlausibleMm kCertificateUncertainty{0, 100, "certificate's expanded uncertainty"};

// "" when `v` is within `range`; else why not, with the unit it looks like
// when one makes it plausible ("130000 mm is not a plausible artifact length
// (1 to 10000 mm): in micrometres it would be 130 mm (the file's units are
// mm)"; `units_note` is that parenthesis).
std::string ImplausibleMm(double v, const PlausibleMm& range, const std::string& units_note);
Artifact ParseArtifactYaml(const std::string& text, const std::string& where);
std::string ArtifactToYaml(const Artifact& artifact);

}  // namespace stereorig
