#include "hil/sim/dataset/euroc_writer.h"

#include <opencv2/imgcodecs.hpp>

#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "core/calib/euroc_sensor_yaml.h"

namespace rover::sim {
namespace {

namespace fs = std::filesystem;
using drivers::DatasetError;

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

std::string Stamp(Time t) { return std::to_string(t.nanoseconds()); }

std::ofstream OpenCsv(const fs::path& path, const char* header) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw DatasetError(path.string() + ": cannot create");
  out << header << '\n';
  return out;
}

std::string TbsYaml(const Eigen::Isometry3d& T) {
  const Eigen::Matrix4d m = T.matrix();
  std::string s = "T_BS:\n  cols: 4\n  rows: 4\n  data: [";
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) {
      s += Num(m(r, c));
      if (r * 4 + c < 15) s += (c == 3 ? ",\n         " : ", ");
    }
  }
  return s + "]\n";
}

void WriteText(const fs::path& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out << text;
  if (!out) throw DatasetError(path.string() + ": cannot write");
}

void WritePng(const fs::path& path, const cv::Mat& image) {
  if (!cv::imwrite(path.string(), image)) throw DatasetError(path.string() + ": cannot write PNG");
}

}  // namespace

struct EurocWriter::Files {
  fs::path mav0;
  std::ofstream imu, cam0, cam1, depth, ground_truth, wheel, can, gpio, tags;
};

EurocWriter::EurocWriter(const std::string& dir) : dir_(dir), files_(std::make_unique<Files>()) {
  Files& f = *files_;
  f.mav0 = fs::path(dir) / "mav0";
  if (fs::exists(f.mav0)) {
    throw DatasetError(f.mav0.string() + ": already exists; choose an empty output folder");
  }
  for (const char* sub : {"imu0", "cam0/data", "cam1/data", "depth0/data",
                          "state_groundtruth_estimate0", "wheel0", "can0", "gpio0", "tags0"}) {
    fs::create_directories(f.mav0 / sub);
  }
  f.imu = OpenCsv(f.mav0 / "imu0/data.csv",
                  "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
                  "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]");
  f.cam0 = OpenCsv(f.mav0 / "cam0/data.csv", "#timestamp [ns],filename");
  f.cam1 = OpenCsv(f.mav0 / "cam1/data.csv", "#timestamp [ns],filename");
  f.depth = OpenCsv(f.mav0 / "depth0/data.csv", "#timestamp [ns],filename");
  f.ground_truth = OpenCsv(
      f.mav0 / "state_groundtruth_estimate0/data.csv",
      "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], "
      "q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], "
      "b_w_RS_S_x [rad s^-1], b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], "
      "b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], b_a_RS_S_z [m s^-2]");
  f.wheel = OpenCsv(f.mav0 / "wheel0/data.csv",
                    "#timestamp [ns],w_fl [rad s^-1],w_fr [rad s^-1],w_rl [rad s^-1],"
                    "w_rr [rad s^-1],ticks_fl,ticks_fr,ticks_rl,ticks_rr");
  f.can = OpenCsv(f.mav0 / "can0/data.csv", "#timestamp [ns],id,dlc,data_hex");
  f.gpio = OpenCsv(f.mav0 / "gpio0/data.csv", "#timestamp [ns],line,name,edge");
  f.tags = OpenCsv(f.mav0 / "tags0/data.csv",
                   "#timestamp [ns],carrier,tag_id,p_x [m],p_y [m],p_z [m],q_w,q_x,q_y,q_z");
  WriteText(f.mav0 / "state_groundtruth_estimate0/sensor.yaml",
            "%YAML:1.0\nsensor_type: visual-inertial\n"
            "comment: Simulator ground truth of the body (IMU) frame in the world frame.\n" +
                TbsYaml(Eigen::Isometry3d::Identity()));
}

EurocWriter::~EurocWriter() {
  try {
    Close();
  } catch (...) {  // a destructor must not throw; call Close() to see errors
  }
}

