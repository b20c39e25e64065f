#include "core/log/msgs/tf2_msgs.h"

#include "core/log/msgs/definitions.h"

namespace rover::log {
namespace tf2_msgs {
namespace {

// Fewest bytes a TransformStamped can occupy (stamp 8, two empty-string length
// prefixes 8, seven float64 56), used to reject impossible element counts
// before allocating.
constexpr size_t kMinTransformStampedSize = 72;

}  // namespace

void Serialize(const TFMessage& msg, CdrWriter& writer) {
  writer.WriteSequenceSize(msg.transforms.size());
  for (const geometry_msgs::TransformStamped& transform : msg.transforms) {
    Serialize(transform, writer);
  }
}

bool Deserialize(CdrReader& reader, TFMessage* msg) {
  return reader.ReadSequence("transforms", &msg->transforms, kMinTransformStampedSize);
}

}  // namespace tf2_msgs

std::string_view MessageTraits<tf2_msgs::TFMessage>::Definition() {
  return internal::CachedDefinition<tf2_msgs::TFMessage>();
}

}  // namespace rover::log
