// V4L2 scenarios on the HIL bench: run inside the bench VM (Debian's kernel
// with vivid loaded as two capture nodes: /dev/video0 single-planar,
// /dev/video1 multi-planar; see hil/bench/README.md) by ctest through rover_add_hil_vm_test. Every
// frame crosses the kernel: vivid's kernel thread draws it into a vb2 buffer that V4l2Camera
// dequeues from its memory mapping.
//
// vivid's own controls drive the faults: "percentage_of_dropped_buffers",
// "inject_v4l2_buf_flag_error", "inject_fatal_streaming_error",
// "disconnect", "wrap_sequence_number" and "timestamp_source". vivid's
// stamps are nominal: frame n of a stream is stamped start + n * period
// (+ one period for end-of-frame stamps), which makes the stamp checks
// exact.
//
// The guest is emulated (TCG) on a shared host: frame rates are kept at or
// below 25 fps, where the emulated guest keeps up with margin.

#include <fcntl.h>
#include <linux/videodev2.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stop_token>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "drivers/camera/v4l2_camera.h"
#include "tests/support/malloc_counter.h"

namespace rover::drivers {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

constexpr const char* kDevice = "/dev/video0";
/// A vivid instance that offers only the multi-planar capture API.
constexpr const char* kMultiPlanarDevice = "/dev/video1";
/// As hil/bench/guest_init.sh loads vivid.
constexpr const char* kVividParameters = "n_devs=2 node_types=0x1,0x1 multiplanar=1,2";
constexpr Duration kWait = Duration::Seconds(5);

/// Writes one of vivid's controls through a descriptor of its own (closed
/// again, so nothing keeps the module busy). Fails the test if the control
/// is missing or refused.
void SetVividControl(const std::string& name, int64_t value, const char* device = kDevice) {
  const int fd = open(device, O_RDWR | O_NONBLOCK | O_CLOEXEC);
  ASSERT_GE(fd, 0) << device << ": " << std::strerror(errno);
  bool done = false;
  uint32_t id = V4L2_CTRL_FLAG_NEXT_CTRL;
  for (int i = 0; i < 1000 && !done; ++i) {
    v4l2_query_ext_ctrl q{};
    q.id = id;
    if (ioctl(fd, VIDIOC_QUERY_EXT_CTRL, &q) != 0) break;
    id = q.id | V4L2_CTRL_FLAG_NEXT_CTRL;
    if (V4l2Camera::NormalizeControlName(q.name) != name) continue;
    v4l2_ext_control c{};
    c.id = q.id;
    c.value = static_cast<int32_t>(value);
    v4l2_ext_controls cs{};
    cs.which = V4L2_CTRL_WHICH_CUR_VAL;
    cs.count = 1;
    cs.controls = &c;
    EXPECT_EQ(ioctl(fd, VIDIOC_S_EXT_CTRLS, &cs), 0)
        << name << " = " << value << ": " << std::strerror(errno);
    done = true;
  }
  close(fd);
  ASSERT_TRUE(done) << "vivid has no control " << name;
}

void Shell(const std::string& command) { ASSERT_EQ(std::system(command.c_str()), 0) << command; }

V4l2CameraOptions Options(const std::string& format, double rate_hz = 25.0, int buffers = 4,
                          const char* device = kDevice) {
  V4l2CameraOptions o;
  o.device = device;
  o.pixel_format = format;
  o.width_px = 640;
  o.height_px = 480;
  o.frame_rate_hz = rate_hz;
  o.buffer_count = buffers;
  o.reconnect_initial_backoff = Duration::Milliseconds(50);
  o.reconnect_max_backoff = Duration::Milliseconds(400);
  return o;
}

/// The message of the V4l2CameraError that starting with `options` throws.
std::string StartupError(const V4l2CameraOptions& options) {
  try {
    V4l2Camera camera(options);
  } catch (const V4l2CameraError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected V4l2CameraError";
  return "";
}

/// One frame's image copied out (the frame is released).
struct Image {
  int width_px = 0;
  int height_px = 0;
  std::vector<uint8_t> pixels{};
  uint8_t at(int x, int y) const {
    return pixels[static_cast<std::size_t>(y) * static_cast<std::size_t>(width_px) +
                  static_cast<std::size_t>(x)];
  }
};

Image Grab(V4l2Camera& camera, int skip = 2) {
  CameraFrame frame;
  Image image;
  for (int i = 0; i <= skip; ++i) {
    const ReadStatus status = camera.Next(&frame, kWait);
    EXPECT_EQ(status, ReadStatus::kOk);
    if (status != ReadStatus::kOk) return image;
    if (i == skip) {
      image.width_px = frame.image.width_px;
      image.height_px = frame.image.height_px;
      for (int y = 0; y < frame.image.height_px; ++y) {
        const uint8_t* row =
            frame.image.data + static_cast<std::size_t>(y) * frame.image.stride_bytes;
        image.pixels.insert(image.pixels.end(), row, row + frame.image.width_px);
      }
    }
    camera.Release(frame);
  }
  return image;
}

/// The luma of the 8 bars of vivid's 75% colour bar, sampled at the
/// centre of each bar on row `y`.
std::vector<int> BarLuma(const Image& image, int y) {
  std::vector<int> luma;
  const int bar = image.width_px / 8;
  for (int i = 0; i < 8; ++i) luma.push_back(image.at(i * bar + bar / 2, y));
  return luma;
}

/// Watches for stalls of the whole guest. Under TCG the guest runs in a
/// host process that shares its cores with other work; when the host does
/// not schedule it, every guest clock jumps ahead when it runs again. vivid
/// then sees several frame periods gone and skips their sequence numbers:
/// frames lost in the "device", not in the driver. A thread that sleeps
/// 2 ms at a time sees the same stall as a late wake-up.
class GuestStallWatch {
 public:
  explicit GuestStallWatch(Duration threshold)
      : threshold_(threshold), thread_([this](std::stop_token stop) {
          while (!stop.stop_requested()) {
            const Time before = Time::Now();
            std::this_thread::sleep_for(std::chrono::milliseconds(2));
            const Time after = Time::Now();
            if (after - before > threshold_ && count_ < windows_.size())
              windows_[count_++] = {before, after};
          }
        }) {}
  /// Stops watching; the windows are final after this.
  void Stop() {
    thread_.request_stop();
    if (thread_.joinable()) thread_.join();
  }
  ~GuestStallWatch() { Stop(); }
  /// True if a stall overlapped [from, to].
  bool StalledDuring(Time from, Time to) const {
    for (std::size_t i = 0; i < count_; ++i) {
      if (windows_[i].first <= to && windows_[i].second >= from) return true;
    }
    return false;
  }
  std::size_t stalls() const { return count_; }

 private:
  Duration threshold_;
  std::array<std::pair<Time, Time>, 256> windows_{};
  std::size_t count_ = 0;
  std::jthread thread_;
};

class VividTest : public ::testing::Test {
 protected:
  // vivid keeps its control values across opens: every scenario starts
  // from the defaults it relies on.
  void SetUp() override {
    for (const char* device : {kDevice, kMultiPlanarDevice}) {
      SetVividControl("timestamp_source", 0, device);  // end of frame
      SetVividControl("percentage_of_dropped_buffers", 0, device);
      SetVividControl("wrap_sequence_number", 0, device);
      SetVividControl("test_pattern", 0, device);   // 75% colour bar
      SetVividControl("osd_text_mode", 2, device);  // no text over the bars
    }
  }
};

// ---------------------------------------------------------------------------
// Format negotiation.

// vivid offers GREY, Y10, Y12, Y16 and YUYV at 640x480 (v4l2-ctl
// --list-formats-ext): each is negotiated exactly and converts to 8-bit
// luma. The 75% colour bar's luma falls from bar to bar (white, yellow,
// cyan, green, magenta, red, blue, black), so reading chroma or the wrong
// byte of a 16-bit pixel would break the order. (vivid's GREY weighs R, G,
// B as Rec. 709 luma at full range, its YUYV as ITU-R 601 at limited range:
// their values differ by design.)
TEST_F(VividTest, EachMonoFormatIsNegotiatedExactlyAndGivesTheLuma) {
  std::vector<int> grey_bars;
  for (const std::string format : {"GREY", "YUYV", "Y16", "Y12", "Y10"}) {
    SCOPED_TRACE(format);
    V4l2Camera camera(Options(format));
    EXPECT_EQ(FourccToString(camera.fourcc()), format);
    EXPECT_EQ(camera.width_px(), 640);
    EXPECT_EQ(camera.height_px(), 480);
    EXPECT_DOUBLE_EQ(camera.frame_rate_hz(), 25.0);
    EXPECT_GE(camera.buffer_count(), 4);
    EXPECT_EQ(camera.bytes_per_line(), format == "GREY" ? 640u : 1280u);
    const Image image = Grab(camera);
    ASSERT_EQ(image.width_px, 640);
    ASSERT_EQ(image.height_px, 480);
    const std::vector<int> bars = BarLuma(image, 240);
    std::printf("%s bars:", format.c_str());
    for (const int v : bars) std::printf(" %d", v);
    std::printf("\n");
    for (std::size_t i = 1; i < bars.size(); ++i) EXPECT_LT(bars[i], bars[i - 1]) << "bar " << i;
    if (format == "GREY") {
      grey_bars = bars;
    } else if (format == "YUYV") {
      // Limited-range Y'CbCr: 75% white is 16 + 0.75 * 219 = 180, black 16.
      // The chroma bytes would read about 128 on both.
      EXPECT_NEAR(bars.front(), 180, 4);
      EXPECT_NEAR(bars.back(), 16, 4);
    } else {
      // vivid draws Y10/Y12/Y16 from the same grey level as GREY: their
      // 8 most significant bits are GREY's value.
      ASSERT_EQ(grey_bars.size(), bars.size());
      for (std::size_t i = 0; i < bars.size(); ++i)
        EXPECT_NEAR(bars[i], grey_bars[i], 1) << "bar " << i;
    }
    EXPECT_EQ(camera.stats().short_buffers, 0u);
  }
}

TEST_F(VividTest, GreyIsHandedOverWithoutCopy) {
  V4l2CameraOptions options = Options("GREY");
  options.export_dmabuf = true;
  V4l2Camera camera(options);
  CameraFrame frame;
  ASSERT_EQ(camera.Next(&frame, kWait), ReadStatus::kOk);
  EXPECT_EQ(frame.image.stride_bytes, camera.bytes_per_line());
  // The view is the capture buffer itself: the buffer exported as a DMABUF
  // holds the very bytes the view shows.
  const int dmabuf = camera.dmabuf_fd(frame.buffer_index);
  ASSERT_GE(dmabuf, 0);
  const std::size_t bytes =
      frame.image.stride_bytes * static_cast<std::size_t>(frame.image.height_px);
  void* mapped = mmap(nullptr, bytes, PROT_READ, MAP_SHARED, dmabuf, 0);
  ASSERT_NE(mapped, MAP_FAILED) << std::strerror(errno);
  EXPECT_EQ(std::memcmp(mapped, frame.image.data, bytes), 0);
  munmap(mapped, bytes);
  camera.Release(frame);
}

TEST_F(VividTest, UnsupportedFourccIsRefusedWithWhatTheDeviceOffers) {
  const std::string message = StartupError(Options("MJPG"));
  std::printf("%.600s...\n", message.c_str());
  EXPECT_THAT(message,
              AllOf(HasSubstr(kDevice), HasSubstr("MJPG 640x480"), HasSubstr("not available"),
                    HasSubstr("the driver proposed"), HasSubstr("the device offers"),
                    HasSubstr("GREY 320x180 640x360 640x480 1280x720"), HasSubstr("YUYV 320x180")));
}

TEST_F(VividTest, SizeTheDriverWouldAdjustIsAnError) {
  V4l2CameraOptions options = Options("GREY");
  options.width_px = 9999;
  options.height_px = 9999;
  options.frame_rate_hz.reset();
  const std::string message = StartupError(options);
  EXPECT_THAT(message, AllOf(HasSubstr(kDevice), HasSubstr("GREY 9999x9999"),
                             HasSubstr("proposed GREY 3840x2160"), HasSubstr("the device offers")));
  options.width_px = 641;
  options.height_px = 481;
  EXPECT_THAT(StartupError(options),
              AllOf(HasSubstr("GREY 641x481"), HasSubstr("proposed GREY 640x480")));
}

TEST_F(VividTest, FrameRateTheDeviceDoesNotOfferIsAnError) {
  const std::string message = StartupError(Options("GREY", 60.0));
  EXPECT_THAT(
      message,
      AllOf(HasSubstr(kDevice), HasSubstr("60 fps is not available for GREY 640x480"),
            HasSubstr("the device set 25 fps"), HasSubstr("1, 2, 4, 5, 10, 12.5, 15, 25 fps")));
}

// ---------------------------------------------------------------------------
// Streaming.

// 300 frames at 15 fps with 8 buffers: every sequence number once, in
// order, nothing lost, stamps on CLOCK_MONOTONIC one frame period apart.
// Losing a frame would take this consumer, which releases every frame at
// once, falling 7 periods (467 ms) behind. A gap that coincides with a
// stall of the whole emulated guest (GuestStallWatch) is vivid's, not the
// driver's: it is reported, and must stay rare.
TEST_F(VividTest, ThreeHundredFramesInOrderWithMonotonicStampsAndNoDrops) {
  constexpr int kFrames = 300;
  constexpr double kRate = 15.0;
  const Duration period = Duration::FromSeconds(1.0 / kRate);
  GuestStallWatch watch(period / 2);
  V4l2Camera camera(Options("GREY", kRate, 8));
  std::vector<CameraFrame> frames;
  frames.reserve(kFrames);
  const Time wall_start = Time::Now();
  CameraFrame frame;
  for (int i = 0; i < kFrames; ++i) {
    ASSERT_EQ(camera.Next(&frame, kWait), ReadStatus::kOk) << "frame " << i;
    const Time now = Time::Now();
    // On CLOCK_MONOTONIC: vivid stamps the end of frame 0.9 periods after
    // it starts drawing, which is before delivery: at most that far ahead.
    ASSERT_LT(frame.stamp, now + period) << "frame " << i;
    ASSERT_GT(frame.stamp, now - Duration::Seconds(2)) << "frame " << i;
    frames.push_back(frame);
    camera.Release(frame);
  }
  const double wall_s = (Time::Now() - wall_start).ToSeconds();
  watch.Stop();
  uint64_t lost = 0, excused = 0;
  for (std::size_t i = 1; i < frames.size(); ++i) {
    const CameraFrame& f = frames[i];
    const CameraFrame& p = frames[i - 1];
    ASSERT_GT(f.stamp, p.stamp) << "frame " << i;
    ASSERT_EQ(f.sequence, p.sequence + 1 + f.dropped_before) << "frame " << i;
    // vivid stamps when its thread draws, which wakes on the 4 ms jiffy.
    EXPECT_NEAR((f.stamp - p.stamp).ToMilliseconds(),
                period.ToMilliseconds() * (1 + f.dropped_before), period.ToMilliseconds() / 2)
        << "frame " << i;
    lost += f.dropped_before;
    if (f.dropped_before == 0) continue;
    if (watch.StalledDuring(p.stamp - period, f.stamp)) {
      excused += f.dropped_before;
      std::printf("frame %zu: %u frames lost while the guest stalled (vivid skipped them)\n", i,
                  f.dropped_before);
    } else {
      ADD_FAILURE() << "frame " << i << " (sequence " << f.sequence << "): " << f.dropped_before
                    << " frames lost without a guest stall";
    }
  }
  const double fps = (kFrames - 1) / (frames.back().stamp - frames.front().stamp).ToSeconds();
  std::printf(
      "300 frames GREY 640x480 at %.1f fps set: %.2f fps by the stamps, %.2f fps by the wall "
      "clock; "
      "%llu lost (%llu during %zu guest stalls)\n",
      kRate, fps, kFrames / wall_s, static_cast<unsigned long long>(lost),
      static_cast<unsigned long long>(excused), watch.stalls());
  RecordProperty("measured_fps", std::to_string(fps));
  RecordProperty("frames_lost_in_guest_stalls", std::to_string(excused));
  const V4l2CameraStats s = camera.stats();
  EXPECT_LE(excused, static_cast<uint64_t>(kFrames / 20))
      << "the guest stalled too often for a meaningful run";
  EXPECT_EQ(s.frames, static_cast<uint64_t>(kFrames));
  EXPECT_EQ(s.dropped_frames, lost);
  EXPECT_EQ(s.error_buffers, 0u);
  EXPECT_EQ(s.foreign_clock_stamps, 0u) << "vivid's buffers say CLOCK_MONOTONIC";
  EXPECT_EQ(s.backward_stamps, 0u);
  EXPECT_EQ(s.sequence_resets, 0u);
  EXPECT_EQ(s.end_of_frame_stamps, static_cast<uint64_t>(kFrames));
  EXPECT_EQ(camera.health(), V4l2CameraHealth::kStreaming);
}

// A consumer that stops calling Next() for 1 s with 4 buffers at 25 fps: the
// four buffers fill, vivid has nowhere to put the next ~21 frames, and the
// first frame after them shows the gap. Then frames flow with no loss
// (except in a stall of the whole guest, see GuestStallWatch).
TEST_F(VividTest, StalledConsumerLosesFramesCountedThenRecovers) {
  const Duration period = Duration::Milliseconds(40);
  V4l2Camera camera(Options("GREY", 25.0, 4));
  CameraFrame frame, previous;
  for (int i = 0; i < 10; ++i) {
    ASSERT_EQ(camera.Next(&frame, kWait), ReadStatus::kOk);
    previous = frame;
    camera.Release(frame);
  }
  std::this_thread::sleep_for(std::chrono::seconds(1));
  uint64_t lost = 0;
  int frames_with_gap = 0;
  for (int i = 0; i < 12; ++i) {
    ASSERT_EQ(camera.Next(&frame, kWait), ReadStatus::kOk);
    EXPECT_EQ(frame.sequence, previous.sequence + 1 + frame.dropped_before);
    lost += frame.dropped_before;
    frames_with_gap += frame.dropped_before > 0 ? 1 : 0;
    previous = frame;
    camera.Release(frame);
  }
  std::printf("stall of 1 s at 25 fps with 4 buffers: %llu frames lost\n",
              static_cast<unsigned long long>(lost));
  EXPECT_GE(lost, 12u) << "1 s at 25 fps is 25 frames; 4 fit in the buffers";
  EXPECT_LE(lost, 40u);
  EXPECT_GE(frames_with_gap, 1);
  EXPECT_EQ(camera.stats().dropped_frames, lost);
  // Recovered: the following frames arrive without loss.
  GuestStallWatch watch(period / 2);
  std::vector<CameraFrame> frames{previous};
  for (int i = 0; i < 50; ++i) {
    ASSERT_EQ(camera.Next(&frame, kWait), ReadStatus::kOk);
    frames.push_back(frame);
    camera.Release(frame);
  }
  watch.Stop();
  uint64_t lost_after = 0;
  for (std::size_t i = 1; i < frames.size(); ++i) {
    EXPECT_EQ(frames[i].sequence, frames[i - 1].sequence + 1 + frames[i].dropped_before);
    lost_after += frames[i].dropped_before;
    if (frames[i].dropped_before > 0) {
      EXPECT_TRUE(watch.StalledDuring(frames[i - 1].stamp - period, frames[i].stamp))
          << "frame " << i << " after recovery: " << frames[i].dropped_before
          << " lost without a guest stall";
    }
  }
  EXPECT_EQ(camera.stats().dropped_frames, lost + lost_after);
}

// vivid skips filling half its buffers (the sequence moves on): every skipped
// frame is counted once, and the stamps agree with the counted gaps.
TEST_F(VividTest, FramesTheDeviceDropsAreCountedExactly) {
  V4l2Camera camera(Options("GREY", 25.0, 4));
  CameraFrame frame, previous;
  ASSERT_EQ(camera.Next(&frame, kWait), ReadStatus::kOk);
  previous = frame;
  camera.Release(frame);
  camera.SetControl("percentage_of_dropped_buffers", 50);
  const Duration period = Duration::Milliseconds(40);
  uint64_t lost = 0;
  for (int i = 0; i < 40; ++i) {
    ASSERT_EQ(camera.Next(&frame, kWait), ReadStatus::kOk);
    ASSERT_EQ(frame.sequence, previous.sequence + 1 + frame.dropped_before);
    // vivid stamps when its thread draws, which wakes on the 4 ms jiffy.
    EXPECT_NEAR((frame.stamp - previous.stamp).ToMilliseconds(),
                period.ToMilliseconds() * (1 + frame.dropped_before), period.ToMilliseconds() / 2);
    lost += frame.dropped_before;
    previous = frame;
    camera.Release(frame);
  }
  camera.SetControl("percentage_of_dropped_buffers", 0);
  std::printf("vivid dropping 50%%: %llu frames lost over 40 delivered\n",
              static_cast<unsigned long long>(lost));
  EXPECT_GE(lost, 10u);
  EXPECT_EQ(camera.stats().dropped_frames, lost);
}

// Buffers vivid flags V4L2_BUF_FLAG_ERROR are counted, requeued and never
// delivered; each shows as one lost frame.
TEST_F(VividTest, ErrorBuffersAreCountedRequeuedAndSkipped) {
  V4l2Camera camera(Options("GREY", 25.0, 4));
  CameraFrame frame;
  uint64_t lost = 0;
  uint64_t delivered = 0;
  for (int injection = 0; injection < 3; ++injection) {
    camera.SetControl("inject_v4l2_buf_flag_error", 1);
    for (int i = 0; i < 6; ++i) {
      ASSERT_EQ(camera.Next(&frame, kWait), ReadStatus::kOk);
      lost += frame.dropped_before;
      ++delivered;
      camera.Release(frame);
    }
  }
  const V4l2CameraStats s = camera.stats();
  EXPECT_EQ(s.error_buffers, 3u);
  EXPECT_EQ(s.frames, delivered);
  EXPECT_GE(s.dropped_frames, 3u) << "each error buffer is a lost frame";
  EXPECT_EQ(s.dropped_frames, lost);
  EXPECT_EQ(camera.health(), V4l2CameraHealth::kStreaming);
}

// vivid's "wrap sequence number" starts the 32-bit sequence 128 frames
// before it wraps: the 64-bit sequence runs on through the wrap, without a
// reset or a loss.
TEST_F(VividTest, SequenceWrapIsExtendedTo64Bits) {
  SetVividControl("wrap_sequence_number", 1);
  V4l2Camera camera(Options("GREY", 25.0, 8));
  CameraFrame frame, previous;
  ASSERT_EQ(camera.Next(&frame, kWait), ReadStatus::kOk);
  EXPECT_GE(frame.sequence, 0xFFFF'FF00u) << "the first sequence is the driver's";
  previous = frame;
  camera.Release(frame);
  for (int i = 0; i < 150; ++i) {
    ASSERT_EQ(camera.Next(&frame, kWait), ReadStatus::kOk);
    ASSERT_EQ(frame.sequence, previous.sequence + 1 + frame.dropped_before);
    previous = frame;
    camera.Release(frame);
  }
  EXPECT_GT(previous.sequence, 0xFFFF'FFFFu) << "the 32-bit counter wrapped";
  EXPECT_EQ(camera.stats().sequence_resets, 0u);
  EXPECT_LT(camera.stats().dropped_frames, 5u);
  SetVividControl("wrap_sequence_number", 0);
}

// ---------------------------------------------------------------------------
// Timestamps.

// An end-of-frame stamp moved back by exposure_and_readout is the start of
// exposure. vivid stamps a frame when its thread starts drawing it, plus
// 0.9 periods when set to "end of frame" (its model of exposure +
// readout). With exposure_and_readout = 0.9 periods, both modes give the
// same start of exposure: stamp - sequence * period keeps its level when
// vivid switches mode mid-stream. Uncorrected, it would move by 36 ms.
TEST_F(VividTest, EndOfFrameStampsAreMovedToTheStartOfExposure) {
  V4l2CameraOptions options = Options("GREY", 25.0, 4);
  const Duration period = Duration::Milliseconds(40);
  options.exposure_and_readout = period * 9 / 10;
  V4l2Camera camera(options);
  CameraFrame frame;
  // The stamp's offset from the frame's nominal place on the sequence grid.
  auto offset_ms = [&](const CameraFrame& f) {
    return static_cast<double>(f.stamp.nanoseconds() -
                               static_cast<int64_t>(f.sequence) * period.nanoseconds()) *
           1e-6;
  };
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  std::vector<double> eof, soe;
  for (int i = 0; i < 15; ++i) {
    ASSERT_EQ(camera.Next(&frame, kWait), ReadStatus::kOk);
    eof.push_back(offset_ms(frame));
    camera.Release(frame);
  }
  EXPECT_EQ(camera.stats().end_of_frame_stamps, 15u);
  camera.SetControl("timestamp_source", 1);
  // Frames drawn before the switch may still be queued: skip them.
  for (int i = 0; i < 5; ++i) {
    ASSERT_EQ(camera.Next(&frame, kWait), ReadStatus::kOk);
    camera.Release(frame);
  }
  const uint64_t eof_after_switch = camera.stats().end_of_frame_stamps;
  for (int i = 0; i < 15; ++i) {
    ASSERT_EQ(camera.Next(&frame, kWait), ReadStatus::kOk);
    soe.push_back(offset_ms(frame));
    camera.Release(frame);
  }
  EXPECT_EQ(camera.stats().end_of_frame_stamps, eof_after_switch)
      << "start-of-exposure stamps are used as they are";
  const double eof_level = median(eof);
  const double soe_level = median(soe);
  std::printf(
      "start of exposure from end-of-frame stamps vs start-of-exposure stamps: %.2f ms apart\n",
      eof_level - soe_level);
  EXPECT_NEAR(eof_level, soe_level, 5.0)
      << "end-of-frame stamps not moved back by exposure_and_readout";
  EXPECT_EQ(camera.stats().backward_stamps, 0u);
}

// ---------------------------------------------------------------------------
// Controls. vivid has brightness, contrast, gain with automatic gain, and
// no exposure or trigger control.

TEST_F(VividTest, GainAndBrightnessReadBack) {
  V4l2CameraOptions options = Options("GREY");
  options.gain = 50;
  V4l2Camera camera(options);
  EXPECT_EQ(camera.GetControl("gain"), 50);
  EXPECT_EQ(camera.GetControl("Gain, Automatic"), 0)
      << "setting the gain switches automatic gain off";
  EXPECT_EQ(camera.SetControl("gain", 77), 77);
  EXPECT_EQ(camera.GetControl("gain"), 77);
  EXPECT_EQ(camera.SetControl("Brightness", 100), 100);
  EXPECT_EQ(camera.GetControl("brightness"), 100);
  camera.SetControl("brightness", 128);
  EXPECT_FALSE(camera.GetControl("exposure_time_absolute").has_value());
  try {
    camera.SetControl("gain", 300);
    ADD_FAILURE() << "gain 300 accepted";
  } catch (const V4l2CameraError& e) {
    EXPECT_THAT(e.what(),
                AllOf(HasSubstr(kDevice), HasSubstr("'gain' = 300"), HasSubstr("0..255")));
  }
  // Frames still flow after the control changes.
  EXPECT_EQ(Grab(camera, 0).width_px, 640);
  SetVividControl("gain_automatic", 1);
}

TEST_F(VividTest, ControlOutOfRangeOrMissingIsAStartupError) {
  V4l2CameraOptions options = Options("GREY");
  options.gain = 300;
  EXPECT_THAT(StartupError(options), AllOf(HasSubstr(kDevice), HasSubstr("gain"),
                                           HasSubstr("0..255"), HasSubstr("found 300")));
  options = Options("GREY");
  options.exposure = Duration::Milliseconds(10);
  EXPECT_THAT(StartupError(options),
              AllOf(HasSubstr(kDevice), HasSubstr("exposure 100 asked for"),
                    HasSubstr("no V4L2_CID_EXPOSURE_ABSOLUTE control"),
                    HasSubstr("the device's controls: brightness, contrast")));
}

TEST_F(VividTest, MissingTriggerIsReportedAndOnlyFatalWhenRequired) {
  V4l2CameraOptions options = Options("GREY");
  options.trigger_value = 1;
  {
    V4l2Camera camera(options);
    EXPECT_FALSE(camera.trigger_supported());
    std::string report;
    for (const std::string& line : camera.startup_report()) report += line + "\n";
    std::printf("%s", report.c_str());
    EXPECT_THAT(report, AllOf(HasSubstr("trigger"), HasSubstr("'trigger_mode'"),
                              HasSubstr("not supported")));
    EXPECT_THAT(report, HasSubstr("no V4L2_CID_EXPOSURE_AUTO control"));
    EXPECT_EQ(Grab(camera, 0).width_px, 640) << "the camera free-runs";
  }
  options.trigger_required = true;
  EXPECT_THAT(StartupError(options), AllOf(HasSubstr(kDevice), HasSubstr("trigger_mode control"),
                                           HasSubstr("the device's controls")));
}

// ---------------------------------------------------------------------------
// Real time.

/// Next() and Release() with the malloc count of only those calls.
struct CountingCamera {
  V4l2Camera& camera;
  uint64_t mallocs = 0;
  ReadStatus Next(CameraFrame* frame, Duration timeout) {
    const rover::testing::ScopedMallocCheck check;
    const ReadStatus status = camera.Next(frame, timeout);
    mallocs += check.mallocs();
    return status;
  }
  void Release(const CameraFrame& frame) {
    const rover::testing::ScopedMallocCheck check;
    camera.Release(frame);
    mallocs += check.mallocs();
  }
};

TEST_F(VividTest, NextAndReleaseDoNotAllocate) {
  for (const std::string format : {"GREY", "YUYV", "Y16"}) {
    SCOPED_TRACE(format);
    V4l2Camera camera(Options(format, 25.0, 4));
    CameraFrame frame;
    ASSERT_EQ(camera.Next(&frame, kWait), ReadStatus::kOk);  // start-up
    camera.Release(frame);
    CountingCamera counting{camera};
    uint64_t sum = 0;
    for (int i = 0; i < 40; ++i) {
      ASSERT_EQ(counting.Next(&frame, kWait), ReadStatus::kOk);
      sum += frame.image.data[frame.image.stride_bytes * 240 + 320];
      counting.Release(frame);
    }
    // A timeout (every buffer held) and an error buffer on the way.
    ASSERT_EQ(counting.Next(&frame, kWait), ReadStatus::kOk);
    std::vector<CameraFrame> held{frame};
    for (int i = 1; i < camera.buffer_count(); ++i) {
      ASSERT_EQ(counting.Next(&frame, kWait), ReadStatus::kOk);
      held.push_back(frame);
    }
    EXPECT_EQ(counting.Next(&frame, Duration::Milliseconds(100)), ReadStatus::kTimeout);
    for (const CameraFrame& f : held) counting.Release(f);
    camera.SetControl("inject_v4l2_buf_flag_error", 1);
    for (int i = 0; i < 4; ++i) {
      ASSERT_EQ(counting.Next(&frame, kWait), ReadStatus::kOk);
      counting.Release(frame);
    }
    EXPECT_EQ(counting.mallocs, 0u);
    EXPECT_EQ(camera.stats().error_buffers, 1u);
    EXPECT_EQ(camera.stats().timeouts, 1u);
    EXPECT_GT(sum, 0u);
  }
}

// ---------------------------------------------------------------------------
// The multi-planar API. /dev/video1 offers only
// V4L2_CAP_VIDEO_CAPTURE_MPLANE, as many SoC CSI-2 receivers do: every
// format, buffer and stream ioctl then takes the _MPLANE type and describes
// its memory in v4l2_plane entries.

// The same formats as the single-planar device, and the same pixels.
TEST_F(VividTest, MultiPlanarDeviceGivesTheSameImagesAsTheSinglePlanarOne) {
  for (const std::string format : {"GREY", "YUYV", "Y16"}) {
    SCOPED_TRACE(format);
    V4l2Camera single(Options(format));
    EXPECT_FALSE(single.multi_planar());
    const Image reference = Grab(single);
    V4l2Camera camera(Options(format, 25.0, 4, kMultiPlanarDevice));
    EXPECT_TRUE(camera.multi_planar());
    EXPECT_EQ(FourccToString(camera.fourcc()), format);
    EXPECT_EQ(camera.bytes_per_line(), single.bytes_per_line());
    EXPECT_DOUBLE_EQ(camera.frame_rate_hz(), 25.0);
    const Image image = Grab(camera);
    ASSERT_EQ(image.width_px, 640);
    ASSERT_EQ(image.height_px, 480);
    EXPECT_EQ(BarLuma(image, 240), BarLuma(reference, 240));
    EXPECT_EQ(camera.stats().short_buffers, 0u);
  }
}

// Sequence, stamps, device drops and error buffers are read from the
// multi-planar buffers as from single-planar ones, with no allocation.
TEST_F(VividTest, MultiPlanarStreamCountsDropsAndErrorsWithoutAllocating) {
  V4l2Camera camera(Options("GREY", 25.0, 4, kMultiPlanarDevice));
  CameraFrame frame, previous;
  ASSERT_EQ(camera.Next(&frame, kWait), ReadStatus::kOk);
  previous = frame;
  camera.Release(frame);
  CountingCamera counting{camera};
  uint64_t lost = 0;
  auto stream = [&](int frames) {
    for (int i = 0; i < frames; ++i) {
      ASSERT_EQ(counting.Next(&frame, kWait), ReadStatus::kOk) << "frame " << i;
      ASSERT_EQ(frame.sequence, previous.sequence + 1 + frame.dropped_before);
      ASSERT_GT(frame.stamp, previous.stamp);
      EXPECT_EQ(frame.image.width_px, 640);
      lost += frame.dropped_before;
      previous = frame;
      counting.Release(frame);
    }
  };
  ASSERT_NO_FATAL_FAILURE(stream(30));
  camera.SetControl("percentage_of_dropped_buffers", 50);
  ASSERT_NO_FATAL_FAILURE(stream(20));
  camera.SetControl("percentage_of_dropped_buffers", 0);
  const uint64_t lost_while_dropping = lost;
  camera.SetControl("inject_v4l2_buf_flag_error", 1);
  ASSERT_NO_FATAL_FAILURE(stream(10));
  const V4l2CameraStats s = camera.stats();
  std::printf("multi-planar: %llu frames, %llu lost (%llu while vivid dropped half)\n",
              static_cast<unsigned long long>(s.frames), static_cast<unsigned long long>(lost),
              static_cast<unsigned long long>(lost_while_dropping));
  EXPECT_GE(lost_while_dropping, 5u);
  EXPECT_EQ(s.frames, 61u);
  EXPECT_EQ(s.dropped_frames, lost);
  EXPECT_EQ(s.error_buffers, 1u);
  EXPECT_EQ(s.foreign_clock_stamps, 0u);
  EXPECT_EQ(s.backward_stamps, 0u);
  EXPECT_EQ(counting.mallocs, 0u);
}

// A refused format lists what the device offers through the multi-planar
// format enumeration (the single-planar one lists nothing here).
TEST_F(VividTest, MultiPlanarRefusalListsTheDeviceFormats) {
  const std::string message = StartupError(Options("MJPG", 25.0, 4, kMultiPlanarDevice));
  EXPECT_THAT(message, AllOf(HasSubstr(kMultiPlanarDevice), HasSubstr("MJPG 640x480"),
                             HasSubstr("not available"), HasSubstr("GREY 320x180"),
                             HasSubstr("YUYV 320x180")));
}

// ---------------------------------------------------------------------------
// Failures of the stream and of the device.

// vivid fails the queue (vb2_queue_error): DQBUF answers EIO. The camera
// closes the device and reopens it within the same Next() call's timeout.
TEST_F(VividTest, FailedStreamIsReopenedWithinNext) {
  V4l2Camera camera(Options("GREY", 25.0, 4));
  CameraFrame frame, previous;
  ASSERT_EQ(camera.Next(&frame, kWait), ReadStatus::kOk);
  previous = frame;
  camera.Release(frame);
  camera.SetControl("inject_fatal_streaming_error", 1);
  CountingCamera counting{camera};
  for (int i = 0; i < 20; ++i) {
    ASSERT_EQ(counting.Next(&frame, kWait), ReadStatus::kOk) << "frame " << i;
    EXPECT_EQ(frame.sequence, previous.sequence + 1 + frame.dropped_before);
    previous = frame;
    counting.Release(frame);
  }
  const V4l2CameraStats s = camera.stats();
  EXPECT_EQ(s.disconnects, 1u);
  EXPECT_EQ(s.reconnects, 1u);
  EXPECT_EQ(s.last_errno, EIO);
  EXPECT_EQ(camera.health(), V4l2CameraHealth::kStreaming);
  EXPECT_EQ(counting.mallocs, 0u) << "the reopen path allocates nothing either";
}

// vivid's "disconnect" unregisters the device as if its USB cable was
// pulled: ioctls answer ENODEV and poll() POLLERR. vivid registers it again
// once its last user has closed it (descriptors and mappings).
//  1. A frame is held across the disconnect: it stays readable, Next()
//     reports kError within its timeout and does not reopen while the old
//     frame is out. Its release lets go of the last mapping, vivid comes
//     back, and the next Next() reopens it.
//  2. The device node goes away (vivid unloaded): that the module unloads
//     at all proves the camera closed and unmapped everything. Reopen
//     attempts fail (ENOENT) until vivid is loaded again, then frames flow.
// Nothing in Next()/Release() allocates throughout. (Runs last: it reloads
// the vivid module.)
TEST_F(VividTest, ZDeviceDisappearsAndComesBack) {
  V4l2Camera camera(Options("GREY", 25.0, 4));
  CountingCamera counting{camera};
  const Duration timeout = Duration::Milliseconds(300);
  CameraFrame held, frame;
  uint64_t last_sequence = 0;
  // Disconnects while `held` is out; returns once Next() reports it.
  auto disconnect_holding_a_frame = [&] {
    ASSERT_EQ(counting.Next(&held, kWait), ReadStatus::kOk);
    last_sequence = held.sequence;
    SetVividControl("disconnect", 1);
    ReadStatus status = ReadStatus::kOk;
    for (int i = 0; i < 20 && status == ReadStatus::kOk; ++i) {
      const Time start = Time::Now();
      status = counting.Next(&frame, timeout);
      EXPECT_LT(Time::Now() - start, timeout + Duration::Milliseconds(250))
          << "Next() overran its timeout";
      if (status == ReadStatus::kOk) {  // dequeued before the disconnect was seen
        last_sequence = frame.sequence;
        counting.Release(frame);
      }
    }
    ASSERT_EQ(status, ReadStatus::kError);
    EXPECT_EQ(camera.health(), V4l2CameraHealth::kDisconnected);
  };

  // 1. vivid's disconnect, with a frame held.
  ASSERT_NO_FATAL_FAILURE(disconnect_holding_a_frame());
  EXPECT_EQ(camera.stats().disconnects, 1u);
  const uint8_t pixel = held.image.data[held.image.stride_bytes * 240 + 100];
  EXPECT_EQ(counting.Next(&frame, timeout), ReadStatus::kError);
  EXPECT_EQ(camera.stats().reconnect_attempts, 0u) << "no reopen while an old frame is out";
  EXPECT_EQ(held.image.data[held.image.stride_bytes * 240 + 100], pixel)
      << "a held frame stays readable";
  counting.Release(held);
  ReadStatus status = ReadStatus::kError;
  for (int i = 0; i < 10 && status != ReadStatus::kOk; ++i)
    status = counting.Next(&frame, Duration::Seconds(1));
  ASSERT_EQ(status, ReadStatus::kOk) << "not reconnected after vivid came back";
  EXPECT_EQ(camera.health(), V4l2CameraHealth::kStreaming);
  EXPECT_EQ(camera.stats().reconnects, 1u);
  EXPECT_EQ(frame.sequence, last_sequence + 1) << "the new stream continues the sequence";
  EXPECT_EQ(frame.dropped_before, 0u);
  counting.Release(frame);

  // 2. The device node disappears and comes back.
  ASSERT_NO_FATAL_FAILURE(disconnect_holding_a_frame());
  counting.Release(held);  // the camera is now closed and waits for Next() to reopen
  Shell("/usr/sbin/rmmod vivid");
  for (int i = 0; i < 3; ++i) EXPECT_EQ(counting.Next(&frame, timeout), ReadStatus::kError);
  EXPECT_EQ(camera.stats().reconnects, 1u);
  EXPECT_EQ(camera.stats().last_errno, ENOENT) << "reopen attempts find no device node";
  Shell(std::string("/usr/sbin/modprobe vivid ") + kVividParameters);
  SetUp();  // the fresh module has default controls; every scenario expects these
  status = ReadStatus::kError;
  for (int i = 0; i < 30 && status != ReadStatus::kOk; ++i)
    status = counting.Next(&frame, Duration::Seconds(1));
  ASSERT_EQ(status, ReadStatus::kOk) << "not reconnected after vivid was loaded again";
  EXPECT_EQ(frame.sequence, last_sequence + 1);
  CameraFrame previous = frame;
  counting.Release(frame);
  for (int i = 0; i < 20; ++i) {
    ASSERT_EQ(counting.Next(&frame, kWait), ReadStatus::kOk);
    EXPECT_EQ(frame.sequence, previous.sequence + 1 + frame.dropped_before);
    EXPECT_EQ(frame.image.width_px, 640);
    previous = frame;
    counting.Release(frame);
  }
  const V4l2CameraStats s = camera.stats();
  std::printf("disconnects: %llu, reopen attempts %llu, reconnects %llu, Next() errors %llu\n",
              static_cast<unsigned long long>(s.disconnects),
              static_cast<unsigned long long>(s.reconnect_attempts),
              static_cast<unsigned long long>(s.reconnects),
              static_cast<unsigned long long>(s.errors));
  EXPECT_EQ(s.disconnects, 2u);
  EXPECT_EQ(s.reconnects, 2u);
  EXPECT_GE(s.reconnect_attempts, 4u);
  EXPECT_EQ(s.bad_releases, 0u);
  EXPECT_EQ(camera.health(), V4l2CameraHealth::kStreaming);
  EXPECT_EQ(counting.mallocs, 0u) << "disconnect, reopen attempts and reconnect allocate nothing";
}

}  // namespace
}  // namespace rover::drivers
