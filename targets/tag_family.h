// AprilTag families by name, and the bit pattern of one tag.
//
// Wraps libapriltag's per-family constructors so the rest of the project
// names a family by string (as the target file does) and never touches the C
// structs.
#pragma once

#include <memory>
#include <string>
#include <vector>

struct apriltag_family;

namespace stereorig {

// Families this build supports. tag36h11 is the default: 587 codes, Hamming
// distance 11, robust to the blur of a 752x582 camera at 200 mm.
const std::vector<std::string>& SupportedTagFamilies();

struct TagFamilyDeleter {
  void operator()(apriltag_family* f) const;
};
using TagFamilyPtr = std::unique_ptr<apriltag_family, TagFamilyDeleter>;

// Null if `name` is not one of SupportedTagFamilies().
TagFamilyPtr CreateTagFamily(const std::string& name);
int TagFamilySize(const std::string& name);  // number of codes, or 0 if unknown

// One tag rendered as cells: `total_width` x `total_width` values, row-major,
// true = black. The black border square spans cells
// [border_start, border_start + width_at_border).
struct TagBits {
  int total_width = 0;
  int width_at_border = 0;
  int border_start = 0;
  std::vector<bool> black;  // (total_width * total_width)
};
TagBits RenderTagBits(const std::string& family, int id);

}  // namespace stereorig
