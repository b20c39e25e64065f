#include "drivers/replay/euroc_dataset.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>

#include "core/calib/euroc_sensor_yaml.h"

namespace rover::drivers {
namespace {

namespace fs = std::filesystem;

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) {
    s.remove_suffix(1);
  }
  return s;
}

// One CSV file, read line by line with its position for error messages.
class CsvFile {
 public:
  explicit CsvFile(std::string path) : path_(std::move(path)), in_(path_) {
    if (!in_) throw DatasetError(path_ + ": cannot open");
  }

  /// Next data row (comment and empty lines skipped), split at commas.
  bool Next(std::vector<std::string_view>* cells) {
    while (std::getline(in_, line_)) {
      ++line_number_;
      const std::string_view line = Trim(line_);
      if (line.empty() || line.front() == '#') continue;
      cells->clear();
      std::size_t start = 0;
      for (std::size_t comma; (comma = line.find(',', start)) != std::string_view::npos;) {
        cells->push_back(Trim(line.substr(start, comma - start)));
        start = comma + 1;
      }
      cells->push_back(Trim(line.substr(start)));
      return true;
    }
    return false;
  }

  [[noreturn]] void Fail(const std::string& what) const {
    throw DatasetError(path_ + ":" + std::to_string(line_number_) + ": " + what);
  }

  int64_t Int64(std::string_view cell, const char* column) const {
    int64_t value = 0;
    const auto [ptr, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), value);
    if (ec != std::errc() || ptr != cell.data() + cell.size()) {
      Fail(std::string(column) + ": expected an integer, found '" + std::string(cell) + "'");
    }
    return value;
  }

  double Double(std::string_view cell, const char* column) const {
    double value = 0;
    const auto [ptr, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), value);
    if (ec != std::errc() || ptr != cell.data() + cell.size() || !std::isfinite(value)) {
      Fail(std::string(column) + ": expected a finite number, found '" + std::string(cell) + "'");
    }
    return value;
  }

  void ExpectColumns(const std::vector<std::string_view>& cells, std::size_t n) const {
    if (cells.size() < n) {
      Fail("expected " + std::to_string(n) + " columns, found " + std::to_string(cells.size()));
    }
  }

  /// Reads three consecutive cells starting at `first` as a vector.
  Eigen::Vector3d Vector3(const std::vector<std::string_view>& cells, std::size_t first,
                          const char* column) const {
    return {Double(cells[first], column), Double(cells[first + 1], column),
            Double(cells[first + 2], column)};
  }

  /// The row's timestamp; timestamps must increase strictly down the file,
  /// because replay merges streams by time.
  Time Stamp(std::string_view cell) {
    const Time t = Time::FromNanoseconds(Int64(cell, "timestamp"));
    if (previous_ && t <= *previous_) {
      Fail("timestamp " + std::to_string(t.nanoseconds()) + " does not increase (previous " +
           std::to_string(previous_->nanoseconds()) + ")");
    }
    previous_ = t;
    return t;
  }

 private:
  std::string path_;
  std::ifstream in_;
  std::string line_;
  int line_number_ = 0;
  std::optional<Time> previous_;
};

std::vector<ImuSample> LoadImu(const std::string& path) {
  CsvFile csv(path);
  std::vector<ImuSample> samples;
  std::vector<std::string_view> c;
  while (csv.Next(&c)) {
    csv.ExpectColumns(c, 7);
    ImuSample s;
    s.stamp = csv.Stamp(c[0]);
    s.sequence = samples.size();
    s.angular_velocity_rad_s = csv.Vector3(c, 1, "w_RS_S");
    s.linear_acceleration_m_s2 = csv.Vector3(c, 4, "a_RS_S");
    samples.push_back(s);
  }
  return samples;
}

// Camera rows whose image exists, keyed by timestamp.
std::map<int64_t, std::string> LoadCameraRows(const fs::path& cam_dir,
                                              std::vector<std::string>* issues) {
  CsvFile csv((cam_dir / "data.csv").string());
  std::map<int64_t, std::string> rows;
  std::vector<std::string_view> c;
  int missing = 0;
  while (csv.Next(&c)) {
    csv.ExpectColumns(c, 2);
    const Time t = csv.Stamp(c[0]);
    const fs::path image = cam_dir / "data" / std::string(c[1]);
    if (!fs::exists(image)) {
      if (missing++ < 5) issues->push_back(image.string() + ": listed in data.csv but missing");
      continue;
    }
    rows.emplace(t.nanoseconds(), image.string());
  }
  if (missing > 5) {
    issues->push_back(cam_dir.string() + ": " + std::to_string(missing - 5) +
                      " more missing images");
  }
  return rows;
}

