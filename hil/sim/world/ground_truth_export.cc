// ExportWorldGroundTruth: the world's ground truth as plain files. Numbers
// are written in their shortest round-trip form (std::to_chars), which does
// not depend on the locale, so the bytes depend only on the world.

#include <bit>
#include <charconv>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "hil/sim/world/world.h"

namespace rover::sim {
namespace {

std::string Num(double v) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), v);
  return std::string(buffer, result.ptr);
}

void WriteFile(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) throw std::runtime_error("ExportWorldGroundTruth: cannot write " + path.string());
}

void WritePng(const std::filesystem::path& path, int cols, int rows,
              const std::vector<uint8_t>& values) {
  // cv::Mat wraps the data without copying; imwrite only reads it.
  const cv::Mat image(rows, cols, CV_8UC1, const_cast<uint8_t*>(values.data()));
  // A fixed compression level: the bytes must not follow OpenCV's default.
  const std::vector<int> params = {cv::IMWRITE_PNG_COMPRESSION, 3};
  bool ok = false;
  try {
    ok = cv::imwrite(path.string(), image, params);
  } catch (const cv::Exception& e) {
    throw std::runtime_error("ExportWorldGroundTruth: cannot write " + path.string() + ": " +
                             e.what());
  }
  if (!ok) throw std::runtime_error("ExportWorldGroundTruth: cannot write " + path.string());
}

std::string GridYaml(int cols, int rows, double resolution_m, const Eigen::Vector2d& origin) {
  std::string s;
  s += "cols: " + std::to_string(cols) + "\n";
  s += "rows: " + std::to_string(rows) + "\n";
  s += "resolution_m: " + Num(resolution_m) + "\n";
  s += "origin_xy_m: [" + Num(origin.x()) + ", " + Num(origin.y()) + "]\n";
  s += "frame: world  # x east, y north, z up, metres\n";
  s += "sample_position: origin_xy_m + resolution_m * [ix, iy]\n";
  return s;
}

// Pose as px,py,pz,qw,qx,qy,qz with qw >= 0, so a rotation has one spelling.
std::string PoseCsv(const Eigen::Isometry3d& pose) {
  Eigen::Quaterniond q(pose.rotation());
  q.normalize();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  const Eigen::Vector3d& p = pose.translation();
  return Num(p.x()) + "," + Num(p.y()) + "," + Num(p.z()) + "," + Num(q.w()) + "," + Num(q.x()) +
         "," + Num(q.y()) + "," + Num(q.z());
}

std::string HeightfieldBytes(const Heightfield& terrain) {
  const std::vector<float>& heights = terrain.heights_m();
  std::string bytes(heights.size() * sizeof(float), '\0');
  if constexpr (std::endian::native == std::endian::little) {
    std::memcpy(bytes.data(), heights.data(), bytes.size());
  } else {
    for (std::size_t i = 0; i < heights.size(); ++i) {
      const auto bits = std::bit_cast<uint32_t>(heights[i]);
      for (std::size_t b = 0; b < 4; ++b) {
        bytes[4 * i + b] = static_cast<char>((bits >> (8 * b)) & 0xffU);
      }
    }
  }
  return bytes;
}

std::string IndentBlock(const std::string& text, const std::string& indent) {
  std::string out;
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);) out += indent + line + "\n";
  return out;
}

}  // namespace

