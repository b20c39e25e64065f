#include "mapping/compose/map_export.h"

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cerrno>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

namespace rover::mapping {
namespace {

constexpr std::size_t kPlyVertexBytes = 3 * sizeof(float) + 4;
// A header longer than this is not one of ours (and a binary file read as
// text must not be scanned to its end for a newline).
constexpr std::size_t kMaxPlyHeaderBytes = 64 * 1024;

[[noreturn]] void Fail(const char* function, const std::filesystem::path& path,
                       const std::string& what) {
  throw std::runtime_error(std::string(function) + ": " + path.string() + ": " + what);
}

std::string ErrnoText() { return std::system_category().message(errno); }

// fsync through a fresh descriptor (std::ofstream has none to offer); on
// Linux that flushes the file's data written through any descriptor.
bool SyncPath(const std::filesystem::path& path, int flags) {
  const int fd = ::open(path.c_str(), flags | O_CLOEXEC);
  if (fd < 0) return false;
  const bool ok = ::fsync(fd) == 0;
  ::close(fd);
  return ok;
}

// Writes `path` through `<path>.tmp` (see the header): `write` fills the
// stream and returns false on failure.
template <typename WriteFn>
void WriteAtomically(const char* function, const std::filesystem::path& path, WriteFn&& write) {
  std::filesystem::path tmp = path;
  tmp += ".tmp";
  std::error_code ignored;
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) Fail(function, path, "cannot open " + tmp.string() + " for writing: " + ErrnoText());
    const bool written = write(out);
    out.flush();
    if (!written || !out) {
      const std::string reason = ErrnoText();
      out.close();
      std::filesystem::remove(tmp, ignored);
      Fail(function, path, "write failed to " + tmp.string() + ": " + reason);
    }
    out.close();
    if (out.fail()) {
      const std::string reason = ErrnoText();
      std::filesystem::remove(tmp, ignored);
      Fail(function, path, "write failed (close) to " + tmp.string() + ": " + reason);
    }
  }
  // On disk before the rename, or a power loss could leave the new name
  // pointing at an empty file.
  if (!SyncPath(tmp, O_RDONLY)) {
    const std::string reason = ErrnoText();
    std::filesystem::remove(tmp, ignored);
    Fail(function, path, "write failed (fsync of " + tmp.string() + "): " + reason);
  }
  std::error_code error;
  std::filesystem::rename(tmp, path, error);
  if (error) {
    std::filesystem::remove(tmp, ignored);
    Fail(function, path, "cannot rename " + tmp.string() + " to it: " + error.message());
  }
  // Makes the rename itself durable; the file is complete either way, so a
  // failure here is not worth an exception.
  std::filesystem::path directory = path.parent_path();
  if (directory.empty()) directory = ".";
  SyncPath(directory, O_RDONLY | O_DIRECTORY);
}

void PutFloat(float value, char* out) {
  const auto bits = std::bit_cast<uint32_t>(value);
  for (int i = 0; i < 4; ++i) out[i] = static_cast<char>((bits >> (8 * i)) & 0xffu);
}

float GetFloat(const char* in) {
  uint32_t bits = 0;
  for (int i = 0; i < 4; ++i) {
    bits |= static_cast<uint32_t>(static_cast<unsigned char>(in[i])) << (8 * i);
  }
  return std::bit_cast<float>(bits);
}

constexpr std::array<std::string_view, 7> kPlyProperties = {
    "property float x",     "property float y",    "property float z",       "property uchar red",
    "property uchar green", "property uchar blue", "property uchar obstacle"};

// One header line without its newline; false at the end of the file or
// once `*budget` bytes are used up (a binary file has no lines to speak of).
bool ReadHeaderLine(std::istream& in, std::string* line, std::size_t* budget) {
  line->clear();
  char c = 0;
  while (*budget > 0 && in.get(c)) {
    --*budget;
    if (c == '\n') return true;
    line->push_back(c);
  }
  return false;
}

std::string_view Trimmed(std::string_view line) {
  while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.remove_suffix(1);
  return line;
}

}  // namespace

void WriteOctreeBt(const octomap::OcTree& tree, const std::filesystem::path& path) {
  WriteAtomically("WriteOctreeBt", path,
                  [&tree](std::ostream& out) { return tree.writeBinaryConst(out); });
}

void WriteOctreeOt(const octomap::OcTree& tree, const std::filesystem::path& path) {
  WriteAtomically("WriteOctreeOt", path, [&tree](std::ostream& out) { return tree.write(out); });
}