void EurocWriter::WriteImuCalibration(const calib::ImuCalibration& c) {
  WriteText(files_->mav0 / "imu0/sensor.yaml",
            "%YAML:1.0\nsensor_type: imu\ncomment: rover-sim IMU\n" + TbsYaml(c.T_body_imu) +
                "rate_hz: " + Num(c.rate_hz) + "\n" + "gyroscope_noise_density: " +
                Num(c.gyro_noise_density_rad_s_sqrt_hz) + "     # [ rad / s / sqrt(Hz) ]\n" +
                "gyroscope_random_walk: " + Num(c.gyro_random_walk_rad_s2_sqrt_hz) +
                "       # [ rad / s^2 / sqrt(Hz) ]\n" + "accelerometer_noise_density: " +
                Num(c.accel_noise_density_m_s2_sqrt_hz) + "  # [ m / s^2 / sqrt(Hz) ]\n" +
                "accelerometer_random_walk: " + Num(c.accel_random_walk_m_s3_sqrt_hz) +
                "    # [ m / s^3 / sqrt(Hz) ]\n");
}

void EurocWriter::WriteCameraCalibration(int index, const calib::CameraModel& c) {
  const std::string yaml =
      "%YAML:1.0\nsensor_type: camera\ncomment: rover-sim cam" + std::to_string(index) + "\n" +
      TbsYaml(c.T_body_cam) + "rate_hz: " + Num(c.rate_hz) + "\nresolution: [" +
      std::to_string(c.width_px) + ", " + std::to_string(c.height_px) +
      "]\ncamera_model: pinhole\nintrinsics: [" + Num(c.intrinsics[0]) + ", " +
      Num(c.intrinsics[1]) + ", " + Num(c.intrinsics[2]) + ", " + Num(c.intrinsics[3]) +
      "] #fu, fv, cu, cv\ndistortion_model: " +
      std::string(calib::EurocDistortionName(c.distortion_model)) + "\ndistortion_coefficients: [" +
      Num(c.distortion[0]) + ", " + Num(c.distortion[1]) + ", " + Num(c.distortion[2]) + ", " +
      Num(c.distortion[3]) + "]\n" +
      (c.vignetting_cos4_strength != 0.0
           ? "vignetting_cos4_strength: " + Num(c.vignetting_cos4_strength) +
                 "  # not EuRoC: brightness 1 - v (1 - cos^4 theta) off axis\n"
           : std::string());
  WriteText(files_->mav0 / ("cam" + std::to_string(index)) / "sensor.yaml", yaml);
  if (index == 0) {
    WriteText(files_->mav0 / "depth0/sensor.yaml",
              yaml +
                  "# depth0: z-depth of cam0 in the distorted cam0 image, uint16 PNG in "
                  "millimetres, 0 = no surface\ndepth_scale_m: 0.001\n");
  }
}

void EurocWriter::WriteWheelCalibration(const calib::WheelCalibration& c) {
  WriteText(files_->mav0 / "can0/sensor.yaml", calib::EurocWheelsYaml(c, "rover-sim wheel drives"));
}

void EurocWriter::AddImu(const drivers::ImuSample& s) {
  const auto& w = s.angular_velocity_rad_s;
  const auto& a = s.linear_acceleration_m_s2;
  files_->imu << Stamp(s.stamp) << ',' << Num(w.x()) << ',' << Num(w.y()) << ',' << Num(w.z())
              << ',' << Num(a.x()) << ',' << Num(a.y()) << ',' << Num(a.z()) << '\n';
}

void EurocWriter::AddStereo(Time stamp, const cv::Mat& cam0, const cv::Mat& cam1) {
  const std::string name = Stamp(stamp) + ".png";
  WritePng(files_->mav0 / "cam0/data" / name, cam0);
  WritePng(files_->mav0 / "cam1/data" / name, cam1);
  files_->cam0 << Stamp(stamp) << ',' << name << '\n';
  files_->cam1 << Stamp(stamp) << ',' << name << '\n';
}