std::vector<GroundTruthState> LoadGroundTruth(const std::string& path) {
  CsvFile csv(path);
  std::vector<GroundTruthState> states;
  std::vector<std::string_view> c;
  while (csv.Next(&c)) {
    csv.ExpectColumns(c, 8);
    GroundTruthState s;
    s.stamp = csv.Stamp(c[0]);
    s.p_world_body = csv.Vector3(c, 1, "p_RS_R");
    s.q_world_body = Eigen::Quaterniond(csv.Double(c[4], "q_w"), csv.Double(c[5], "q_x"),
                                        csv.Double(c[6], "q_y"), csv.Double(c[7], "q_z"));
    if (std::abs(s.q_world_body.norm() - 1.0) > 1e-3) {
      csv.Fail("quaternion norm " + std::to_string(s.q_world_body.norm()) + ", expected 1");
    }
    s.q_world_body.normalize();
    s.v_world_body_m_s = s.gyro_bias_rad_s = s.accel_bias_m_s2 = Eigen::Vector3d::Zero();
    if (c.size() >= 17) {
      s.v_world_body_m_s = csv.Vector3(c, 8, "v_RS_R");
      s.gyro_bias_rad_s = csv.Vector3(c, 11, "b_w_RS_S");
      s.accel_bias_m_s2 = csv.Vector3(c, 14, "b_a_RS_S");
    }
    states.push_back(s);
  }
  return states;
}

}  // namespace

EurocDataset EurocDataset::Load(const std::string& dir, const std::string& ground_truth_csv) {
  const fs::path mav0 = fs::path(dir) / "mav0";
  if (!fs::is_directory(mav0)) {
    throw DatasetError(dir + ": not an EuRoC dataset (expected a mav0/ folder inside)");
  }
  EurocDataset d;
  d.dir_ = dir;
  d.imu_ = LoadImu((mav0 / "imu0/data.csv").string());
  try {
    d.calibration_ = calib::LoadEurocCalibration(mav0.string());
  } catch (const calib::CalibrationError& e) {
    throw DatasetError(e.what());  // the dataset's one error type, same message
  }

  const auto rows0 = LoadCameraRows(mav0 / "cam0", &d.issues_);
  const auto rows1 = LoadCameraRows(mav0 / "cam1", &d.issues_);
  std::size_t unpaired = 0;
  for (const auto& [stamp, path0] : rows0) {
    const auto it = rows1.find(stamp);
    if (it == rows1.end()) {
      ++unpaired;
      continue;
    }
    d.frames_.push_back({Time::FromNanoseconds(stamp), path0, it->second});
  }
  unpaired += rows1.size() - (rows0.size() - unpaired);
  if (unpaired > 0) {
    d.issues_.push_back(std::to_string(unpaired) +
                        " camera rows without a partner image in the "
                        "other camera were left out");
  }

  const std::string gt_path = !ground_truth_csv.empty()
                                  ? ground_truth_csv
                                  : (mav0 / "state_groundtruth_estimate0/data.csv").string();
  if (fs::exists(gt_path)) {
    d.ground_truth_ = LoadGroundTruth(gt_path);
  } else if (!ground_truth_csv.empty()) {
    throw DatasetError(ground_truth_csv + ": ground truth file does not exist");
  } else {
    d.issues_.push_back("no ground truth (" + gt_path + " missing)");
  }
  return d;
}

std::optional<GroundTruthState> EurocDataset::GroundTruthAt(Time t, Duration max_gap) const {
  const auto after =
      std::lower_bound(ground_truth_.begin(), ground_truth_.end(), t,
                       [](const GroundTruthState& s, Time value) { return s.stamp < value; });
  if (after == ground_truth_.end()) return std::nullopt;
  if (after->stamp == t) return *after;
  if (after == ground_truth_.begin()) return std::nullopt;
  const GroundTruthState& a = *(after - 1);
  const GroundTruthState& b = *after;
  if (b.stamp - a.stamp > max_gap) return std::nullopt;
  const double u = (t - a.stamp) / (b.stamp - a.stamp);
  GroundTruthState s = a;
  s.stamp = t;
  s.p_world_body = (1 - u) * a.p_world_body + u * b.p_world_body;
  s.v_world_body_m_s = (1 - u) * a.v_world_body_m_s + u * b.v_world_body_m_s;
  s.q_world_body = a.q_world_body.slerp(u, b.q_world_body);
  s.gyro_bias_rad_s = (1 - u) * a.gyro_bias_rad_s + u * b.gyro_bias_rad_s;
  s.accel_bias_m_s2 = (1 - u) * a.accel_bias_m_s2 + u * b.accel_bias_m_s2;
  return s;
}

}  // namespace rover::drivers
