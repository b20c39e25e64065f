#include "drivers/camera/v4l2_camera.h"

#include <fcntl.h>
#include <linux/videodev2.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <numeric>

#include "core/time/posix_time.h"

namespace rover::drivers {

static_assert(V4l2Camera::kMaxBuffers == VIDEO_MAX_FRAME);

namespace {

constexpr uint32_t kSinglePlanar = V4L2_BUF_TYPE_VIDEO_CAPTURE;
constexpr uint32_t kMultiPlanar = V4L2_BUF_TYPE_VIDEO_CAPTURE_MPLANE;
/// Buffer indices handed out are generation * kMaxBuffers + index; the
/// generation wraps here so the index stays a positive int.
constexpr uint32_t kGenerationMask = (1u << 20) - 1;
/// Relative tolerance of a negotiated frame rate.
constexpr double kFrameRateTolerance = 1e-3;

uint32_t CaptureType(bool multi_planar) { return multi_planar ? kMultiPlanar : kSinglePlanar; }

/// A v4l2_buffer for either capture API. The multi-planar API (the one most
/// SoC capture interfaces speak) describes every memory plane in its own
/// v4l2_plane; the camera takes single-plane formats only, so one is enough.
struct BufferRequest {
  v4l2_buffer buffer{};
  v4l2_plane plane{};

  BufferRequest(bool multi_planar, uint32_t index) {
    buffer.type = CaptureType(multi_planar);
    buffer.memory = V4L2_MEMORY_MMAP;
    buffer.index = index;
    if (multi_planar) {
      buffer.m.planes = &plane;
      buffer.length = 1;
    }
  }
  BufferRequest(const BufferRequest&) = delete;  // buffer points at plane
  BufferRequest& operator=(const BufferRequest&) = delete;