void EurocWriter::AddDepth(Time stamp, const cv::Mat& depth_m) {
  cv::Mat depth_mm(depth_m.size(), CV_16UC1);
  for (int r = 0; r < depth_m.rows; ++r) {
    const float* in = depth_m.ptr<float>(r);
    uint16_t* out = depth_mm.ptr<uint16_t>(r);
    for (int c = 0; c < depth_m.cols; ++c) {
      const double mm = std::isfinite(in[c]) ? std::round(static_cast<double>(in[c]) * 1000.0) : 0;
      out[c] = static_cast<uint16_t>(mm > 0 && mm < 65535 ? mm : 0);
    }
  }
  const std::string name = Stamp(stamp) + ".png";
  WritePng(files_->mav0 / "depth0/data" / name, depth_mm);
  files_->depth << Stamp(stamp) << ',' << name << '\n';
}

void EurocWriter::AddGroundTruth(const drivers::GroundTruthState& s) {
  const Eigen::Quaterniond q =
      s.q_world_body.w() < 0 ? Eigen::Quaterniond(-s.q_world_body.coeffs()) : s.q_world_body;
  auto& o = files_->ground_truth;
  o << Stamp(s.stamp);
  for (double v : {s.p_world_body.x(), s.p_world_body.y(), s.p_world_body.z(), q.w(), q.x(), q.y(),
                   q.z(), s.v_world_body_m_s.x(), s.v_world_body_m_s.y(), s.v_world_body_m_s.z(),
                   s.gyro_bias_rad_s.x(), s.gyro_bias_rad_s.y(), s.gyro_bias_rad_s.z(),
                   s.accel_bias_m_s2.x(), s.accel_bias_m_s2.y(), s.accel_bias_m_s2.z()}) {
    o << ',' << Num(v);
  }
  o << '\n';
}

void EurocWriter::AddWheel(const WheelReading& r) {
  auto& o = files_->wheel;
  o << Stamp(r.stamp);
  for (double w : r.angular_velocity_rad_s) o << ',' << Num(w);
  for (int64_t t : r.encoder_ticks) o << ',' << t;
  o << '\n';
}

void EurocWriter::AddCanFrame(const drivers::CanFrame& f) {
  char id[16];
  std::snprintf(id, sizeof id, "0x%03" PRIx32, f.id);
  std::string hex;
  for (std::size_t i = 0; i < f.dlc && i < f.data.size(); ++i) {
    char b[4];
    std::snprintf(b, sizeof b, "%02x", f.data[i]);
    hex += b;
  }
  files_->can << Stamp(f.stamp) << ',' << id << ',' << static_cast<int>(f.dlc) << ',' << hex
              << '\n';
}

void EurocWriter::AddGpioEdge(const drivers::GpioEdge& e, const char* line_name) {
  files_->gpio << Stamp(e.stamp) << ',' << e.line << ',' << line_name << ','
               << (e.rising ? "rising" : "falling") << '\n';
}

void EurocWriter::AddTagPose(Time stamp, const std::string& carrier, int tag_id,
                             const Eigen::Isometry3d& T_world_tag) {
  const Eigen::Quaterniond q(T_world_tag.linear());
  const Eigen::Vector3d& p = T_world_tag.translation();
  files_->tags << Stamp(stamp) << ',' << carrier << ',' << tag_id << ',' << Num(p.x()) << ','
               << Num(p.y()) << ',' << Num(p.z()) << ',' << Num(q.w()) << ',' << Num(q.x()) << ','
               << Num(q.y()) << ',' << Num(q.z()) << '\n';
}

void EurocWriter::Close() {
  if (!files_) return;
  Files& f = *files_;
  for (std::ofstream* s :
       {&f.imu, &f.cam0, &f.cam1, &f.depth, &f.ground_truth, &f.wheel, &f.can, &f.gpio, &f.tags}) {
    s->flush();
    if (!*s) throw DatasetError(dir_ + ": write error while closing the dataset");
    s->close();
  }
  files_.reset();
}

}  // namespace rover::sim
