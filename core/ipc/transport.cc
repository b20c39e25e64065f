#include "core/ipc/transport.h"

namespace rover::ipc {

bool Transport::SetError(std::string* error, std::string message) {
  if (error != nullptr) {
    *error = std::move(message);
  }
  return false;
}

bool Transport::ValidateLayout(const MessageLayout& layout, std::string* error) {
  if (layout.size_bytes == 0 || layout.size_bytes > UINT32_MAX) {
    return SetError(error, "message size must be in [1, 2^32 - 1] bytes, got " +
                               std::to_string(layout.size_bytes));
  }
  // iceoryx takes the alignment as uint32_t and requires a power of two.
  if (layout.alignment_bytes == 0 || (layout.alignment_bytes & (layout.alignment_bytes - 1)) != 0 ||
      layout.alignment_bytes > 4096) {
    return SetError(error, "message alignment must be a power of two <= 4096, got " +
                               std::to_string(layout.alignment_bytes));
  }
  return true;
}

bool Transport::ValidateSubscriberOptions(const SubscriberOptions& options, std::string* error) {
  if (options.queue_capacity == 0) {
    return SetError(error, "subscriber queue_capacity must be at least 1");
  }
  return true;
}

}  // namespace rover::ipc