void ExportWorldGroundTruth(const World& world, const std::string& dir,
                            const ObstacleRuleOptions& rule) {
  const std::filesystem::path root(dir);
  std::error_code error;
  std::filesystem::create_directories(root, error);
  if (error) {
    throw std::runtime_error("ExportWorldGroundTruth: cannot create " + dir + ": " +
                             error.message());
  }
  const Heightfield& terrain = world.terrain;
  const WorldOptions& o = world.options;

  {
    std::string s;
    s += "seed: " + std::to_string(world.seed) + "\n";
    s += "size_m: " + Num(o.size_m) + "\n";
    s += "resolution_m: " + Num(o.resolution_m) + "\n";
    s += "albedo_resolution_m: " + Num(o.albedo_resolution_m) + "\n";
    s += "max_slope_deg: " + Num(o.max_slope_deg) + "  # over 0.5 m baselines, off rocks/craters\n";
    s += "rock_count: " + std::to_string(o.rock_count) + "  # requested\n";
    s += "rocks_placed: " + std::to_string(world.rocks.size()) + "\n";
    s += "crater_count: " + std::to_string(o.crater_count) + "\n";
    s += "landmark_post_count: " + std::to_string(o.landmark_post_count) + "\n";
    s += "other_rover_count: " + std::to_string(o.other_rover_count) + "\n";
    s += "tag_size_m: " + Num(o.tag_size_m) + "\n";
    s += "rover_tag_size_m: " + Num(o.rover_tag_size_m) + "\n";
    s += "clear_radius_m: " + Num(o.clear_radius_m) + "\n";
    WriteFile(root / "world.yaml", s);
  }

  WriteFile(root / "heightfield.bin", HeightfieldBytes(terrain));
  {
    std::string s =
        GridYaml(terrain.cols(), terrain.rows(), terrain.resolution_m(), terrain.origin_xy());
    s += "layout: row-major float32 little-endian heights in metres, row iy outer "
         "(byte offset 4 * (iy * cols + ix)), no header\n";
    s += "surface: bilinear between samples\n";
    s += "min_height_m: " + Num(terrain.min_height_m()) + "\n";
    s += "max_height_m: " + Num(terrain.max_height_m()) + "\n";
    WriteFile(root / "heightfield.yaml", s);
  }

  const AlbedoMap& albedo = world.albedo;
  WritePng(root / "albedo.png", albedo.cols, albedo.rows, albedo.values);
  {
    std::string s = GridYaml(albedo.cols, albedo.rows, albedo.resolution_m, albedo.origin_xy);
    s += "layout: 8-bit grey PNG, image row r = grid row iy = r (north is down when viewed)\n";
    s += "albedo: value / 255, bilinear between samples\n";
    WriteFile(root / "albedo.yaml", s);
  }

  const ObstacleGrid obstacles = ComputeObstacleCells(world, rule);
  WritePng(root / "obstacles.png", obstacles.cols, obstacles.rows, obstacles.codes);
  {
    std::size_t counts[4] = {0, 0, 0, 0};
    for (uint8_t code : obstacles.codes) ++counts[code & 3U];
    std::string s =
        GridYaml(obstacles.cols, obstacles.rows, obstacles.resolution_m, obstacles.origin_xy);
    s += "layout: 8-bit PNG of codes, image row r = grid row iy = r, one code per heightfield "
         "sample\n";
    s += "codes:\n";
    s += "  0: free\n";
    s += "  1: positive  # a rock or a step higher than a wheel can climb\n";
    s += "  2: slope  # steeper than the rover may drive\n";
    s += "  3: negative  # the top edge of a drop (crater scarp, cliff)\n";
    s += "parameters:\n";
    s += "  rock_min_height_m: " + Num(rule.rock_min_height_m) + "\n";
    s += "  step_window_m: " + Num(rule.step_window_m) + "\n";
    s += "  step_height_m: " + Num(rule.step_height_m) + "\n";
    s += "  slope_window_m: " + Num(rule.slope_window_m) + "\n";
    s += "  max_slope_deg: " + Num(rule.max_slope_deg) + "\n";
    s += "  negative_window_m: " + Num(rule.negative_window_m) + "\n";
    s += "  negative_drop_m: " + Num(rule.negative_drop_m) + "\n";
    s += "rule: |\n" + IndentBlock(DescribeObstacleRule(rule), "  ");
    s += "cell_counts:\n";
    s += "  free: " + std::to_string(counts[0]) + "\n";
    s += "  positive: " + std::to_string(counts[1]) + "\n";
    s += "  slope: " + std::to_string(counts[2]) + "\n";
    s += "  negative: " + std::to_string(counts[3]) + "\n";
    WriteFile(root / "obstacles.yaml", s);
  }

  {
    std::string s = "carrier,is_static,tag_id,size_m,frame,px,py,pz,qw,qx,qy,qz\n";
    for (const TagCarrier& carrier : world.carriers) {
      for (const TagMarker& tag : carrier.tags) {
        // Static carriers: the tag in the world; moving ones: in the carrier
        // frame, posed per frame by the motion model.
        const Eigen::Isometry3d pose =
            carrier.is_static ? carrier.T_world_carrier * tag.T_carrier_tag : tag.T_carrier_tag;
        s += carrier.name + "," + (carrier.is_static ? "1" : "0") + "," + std::to_string(tag.id) +
             "," + Num(tag.size_m) + "," + (carrier.is_static ? "world" : "carrier") + "," +
             PoseCsv(pose) + "\n";
      }
    }
    WriteFile(root / "tags.csv", s);
  }
  {
    std::string s = "carrier,is_static,frame,px,py,pz,qw,qx,qy,qz\n";
    std::string boxes = "carrier,box,cx,cy,cz,sx,sy,sz,albedo\n";
    for (const TagCarrier& carrier : world.carriers) {
      s += carrier.name + "," +
           (carrier.is_static ? "1,world," + PoseCsv(carrier.T_world_carrier)
                              : std::string("0,moving,,,,,,,")) +
           "\n";
      for (std::size_t b = 0; b < carrier.boxes.size(); ++b) {
        const Box& box = carrier.boxes[b];
        boxes += carrier.name + "," + std::to_string(b) + "," + Num(box.center_carrier.x()) + "," +
                 Num(box.center_carrier.y()) + "," + Num(box.center_carrier.z()) + "," +
                 Num(box.size_m.x()) + "," + Num(box.size_m.y()) + "," + Num(box.size_m.z()) + "," +
                 Num(box.albedo) + "\n";
      }
    }
    WriteFile(root / "carriers.csv", s);
    WriteFile(root / "boxes.csv", boxes);
  }
  {
    std::string s =
        "index,x,y,top_z,radius_m,outer_radius_m,height_m,shape_exponent,a1,b1,a2,b2,a3,b3,"
        "surface_seed\n";
    for (std::size_t i = 0; i < world.rocks.size(); ++i) {
      const Rock& r = world.rocks[i];
      s += std::to_string(i) + "," + Num(r.center_xy.x()) + "," + Num(r.center_xy.y()) + "," +
           Num(terrain.HeightAt(r.center_xy.x(), r.center_xy.y())) + "," + Num(r.radius_m) + "," +
           Num(RockOuterRadius(r)) + "," + Num(r.height_m) + "," + Num(r.shape_exponent) + "," +
           Num(r.outline_harmonics[0]) + "," + Num(r.outline_harmonics[1]) + "," +
           Num(r.outline_harmonics[2]) + "," + Num(r.outline_harmonics[3]) + "," +
           Num(r.outline_harmonics[4]) + "," + Num(r.outline_harmonics[5]) + "," +
           std::to_string(r.surface_seed) + "\n";
    }
    WriteFile(root / "rocks.csv", s);
  }
  {
    std::string s =
        "index,x,y,radius_m,depth_m,rim_height_m,scarp_drop_m,scarp_width_m,outer_radius_m\n";
    for (std::size_t i = 0; i < world.craters.size(); ++i) {
      const Crater& c = world.craters[i];
      s += std::to_string(i) + "," + Num(c.center_xy.x()) + "," + Num(c.center_xy.y()) + "," +
           Num(c.radius_m) + "," + Num(c.depth_m) + "," + Num(c.rim_height_m) + "," +
           Num(c.scarp_drop_m) + "," + Num(c.scarp_width_m) + "," + Num(CraterOuterRadius(c)) +
           "\n";
    }
    WriteFile(root / "craters.csv", s);
  }
}

