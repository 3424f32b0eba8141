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
};

struct Artifact {
  std::string name;  // e.g. a serial number
  ArtifactType type = ArtifactType::kSphere;
  double sphere_diameter_mm = 0;              // sphere, and each ball of a ball bar
  double sphere_diameter_uncertainty_mm = 0;  // certified, k = 2
  double center_distance_mm = 0;              // ball bar
  double center_distance_uncertainty_mm = 0;
  double plate_length_mm = 0;  // plate
  double plate_width_mm = 0;
  double flatness_uncertainty_mm = 0;  // certified flatness of the plate, k = 2
  MaximumPermissibleErrors mpe;
};

// Throws InputError naming the file and key (missing fields for the type,
// unknown keys, non-positive sizes, ...).
Artifact ReadArtifactFile(const std::string& path);
Artifact ParseArtifactYaml(const std::string& text, const std::string& where);
std::string ArtifactToYaml(const Artifact& artifact);

}  // namespace stereorig
