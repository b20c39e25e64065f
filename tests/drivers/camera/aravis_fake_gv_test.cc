// AravisCamera against a real GigE Vision device: Aravis's own simulator,
// arv-fake-gv-camera-0.8, started per test on the loopback interface. It
// speaks GVCP (control, heartbeat) and GVSP (streaming) over UDP exactly as
// a camera does, so everything below the GenICam feature names runs for
// real: discovery, control-channel privilege, packet reassembly, the
// stream's buffer queues, heartbeat loss.
//
// What the simulator does (Aravis 0.8.26), and so what these tests can prove:
// - frame ids start at 65401, so the 16-bit wrap (65535 -> 1) comes after
//   135 frames;
// - Mono8 pixels are (x + y + frame_id) % 255 at the default exposure and
//   gain, Mono16 pixels ((x + y + frame_id) * 256) % 65535, so the image
//   content (and the 16 -> 8 bit conversion) is checked exactly;
// - timestamps are its CLOCK_REALTIME in ns;
// - TriggerMode On + TriggerSource Software: one frame per TriggerSoftware;
// - --gvsp-lost-ratio drops leader, data and trailer packets at random, but
//   it does not implement GVCP PACKETRESEND: resend requests go out and are
//   counted, no packet ever comes back;
// - killing it stops the heartbeat replies: Aravis reports "control-lost"
//   after its heartbeat retries, about 6 s later.

#include <unistd.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "drivers/camera/aravis_camera.h"
#include "hil/sim/devices/fake_gv_camera_process.h"
#include "tests/support/malloc_counter.h"