  bool multi_planar() const { return buffer.type == kMultiPlanar; }
  /// Bytes of the mapping.
  uint32_t length() const { return multi_planar() ? plane.length : buffer.length; }
  /// The mmap offset of the buffer.
  off_t map_offset() const {
    return static_cast<off_t>(multi_planar() ? plane.m.mem_offset : buffer.m.offset);
  }
  /// Where the image starts in the mapping, and its bytes: a multi-planar
  /// driver may put a header first (data_offset, included in bytesused).
  uint32_t data_offset() const { return multi_planar() ? plane.data_offset : 0u; }
  uint32_t bytes_used() const { return multi_planar() ? plane.bytesused : buffer.bytesused; }
};

/// A format request for the API in use: one plane, progressive.
v4l2_format FormatRequest(bool multi_planar, uint32_t fourcc, uint32_t width, uint32_t height) {
  v4l2_format format{};
  format.type = CaptureType(multi_planar);
  if (multi_planar) {
    format.fmt.pix_mp.width = width;
    format.fmt.pix_mp.height = height;
    format.fmt.pix_mp.pixelformat = fourcc;
    format.fmt.pix_mp.field = V4L2_FIELD_NONE;
    format.fmt.pix_mp.num_planes = 1;
  } else {
    format.fmt.pix.width = width;
    format.fmt.pix.height = height;
    format.fmt.pix.pixelformat = fourcc;
    format.fmt.pix.field = V4L2_FIELD_NONE;
  }
  return format;
}

/// A format of either API as the single-planar struct (plane 0's stride
/// and size), so negotiation and its messages need one form only.
v4l2_pix_format SinglePlaneView(const v4l2_format& format) {
  if (format.type != kMultiPlanar) return format.fmt.pix;
  const v4l2_pix_format_mplane& mp = format.fmt.pix_mp;
  v4l2_pix_format view{};
  view.width = mp.width;
  view.height = mp.height;
  view.pixelformat = mp.pixelformat;
  view.field = mp.field;
  view.bytesperline = mp.plane_fmt[0].bytesperline;
  view.sizeimage = mp.plane_fmt[0].sizeimage;
  view.colorspace = mp.colorspace;
  return view;
}

uint32_t PlaneCount(const v4l2_format& format) {
  return format.type == kMultiPlanar ? format.fmt.pix_mp.num_planes : 1u;
}

void Add(std::atomic<uint64_t>& counter, uint64_t n = 1) {
  counter.fetch_add(n, std::memory_order_relaxed);
}

/// ioctl that retries when a signal interrupted it.
int Ioctl(int fd, unsigned long request, void* arg) {
  int result = 0;
  do {
    result = ioctl(fd, request, arg);
  } while (result != 0 && errno == EINTR);
  return result;
}

/// Writes the normalised form of `name` (see NormalizeControlName) into
/// `out` of `out_size` bytes, without allocating.
void NormalizeInto(const char* name, char* out, std::size_t out_size) {
  std::size_t n = 0;
  bool pending_separator = false;
  for (const char* p = name; *p != '\0' && n + 1 < out_size; ++p) {
    const auto c = static_cast<unsigned char>(*p);
    if ((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9')) {
      if (pending_separator && n > 0 && n + 2 < out_size) out[n++] = '_';
      pending_separator = false;
      out[n++] = static_cast<char>(c);
    } else if (c >= 'A' && c <= 'Z') {
      if (pending_separator && n > 0 && n + 2 < out_size) out[n++] = '_';
      pending_separator = false;
      out[n++] = static_cast<char>(c - 'A' + 'a');
    } else {
      pending_separator = true;
    }
  }
  out[n] = '\0';
}

/// Control types that carry one scalar value.
bool IsScalar(const v4l2_query_ext_ctrl& q) {
  if ((q.flags & V4L2_CTRL_FLAG_HAS_PAYLOAD) != 0) return false;
  switch (q.type) {
    case V4L2_CTRL_TYPE_INTEGER:
    case V4L2_CTRL_TYPE_BOOLEAN:
    case V4L2_CTRL_TYPE_MENU:
    case V4L2_CTRL_TYPE_INTEGER_MENU:
    case V4L2_CTRL_TYPE_BUTTON:
    case V4L2_CTRL_TYPE_INTEGER64:
    case V4L2_CTRL_TYPE_BITMASK:
      return true;
    default:
      return false;
  }
}

/// The control `id` if the device has it enabled.
bool QueryControl(int fd, uint32_t id, v4l2_query_ext_ctrl* q) {
  *q = v4l2_query_ext_ctrl{};
  q->id = id;
  return Ioctl(fd, VIDIOC_QUERY_EXT_CTRL, q) == 0 && (q->flags & V4L2_CTRL_FLAG_DISABLED) == 0;
}

/// Walks every control; `visit` returns true to stop.
template <typename Visit>
void ForEachControl(int fd, Visit&& visit) {
  uint32_t id = V4L2_CTRL_FLAG_NEXT_CTRL | V4L2_CTRL_FLAG_NEXT_COMPOUND;
  for (int guard = 0; guard < 4096; ++guard) {
    v4l2_query_ext_ctrl q{};
    q.id = id;
    if (Ioctl(fd, VIDIOC_QUERY_EXT_CTRL, &q) != 0) return;
    id = q.id | V4L2_CTRL_FLAG_NEXT_CTRL | V4L2_CTRL_FLAG_NEXT_COMPOUND;
    if (q.type == V4L2_CTRL_TYPE_CTRL_CLASS || (q.flags & V4L2_CTRL_FLAG_DISABLED) != 0) continue;
    if (visit(q)) return;
  }
}

/// Finds an enabled control by its normalised name, without allocating.
bool FindControl(int fd, const char* normalized_name, v4l2_query_ext_ctrl* found) {
  bool hit = false;
  ForEachControl(fd, [&](const v4l2_query_ext_ctrl& q) {
    char name[sizeof q.name + 1];
    NormalizeInto(q.name, name, sizeof name);
    if (std::strcmp(name, normalized_name) != 0) return false;
    *found = q;
    hit = true;
    return true;
  });
  return hit;
}

bool WriteControl(int fd, const v4l2_query_ext_ctrl& q, int64_t value) {
  v4l2_ext_control c{};
  c.id = q.id;
  if (q.type == V4L2_CTRL_TYPE_INTEGER64) {
    c.value64 = value;
  } else {
    c.value = static_cast<int32_t>(value);
  }
  v4l2_ext_controls cs{};
  cs.which = V4L2_CTRL_WHICH_CUR_VAL;
  cs.count = 1;
  cs.controls = &c;
  return Ioctl(fd, VIDIOC_S_EXT_CTRLS, &cs) == 0;
}

bool ReadControl(int fd, const v4l2_query_ext_ctrl& q, int64_t* value) {
  v4l2_ext_control c{};
  c.id = q.id;
  v4l2_ext_controls cs{};
  cs.which = V4L2_CTRL_WHICH_CUR_VAL;
  cs.count = 1;
  cs.controls = &c;
  if (Ioctl(fd, VIDIOC_G_EXT_CTRLS, &cs) != 0) return false;
  *value = q.type == V4L2_CTRL_TYPE_INTEGER64 ? c.value64 : int64_t{c.value};
  return true;
}

/// The fraction of seconds per frame closest to 1 / `rate_hz`, in
/// thousandths of a frame per second (12.5 Hz -> 2/25 s).
v4l2_fract IntervalOf(double rate_hz) {
  const auto millihertz = static_cast<uint32_t>(std::llround(rate_hz * 1000.0));
  const uint32_t divisor = std::gcd(1000u, millihertz);
  return v4l2_fract{1000u / divisor, millihertz / divisor};
}

double RateOf(const v4l2_fract& interval) {
  return interval.numerator == 0
             ? 0.0
             : static_cast<double>(interval.denominator) / static_cast<double>(interval.numerator);
}

std::string FormatRate(double rate_hz) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", rate_hz);
  return text;
}

std::string SizeText(uint32_t width, uint32_t height) {
  return std::to_string(width) + "x" + std::to_string(height);
}

std::string ErrnoText(int error) {
  return std::string(std::strerror(error)) + " (errno " + std::to_string(error) + ")";
}

std::string CapabilityNames(uint32_t caps) {
  static constexpr struct {
    uint32_t bit;
    const char* name;
  } kNames[] = {{V4L2_CAP_VIDEO_CAPTURE, "video capture"},
                {V4L2_CAP_VIDEO_CAPTURE_MPLANE, "multi-planar video capture"},
                {V4L2_CAP_VIDEO_OUTPUT, "video output"},
                {V4L2_CAP_VIDEO_OUTPUT_MPLANE, "multi-planar video output"},
                {V4L2_CAP_VIDEO_M2M, "memory-to-memory"},
                {V4L2_CAP_VIDEO_M2M_MPLANE, "multi-planar memory-to-memory"},
                {V4L2_CAP_META_CAPTURE, "metadata capture"},
                {V4L2_CAP_VBI_CAPTURE, "VBI capture"},
                {V4L2_CAP_SDR_CAPTURE, "SDR capture"},
                {V4L2_CAP_TOUCH, "touch"},
                {V4L2_CAP_READWRITE, "read/write"},
                {V4L2_CAP_STREAMING, "streaming"}};
  std::string text;
  for (const auto& entry : kNames) {
    if ((caps & entry.bit) == 0) continue;
    if (!text.empty()) text += ", ";
    text += entry.name;
  }
  return text.empty() ? "none" : text;
}

/// "640x480 1280x720" or "16x16..1920x1080 step 2x2" for one format.
std::string ListSizes(int fd, uint32_t fourcc) {
  std::string text;
  for (uint32_t i = 0; i < 256; ++i) {
    v4l2_frmsizeenum s{};
    s.index = i;
    s.pixel_format = fourcc;
    if (Ioctl(fd, VIDIOC_ENUM_FRAMESIZES, &s) != 0) break;
    if (s.type == V4L2_FRMSIZE_TYPE_DISCRETE) {
      if (!text.empty()) text += " ";
      text += SizeText(s.discrete.width, s.discrete.height);
    } else {
      text = SizeText(s.stepwise.min_width, s.stepwise.min_height) + ".." +
             SizeText(s.stepwise.max_width, s.stepwise.max_height) + " step " +
             SizeText(s.stepwise.step_width, s.stepwise.step_height);
      break;
    }
  }
  return text.empty() ? "(sizes not listed)" : text;
}

/// "YUYV 320x180 640x480; GREY 640x480; ..." (VIDIOC_ENUM_FMT and
/// VIDIOC_ENUM_FRAMESIZES).
std::string ListFormats(int fd, bool multi_planar) {
  std::string text;
  for (uint32_t i = 0; i < 256; ++i) {
    v4l2_fmtdesc d{};
    d.index = i;
    d.type = CaptureType(multi_planar);
    if (Ioctl(fd, VIDIOC_ENUM_FMT, &d) != 0) break;
    if (!text.empty()) text += "; ";
    text += FourccToString(d.pixelformat) + " " + ListSizes(fd, d.pixelformat);
  }
  return text.empty() ? "no formats (VIDIOC_ENUM_FMT lists none)" : text;
}

/// "1, 2, 5, 15, 25 fps" for one format and size (VIDIOC_ENUM_FRAMEINTERVALS).
std::string ListRates(int fd, uint32_t fourcc, uint32_t width, uint32_t height) {
  std::string text;
  for (uint32_t i = 0; i < 256; ++i) {
    v4l2_frmivalenum f{};
    f.index = i;
    f.pixel_format = fourcc;
    f.width = width;
    f.height = height;
    if (Ioctl(fd, VIDIOC_ENUM_FRAMEINTERVALS, &f) != 0) break;
    if (f.type == V4L2_FRMIVAL_TYPE_DISCRETE) {
      if (!text.empty()) text += ", ";
      text += FormatRate(RateOf(f.discrete));
    } else {
      // Longest interval = lowest rate.
      text = FormatRate(RateOf(f.stepwise.max)) + ".." + FormatRate(RateOf(f.stepwise.min));
      break;
    }
  }
  return text.empty() ? "no frame intervals listed" : text + " fps";
}

std::string ListControlNames(int fd) {
  std::string text;
  ForEachControl(fd, [&](const v4l2_query_ext_ctrl& q) {
    if (!text.empty()) text += ", ";
    text += V4l2Camera::NormalizeControlName(q.name);
    return false;
  });
  return text.empty() ? "none" : text;
}

}  // namespace

/// Plain data: filled on the reopen path, which must not allocate.
struct V4l2Camera::StartFailure {
  enum class Step {
    kNone,
    kOpen,
    kQueryCap,
    kCapabilities,
    kInput,
    kFormat,
    kFormatMismatch,
    kStrideChanged,
    kNoFrameInterval,
    kFrameInterval,
    kFrameRateMismatch,
    kControlMissing,
    kControlRange,
    kControlRefused,
    kControlReadBack,
    kBuffers,
    kTooFewBuffers,
    kMap,
    kExport,
    kQueue,
    kStreamOn,
  };
  Step step = Step::kNone;
  int error = 0;                ///< errno of the failing call, 0 if none
  const char* call = "";        ///< the ioctl or call that failed
  uint32_t capabilities = 0;    ///< what QUERYCAP reported
  v4l2_pix_format got{};        ///< the format the driver proposed or set
  uint32_t got_planes = 1;      ///< its memory planes (multi-planar API)
  v4l2_fract got_interval{};    ///< the frame interval the driver set
  const char* control = "";     ///< the option behind the control
  const char* control_id = "";  ///< the V4L2 control it needs
  v4l2_query_ext_ctrl query{};  ///< the control's description
  int64_t value = 0;            ///< the value asked for
  int64_t read_back = 0;        ///< the value the device reports after writing
  uint32_t buffers = 0;         ///< buffers granted / the failing buffer's index
};

const char* ToString(V4l2CameraHealth health) {
  switch (health) {
    case V4l2CameraHealth::kStreaming:
      return "streaming";
    case V4l2CameraHealth::kDisconnected:
      return "disconnected";
  }
  return "unknown";
}

std::string V4l2Camera::NormalizeControlName(const std::string& name) {
  std::vector<char> out(name.size() * 2 + 2);
  NormalizeInto(name.c_str(), out.data(), out.size());
  return out.data();
}

V4l2Camera::V4l2Camera(const V4l2CameraOptions& options)
    : options_(options), backoff_(options.reconnect_initial_backoff) {
  options_.Validate();
  fourcc_ = FourccFromString(options_.pixel_format);
  trigger_control_normalized_ = NormalizeControlName(options_.trigger_control);
  StartFailure failure;
  if (!OpenAndStart(&failure)) {
    const std::string message = Describe(failure);
    StopAndClose();
    throw V4l2CameraError(message);
  }
  try {
    converter_ = std::make_unique<PixelFormatConverter>(
        fourcc_, options_.width_px, options_.height_px, bytes_per_line_, buffer_count_);
  } catch (const std::invalid_argument& e) {
    StopAndClose();
    throw V4l2CameraError("V4L2 camera " + options_.device + ": " + e.what());
  }
  startup_report_.push_back(
      FourccToString(fourcc_) + " " +
      SizeText(static_cast<uint32_t>(options_.width_px),
               static_cast<uint32_t>(options_.height_px)) +
      ", " + std::to_string(bytes_per_line_) + " bytes per line, " +
      (frame_rate_hz_ > 0.0 ? FormatRate(frame_rate_hz_) + " fps" : "frame rate unknown") + ", " +
      std::to_string(buffer_count_) + " mmap buffers" +
      (converter_->zero_copy() ? ", zero copy" : ", converted to 8-bit mono") +
      (converter_->real_time_safe() ? "" : " (MJPG decoding allocates: not real-time safe)"));
  if (options_.auto_exposure_off && !has_auto_exposure_control_) {
    startup_report_.push_back("auto exposure: " + options_.device +
                              " has no V4L2_CID_EXPOSURE_AUTO control: nothing to switch off");
  }
  if (options_.trigger_value.has_value() && !trigger_supported_) {
    startup_report_.push_back("trigger: " + options_.device + " has no control named '" +
                              trigger_control_normalized_ + "': not supported, trigger_value " +
                              std::to_string(*options_.trigger_value) +
                              " not applied (the camera free-runs)");
  }
}

V4l2Camera::~V4l2Camera() {
  StopAndClose();
  for (Buffer& b : buffers_) {
    if (b.mapped) munmap(b.start, b.length);
    b = Buffer{};
  }
}

bool V4l2Camera::OpenAndStart(StartFailure* failure) {
  fd_ = open(options_.device.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  if (fd_ < 0) {
    failure->step = StartFailure::Step::kOpen;
    failure->error = errno;
    failure->call = "open";
    return false;
  }
  v4l2_capability cap{};
  if (Ioctl(fd_, VIDIOC_QUERYCAP, &cap) != 0) {
    failure->step = StartFailure::Step::kQueryCap;
    failure->error = errno;
    failure->call = "VIDIOC_QUERYCAP";
    return false;
  }
  const uint32_t caps =
      (cap.capabilities & V4L2_CAP_DEVICE_CAPS) != 0 ? cap.device_caps : cap.capabilities;
  // The single-planar API where the device has it; otherwise the
  // multi-planar one, which many SoC (CSI-2) capture drivers offer alone.
  const bool capture = (caps & (V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_VIDEO_CAPTURE_MPLANE)) != 0;
  if (!capture || (caps & V4L2_CAP_STREAMING) == 0) {
    failure->step = StartFailure::Step::kCapabilities;
    failure->capabilities = caps;
    return false;
  }
  multi_planar_ = (caps & V4L2_CAP_VIDEO_CAPTURE) == 0;
  if (options_.input.has_value()) {
    int input = *options_.input;
    if (Ioctl(fd_, VIDIOC_S_INPUT, &input) != 0) {
      failure->step = StartFailure::Step::kInput;
      failure->error = errno;
      failure->call = "VIDIOC_S_INPUT";
      return false;
    }
  }
  if (!Negotiate(failure) || !ApplyControls(failure) || !StartBuffers(failure)) return false;
  generation_ = (generation_ + 1) & kGenerationMask;
  have_sequence_ = false;
  return true;
}

bool V4l2Camera::Negotiate(StartFailure* failure) {
  const uint32_t width = static_cast<uint32_t>(options_.width_px);
  const uint32_t height = static_cast<uint32_t>(options_.height_px);
  v4l2_format format = FormatRequest(multi_planar_, fourcc_, width, height);
  auto exact = [&](const v4l2_format& f) {
    const v4l2_pix_format got = SinglePlaneView(f);
    return got.pixelformat == fourcc_ && got.width == width && got.height == height &&
           got.field == V4L2_FIELD_NONE && PlaneCount(f) == 1;
  };
  auto mismatch = [&](const v4l2_format& f) {
    failure->step = StartFailure::Step::kFormatMismatch;
    failure->got = SinglePlaneView(f);
    failure->got_planes = PlaneCount(f);
    return false;
  };
  // TRY_FMT first: a refused request then leaves the device as it was.
  // It is optional for drivers (ENOTTY): S_FMT's answer is checked anyway.
  v4l2_format trial = format;
  if (Ioctl(fd_, VIDIOC_TRY_FMT, &trial) == 0) {
    if (!exact(trial)) return mismatch(trial);
  } else if (errno != ENOTTY) {
    failure->step = StartFailure::Step::kFormat;
    failure->error = errno;
    failure->call = "VIDIOC_TRY_FMT";
    return false;
  }
  if (Ioctl(fd_, VIDIOC_S_FMT, &format) != 0) {
    failure->step = StartFailure::Step::kFormat;
    failure->error = errno;
    failure->call = "VIDIOC_S_FMT";
    return false;
  }
  if (!exact(format)) return mismatch(format);
  const v4l2_pix_format set = SinglePlaneView(format);
  // Some drivers leave bytesperline at 0 for packed formats: a tight row.
  std::size_t bytes_per_line = set.bytesperline;
  if (bytes_per_line == 0 && fourcc_ != V4L2_PIX_FMT_MJPEG) {
    bytes_per_line =
        static_cast<std::size_t>(options_.width_px) * (fourcc_ == V4L2_PIX_FMT_GREY ? 1u : 2u);
  }
  // After a reconnect the preallocated conversion must still fit.
  if (bytes_per_line_ != 0 && bytes_per_line != bytes_per_line_) {
    failure->step = StartFailure::Step::kStrideChanged;
    failure->got = set;
    return false;
  }
  bytes_per_line_ = bytes_per_line;
  size_image_ = set.sizeimage;

  v4l2_streamparm parm{};
  parm.type = CaptureType(multi_planar_);
  const bool has_parm = Ioctl(fd_, VIDIOC_G_PARM, &parm) == 0;
  const bool settable = has_parm && (parm.parm.capture.capability & V4L2_CAP_TIMEPERFRAME) != 0;
  if (options_.frame_rate_hz.has_value()) {
    if (!settable) {
      failure->step = StartFailure::Step::kNoFrameInterval;
      failure->error = has_parm ? 0 : errno;
      failure->call = "VIDIOC_G_PARM";
      return false;
    }
    parm = v4l2_streamparm{};
    parm.type = CaptureType(multi_planar_);
    parm.parm.capture.timeperframe = IntervalOf(*options_.frame_rate_hz);
    if (Ioctl(fd_, VIDIOC_S_PARM, &parm) != 0) {
      failure->step = StartFailure::Step::kFrameInterval;
      failure->error = errno;
      failure->call = "VIDIOC_S_PARM";
      return false;
    }
    const double got = RateOf(parm.parm.capture.timeperframe);
    if (std::fabs(got - *options_.frame_rate_hz) > kFrameRateTolerance * *options_.frame_rate_hz) {
      failure->step = StartFailure::Step::kFrameRateMismatch;
      failure->got_interval = parm.parm.capture.timeperframe;
      return false;
    }
  }
  frame_rate_hz_ =
      has_parm || options_.frame_rate_hz.has_value() ? RateOf(parm.parm.capture.timeperframe) : 0.0;
  return true;
}

bool V4l2Camera::ApplyControls(StartFailure* failure) {
  // Writes `value` to `q` after a range check and reads it back.
  auto set = [&](const char* option, const char* control_id, const v4l2_query_ext_ctrl& q,
                 int64_t value) {
    failure->control = option;
    failure->control_id = control_id;
    failure->query = q;
    failure->value = value;
    if (q.type != V4L2_CTRL_TYPE_BUTTON && (value < q.minimum || value > q.maximum)) {
      failure->step = StartFailure::Step::kControlRange;
      return false;
    }
    if (!WriteControl(fd_, q, value)) {
      failure->step = StartFailure::Step::kControlRefused;
      failure->error = errno;
      failure->call = "VIDIOC_S_EXT_CTRLS";
      return false;
    }
    if ((q.flags & V4L2_CTRL_FLAG_WRITE_ONLY) != 0 || q.type == V4L2_CTRL_TYPE_BUTTON) return true;
    int64_t read_back = 0;
    if (!ReadControl(fd_, q, &read_back) || read_back != value) {
      failure->step = StartFailure::Step::kControlReadBack;
      failure->read_back = read_back;
      return false;
    }
    return true;
  };
  auto missing = [&](const char* option, const char* control_id, int64_t value) {
    failure->step = StartFailure::Step::kControlMissing;
    failure->control = option;
    failure->control_id = control_id;
    failure->value = value;
    return false;
  };
  v4l2_query_ext_ctrl q{};
  const bool manual_exposure = options_.auto_exposure_off || options_.exposure.has_value() ||
                               options_.exposure_raw.has_value();
  has_auto_exposure_control_ = QueryControl(fd_, V4L2_CID_EXPOSURE_AUTO, &q);
  if (manual_exposure && has_auto_exposure_control_ &&
      !set("auto_exposure_off", "V4L2_CID_EXPOSURE_AUTO", q, V4L2_EXPOSURE_MANUAL)) {
    return false;
  }
  if (options_.exposure.has_value()) {
    // V4L2_CID_EXPOSURE_ABSOLUTE counts 100 us.
    const int64_t value = (options_.exposure->nanoseconds() + 50'000) / 100'000;
    if (!QueryControl(fd_, V4L2_CID_EXPOSURE_ABSOLUTE, &q)) {
      return missing("exposure", "V4L2_CID_EXPOSURE_ABSOLUTE", value);
    }
    if (!set("exposure", "V4L2_CID_EXPOSURE_ABSOLUTE", q, value)) return false;
  }
  if (options_.exposure_raw.has_value()) {
    if (!QueryControl(fd_, V4L2_CID_EXPOSURE, &q)) {
      return missing("exposure_raw", "V4L2_CID_EXPOSURE", *options_.exposure_raw);
    }
    if (!set("exposure_raw", "V4L2_CID_EXPOSURE", q, *options_.exposure_raw)) return false;
  }
  if (options_.gain.has_value()) {
    // Automatic gain owns the gain control (it is read-only or volatile
    // while on): switch it off first.
    if (QueryControl(fd_, V4L2_CID_AUTOGAIN, &q) && !set("gain", "V4L2_CID_AUTOGAIN", q, 0))
      return false;
    if (!QueryControl(fd_, V4L2_CID_GAIN, &q))
      return missing("gain", "V4L2_CID_GAIN", *options_.gain);
    if (!set("gain", "V4L2_CID_GAIN", q, *options_.gain)) return false;
  }
  if (options_.trigger_value.has_value()) {
    trigger_supported_ = FindControl(fd_, trigger_control_normalized_.c_str(), &q);
    if (!trigger_supported_) {
      if (options_.trigger_required) {
        return missing("trigger_value", trigger_control_normalized_.c_str(),
                       *options_.trigger_value);
      }
    } else if (!set("trigger_value", trigger_control_normalized_.c_str(), q,
                    *options_.trigger_value)) {
      return false;
    }
  }
  return true;
}

bool V4l2Camera::StartBuffers(StartFailure* failure) {
  v4l2_requestbuffers request{};
  request.count = static_cast<uint32_t>(options_.buffer_count);
  request.type = CaptureType(multi_planar_);
  request.memory = V4L2_MEMORY_MMAP;
  if (Ioctl(fd_, VIDIOC_REQBUFS, &request) != 0) {
    failure->step = StartFailure::Step::kBuffers;
    failure->error = errno;
    failure->call = "VIDIOC_REQBUFS";
    return false;
  }
  // After a reconnect the converter has one image per buffer of the first
  // start: more buffers than that cannot be converted.
  const uint32_t limit = buffer_count_ > 0 ? static_cast<uint32_t>(buffer_count_) : kMaxBuffers;
  if (request.count < 2 || request.count > limit) {
    failure->step = StartFailure::Step::kTooFewBuffers;
    failure->buffers = request.count;
    return false;
  }
  for (uint32_t i = 0; i < request.count; ++i) {
    Buffer& b = buffers_[i];
    BufferRequest query(multi_planar_, i);
    failure->buffers = i;
    if (Ioctl(fd_, VIDIOC_QUERYBUF, &query.buffer) != 0) {
      failure->step = StartFailure::Step::kMap;
      failure->error = errno;
      failure->call = "VIDIOC_QUERYBUF";
      return false;
    }
    // Capture buffers are only read: PROT_READ is all vb2 asks for.
    void* start = mmap(nullptr, query.length(), PROT_READ, MAP_SHARED, fd_, query.map_offset());
    if (start == MAP_FAILED) {
      failure->step = StartFailure::Step::kMap;
      failure->error = errno;
      failure->call = "mmap";
      return false;
    }
    b.start = start;
    b.length = query.length();
    b.mapped = true;
    b.held = false;
    if (options_.export_dmabuf) {
      v4l2_exportbuffer e{};
      e.type = CaptureType(multi_planar_);
      e.index = i;
      e.plane = 0;
      e.flags = O_RDONLY | O_CLOEXEC;
      if (Ioctl(fd_, VIDIOC_EXPBUF, &e) != 0) {
        failure->step = StartFailure::Step::kExport;
        failure->error = errno;
        failure->call = "VIDIOC_EXPBUF";
        return false;
      }
      b.dmabuf_fd = e.fd;
    }
  }
  buffer_count_ = static_cast<int>(request.count);
  for (uint32_t i = 0; i < request.count; ++i) {
    BufferRequest buffer(multi_planar_, i);
    if (Ioctl(fd_, VIDIOC_QBUF, &buffer.buffer) != 0) {
      failure->step = StartFailure::Step::kQueue;
      failure->error = errno;
      failure->call = "VIDIOC_QBUF";
      failure->buffers = i;
      return false;
    }
  }
  int type = static_cast<int>(CaptureType(multi_planar_));
  if (Ioctl(fd_, VIDIOC_STREAMON, &type) != 0) {
    failure->step = StartFailure::Step::kStreamOn;
    failure->error = errno;
    failure->call = "VIDIOC_STREAMON";
    return false;
  }
  return true;
}

void V4l2Camera::StopAndClose() {
  if (fd_ >= 0) {
    int type = static_cast<int>(CaptureType(multi_planar_));
    Ioctl(fd_, VIDIOC_STREAMOFF, &type);
  }
  for (Buffer& b : buffers_) {
    if (b.dmabuf_fd >= 0) close(b.dmabuf_fd);
    b.dmabuf_fd = -1;
    // A held frame keeps its memory until Release(): the mapping holds its
    // own reference to the buffer, independent of the closed descriptor.
    if (b.mapped && !b.held) {
      munmap(b.start, b.length);
      b.mapped = false;
      b.start = nullptr;
      b.length = 0;
    }
  }
  if (fd_ >= 0) close(fd_);
  fd_ = -1;
  have_sequence_ = false;
}

std::string V4l2Camera::Describe(const StartFailure& f) const {
  using Step = StartFailure::Step;
  const std::string prefix = "V4L2 camera " + options_.device + ": ";
  const std::string asked =
      FourccToString(fourcc_) + " " +
      SizeText(static_cast<uint32_t>(options_.width_px), static_cast<uint32_t>(options_.height_px));
  // Listings come from the open descriptor, or a fresh one once it is gone.
  int fd = fd_;
  if (fd < 0) fd = open(options_.device.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
  struct Closer {
    int fd;
    bool own;
    ~Closer() {
      if (own && fd >= 0) close(fd);
    }
  } closer{fd, fd != fd_};
  auto controls = [&] { return "; the device's controls: " + ListControlNames(fd); };
  switch (f.step) {
    case Step::kNone:
      return prefix + "start-up failed for an unknown reason";
    case Step::kOpen:
      return prefix + "cannot open the device node (expected a V4L2 video capture device): " +
             (f.error == ENOENT ? "no such file (is the camera connected and its driver loaded?) "
                                : "") +
             ErrnoText(f.error);
    case Step::kQueryCap:
      return prefix + "not a V4L2 device: expected VIDIOC_QUERYCAP to succeed, it failed with " +
             ErrnoText(f.error);
    case Step::kCapabilities:
      return prefix + "expected a video capture device with streaming I/O " +
             "(V4L2_CAP_VIDEO_CAPTURE or V4L2_CAP_VIDEO_CAPTURE_MPLANE, and "
             "V4L2_CAP_STREAMING), found: " +
             CapabilityNames(f.capabilities);
    case Step::kInput: {
      std::string inputs;
      for (uint32_t i = 0; i < 64; ++i) {
        v4l2_input in{};
        in.index = i;
        if (fd < 0 || Ioctl(fd, VIDIOC_ENUMINPUT, &in) != 0) break;
        inputs += (inputs.empty() ? "" : ", ") + std::to_string(i) + " '" +
                  reinterpret_cast<const char*>(in.name) + "'";
      }
      return prefix + "cannot select input " + std::to_string(*options_.input) + " (" + f.call +
             ": " + ErrnoText(f.error) +
             "); the device's inputs: " + (inputs.empty() ? "none listed" : inputs);
    }
    case Step::kFormat:
      return prefix + "format " + asked + " refused (" + f.call + ": " + ErrnoText(f.error) +
             "); the device offers: " +
             (fd >= 0 ? ListFormats(fd, multi_planar_) : "(cannot list)");
    case Step::kFormatMismatch:
      return prefix + "format " + asked + " progressive is not available: the driver proposed " +
             FourccToString(f.got.pixelformat) + " " + SizeText(f.got.width, f.got.height) +
             (f.got.field == V4L2_FIELD_NONE
                  ? ""
                  : " (field " + std::to_string(f.got.field) + ", not progressive)") +
             (f.got_planes == 1 ? ""
                                : " in " + std::to_string(f.got_planes) +
                                      " memory planes (expected one: single-plane formats only)") +
             "; the device offers: " + (fd >= 0 ? ListFormats(fd, multi_planar_) : "(cannot list)");
    case Step::kStrideChanged:
      return prefix + "after reopening, " + asked + " has " + std::to_string(f.got.bytesperline) +
             " bytes per line instead of " + std::to_string(bytes_per_line_);
    case Step::kNoFrameInterval:
      return prefix + "frame rate " + FormatRate(*options_.frame_rate_hz) +
             " fps asked for, but the device has no settable frame interval "
             "(V4L2_CAP_TIMEPERFRAME" +
             (f.error != 0 ? ", VIDIOC_G_PARM: " + ErrnoText(f.error) : std::string()) + ")";
    case Step::kFrameInterval:
      return prefix + "frame rate " + FormatRate(*options_.frame_rate_hz) + " fps refused (" +
             f.call + ": " + ErrnoText(f.error) + "); " + asked + " offers " +
             (fd >= 0 ? ListRates(fd, fourcc_, static_cast<uint32_t>(options_.width_px),
                                  static_cast<uint32_t>(options_.height_px))
                      : "(cannot list)");
    case Step::kFrameRateMismatch:
      return prefix + "frame rate " + FormatRate(*options_.frame_rate_hz) +
             " fps is not available for " + asked + ": the device set " +
             FormatRate(RateOf(f.got_interval)) + " fps; it offers " +
             (fd >= 0 ? ListRates(fd, fourcc_, static_cast<uint32_t>(options_.width_px),
                                  static_cast<uint32_t>(options_.height_px))
                      : "(cannot list)");
    case Step::kControlMissing:
      return prefix + std::string(f.control) + " " + std::to_string(f.value) +
             " asked for, but the device has no " + f.control_id + " control" +
             (fd >= 0 ? controls() : std::string());
    case Step::kControlRange:
      return prefix + f.control + ": expected a value of " + f.control_id + " in its range " +
             std::to_string(f.query.minimum) + ".." + std::to_string(f.query.maximum) + " (step " +
             std::to_string(f.query.step) + "), found " + std::to_string(f.value);
    case Step::kControlRefused:
      return prefix + f.control + ": the device refused " + f.control_id + " = " +
             std::to_string(f.value) + " (" + f.call + ": " + ErrnoText(f.error) + ")";
    case Step::kControlReadBack:
      return prefix + f.control + ": wrote " + f.control_id + " = " + std::to_string(f.value) +
             ", expected to read it back, found " + std::to_string(f.read_back);
    case Step::kBuffers:
      return prefix + "cannot allocate " + std::to_string(options_.buffer_count) +
             " mmap capture buffers (" + f.call + ": " + ErrnoText(f.error) + ")";
    case Step::kTooFewBuffers:
      return prefix + "asked for " + std::to_string(options_.buffer_count) +
             " mmap capture buffers, expected the driver to grant 2 to " +
             std::to_string(buffer_count_ > 0 ? buffer_count_ : kMaxBuffers) + ", found " +
             std::to_string(f.buffers);
    case Step::kMap:
    case Step::kExport:
    case Step::kQueue:
      return prefix + "capture buffer " + std::to_string(f.buffers) + ": " + f.call +
             " failed: " + ErrnoText(f.error);
    case Step::kStreamOn:
      return prefix + "cannot start streaming (" + std::string(f.call) + ": " + ErrnoText(f.error) +
             ")";
  }
  return prefix + "start-up failed";
}

void V4l2Camera::MarkDisconnected(int error) {
  Add(disconnects_);
  last_errno_.store(error, std::memory_order_relaxed);
  health_.store(V4l2CameraHealth::kDisconnected, std::memory_order_relaxed);
  StopAndClose();
  backoff_ = options_.reconnect_initial_backoff;
  next_reconnect_ = Time::Now() + backoff_;
}

bool V4l2Camera::WaitAndReconnect(Time deadline) {
  // Reopening needs every old frame back: their buffers' mappings would
  // otherwise clash with the new stream's buffer indices.
  if (!options_.reconnect || held_count_ > 0) {
    SleepUntil(deadline);
    return false;
  }
  SleepUntil(std::min(deadline, next_reconnect_));
  if (Time::Now() < next_reconnect_) return false;
  Add(reconnect_attempts_);
  StartFailure failure;
  if (OpenAndStart(&failure)) {
    Add(reconnects_);
    backoff_ = options_.reconnect_initial_backoff;
    health_.store(V4l2CameraHealth::kStreaming, std::memory_order_relaxed);
    return true;
  }
  if (failure.error != 0) last_errno_.store(failure.error, std::memory_order_relaxed);
  StopAndClose();
  backoff_ = std::min(backoff_ * 2, options_.reconnect_max_backoff);
  next_reconnect_ = Time::Now() + backoff_;
  return false;
}

bool V4l2Camera::Queue(uint32_t index) {
  BufferRequest request(multi_planar_, index);
  if (Ioctl(fd_, VIDIOC_QBUF, &request.buffer) == 0) return true;
  MarkDisconnected(errno);
  return false;
}

V4l2Camera::Dequeued V4l2Camera::DequeueOne(CameraFrame* frame, bool poll_error) {
  BufferRequest request(multi_planar_, 0);
  const v4l2_buffer& buffer = request.buffer;
  if (Ioctl(fd_, VIDIOC_DQBUF, &request.buffer) != 0) {
    if (errno != EAGAIN) {
      MarkDisconnected(errno);  // ENODEV: gone; EIO: the stream failed; EPIPE: it ended
      return Dequeued::kFailed;
    }
    // poll() flagged an error (an unregistered device, a queue in error)
    // yet nothing can be dequeued: the stream will not recover by itself.
    if (poll_error) {
      MarkDisconnected(EIO);
      return Dequeued::kFailed;
    }
    return Dequeued::kEmpty;
  }
  const Time dequeued = Time::Now();
  if (buffer.index >= static_cast<uint32_t>(buffer_count_)) {
    MarkDisconnected(EINVAL);
    return Dequeued::kFailed;
  }
  Buffer& slot = buffers_[buffer.index];
  // A buffer that is not delivered is a lost frame: the next frame's
  // sequence gap counts it. When it is the first of its stream there is no
  // gap to show it, so it becomes the reference the next frame counts from.
  auto skip = [&](std::atomic<uint64_t>& counter) {
    Add(counter);
    if (!have_sequence_) {
      if (!have_any_frame_) last_sequence_ = uint64_t{buffer.sequence} - 1;
      last_raw_sequence_ = buffer.sequence - 1;
      have_sequence_ = true;
    }
    return Queue(buffer.index) ? Dequeued::kSkipped : Dequeued::kFailed;
  };
  if ((buffer.flags & V4L2_BUF_FLAG_ERROR) != 0) return skip(error_buffers_);
  const uint32_t offset = request.data_offset();
  const uint32_t used = request.bytes_used();
  if (offset > used || used > slot.length || used - offset < converter_->min_frame_bytes()) {
    return skip(short_buffers_);
  }
  ImageView image;
  if (!converter_->Convert(static_cast<const uint8_t*>(slot.start) + offset, used - offset,
                           static_cast<int>(buffer.index), &image)) {
    return skip(decode_errors_);
  }

  // Sequence: 32 bits from the driver, extended; gaps are lost frames.
  uint64_t sequence = 0;
  uint32_t dropped = 0;
  if (!have_sequence_) {
    // The first frame of a stream: no gap is known (before it there was no
    // stream, or an outage of unknown length).
    sequence = have_any_frame_ ? last_sequence_ + 1 : buffer.sequence;
  } else {
    const uint32_t delta = buffer.sequence - last_raw_sequence_;
    if (delta == 0 || delta > 0x8000'0000u) {
      Add(sequence_resets_);
      sequence = last_sequence_ + 1;
    } else {
      sequence = last_sequence_ + delta;
      dropped = delta - 1;
    }
  }
  have_sequence_ = true;
  last_raw_sequence_ = buffer.sequence;
  last_sequence_ = sequence;

  // Stamp: start of exposure on CLOCK_MONOTONIC (see the header).
  int64_t stamp_ns =
      int64_t{buffer.timestamp.tv_sec} * 1'000'000'000 + int64_t{buffer.timestamp.tv_usec} * 1'000;
  bool end_of_frame =
      (buffer.flags & V4L2_BUF_FLAG_TSTAMP_SRC_MASK) != V4L2_BUF_FLAG_TSTAMP_SRC_SOE;
  if ((buffer.flags & V4L2_BUF_FLAG_TIMESTAMP_MASK) != V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC) {
    Add(foreign_clock_stamps_);
    stamp_ns = dequeued.nanoseconds();
    end_of_frame = true;
  }
  if (end_of_frame) {
    Add(end_of_frame_stamps_);
    stamp_ns -= options_.exposure_and_readout.nanoseconds();
  }
  const Time stamp = Time::FromNanoseconds(stamp_ns);
  if (have_any_frame_ && stamp <= last_stamp_) Add(backward_stamps_);
  have_any_frame_ = true;
  last_stamp_ = stamp;

  slot.held = true;
  slot.generation = generation_;
  ++held_count_;
  frame->stamp = stamp;
  frame->sequence = sequence;
  frame->dropped_before = dropped;
  frame->image = image;
  frame->buffer_index =
      static_cast<int>(generation_ * static_cast<uint32_t>(kMaxBuffers) + buffer.index);
  Add(frames_);
  if (dropped > 0) Add(dropped_frames_, dropped);
  const int64_t handover_ns = (Time::Now() - dequeued).nanoseconds();
  last_handover_ns_.store(handover_ns, std::memory_order_relaxed);
  if (handover_ns > max_handover_ns_.load(std::memory_order_relaxed)) {
    max_handover_ns_.store(handover_ns, std::memory_order_relaxed);
  }
  return Dequeued::kFrame;
}

ReadStatus V4l2Camera::Next(CameraFrame* frame, Duration timeout) {
  const Time deadline = Time::Now() + std::max(timeout, Duration::Zero());
  bool poll_error = false;
  for (;;) {
    if (fd_ < 0) {
      if (!WaitAndReconnect(deadline)) {
        if (Time::Now() >= deadline) {
          Add(errors_);
          return ReadStatus::kError;
        }
        continue;
      }
      poll_error = false;
    }
    switch (DequeueOne(frame, poll_error)) {
      case Dequeued::kFrame:
        return ReadStatus::kOk;
      case Dequeued::kSkipped:
        poll_error = false;
        continue;
      case Dequeued::kFailed:
        continue;  // disconnected: reopen within the time left
      case Dequeued::kEmpty:
        break;
    }
    const Duration left = deadline - Time::Now();
    if (left <= Duration::Zero()) {
      Add(timeouts_);
      return ReadStatus::kTimeout;
    }
    pollfd p{fd_, POLLIN, 0};
    const timespec ts = ToTimespec(left);
    const int ready = ppoll(&p, 1, &ts, nullptr);
    if (ready < 0 && errno != EINTR) {
      MarkDisconnected(errno);
      continue;
    }
    poll_error = ready > 0 && (p.revents & (POLLERR | POLLHUP | POLLNVAL)) != 0;
  }
}

void V4l2Camera::Release(const CameraFrame& frame) {
  if (frame.buffer_index < 0) {
    Add(bad_releases_);
    return;
  }
  const auto encoded = static_cast<uint32_t>(frame.buffer_index);
  const uint32_t index = encoded % static_cast<uint32_t>(kMaxBuffers);
  const uint32_t generation = encoded / static_cast<uint32_t>(kMaxBuffers);
  Buffer& slot = buffers_[index];
  if (!slot.held || slot.generation != generation) {
    Add(bad_releases_);
    return;
  }
  slot.held = false;
  --held_count_;
  if (fd_ < 0 || slot.generation != generation_) {
    // From a stream that is gone: nothing to requeue, just unmap.
    if (slot.mapped) munmap(slot.start, slot.length);
    slot = Buffer{};
    return;
  }
  Queue(index);
}

int V4l2Camera::dmabuf_fd(int buffer_index) const {
  if (fd_ < 0 || buffer_index < 0) return -1;
  return buffers_[static_cast<uint32_t>(buffer_index) % static_cast<uint32_t>(kMaxBuffers)]
      .dmabuf_fd;
}

V4l2CameraStats V4l2Camera::stats() const {
  auto get = [](const std::atomic<uint64_t>& c) { return c.load(std::memory_order_relaxed); };
  V4l2CameraStats s;
  s.frames = get(frames_);
  s.timeouts = get(timeouts_);
  s.errors = get(errors_);
  s.dropped_frames = get(dropped_frames_);
  s.error_buffers = get(error_buffers_);
  s.short_buffers = get(short_buffers_);
  s.decode_errors = get(decode_errors_);
  s.sequence_resets = get(sequence_resets_);
  s.foreign_clock_stamps = get(foreign_clock_stamps_);
  s.backward_stamps = get(backward_stamps_);
  s.end_of_frame_stamps = get(end_of_frame_stamps_);
  s.disconnects = get(disconnects_);
  s.reconnect_attempts = get(reconnect_attempts_);
  s.reconnects = get(reconnects_);
  s.bad_releases = get(bad_releases_);
  s.last_errno = last_errno_.load(std::memory_order_relaxed);
  s.last_handover_ns = last_handover_ns_.load(std::memory_order_relaxed);
  s.max_handover_ns = max_handover_ns_.load(std::memory_order_relaxed);
  return s;
}

std::vector<V4l2ControlInfo> V4l2Camera::ListControls() const {
  if (fd_ < 0)
    throw V4l2CameraError("V4L2 camera " + options_.device +
                          ": cannot list controls: disconnected");
  std::vector<V4l2ControlInfo> list;
  ForEachControl(fd_, [&](const v4l2_query_ext_ctrl& q) {
    V4l2ControlInfo info;
    info.id = q.id;
    info.name = NormalizeControlName(q.name);
    info.type = q.type;
    info.minimum = q.minimum;
    info.maximum = q.maximum;
    info.step = q.step;
    info.default_value = q.default_value;
    info.flags = q.flags;
    list.push_back(std::move(info));
    return false;
  });
  return list;
}

std::optional<int64_t> V4l2Camera::GetControl(const std::string& name) const {
  if (fd_ < 0) return std::nullopt;
  v4l2_query_ext_ctrl q{};
  if (!FindControl(fd_, NormalizeControlName(name).c_str(), &q) || !IsScalar(q) ||
      (q.flags & V4L2_CTRL_FLAG_WRITE_ONLY) != 0) {
    return std::nullopt;
  }
  int64_t value = 0;
  if (!ReadControl(fd_, q, &value)) return std::nullopt;
  return value;
}

int64_t V4l2Camera::SetControl(const std::string& name, int64_t value) {
  const std::string prefix = "V4L2 camera " + options_.device + ": control '" +
                             NormalizeControlName(name) + "' = " + std::to_string(value) + ": ";
  if (fd_ < 0) throw V4l2CameraError(prefix + "the device is disconnected");
  v4l2_query_ext_ctrl q{};
  if (!FindControl(fd_, NormalizeControlName(name).c_str(), &q)) {
    throw V4l2CameraError(prefix +
                          "no such control; the device's controls: " + ListControlNames(fd_));
  }
  if (!IsScalar(q))
    throw V4l2CameraError(prefix + "expected a scalar control, found a compound or array one");
  if ((q.flags & V4L2_CTRL_FLAG_READ_ONLY) != 0)
    throw V4l2CameraError(prefix + "the control is read-only");
  if (q.type != V4L2_CTRL_TYPE_BUTTON && (value < q.minimum || value > q.maximum)) {
    throw V4l2CameraError(prefix + "expected a value in " + std::to_string(q.minimum) + ".." +
                          std::to_string(q.maximum) + " (step " + std::to_string(q.step) + ")");
  }
  if (!WriteControl(fd_, q, value)) {
    throw V4l2CameraError(prefix + "refused (VIDIOC_S_EXT_CTRLS: " + ErrnoText(errno) + ")");
  }
  if ((q.flags & V4L2_CTRL_FLAG_WRITE_ONLY) != 0 || q.type == V4L2_CTRL_TYPE_BUTTON) return value;
  int64_t read_back = 0;
  if (!ReadControl(fd_, q, &read_back)) {
    throw V4l2CameraError(prefix + "cannot read it back (VIDIOC_G_EXT_CTRLS: " + ErrnoText(errno) +
                          ")");
  }
  return read_back;
}

}  // namespace rover::drivers
