#include "targets/tag_family.h"

extern "C" {
#include <apriltag/apriltag.h>
#include <apriltag/tag16h5.h>
#include <apriltag/tag25h9.h>
#include <apriltag/tag36h11.h>
#include <apriltag/tagStandard41h12.h>
}

#include "calib/core/input_error.h"

namespace stereorig {

namespace {

struct FamilyEntry {
  const char* name;
  apriltag_family_t* (*create)();
  void (*destroy)(apriltag_family_t*);
};

const FamilyEntry kFamilies[] = {
    {"tag36h11", &tag36h11_create, &tag36h11_destroy},
    {"tag25h9", &tag25h9_create, &tag25h9_destroy},
    {"tag16h5", &tag16h5_create, &tag16h5_destroy},
    {"tagStandard41h12", &tagStandard41h12_create, &tagStandard41h12_destroy},
};

const FamilyEntry* Find(const std::string& name) {
  for (const auto& f : kFamilies)
    if (name == f.name) return &f;
  return nullptr;
}

}  // namespace

const std::vector<std::string>& SupportedTagFamilies() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> v;
    for (const auto& f : kFamilies) v.push_back(f.name);
    return v;
  }();
  return names;
}

void TagFamilyDeleter::operator()(apriltag_family* f) const {
  if (!f) return;
  const FamilyEntry* e = Find(f->name);
  STEREORIG_CHECK(e != nullptr);
  e->destroy(f);
}

TagFamilyPtr CreateTagFamily(const std::string& name) {
  const FamilyEntry* e = Find(name);
  return TagFamilyPtr(e ? e->create() : nullptr);
}

int TagFamilySize(const std::string& name) {
  TagFamilyPtr f = CreateTagFamily(name);
  return f ? static_cast<int>(f->ncodes) : 0;
}

TagBits RenderTagBits(const std::string& family, int id) {
  TagFamilyPtr f = CreateTagFamily(family);
  STEREORIG_CHECK(f != nullptr);
  STEREORIG_CHECK(id >= 0 && id < static_cast<int>(f->ncodes));
  image_u8_t* im = apriltag_to_image(f.get(), id);
  TagBits bits;
  bits.total_width = f->total_width;
  bits.width_at_border = f->width_at_border;
  bits.border_start = (f->total_width - f->width_at_border) / 2;
  bits.black.resize(static_cast<size_t>(im->width) * im->height);
  STEREORIG_CHECK(im->width == f->total_width && im->height == f->total_width);
  for (int y = 0; y < im->height; ++y)
    for (int x = 0; x < im->width; ++x) bits.black[y * im->width + x] = im->buf[y * im->stride + x] < 128;
  image_u8_destroy(im);
  return bits;
}

}  // namespace stereorig
