#include "mapping/submap/submap_codec.h"

#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <sstream>
#include <stdexcept>

namespace rover::mapping {
namespace {

constexpr std::string_view kBinaryMagic = "# Octomap OcTree binary file";
constexpr std::string_view kFullMagic = "# Octomap OcTree file";
constexpr int kTreeDepth = 16;

[[noreturn]] void Fail(const char* what, const std::string& problem) {
  throw std::runtime_error(std::string(what) + ": " + problem);
}

struct Header {
  std::string id;
  uint64_t size = 0;
  double resolution_m = 0.0;
  std::size_t data_offset = 0;  ///< first byte after the "data" line
};

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r')) {
    s.remove_prefix(1);
  }
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) {
    s.remove_suffix(1);
  }
  return s;
}

// The text header as OctoMap's AbstractOcTree::readHeader reads it: after
// the magic line, "#" comments and "id", "size", "res" lines up to "data".
Header ParseHeader(std::string_view bytes, std::string_view magic, std::string_view other_magic,
                   const char* what, const char* other_decoder) {
  if (bytes.empty()) Fail(what, "empty input");
  const std::size_t first_end = bytes.find('\n');
  const std::string_view first = bytes.substr(0, first_end);
  if (first.substr(0, magic.size()) != magic) {
    if (first.substr(0, other_magic.size()) == other_magic) {
      Fail(what, std::string("not this format: the stream starts with \"") +
                     std::string(other_magic) + "\", use " + other_decoder);
    }
    Fail(what, "not an OctoMap stream: the first line does not start with \"" + std::string(magic) +
                   "\"");
  }
  Header h;
  bool has_id = false, has_size = false, has_res = false;
  std::size_t pos = first_end == std::string_view::npos ? bytes.size() : first_end + 1;
  while (true) {
    if (pos >= bytes.size()) Fail(what, "truncated header: no \"data\" line");
    const std::size_t end = bytes.find('\n', pos);
    if (end == std::string_view::npos) Fail(what, "truncated header: no \"data\" line");
    const std::string_view line = Trim(bytes.substr(pos, end - pos));
    pos = end + 1;
    if (line.empty() || line.front() == '#') continue;
    const std::size_t space = line.find_first_of(" \t");
    const std::string_view key = line.substr(0, space);
    const std::string_view value =
        space == std::string_view::npos ? std::string_view() : Trim(line.substr(space));
    if (key == "data") {
      h.data_offset = pos;
      break;
    }
    if (key == "id") {
      h.id = std::string(value);
      has_id = true;
    } else if (key == "size") {
      const auto r = std::from_chars(value.data(), value.data() + value.size(), h.size);
      if (r.ec != std::errc() || r.ptr != value.data() + value.size()) {
        Fail(what, "bad header: size \"" + std::string(value) + "\" is not a node count");
      }
      has_size = true;
    } else if (key == "res") {
      // std::from_chars for double is in GCC 12's libstdc++; strtod would
      // depend on the locale.
      const auto r = std::from_chars(value.data(), value.data() + value.size(), h.resolution_m);
      if (r.ec != std::errc() || !std::isfinite(h.resolution_m) || h.resolution_m <= 0.0) {
        Fail(what, "bad header: res \"" + std::string(value) + "\" is not a resolution > 0");
      }
      has_res = true;
    }
    // Other keywords: OctoMap skips them too.
  }
  if (!has_id || !has_size || !has_res) {
    Fail(what, std::string("bad header: missing ") + (!has_id ? "id" : !has_size ? "size" : "res"));
  }
  if (h.id == "1") h.id = "OcTree";  // OctoMap's deprecated id of the same type
  if (h.id != "OcTree") Fail(what, "the stream holds a " + h.id + ", expected an OcTree");
  return h;
}

// Walks the 2-bits-per-child encoding of writeBinaryNode over the bytes.
class BinaryWalker {
 public:
  BinaryWalker(std::string_view data, const char* what) : data_(data), what_(what) {}

  uint64_t WalkRoot() {
    nodes_ = 1;
    Walk(0);
    return nodes_;
  }
  std::size_t consumed() const { return pos_; }

 private:
  void Walk(int depth) {
    if (pos_ + 2 > data_.size()) {
      Fail(what_, "truncated data: it ends after " + std::to_string(data_.size()) +
                      " bytes, inside the tree");
    }
    const auto lo = static_cast<unsigned char>(data_[pos_]);
    const auto hi = static_cast<unsigned char>(data_[pos_ + 1]);
    pos_ += 2;
    const unsigned bits = lo | (hi << 8);  // child i: bits 2i and 2i + 1
    for (unsigned i = 0; i < 8; ++i) {
      if (((bits >> (2 * i)) & 3u) != 0) ++nodes_;
    }
    for (unsigned i = 0; i < 8; ++i) {
      if (((bits >> (2 * i)) & 3u) != 3u) continue;
      if (depth + 1 >= kTreeDepth) {
        Fail(what_, "corrupt data: inner node below depth " + std::to_string(kTreeDepth - 1));
      }
      Walk(depth + 1);
    }
  }

