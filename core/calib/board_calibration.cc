#include "core/calib/board_calibration.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <utility>

namespace rover::calib {
namespace {

// The `model` key's values.
constexpr std::string_view kRadTanName = "pinhole-radtan";
constexpr std::string_view kEquidistantName = "pinhole-equidistant";

std::string_view ModelName(DistortionModel model) {
  return model == DistortionModel::kEquidistant ? kEquidistantName : kRadTanName;
}

// Reads a T_ key as written: no re-orthonormalisation, so the file reads back
// bit for bit; a matrix that is not a rigid transform is an error at the key.
Eigen::Isometry3d ReadTransform(const ConfigNode& node, std::string_view key) {
  const Eigen::Matrix4d m = node.Get<Eigen::Matrix4d>(key);
  if (const std::optional<std::string> problem = RigidTransformProblem(m)) {
    node.Fail(key, *problem);
  }
  Eigen::Isometry3d T;
  T.matrix() = m;
  return T;
}

std::array<double, 4> ReadArray4(const ConfigNode& node, std::string_view key) {
  const Eigen::Vector4d v = node.Get<Eigen::Vector4d>(key);
  return {v(0), v(1), v(2), v(3)};
}

// Fails at the key the problem names, if there is one.
void FailOn(const ConfigNode& node, const std::optional<FieldProblem>& problem) {
  if (problem) node.Fail(problem->field, problem->message);
}

ImuCalibration LoadImu(const ConfigNode& n) {
  ImuCalibration c;
  c.rate_hz = n.Get<double>("rate_hz");
  c.gyro_noise_density_rad_s_sqrt_hz = n.Get<double>("gyro_noise_density_rad_s_sqrt_hz");
  c.gyro_random_walk_rad_s2_sqrt_hz = n.Get<double>("gyro_random_walk_rad_s2_sqrt_hz");
  c.accel_noise_density_m_s2_sqrt_hz = n.Get<double>("accel_noise_density_m_s2_sqrt_hz");
  c.accel_random_walk_m_s3_sqrt_hz = n.Get<double>("accel_random_walk_m_s3_sqrt_hz");
  c.T_body_imu = ReadTransform(n, "T_body_imu");
  FailOn(n, c.Problem());
  return c;
}

CameraModel LoadCamera(const ConfigNode& n) {
  CameraModel c;
  c.width_px = n.Get<int>("width_px");
  c.height_px = n.Get<int>("height_px");
  c.rate_hz = n.Get<double>("rate_hz");
  c.distortion_model =
      n.GetEnum<DistortionModel>("model", {{kRadTanName, DistortionModel::kRadialTangential},
                                           {kEquidistantName, DistortionModel::kEquidistant}});
  c.intrinsics = ReadArray4(n, "intrinsics");
  c.distortion = ReadArray4(n, "distortion");
  c.T_body_cam = ReadTransform(n, "T_body_cam");
  c.vignetting_cos4_strength = n.Get<double>("vignetting_cos4_strength", 0.0);
  FailOn(n, c.Problem());
  return c;
}

// Writes "key: value" lines at one indentation.
class YamlBlock {
 public:
  YamlBlock(std::string* out, std::size_t indent) : out_(out), indent_(indent, ' ') {}

  void Section(std::string_view key) { Line(key, ""); }
  void Put(std::string_view key, double value) { Line(key, " " + NumberText(value)); }
  void Put(std::string_view key, int value) { Line(key, " " + std::to_string(value)); }
  void Put(std::string_view key, std::string_view text) { Line(key, " " + std::string(text)); }
  void Put(std::string_view key, const std::array<double, 4>& v, std::string_view comment) {
    Line(key, " [" + NumberText(v[0]) + ", " + NumberText(v[1]) + ", " + NumberText(v[2]) + ", " +
                  NumberText(v[3]) + "]  # " + std::string(comment));
  }
  // A 4x4 transform as a flat row-major list, one matrix row per line.
  void Put(std::string_view key, const Eigen::Isometry3d& T) {
    const Eigen::Matrix4d& m = T.matrix();
    const std::string continuation(indent_.size() + key.size() + 3, ' ');
    std::string text = " [";
    for (int r = 0; r < 4; ++r) {
      if (r > 0) text += ",\n" + continuation;
      for (int c = 0; c < 4; ++c) text += (c > 0 ? ", " : "") + NumberText(m(r, c));
    }
    Line(key, text + "]");
  }