void WritePly(const PointCloud& cloud_world, const std::filesystem::path& path) {
  WriteAtomically("WritePly", path, [&cloud_world](std::ostream& out) {
    out << "ply\nformat binary_little_endian 1.0\n"
        << "comment rover global map, world frame, metres\n"
        << "element vertex " << cloud_world.size() << "\n";
    for (std::string_view property : kPlyProperties) out << property << "\n";
    out << "end_header\n";
    // Buffered in blocks: one stream call per point would dominate.
    constexpr std::size_t kBlockVertices = 4096;
    std::vector<char> block(kBlockVertices * kPlyVertexBytes);
    std::size_t used = 0;
    for (const CloudPoint& point : cloud_world) {
      char* v = block.data() + used;
      for (int a = 0; a < 3; ++a) PutFloat(point.p_submap_m[a], v + 4 * a);
      const auto byte = [](unsigned value) { return static_cast<char>(value); };
      v[12] = byte(point.obstacle ? 255 : 160);
      v[13] = byte(point.obstacle ? 0 : 160);
      v[14] = byte(point.obstacle ? 0 : 160);
      v[15] = byte(point.obstacle ? 1 : 0);
      used += kPlyVertexBytes;
      if (used == block.size()) {
        out.write(block.data(), static_cast<std::streamsize>(used));
        used = 0;
      }
    }
    out.write(block.data(), static_cast<std::streamsize>(used));
    return static_cast<bool>(out);
  });
}

PointCloud ReadPly(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) Fail("ReadPly", path, "cannot open: " + ErrnoText());
  std::error_code error;
  const std::uintmax_t file_bytes = std::filesystem::file_size(path, error);
  if (error) Fail("ReadPly", path, "cannot read its size: " + error.message());

  // Header: ASCII lines up to end_header.
  std::vector<std::string> lines;
  std::size_t budget = kMaxPlyHeaderBytes;
  std::string line;
  bool ended = false;
  while (ReadHeaderLine(in, &line, &budget)) {
    const std::string_view trimmed = Trimmed(line);
    if (trimmed == "end_header") {
      ended = true;
      break;
    }
    if (trimmed.starts_with("comment") || trimmed.starts_with("obj_info")) continue;
    lines.emplace_back(trimmed);
  }
  if (lines.empty() || lines[0] != "ply") Fail("ReadPly", path, "bad header: not a PLY file");
  if (!ended) Fail("ReadPly", path, "bad header: no end_header line");
  const std::size_t expected_lines = 3 + kPlyProperties.size();
  if (lines.size() != expected_lines) {
    Fail("ReadPly", path,
         "bad header: expected " + std::to_string(expected_lines) +
             " lines (ply, format, element vertex, 7 properties) besides comments, found " +
             std::to_string(lines.size()));
  }
  if (lines[1] != "format binary_little_endian 1.0") {
    Fail("ReadPly", path,
         "bad header: expected 'format binary_little_endian 1.0', found '" + lines[1] + "'");
  }
  constexpr std::string_view kElement = "element vertex ";
  uint64_t declared = 0;
  {
    const std::string_view element = lines[2];
    const char* first = element.data() + std::min(kElement.size(), element.size());
    const char* last = element.data() + element.size();
    const std::from_chars_result parsed =
        element.starts_with(kElement) ? std::from_chars(first, last, declared)
                                      : std::from_chars_result{first, std::errc::invalid_argument};
    if (parsed.ec != std::errc() || parsed.ptr != last) {
      Fail("ReadPly", path,
           "bad header: expected 'element vertex <count>', found '" + lines[2] + "'");
    }
  }
  for (std::size_t i = 0; i < kPlyProperties.size(); ++i) {
    if (lines[3 + i] != kPlyProperties[i]) {
      Fail("ReadPly", path,
           "bad header: expected '" + std::string(kPlyProperties[i]) + "', found '" + lines[3 + i] +
               "'");
    }
  }

  // Data: sizes checked against the file before anything is allocated, so
  // that a corrupt count cannot ask for terabytes.
  const std::uintmax_t header_bytes = kMaxPlyHeaderBytes - budget;
  const std::uintmax_t data_bytes = file_bytes > header_bytes ? file_bytes - header_bytes : 0;
  const std::uintmax_t present = data_bytes / kPlyVertexBytes;
  if (present < declared) {
    Fail("ReadPly", path,
         "truncated data: header declares " + std::to_string(declared) + " vertices, file holds " +
             std::to_string(present) + " complete vertices (" + std::to_string(data_bytes) +
             " of " + std::to_string(declared * kPlyVertexBytes) + " bytes)");
  }
  if (data_bytes != declared * kPlyVertexBytes) {
    Fail("ReadPly", path,
         "trailing data: header declares " + std::to_string(declared) + " vertices (" +
             std::to_string(declared * kPlyVertexBytes) + " bytes), file holds " +
             std::to_string(data_bytes) + " bytes");
  }
  std::vector<char> data(static_cast<std::size_t>(data_bytes));
  if (!data.empty() && !in.read(data.data(), static_cast<std::streamsize>(data.size()))) {
    Fail("ReadPly", path,
         "read failed after " + std::to_string(in.gcount()) + " of " + std::to_string(data.size()) +
             " data bytes");
  }
  PointCloud cloud(static_cast<std::size_t>(declared));
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const char* v = data.data() + i * kPlyVertexBytes;
    for (int a = 0; a < 3; ++a) cloud[i].p_submap_m[a] = GetFloat(v + 4 * a);
    cloud[i].obstacle = v[15] != 0;
  }
  return cloud;
}

}  // namespace rover::mapping