  std::string_view data_;
  const char* what_;
  std::size_t pos_ = 0;
  uint64_t nodes_ = 0;
};

// Walks the value + child-mask encoding of writeNodesRecurs.
class FullWalker {
 public:
  FullWalker(std::string_view data, const char* what) : data_(data), what_(what) {}

  uint64_t WalkRoot() {
    Walk(0);
    return nodes_;
  }
  std::size_t consumed() const { return pos_; }

 private:
  void Walk(int depth) {
    if (pos_ + sizeof(float) + 1 > data_.size()) {
      Fail(what_, "truncated data: it ends after " + std::to_string(data_.size()) +
                      " bytes, inside the tree");
    }
    float value = 0.0f;
    std::memcpy(&value, data_.data() + pos_, sizeof(value));
    if (!std::isfinite(value)) Fail(what_, "corrupt data: a node's log-odds is not finite");
    const auto children = static_cast<unsigned char>(data_[pos_ + sizeof(float)]);
    pos_ += sizeof(float) + 1;
    ++nodes_;
    if (children != 0 && depth >= kTreeDepth) {
      Fail(what_, "corrupt data: a leaf at depth " + std::to_string(kTreeDepth) + " has children");
    }
    for (unsigned i = 0; i < 8; ++i) {
      if (((children >> i) & 1u) != 0) Walk(depth + 1);
    }
  }

  std::string_view data_;
  const char* what_;
  std::size_t pos_ = 0;
  uint64_t nodes_ = 0;
};

template <typename Walker>
void CheckData(std::string_view bytes, const Header& h, const char* what) {
  const std::string_view data = bytes.substr(h.data_offset);
  uint64_t nodes = 0;
  std::size_t consumed = 0;
  if (h.size > 0) {
    Walker walker(data, what);
    nodes = walker.WalkRoot();
    consumed = walker.consumed();
  }
  if (nodes != h.size) {
    Fail(what, "corrupt data: the header says " + std::to_string(h.size) +
                   " nodes, the data holds " + std::to_string(nodes));
  }
  if (consumed != data.size()) {
    Fail(what, std::to_string(data.size() - consumed) + " unexpected bytes after the tree data");
  }
}

}  // namespace

std::string EncodeOctreeBinary(const octomap::OcTree& tree) {
  std::ostringstream out(std::ios::out | std::ios::binary);
  if (!tree.writeBinaryConst(out)) throw std::runtime_error("EncodeOctreeBinary: write failed");
  return std::move(out).str();
}

std::unique_ptr<octomap::OcTree> DecodeOctreeBinary(std::string_view bytes) {
  constexpr const char* kWhat = "DecodeOctreeBinary";
  const Header h = ParseHeader(bytes, kBinaryMagic, kFullMagic, kWhat, "DecodeOctreeFull");
  CheckData<BinaryWalker>(bytes, h, kWhat);
  auto tree = std::make_unique<octomap::OcTree>(h.resolution_m);
  if (h.size == 0) return tree;
  std::istringstream in(std::string(bytes), std::ios::in | std::ios::binary);
  if (!tree->readBinary(in)) Fail(kWhat, "OctoMap rejected the stream");
  return tree;
}

std::string EncodeOctreeFull(const octomap::OcTree& tree) {
  std::ostringstream out(std::ios::out | std::ios::binary);
  if (!tree.write(out)) throw std::runtime_error("EncodeOctreeFull: write failed");
  return std::move(out).str();
}

std::unique_ptr<octomap::OcTree> DecodeOctreeFull(std::string_view bytes) {
  constexpr const char* kWhat = "DecodeOctreeFull";
  const Header h = ParseHeader(bytes, kFullMagic, kBinaryMagic, kWhat, "DecodeOctreeBinary");
  CheckData<FullWalker>(bytes, h, kWhat);
  // OctoMap would read a root from the absent data of an empty tree.
  if (h.size == 0) return std::make_unique<octomap::OcTree>(h.resolution_m);
  std::istringstream in(std::string(bytes), std::ios::in | std::ios::binary);
  std::unique_ptr<octomap::AbstractOcTree> read(octomap::AbstractOcTree::read(in));
  auto* tree = dynamic_cast<octomap::OcTree*>(read.get());
  if (tree == nullptr) Fail(kWhat, "OctoMap rejected the stream");
  read.release();
  return std::unique_ptr<octomap::OcTree>(tree);
}

}  // namespace rover::mapping
