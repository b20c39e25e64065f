#ifndef ROVER_TESTS_CORE_IPC_TEST_MESSAGES_H_
#define ROVER_TESTS_CORE_IPC_TEST_MESSAGES_H_

// Message types shared by the IPC tests and their helper process.

#include <cstdint>

namespace rover::ipc::test {

// Pose-like message: mixed field types and padding, 112 bytes.
struct TestPose {
  int64_t stamp_ns = 0;
  double position_m[3] = {0, 0, 0};
  double orientation_xyzw[4] = {0, 0, 0, 1};
  uint32_t sequence = 0;
  char frame_id[20] = {};
};

// Request/reply pair for the two-process round trip.
struct Ping {
  uint64_t sequence = 0;
  double value = 0;
};

struct Pong {
  uint64_t sequence = 0;
  double doubled_value = 0;
  int32_t peer_pid = 0;
};

// Different size than TestPose, to provoke a type mismatch on a topic.
struct Small {
  uint32_t value = 0;
};

}  // namespace rover::ipc::test

#endif  // ROVER_TESTS_CORE_IPC_TEST_MESSAGES_H_
