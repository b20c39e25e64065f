// roverd's lockstep gate: the IMU thread steps to t only once everything due
// by t has been handed over, whatever the threads' relative speed.

#include "firmware/roverd/lockstep_gate.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <future>
#include <thread>

namespace rover::roverd {
namespace {

Time Ms(int64_t ms) { return Time::FromNanoseconds(ms * 1'000'000); }

// A camera thread slower than the IMU thread: the clone trigger of a frame
// captured before t must be in before the IMU steps to t, even though the VO
// owes nothing for that frame until t + latency.
TEST(LockstepGateTest, ImuWaitsForEveryFrameCapturedByItsStep) {
  LockstepGate gate(/*camera=*/true, /*can=*/false, Duration::Milliseconds(100),
                    Duration::Seconds(1));
  std::atomic<bool> handed_over{false};
  std::thread camera([&] {
    gate.FrameArrived(Ms(0));  // waits for the IMU thread's first step
    gate.FrameQueued(Ms(0));
    gate.FrameArrived(Ms(50));
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    handed_over.store(true);
    gate.FrameQueued(Ms(50));
    gate.FrameArrived(Ms(100));  // the next frame: captured after the step
  });
  gate.WaitBeforeImu(Ms(60));
  EXPECT_TRUE(handed_over.load()) << "the IMU stepped past a frame not yet handed over";
  camera.join();
}

// The VO result of a frame is due at capture + latency, not before.
TEST(LockstepGateTest, ImuWaitsForTheVoResultDueByItsStep) {
  LockstepGate gate(true, false, Duration::Milliseconds(100), Duration::Seconds(1));
  std::atomic<bool> done{false};
  std::thread camera([&] {
    gate.FrameArrived(Ms(0));
    gate.FrameQueued(Ms(0));
    gate.FrameArrived(Ms(200));  // held: nothing else comes before 200 ms
  });
  std::thread vo([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    done.store(true);
    gate.FrameDone();
  });
  gate.WaitBeforeImu(Ms(90));  // frame 0's result is not due yet: no wait
  gate.WaitBeforeImu(Ms(100));
  EXPECT_TRUE(done.load()) << "the IMU stepped to capture + latency without the VO result";
  camera.join();
  vo.join();
}

// A frame captured between two IMU samples: once the IMU thread announces
// the sample after the capture, the VO may read the filter as of the capture.
// Asking for more would deadlock when the IMU thread waits for the camera and
// the camera for the slot this frame holds.
TEST(LockstepGateTest, VoGoesOnOnceTheImuAnnouncesASampleAfterTheCapture) {
  LockstepGate gate(/*camera=*/false, /*can=*/false, Duration::Milliseconds(100),
                    Duration::Seconds(1));
  gate.WaitBeforeImu(Ms(50));
  gate.ImuStepped(Ms(50));
  gate.WaitBeforeImu(Ms(60));
  auto vo = std::async(std::launch::async, [&] { gate.WaitForImuAt(Ms(55)); });
  const bool returned = vo.wait_for(std::chrono::seconds(10)) == std::future_status::ready;
  gate.Stop();
  EXPECT_TRUE(returned) << "the VO waited for a sample after the capture to be stepped";
}

}  // namespace
}  // namespace rover::roverd