std::string TagMarkerFile(const World& world, const std::map<int, double>& rover_body_height_m) {
  std::ostringstream out;
  out << "# The simulated world's AprilTags (seed " << world.seed
      << "): landmark posts and other rovers.\n"
      << "families: [tag36h11]\nmarkers:\n";
  int64_t landmark = 0;
  // Robot ids are the team's rover numbers (MakeTeamRovers, rover-team): the
  // scenario's own rover "rover_a" is 0, the other rovers 1, 2, ... in world
  // order.
  int next_other_robot = 1;
  for (const TagCarrier& carrier : world.carriers) {
    const int robot = carrier.name == "rover_a" ? 0 : next_other_robot;
    for (const TagMarker& tag : carrier.tags) {
      out << "  - {id: " << tag.id << ", size_m: " << Num(tag.size_m) << ", ";
      if (carrier.is_static) {
        out << "landmark: " << landmark;
      } else {
        out << "robot: " << robot;
      }
      Eigen::Isometry3d T_marker_tag = tag.T_carrier_tag;
      if (!carrier.is_static) {
        // Into the body frame: the carrier frame is body_height below it.
        const auto height = rover_body_height_m.find(robot);
        if (height != rover_body_height_m.end()) {
          T_marker_tag.translation().z() -= height->second;
        }
      }
      out << ", T_carrier_tag: [";
      const Eigen::Matrix4d T = T_marker_tag.matrix();
      for (int i = 0; i < 16; ++i) out << (i > 0 ? ", " : "") << Num(T(i / 4, i % 4));
      out << "]}  # " << carrier.name << "\n";
    }
    if (carrier.is_static) {
      ++landmark;
    } else if (robot > 0) {
      ++next_other_robot;
    }
  }
  return out.str();
}

}  // namespace rover::sim