namespace rover::drivers {
namespace {

using ::testing::HasSubstr;

using FakeGvCamera = sim::FakeGvCameraProcess;

// A serial no other test (or other run on this machine) uses.
std::string UniqueSerial() {
  static std::atomic<int> counter{0};
  return "RT" + std::to_string(getpid()) + "-" + std::to_string(counter++);
}

AravisCameraOptions OptionsFor(const FakeGvCamera& fake) {
  AravisCameraOptions o;
  o.serial = fake.serial();
  o.width_px = 640;
  o.height_px = 480;
  o.frame_rate_hz = 50.0;
  o.buffer_count = 8;
  return o;
}

// The simulator's pattern for frame id `raw_id`: Mono8 (x + y + id) % 255;
// Mono16 ((x + y + id) * 256) % 65535, which the driver shifts right by
// `mono16_shift` and clamps to 255.
uint8_t Expected(int x, int y, uint64_t raw_id, bool mono16, int mono16_shift = 8) {
  const uint64_t n = static_cast<uint64_t>(x + y) + raw_id;
  if (!mono16) return static_cast<uint8_t>(n % 255);
  return static_cast<uint8_t>(std::min<uint64_t>(((n * 256) % 65535) >> mono16_shift, 255));
}

// The 16-bit GVSP id of a sequence extended from ids starting at 65401.
uint64_t RawId(uint64_t sequence) { return (sequence - 1) % 65535 + 1; }

// Checks a frame against the simulator's pattern (a sparse grid of pixels
// plus the whole first and last rows).
::testing::AssertionResult HasPattern(const CameraFrame& f, bool mono16 = false,
                                      int mono16_shift = 8) {
  const uint64_t raw = RawId(f.sequence);
  const auto at = [&](int x, int y) {
    return f.image
        .data[static_cast<std::size_t>(y) * f.image.stride_bytes + static_cast<std::size_t>(x)];
  };
  const int last_row = f.image.height_px - 1;
  for (int y = 0; y <= last_row; y = (y == last_row || y + 37 < last_row) ? y + 37 : last_row) {
    const int step = (y == 0 || y == last_row) ? 1 : 29;
    for (int x = 0; x < f.image.width_px; x += step) {
      if (at(x, y) != Expected(x, y, raw, mono16, mono16_shift)) {
        return ::testing::AssertionFailure()
               << "pixel (" << x << ", " << y << ") of frame " << f.sequence << " (id " << raw
               << ") is " << int{at(x, y)} << ", expected "
               << int{Expected(x, y, raw, mono16, mono16_shift)};
      }
    }
  }
  return ::testing::AssertionSuccess();
}

// Next() until kOk, up to `budget`.
ReadStatus NextWithin(AravisCamera* camera, CameraFrame* frame, Duration budget) {
  const Time deadline = Time::Now() + budget;
  ReadStatus status = ReadStatus::kTimeout;
  while (Time::Now() < deadline) {
    status = camera->Next(frame, Duration::Milliseconds(500));
    if (status == ReadStatus::kOk) return status;
  }
  return status;
}

TEST(AravisFakeGvTest, StreamsCompleteFramesAcrossTheFrameIdWrap) {
  FakeGvCamera fake({.serial = UniqueSerial()});
  ASSERT_NO_THROW(fake.Start());
  AravisCamera camera(OptionsFor(fake));
  EXPECT_EQ(camera.device_id(), fake.device_id());
  EXPECT_EQ(camera.payload_bytes(), 640u * 480u);
  EXPECT_GE(camera.packet_size_bytes(), 576);  // negotiated

  constexpr int kFrames = 150;  // 65401 + 150 wraps past 65535
  std::vector<CameraFrame> frames;
  for (int i = 0; i < kFrames; ++i) {
    CameraFrame f;
    ASSERT_EQ(NextWithin(&camera, &f, Duration::Seconds(5)), ReadStatus::kOk) << "frame " << i;
    const Time now = Time::Now();
    EXPECT_EQ(f.image.width_px, 640);
    EXPECT_EQ(f.image.height_px, 480);
    EXPECT_EQ(f.image.stride_bytes, 640u);
    ASSERT_NE(f.image.data, nullptr);
    EXPECT_TRUE(HasPattern(f));
    // The mapped time precedes the delivery, by less than a frame's trip.
    EXPECT_LE(f.stamp, now);
    EXPECT_GT(f.stamp, now - Duration::Milliseconds(500));
    frames.push_back(f);
    camera.Release(f);
  }
  uint64_t dropped = 0;
  for (std::size_t i = 1; i < frames.size(); ++i) {
    EXPECT_EQ(frames[i].sequence, frames[i - 1].sequence + 1 + frames[i].dropped_before);
    EXPECT_GT(frames[i].stamp, frames[i - 1].stamp) << "frame " << i;
    dropped += frames[i].dropped_before;
  }
  EXPECT_EQ(frames.front().sequence, 65401u);
  EXPECT_GT(frames.back().sequence, 65535u);  // extended past the 16-bit wrap
  // The camera's own clock paces the stamps: 50 Hz on average.
  const double period_ms = (frames.back().stamp - frames.front().stamp).ToMilliseconds() /
                           static_cast<double>(frames.back().sequence - frames.front().sequence);
  EXPECT_NEAR(period_ms, 20.0, 2.0);

  const AravisCameraStats s = camera.stats();
  EXPECT_EQ(s.frames, static_cast<uint64_t>(kFrames));
  EXPECT_EQ(s.incomplete, 0u);
  EXPECT_EQ(s.dropped_frames, dropped);
  EXPECT_EQ(dropped, 0u);
  EXPECT_EQ(s.missing_packets, 0u);
  EXPECT_EQ(s.disconnects, 0u);
  EXPECT_EQ(s.sequence_resets, 0u);
  EXPECT_EQ(s.clock_resets, 0u);
  EXPECT_TRUE(camera.connected());
  std::printf(
      "negotiated packet size %d bytes; clock fit after %d frames: offset %lld ns, "
      "drift %.1f ppm, mean excess latency %lld ns\n",
      camera.packet_size_bytes(), kFrames, static_cast<long long>(s.clock_offset_ns),
      s.clock_drift_ppm, static_cast<long long>(s.clock_mean_residual_ns));
}

TEST(AravisFakeGvTest, ConfiguredPacketSizeIsUsed) {
  FakeGvCamera fake({.serial = UniqueSerial()});
  ASSERT_NO_THROW(fake.Start());
  AravisCameraOptions o = OptionsFor(fake);
  o.packet_size_bytes = 4000;  // 77 packets per frame instead of 220
  AravisCamera camera(o);
  EXPECT_EQ(camera.packet_size_bytes(), 4000);
  for (int i = 0; i < 10; ++i) {
    CameraFrame f;
    ASSERT_EQ(NextWithin(&camera, &f, Duration::Seconds(5)), ReadStatus::kOk);
    EXPECT_TRUE(HasPattern(f));
    camera.Release(f);
  }
  EXPECT_EQ(camera.stats().incomplete, 0u);
}

TEST(AravisFakeGvTest, ExposureReachesTheCamera) {
  FakeGvCamera fake({.serial = UniqueSerial()});
  ASSERT_NO_THROW(fake.Start());
  AravisCameraOptions o = OptionsFor(fake);
  // The simulator scales its pattern by 1 + log10(exposure / 10 ms).
  o.exposure_us = 100'000.0;
  AravisCamera camera(o);
  CameraFrame f;
  ASSERT_EQ(NextWithin(&camera, &f, Duration::Seconds(5)), ReadStatus::kOk);
  const uint64_t raw = RawId(f.sequence);
  int mismatches = 0;
  for (int x = 0; x < 640; ++x) {
    const int expected = std::min(255, 2 * Expected(x, 0, raw, false));
    mismatches += f.image.data[x] != expected ? 1 : 0;
  }
  EXPECT_EQ(mismatches, 0);
  camera.Release(f);
}

TEST(AravisFakeGvTest, HeldBuffersAreUnderrunsNotCorruption) {
  FakeGvCamera fake({.serial = UniqueSerial()});
  ASSERT_NO_THROW(fake.Start());
  AravisCameraOptions o = OptionsFor(fake);
  o.buffer_count = 3;
  o.frame_rate_hz = 100.0;
  AravisCamera camera(o);
  // Hold every buffer: the stream has nowhere to put the next frames.
  std::vector<CameraFrame> held(3);
  for (CameraFrame& f : held)
    ASSERT_EQ(NextWithin(&camera, &f, Duration::Seconds(5)), ReadStatus::kOk);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  for (const CameraFrame& f : held) EXPECT_TRUE(HasPattern(f));  // not overwritten
  CameraFrame none;
  EXPECT_EQ(camera.Next(&none, Duration::Milliseconds(50)), ReadStatus::kTimeout);
  for (const CameraFrame& f : held) camera.Release(f);
  CameraFrame next;
  ASSERT_EQ(NextWithin(&camera, &next, Duration::Seconds(5)), ReadStatus::kOk);
  EXPECT_TRUE(HasPattern(next));
  EXPECT_GT(next.dropped_before, 5u);  // ~30 frames went by without a buffer
  const AravisCameraStats s = camera.stats();
  EXPECT_GT(s.underruns, 5u);
  EXPECT_EQ(s.incomplete, 0u);
  EXPECT_GE(s.dropped_frames, next.dropped_before);
}

TEST(AravisFakeGvTest, Mono16IsConvertedToEightBits) {
  FakeGvCamera fake({.serial = UniqueSerial()});
  ASSERT_NO_THROW(fake.Start());
  // 8: the high byte (fast path); 4: 12-bit data, shifted and clamped.
  for (const int shift : {8, 4}) {
    SCOPED_TRACE(shift);
    AravisCameraOptions o = OptionsFor(fake);
    o.pixel_format = "Mono16";
    o.mono16_shift_bits = shift;
    AravisCamera camera(o);
    EXPECT_EQ(camera.payload_bytes(), 640u * 480u * 2u);
    for (int i = 0; i < 5; ++i) {
      CameraFrame f;
      ASSERT_EQ(NextWithin(&camera, &f, Duration::Seconds(5)), ReadStatus::kOk);
      EXPECT_EQ(f.image.width_px, 640);
      EXPECT_EQ(f.image.stride_bytes, 640u);
      ASSERT_NE(f.image.data, nullptr);
      // Little-endian 16-bit pixels: checked exactly.
      EXPECT_TRUE(HasPattern(f, /*mono16=*/true, shift));
      camera.Release(f);
    }
    EXPECT_EQ(camera.stats().incomplete, 0u);
  }
}

TEST(AravisFakeGvTest, SoftwareTriggerGivesExactlyOneFramePerTrigger) {
  FakeGvCamera fake({.serial = UniqueSerial()});
  ASSERT_NO_THROW(fake.Start());
  AravisCameraOptions o = OptionsFor(fake);
  o.trigger_enabled = true;
  o.trigger_source = "Software";
  AravisCamera camera(o);
  CameraFrame f;
  // Free-running at 50 Hz this would give ~25 frames.
  EXPECT_EQ(camera.Next(&f, Duration::Milliseconds(500)), ReadStatus::kTimeout);
  uint64_t previous = 0;
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(camera.SoftwareTrigger());
    ASSERT_EQ(camera.Next(&f, Duration::Seconds(5)), ReadStatus::kOk) << "trigger " << i;
    EXPECT_TRUE(HasPattern(f));
    if (i > 0) {
      EXPECT_EQ(f.sequence, previous + 1);
    }
    previous = f.sequence;
    camera.Release(f);
    CameraFrame extra;
    EXPECT_EQ(camera.Next(&extra, Duration::Milliseconds(200)), ReadStatus::kTimeout)
        << "a frame without a trigger after trigger " << i;
  }
  const AravisCameraStats s = camera.stats();
  EXPECT_EQ(s.frames, 5u);
  EXPECT_EQ(s.incomplete, 0u);
  EXPECT_EQ(s.dropped_frames, 0u);
}

TEST(AravisFakeGvTest, PacketLossWithoutResendIsCountedAndTheStreamGoesOn) {
  FakeGvCamera fake({.serial = UniqueSerial(), .lost_packets_per_thousand = 2});
  ASSERT_NO_THROW(fake.Start());
  AravisCameraOptions o = OptionsFor(fake);
  o.packet_resend = false;
  AravisCamera camera(o);
  int delivered = 0;
  uint64_t dropped = 0;
  uint64_t incomplete_before_last_delivery = 0;
  uint64_t incomplete_before_first_delivery = 0;
  const Time end = Time::Now() + Duration::Seconds(4);
  while (Time::Now() < end) {
    CameraFrame f;
    if (camera.Next(&f, Duration::Milliseconds(200)) != ReadStatus::kOk) continue;
    EXPECT_TRUE(HasPattern(f));  // what is delivered is always whole
    dropped += f.dropped_before;
    ++delivered;
    // Incomplete buffers are skipped inside Next(), before the frame it
    // returns: those after the first delivery lie in the id gaps counted.
    incomplete_before_last_delivery = camera.stats().incomplete;
    if (delivered == 1) incomplete_before_first_delivery = incomplete_before_last_delivery;
    camera.Release(f);
  }
  const AravisCameraStats s = camera.stats();
  std::printf(
      "resend off, 0.2 %% packet loss: %d delivered, %llu incomplete (%llu missing packets,"
      " %llu timeout), %llu missing packets, %llu resend requests\n",
      delivered, static_cast<unsigned long long>(s.incomplete),
      static_cast<unsigned long long>(s.incomplete_missing_packets),
      static_cast<unsigned long long>(s.incomplete_timeout),
      static_cast<unsigned long long>(s.missing_packets),
      static_cast<unsigned long long>(s.resend_requests));
  // 220 packets a frame at 0.2 % loss: ~35 % of the frames lose one.
  EXPECT_GT(delivered, 40);
  EXPECT_GT(s.incomplete, 5u);
  EXPECT_GT(s.incomplete_missing_packets + s.incomplete_timeout, 0u);
  EXPECT_GT(s.missing_packets, 0u);
  EXPECT_EQ(s.resend_requests, 0u);
  EXPECT_EQ(s.resent_packets, 0u);
  EXPECT_EQ(s.dropped_frames, dropped);
  // Every incomplete frame is a dropped one; frames whose packets were all
  // lost are dropped without a buffer.
  EXPECT_GE(dropped, incomplete_before_last_delivery - incomplete_before_first_delivery);
}

TEST(AravisFakeGvTest, PacketLossWithResendRequestsResends) {
  FakeGvCamera fake({.serial = UniqueSerial(), .lost_packets_per_thousand = 2});
  ASSERT_NO_THROW(fake.Start());
  AravisCameraOptions o = OptionsFor(fake);
  o.packet_resend = true;
  AravisCamera camera(o);
  int delivered = 0;
  const Time end = Time::Now() + Duration::Seconds(4);
  while (Time::Now() < end) {
    CameraFrame f;
    if (camera.Next(&f, Duration::Milliseconds(200)) != ReadStatus::kOk) continue;
    EXPECT_TRUE(HasPattern(f));
    ++delivered;
    camera.Release(f);
  }
  const AravisCameraStats s = camera.stats();
  std::printf(
      "resend on, 0.2 %% packet loss: %d delivered, %llu incomplete (%llu missing packets,"
      " %llu timeout), %llu missing packets, %llu resend requests, %llu resent packets\n",
      delivered, static_cast<unsigned long long>(s.incomplete),
      static_cast<unsigned long long>(s.incomplete_missing_packets),
      static_cast<unsigned long long>(s.incomplete_timeout),
      static_cast<unsigned long long>(s.missing_packets),
      static_cast<unsigned long long>(s.resend_requests),
      static_cast<unsigned long long>(s.resent_packets));
  EXPECT_GT(delivered, 40);
  EXPECT_GT(s.resend_requests, 0u);  // the driver turned resend on, Aravis asked
  // arv-fake-gv-camera-0.8 ignores PACKETRESEND_CMD, so no packet comes
  // back and those frames end incomplete; with a real camera
  // resent_packets > 0 and incomplete stays 0.
  EXPECT_GT(s.incomplete, 0u);
}

TEST(AravisFakeGvTest, DisconnectIsCountedNextStaysBoundedAndTheCameraComesBack) {
  FakeGvCamera fake({.serial = UniqueSerial()});
  ASSERT_NO_THROW(fake.Start());
  // Declared before the camera so that it outlives it: a camera destroyed
  // after its device died waits out Aravis's GVCP retries (~10 s).
  FakeGvCamera again({.serial = fake.serial()});
  AravisCameraOptions o = OptionsFor(fake);
  o.reconnect_initial_backoff = Duration::Milliseconds(100);
  o.reconnect_max_backoff = Duration::Milliseconds(800);
  AravisCamera camera(o);
  CameraFrame f;
  uint64_t last_sequence = 0;
  for (int i = 0; i < 10; ++i) {
    ASSERT_EQ(NextWithin(&camera, &f, Duration::Seconds(5)), ReadStatus::kOk);
    last_sequence = f.sequence;
    camera.Release(f);
  }
  CameraFrame held;  // held across the disconnect, released after it
  ASSERT_EQ(NextWithin(&camera, &held, Duration::Seconds(5)), ReadStatus::kOk);
  last_sequence = held.sequence;

  fake.Kill();
  const Time killed = Time::Now();
  const Duration timeout = Duration::Milliseconds(100);
  Duration longest = Duration::Zero();
  int timeouts = 0, errors = 0, late_frames = 0;
  const Time give_up = Time::Now() + Duration::Seconds(30);
  while (camera.stats().disconnects == 0 && Time::Now() < give_up) {
    const Time start = Time::Now();
    const ReadStatus status = camera.Next(&f, timeout);
    longest = std::max(longest, Time::Now() - start);
    timeouts += status == ReadStatus::kTimeout ? 1 : 0;
    errors += status == ReadStatus::kError ? 1 : 0;
    if (status == ReadStatus::kOk) {  // frames already queued before the kill
      ++late_frames;
      last_sequence = f.sequence;
      camera.Release(f);
    }
  }
  ASSERT_EQ(camera.stats().disconnects, 1u) << "no control-lost within 30 s";
  const Duration to_disconnect = Time::Now() - killed;
  EXPECT_FALSE(camera.connected());
  EXPECT_GT(timeouts, 0);
  EXPECT_LE(late_frames, 8);
  // Disconnected: Next waits out its timeout and reports the error, still
  // without allocating.
  Duration shortest = Duration::Max();
  testing::ScopedMallocCheck disconnected_mallocs;
  for (int i = 0; i < 3; ++i) {
    const Time start = Time::Now();
    EXPECT_EQ(camera.Next(&f, timeout), ReadStatus::kError);
    longest = std::max(longest, Time::Now() - start);
    shortest = std::min(shortest, Time::Now() - start);
  }
  camera.Release(held);  // no stream now: parked until the reconnect
  EXPECT_EQ(disconnected_mallocs.mallocs(), 0u);
  EXPECT_GE(shortest, timeout);  // waits for a reconnect instead of spinning
  // Bounded by the timeout (plus scheduling slack on a loaded machine).
  EXPECT_LT(longest, timeout + Duration::Milliseconds(400)) << longest.ToString();

  ASSERT_NO_THROW(again.Start());
  const Time restarted = Time::Now();
  ReadStatus status = ReadStatus::kError;
  const Time reconnect_deadline = Time::Now() + Duration::Seconds(60);
  while (status != ReadStatus::kOk && Time::Now() < reconnect_deadline) {
    status = camera.Next(&f, Duration::Milliseconds(500));
  }
  ASSERT_EQ(status, ReadStatus::kOk) << "no frame within 60 s of the camera's return";
  const Duration to_reconnect = Time::Now() - restarted;
  EXPECT_TRUE(camera.connected());
  EXPECT_EQ(f.sequence, last_sequence + 1);  // numbering continues across sessions
  EXPECT_EQ(f.dropped_before, 0u);
  camera.Release(f);
  // Every buffer, including the one held across the reconnect, streams again.
  for (int i = 0; i < 20; ++i) {
    ASSERT_EQ(NextWithin(&camera, &f, Duration::Seconds(5)), ReadStatus::kOk);
    camera.Release(f);
  }
  const AravisCameraStats s = camera.stats();
  EXPECT_EQ(s.disconnects, 1u);
  EXPECT_GE(s.reconnect_attempts, 1u);
  EXPECT_EQ(s.reconnects, 1u);
  EXPECT_GT(s.errors, 0u);
  std::printf(
      "disconnect: control-lost %s after the kill (%d timeouts, %d errors before it), "
      "longest Next %s; first frame %s after the restarted camera was discoverable, "
      "%llu reconnect attempts\n",
      to_disconnect.ToString().c_str(), timeouts, errors, longest.ToString().c_str(),
      to_reconnect.ToString().c_str(), static_cast<unsigned long long>(s.reconnect_attempts));
}

TEST(AravisFakeGvTest, MissingDeviceGivesAnErrorNamingItAndListingTheOthers) {
  FakeGvCamera fake({.serial = UniqueSerial()});
  ASSERT_NO_THROW(fake.Start());
  AravisCameraOptions o;
  o.serial = "NO-SUCH-" + std::to_string(getpid());
  try {
    AravisCamera camera(o);
    FAIL() << "opened a camera that does not exist";
  } catch (const AravisCameraError& e) {
    EXPECT_THAT(e.what(), HasSubstr("serial '" + o.serial + "'"));
    EXPECT_THAT(e.what(), HasSubstr("not found"));
    EXPECT_THAT(e.what(), HasSubstr(fake.device_id()));  // what was there instead
  }
  o.serial.clear();
  o.device_id = "Nobody-" + std::to_string(getpid());
  EXPECT_THROW(
      {
        try {
          AravisCamera camera(o);
        } catch (const AravisCameraError& e) {
          EXPECT_THAT(e.what(), HasSubstr("id '" + o.device_id + "'"));
          throw;
        }
      },
      AravisCameraError);
}

TEST(AravisFakeGvTest, RefusedSettingsNameTheFeature) {
  FakeGvCamera fake({.serial = UniqueSerial()});
  ASSERT_NO_THROW(fake.Start());
  AravisCameraOptions o = OptionsFor(fake);
  o.gain_db = 6.0;  // the simulator only has GainRaw
  try {
    AravisCamera camera(o);
    FAIL() << "gain in dB accepted by a camera without a Gain feature";
  } catch (const AravisCameraError& e) {
    EXPECT_THAT(e.what(), HasSubstr(fake.device_id()));
    EXPECT_THAT(e.what(), HasSubstr("'Gain'"));
  }
  o = OptionsFor(fake);
  o.trigger_enabled = true;
  o.trigger_source = "Line7";  // the simulator has Line0 and Software
  try {
    AravisCamera camera(o);
    FAIL() << "unknown trigger source accepted";
  } catch (const AravisCameraError& e) {
    EXPECT_THAT(e.what(), HasSubstr("TriggerSource"));
    EXPECT_THAT(e.what(), HasSubstr("'Line7'"));
  }
}

TEST(AravisFakeGvTest, OptionsAreValidatedNamingTheField) {
  const auto message_of = [](const AravisCameraOptions& o) {
    try {
      AravisCamera camera(o);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  AravisCameraOptions o;
  EXPECT_THAT(message_of(o), HasSubstr("device_id/serial/address: expected exactly one"));
  o.serial = "X";
  o.width_px = 0;
  EXPECT_THAT(message_of(o), HasSubstr("width_px: expected 1..65535, found 0"));
  o.width_px = 640;
  o.pixel_format = "RGB8";
  EXPECT_THAT(message_of(o), HasSubstr("pixel_format"));
  o.pixel_format = "Mono8";
  o.buffer_count = 1;
  EXPECT_THAT(message_of(o), HasSubstr("buffer_count: expected 2..256, found 1"));
  o.buffer_count = 8;
  o.packet_size_bytes = 100;
  EXPECT_THAT(message_of(o), HasSubstr("packet_size_bytes"));
  o.packet_size_bytes = 0;
  o.reconnect_max_backoff = Duration::Milliseconds(1);
  EXPECT_THAT(message_of(o), HasSubstr("reconnect_max_backoff"));
  o.reconnect_max_backoff = Duration::Seconds(5);
  o.clock_fit.window_size = 1;
  EXPECT_THAT(message_of(o), HasSubstr("clock_fit: DeviceClockFitOptions.window_size"));
}

TEST(AravisFakeGvTest, NextAndReleaseDoNotAllocateAfterStartUp) {
  FakeGvCamera fake({.serial = UniqueSerial()});
  ASSERT_NO_THROW(fake.Start());
  AravisCameraOptions o = OptionsFor(fake);
  o.frame_rate_hz = 100.0;
  AravisCamera camera(o);
  CameraFrame f;
  for (int i = 0; i < 20; ++i) {  // warm-up: first pops may set up GLib state
    ASSERT_EQ(NextWithin(&camera, &f, Duration::Seconds(5)), ReadStatus::kOk);
    camera.Release(f);
  }
  constexpr int kFrames = 200;
  int delivered = 0;
  uint64_t mallocs = 0;
  uint64_t timeout_mallocs = 0;
  {
    testing::ScopedMallocCheck check;
    for (int i = 0; i < kFrames; ++i) {
      if (camera.Next(&f, Duration::Seconds(2)) == ReadStatus::kOk) {
        ++delivered;
        camera.Release(f);
      }
    }
    mallocs = check.mallocs();
  }
  // A timed-out wait (GAsyncQueue's timed condition wait) as well.
  std::vector<CameraFrame> held(8);
  {
    testing::ScopedMallocCheck check;
    // Hold every buffer so that the waits below time out.
    int got = 0;
    for (CameraFrame& h : held) got += camera.Next(&h, Duration::Seconds(2)) == ReadStatus::kOk;
    CameraFrame none;
    for (int i = 0; i < 5; ++i) (void)camera.Next(&none, Duration::Milliseconds(20));
    for (int i = 0; i < got; ++i) camera.Release(held[static_cast<std::size_t>(i)]);
    timeout_mallocs = check.mallocs();
  }
  std::printf(
      "malloc calls on the camera thread: %llu in %d Next/Release cycles (%.3f per "
      "frame), %llu in 8 Next + 5 timed-out Next + 8 Release\n",
      static_cast<unsigned long long>(mallocs), delivered,
      static_cast<double>(mallocs) / std::max(delivered, 1),
      static_cast<unsigned long long>(timeout_mallocs));
  ASSERT_EQ(delivered, kFrames);
  EXPECT_EQ(mallocs, 0u);
  EXPECT_EQ(timeout_mallocs, 0u);
}

}  // namespace
}  // namespace rover::drivers