 private:
  void Line(std::string_view key, const std::string& value) {
    *out_ += indent_ + std::string(key) + ":" + value + "\n";
  }
  std::string* out_;
  std::string indent_;
};

void PutCamera(std::string* out, std::string_view name, const CameraModel& c) {
  YamlBlock(out, 2).Section(name);
  YamlBlock b(out, 4);
  b.Put("width_px", c.width_px);
  b.Put("height_px", c.height_px);
  b.Put("rate_hz", c.rate_hz);
  b.Put("model", ModelName(c.distortion_model));
  b.Put("intrinsics", c.intrinsics, "fu, fv, cu, cv [px]");
  b.Put("distortion", c.distortion,
        c.distortion_model == DistortionModel::kEquidistant ? "k1, k2, k3, k4" : "k1, k2, p1, p2");
  b.Put("T_body_cam", c.T_body_cam);
  if (c.vignetting_cos4_strength != 0.0) {
    b.Put("vignetting_cos4_strength", c.vignetting_cos4_strength);
  }
}

// Prefixes a problem's field with the section it is in.
std::optional<FieldProblem> In(std::string_view section, std::optional<FieldProblem> problem) {
  if (problem) problem->field = std::string(section) + "." + problem->field;
  return problem;
}

}  // namespace

BoardCalibration BoardCalibration::LoadFile(const std::string& path) {
  const ConfigNode root = ConfigNode::LoadFile(path);
  BoardCalibration c = Load(root);
  root.CheckNoUnknownKeysRecursive();
  return c;
}

BoardCalibration BoardCalibration::LoadString(std::string_view yaml, std::string source_name) {
  const ConfigNode root = ConfigNode::LoadString(yaml, std::move(source_name));
  BoardCalibration c = Load(root);
  root.CheckNoUnknownKeysRecursive();
  return c;
}

BoardCalibration BoardCalibration::Load(const ConfigNode& node) {
  const std::string format = node.Get<std::string>("format");
  if (format != kBoardCalibrationFormat) {
    node.Fail("format",
              "expected " + std::string(kBoardCalibrationFormat) + ", found '" + format + "'");
  }
  BoardCalibration c;
  c.imu = LoadImu(node.Child("imu"));
  if (node.Has("cameras")) {
    const ConfigNode cameras = node.Child("cameras");
    c.stereo =
        StereoCalibration{LoadCamera(cameras.Child("cam0")), LoadCamera(cameras.Child("cam1"))};
  }
  if (node.Has("wheels")) c.wheels = WheelCalibration::Load(node.Child("wheels"));
  return c;
}

std::string BoardCalibration::ToYaml() const {
  std::string out =
      "# rover board calibration (format 1). T_a_b maps points from frame b into a,\n"
      "# as 16 numbers row-major; body is the rover's body frame.\n";
  YamlBlock top(&out, 0);
  top.Put("format", kBoardCalibrationFormat);
  top.Section("imu");
  YamlBlock i(&out, 2);
  i.Put("rate_hz", imu.rate_hz);
  i.Put("gyro_noise_density_rad_s_sqrt_hz", imu.gyro_noise_density_rad_s_sqrt_hz);
  i.Put("gyro_random_walk_rad_s2_sqrt_hz", imu.gyro_random_walk_rad_s2_sqrt_hz);
  i.Put("accel_noise_density_m_s2_sqrt_hz", imu.accel_noise_density_m_s2_sqrt_hz);
  i.Put("accel_random_walk_m_s3_sqrt_hz", imu.accel_random_walk_m_s3_sqrt_hz);
  i.Put("T_body_imu", imu.T_body_imu);
  if (stereo) {
    top.Section("cameras");
    PutCamera(&out, "cam0", stereo->cam0);
    PutCamera(&out, "cam1", stereo->cam1);
  }
  if (wheels) {
    top.Section("wheels");
    out += wheels->ToYaml(2);
  }
  return out;
}

void BoardCalibration::SaveFile(const std::string& path) const {
  Validate();
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) {
      throw std::runtime_error(tmp + ": cannot create: " + std::strerror(errno));
    }
    out << ToYaml();
    out.close();
    if (!out) throw std::runtime_error(tmp + ": cannot write: " + std::strerror(errno));
  }
  std::error_code error;
  std::filesystem::rename(tmp, path, error);
  if (error) {
    std::filesystem::remove(tmp, error);
    throw std::runtime_error(path + ": cannot replace with " + tmp + ": " + error.message());
  }
}

std::optional<FieldProblem> BoardCalibration::Problem() const {
  if (auto p = In("imu", imu.Problem())) return p;
  if (stereo) {
    if (auto p = In("cameras.cam0", stereo->cam0.Problem())) return p;
    if (auto p = In("cameras.cam1", stereo->cam1.Problem())) return p;
  }
  if (wheels) {
    if (auto p = In("wheels", wheels->Problem())) return p;
  }
  return std::nullopt;
}

void BoardCalibration::Validate() const {
  if (const std::optional<FieldProblem> problem = Problem()) {
    throw std::invalid_argument(problem->field + ": " + problem->message);
  }
}

CameraModel CameraInImuFrame(const CameraModel& camera, const ImuCalibration& imu) {
  CameraModel c = camera;
  // The same expression as the boards and rover-eval used before, so the
  // VO's input (and every figure measured with it) stays bit for bit.
  const Eigen::Isometry3d T_imu_body = imu.T_body_imu.inverse();
  c.T_body_cam = T_imu_body * camera.T_body_cam;
  return c;
}

}  // namespace rover::calib
