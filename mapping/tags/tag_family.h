#ifndef ROVER_MAPPING_TAGS_TAG_FAMILY_H_
#define ROVER_MAPPING_TAGS_TAG_FAMILY_H_

// The AprilTag families Debian's libapriltag ships, by name: one owner of
// the library's family objects for the detector and the pattern renderer.

#include <memory>
#include <string>
#include <vector>

struct apriltag_family;

namespace rover::mapping {

/// A library family object, destroyed with the library's own function.
using TagFamilyPtr = std::unique_ptr<apriltag_family, void (*)(apriltag_family*)>;

/// Creates the family `name` ("tag36h11", ...). Throws std::invalid_argument
/// naming `name` and the known families if there is no such family.
TagFamilyPtr CreateTagFamily(const std::string& name);

/// The names CreateTagFamily accepts.
std::vector<std::string> KnownTagFamilies();

/// KnownTagFamilies() as one comma-separated list, for messages.
std::string KnownTagFamilyList();

}  // namespace rover::mapping

#endif  // ROVER_MAPPING_TAGS_TAG_FAMILY_H_
