#include "mapping/submap/submap_messages.h"

#include <cmath>
#include <cstring>
#include <sstream>
#include <stdexcept>

namespace rover::mapping {
namespace {

using log::sensor_msgs::PointField;

constexpr uint32_t kPointStep = 13;  // x y z float32 + obstacle uint8

const PointField* FindField(const log::sensor_msgs::PointCloud2& msg, std::string_view name) {
  for (const PointField& f : msg.fields) {
    if (f.name == name) return &f;
  }
  return nullptr;
}

}  // namespace

log::octomap_msgs::Octomap ToOctomapMsg(const octomap::OcTree& tree,
                                        const log::std_msgs::Header& header) {
  std::ostringstream stream(std::ios::binary);
  tree.writeBinaryData(stream);
  const std::string bytes = stream.str();
  log::octomap_msgs::Octomap msg;
  msg.header = header;
  msg.binary = true;
  msg.id = "OcTree";
  msg.resolution = tree.getResolution();
  msg.data.resize(bytes.size());
  std::memcpy(msg.data.data(), bytes.data(), bytes.size());
  return msg;
}

std::unique_ptr<octomap::OcTree> FromOctomapMsg(const log::octomap_msgs::Octomap& msg) {
  if (!msg.binary) throw std::runtime_error("Octomap message: expected binary=true, got false");
  if (msg.id != "OcTree") {
    throw std::runtime_error("Octomap message: expected id \"OcTree\", got \"" + msg.id + "\"");
  }
  if (!(msg.resolution > 0.0) || !std::isfinite(msg.resolution)) {
    throw std::runtime_error("Octomap message: expected a resolution > 0, got " +
                             std::to_string(msg.resolution));
  }
  auto tree = std::make_unique<octomap::OcTree>(msg.resolution);
  std::string bytes(msg.data.size(), '\0');
  std::memcpy(bytes.data(), msg.data.data(), bytes.size());
  std::istringstream stream(bytes, std::ios::binary);
  tree->readBinaryData(stream);
  // readBinaryData reads the node bits depth-first; a truncated stream
  // leaves the stream failed.
  if (!stream || stream.peek() != std::char_traits<char>::eof()) {
    throw std::runtime_error("Octomap message: its " + std::to_string(msg.data.size()) +
                             " data bytes are not one complete binary octree");
  }
  return tree;
}

log::sensor_msgs::PointCloud2 ToPointCloud2(const PointCloud& cloud,
                                            const log::std_msgs::Header& header) {
  log::sensor_msgs::PointCloud2 msg;
  msg.header = header;
  msg.height = 1;
  msg.width = static_cast<uint32_t>(cloud.size());
  msg.fields = {{"x", 0, PointField::kFloat32, 1},
                {"y", 4, PointField::kFloat32, 1},
                {"z", 8, PointField::kFloat32, 1},
                {"obstacle", 12, PointField::kUint8, 1}};
  msg.is_bigendian = false;
  msg.point_step = kPointStep;
  msg.row_step = kPointStep * msg.width;
  msg.data.resize(static_cast<std::size_t>(msg.row_step));
  uint8_t* out = msg.data.data();
  for (const CloudPoint& p : cloud) {
    std::memcpy(out, p.p_submap_m.data(), 12);  // little-endian host (x86, ARM)
    out[12] = p.obstacle ? 1 : 0;
    out += kPointStep;
  }
  msg.is_dense = true;
  return msg;
}

PointCloud FromPointCloud2(const log::sensor_msgs::PointCloud2& msg) {
  const auto need = [&msg](std::string_view name, uint32_t offset) -> const PointField* {
    const PointField* f = FindField(msg, name);
    if (f == nullptr) return nullptr;
    if (f->datatype != PointField::kFloat32 || f->offset != offset) {
      throw std::runtime_error("PointCloud2: expected field " + std::string(name) +
                               " as float32 at offset " + std::to_string(offset) + ", got type " +
                               std::to_string(f->datatype) + " at offset " +
                               std::to_string(f->offset));
    }
    return f;
  };
  if (need("x", 0) == nullptr || need("y", 4) == nullptr || need("z", 8) == nullptr) {
    throw std::runtime_error("PointCloud2: expected fields x, y, z");
  }
  if (msg.is_bigendian) throw std::runtime_error("PointCloud2: big-endian data is not supported");
  const PointField* obstacle = FindField(msg, "obstacle");
  if (obstacle != nullptr &&
      (obstacle->datatype != PointField::kUint8 || obstacle->offset + 1 > msg.point_step)) {
    throw std::runtime_error("PointCloud2: field obstacle must be a uint8 inside the point");
  }
  const std::size_t points = static_cast<std::size_t>(msg.width) * msg.height;
  if (msg.point_step < 12 || msg.data.size() != points * static_cast<std::size_t>(msg.point_step)) {
    throw std::runtime_error("PointCloud2: expected " + std::to_string(points) + " points of " +
                             std::to_string(msg.point_step) + " bytes, got " +
                             std::to_string(msg.data.size()) + " data bytes");
  }
  PointCloud cloud(points);
  const uint8_t* in = msg.data.data();
  for (CloudPoint& p : cloud) {
    std::memcpy(p.p_submap_m.data(), in, 12);
    p.obstacle = obstacle != nullptr && in[obstacle->offset] != 0;
    in += msg.point_step;
  }
  return cloud;
}

}  // namespace rover::mapping
