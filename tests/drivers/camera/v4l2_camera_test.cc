// V4l2Camera on the host, where no capture device exists: its options are
// validated field by field, and a missing device, a non-video character
// device and a regular file give start-up errors that name the path, what
// was expected and the system error. Streaming itself is proven against
// vivid on the HIL bench (tests/hil/bench/v4l2_vivid_test.cc).

#include "drivers/camera/v4l2_camera.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <stdexcept>
#include <string>

#include "tests/support/temp_dir.h"

namespace rover::drivers {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

/// The message of the V4l2CameraError that constructing with `options`
/// throws ("" and a test failure if it throws nothing or something else).
std::string StartupError(const V4l2CameraOptions& options) {
  try {
    V4l2Camera camera(options);
  } catch (const V4l2CameraError& e) {
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected V4l2CameraError, got: " << e.what();
    return "";
  }
  ADD_FAILURE() << "expected V4l2CameraError for " << options.device;
  return "";
}

std::string ValidationError(const V4l2CameraOptions& options) {
  try {
    options.Validate();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(V4l2CameraOptionsTest, DefaultsAreValid) { EXPECT_NO_THROW(V4l2CameraOptions{}.Validate()); }

TEST(V4l2CameraOptionsTest, EachBadFieldIsNamedWithExpectedAndFound) {
  V4l2CameraOptions o;
  o.pixel_format = "RGB3";
  EXPECT_THAT(ValidationError(o), AllOf(HasSubstr("V4l2CameraOptions.pixel_format"),
                                        HasSubstr("GREY"), HasSubstr("found 'RGB3'")));
  o = {};
  o.width_px = 0;
  EXPECT_THAT(ValidationError(o), AllOf(HasSubstr("width_px"), HasSubstr("found 0")));
  o = {};
  o.buffer_count = 1;
  EXPECT_THAT(ValidationError(o),
              AllOf(HasSubstr("buffer_count"), HasSubstr("2 to 32"), HasSubstr("found 1")));
  o = {};
  o.frame_rate_hz = -5.0;
  EXPECT_THAT(ValidationError(o), HasSubstr("frame_rate_hz"));
  o = {};
  o.exposure = Duration::Microseconds(10);
  EXPECT_THAT(ValidationError(o), AllOf(HasSubstr("exposure"), HasSubstr("100 us")));
  o = {};
  o.exposure = Duration::Milliseconds(5);
  o.exposure_raw = 100;
  EXPECT_THAT(ValidationError(o), HasSubstr("exposure_raw"));
  o = {};
  o.trigger_required = true;
  EXPECT_THAT(ValidationError(o), HasSubstr("trigger_value"));
  o = {};
  o.trigger_value = 1;
  o.trigger_control = " -- ";
  EXPECT_THAT(ValidationError(o), HasSubstr("trigger_control"));
  o = {};
  o.exposure_and_readout = Duration::Milliseconds(-1);
  EXPECT_THAT(ValidationError(o), HasSubstr("exposure_and_readout"));
  o = {};
  o.reconnect_max_backoff = Duration::Milliseconds(10);
  EXPECT_THAT(ValidationError(o), HasSubstr("reconnect_max_backoff"));
  o = {};
  o.device = "";
  EXPECT_THAT(ValidationError(o), HasSubstr("V4l2CameraOptions.device"));
}

TEST(V4l2CameraOptionsTest, ConstructorValidatesFirst) {
  V4l2CameraOptions o;
  o.device = "/dev/video99";
  o.buffer_count = 100;
  EXPECT_THROW(V4l2Camera camera(o), std::invalid_argument);
}

TEST(V4l2CameraTest, MissingDeviceIsNamed) {
  V4l2CameraOptions o;
  o.device = "/dev/video99";
  EXPECT_THAT(StartupError(o),
              AllOf(HasSubstr("/dev/video99"), HasSubstr("cannot open"),
                    HasSubstr("V4L2 video capture"), HasSubstr("No such file or directory")));
}

TEST(V4l2CameraTest, NonVideoCharacterDeviceIsNotAV4l2Device) {
  V4l2CameraOptions o;
  o.device = "/dev/null";
  EXPECT_THAT(StartupError(o),
              AllOf(HasSubstr("/dev/null"), HasSubstr("not a V4L2 device"),
                    HasSubstr("VIDIOC_QUERYCAP"), HasSubstr("Inappropriate ioctl for device")));
}

TEST(V4l2CameraTest, RegularFileIsNotAV4l2Device) {
  const rover::testing::TempDir dir;
  const std::string path = dir.File("video0").string();
  std::ofstream(path) << "not a camera\n";
  V4l2CameraOptions o;
  o.device = path;
  EXPECT_THAT(StartupError(o), AllOf(HasSubstr(path), HasSubstr("not a V4L2 device")));
}

TEST(V4l2CameraTest, ControlNamesAreNormalisedLikeV4l2Ctl) {
  EXPECT_EQ(V4l2Camera::NormalizeControlName("Trigger Mode"), "trigger_mode");
  EXPECT_EQ(V4l2Camera::NormalizeControlName("trigger_mode"), "trigger_mode");
  EXPECT_EQ(V4l2Camera::NormalizeControlName("Inject V4L2_BUF_FLAG_ERROR"),
            "inject_v4l2_buf_flag_error");
  EXPECT_EQ(V4l2Camera::NormalizeControlName("  Gain, Automatic "), "gain_automatic");
  EXPECT_EQ(V4l2Camera::NormalizeControlName("Exposure Time, Absolute"), "exposure_time_absolute");
}

TEST(V4l2CameraTest, HealthHasNames) {
  EXPECT_STREQ(ToString(V4l2CameraHealth::kStreaming), "streaming");
  EXPECT_STREQ(ToString(V4l2CameraHealth::kDisconnected), "disconnected");
}

}  // namespace
}  // namespace rover::drivers
