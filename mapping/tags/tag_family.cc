#include "mapping/tags/tag_family.h"

#include <apriltag/apriltag.h>
#include <apriltag/tag16h5.h>
#include <apriltag/tag25h9.h>
#include <apriltag/tag36h10.h>
#include <apriltag/tag36h11.h>
#include <apriltag/tagCircle21h7.h>
#include <apriltag/tagCircle49h12.h>
#include <apriltag/tagCustom48h12.h>
#include <apriltag/tagStandard41h12.h>
#include <apriltag/tagStandard52h13.h>

#include <stdexcept>

namespace rover::mapping {
namespace {

struct FamilyFactory {
  const char* name;
  apriltag_family_t* (*create)();
  void (*destroy)(apriltag_family_t*);
};

constexpr FamilyFactory kFamilies[] = {
    {"tag36h11", tag36h11_create, tag36h11_destroy},
    {"tag36h10", tag36h10_create, tag36h10_destroy},
    {"tag25h9", tag25h9_create, tag25h9_destroy},
    {"tag16h5", tag16h5_create, tag16h5_destroy},
    {"tagCircle21h7", tagCircle21h7_create, tagCircle21h7_destroy},
    {"tagCircle49h12", tagCircle49h12_create, tagCircle49h12_destroy},
    {"tagCustom48h12", tagCustom48h12_create, tagCustom48h12_destroy},
    {"tagStandard41h12", tagStandard41h12_create, tagStandard41h12_destroy},
    {"tagStandard52h13", tagStandard52h13_create, tagStandard52h13_destroy},
};

}  // namespace

std::vector<std::string> KnownTagFamilies() {
  std::vector<std::string> out;
  for (const FamilyFactory& f : kFamilies) out.emplace_back(f.name);
  return out;
}

std::string KnownTagFamilyList() {
  std::string out;
  for (const FamilyFactory& f : kFamilies) out += (out.empty() ? "" : ", ") + std::string(f.name);
  return out;
}

TagFamilyPtr CreateTagFamily(const std::string& name) {
  for (const FamilyFactory& f : kFamilies) {
    if (name != f.name) continue;
    apriltag_family_t* family = f.create();
    if (family == nullptr) throw std::runtime_error("libapriltag could not create " + name);
    return TagFamilyPtr(family, f.destroy);
  }
  throw std::invalid_argument("tag family: expected one of " + KnownTagFamilyList() + ", found '" +
                              name + "'");
}

}  // namespace rover::mapping
