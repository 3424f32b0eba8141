// The artifact file as the simulator writes it: each certified value as the
// shortest text that reads back as the same double. Before, `simulate`
// delivered `diameter_mm: 38.100000000000001` (%.17g), a certificate no
// one would type, whose extra digits said nothing.
#include "reconstruct/metrology/artifact.h"

#include <gtest/gtest.h>

#include <string>

namespace stereorig {
namespace {

TEST(ArtifactFile, CertifiedValuesAreWrittenAsTheirShortestTextAndReadBackTheSame) {
  Artifact sphere;
  sphere.name = "sphere";
  sphere.type = ArtifactType::kSphere;
  sphere.sphere_diameter_mm = 38.1;
  sphere.sphere_diameter_uncertainty_mm = 0.002;
  sphere.mpe.probing_form_mm = 0.34152;
  std::string text = ArtifactToYaml(sphere);
  EXPECT_NE(text.find("diameter_mm: 38.1\n"), std::string::npos) << text;
  EXPECT_NE(text.find("diameter_uncertainty_mm: 0.002\n"), std::string::npos) << text;
  EXPECT_NE(text.find("P_F: 0.34152,"), std::string::npos) << text;
  Artifact back = ParseArtifactYaml(text, "sphere.yaml");
  EXPECT_EQ(back.sphere_diameter_mm, sphere.sphere_diameter_mm);
  EXPECT_EQ(back.mpe.probing_form_mm, sphere.mpe.probing_form_mm);

  Artifact bar;
  bar.name = "ball bar";
  bar.type = ArtifactType::kBallBar;
  bar.sphere_diameter_mm = 25.4;
  bar.center_distance_mm = 33.3 * 3;  // 99.89999999999999: another double than 99.9, written so
  text = ArtifactToYaml(bar);
  EXPECT_NE(text.find("sphere_diameter_mm: 25.4\n"), std::string::npos) << text;
  EXPECT_NE(text.find("center_distance_mm: 99.89999999999999\n"), std::string::npos) << text;
  back = ParseArtifactYaml(text, "bar.yaml");
  EXPECT_EQ(back.sphere_diameter_mm, bar.sphere_diameter_mm);
  EXPECT_EQ(back.center_distance_mm, bar.center_distance_mm);
}

}  // namespace
}  // namespace stereorig
