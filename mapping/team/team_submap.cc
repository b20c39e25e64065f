#include "mapping/team/team_submap.h"

#include <zstd.h>

#include <cmath>
#include <cstring>
#include <string>

#include "core/log/msgs/message_traits.h"
#include "mapping/submap/submap_messages.h"
#include "mapping/team/message_head.h"

namespace rover::mapping {
namespace {

using team_internal::CheckEnd;
using team_internal::Kind;
using team_internal::ReadHead;
using team_internal::WriteHead;

// Writes `v` little-endian at `at` (and moves `at` on).
void PutU32(uint32_t v, std::vector<uint8_t>* out, std::size_t* at) {
  for (int b = 0; b < 4; ++b) (*out)[(*at)++] = static_cast<uint8_t>(v >> (8 * b));
}

// Appends a length-prefixed CDR message. The buffer is sized first and
// written by index: a vector insert after push_backs trips a false
// stringop-overflow warning in GCC 12 at -O3.
void PutMessage(std::span<const std::byte> cdr, std::vector<uint8_t>* out, std::size_t* at) {
  PutU32(static_cast<uint32_t>(cdr.size()), out, at);
  if (!cdr.empty()) std::memcpy(out->data() + *at, cdr.data(), cdr.size());
  *at += cdr.size();
}

template <typename M>
void ReadMessage(link::wire::Reader* r, const char* what, M* msg) {
  const uint32_t size = r->U32();
  const std::span<const uint8_t> cdr = r->Bytes(size);
  if (r->failed()) throw TeamMessageError(std::string("team submap: ") + what + " truncated");
  std::string error;
  if (!log::DeserializeMessage(std::as_bytes(cdr), msg, &error)) {
    throw TeamMessageError(std::string("team submap: ") + what + ": " + error);
  }
}

// The cloud travels quantised to 1 mm (its points are centroids of 5 cm
// voxels), each axis delta-coded between successive points and split into
// byte planes: zstd then finds the long runs that float bytes never have.
constexpr double kCloudQuantumM = 0.001;

uint32_t ZigZag(int32_t v) {
  return (static_cast<uint32_t>(v) << 1) ^ static_cast<uint32_t>(v >> 31);
}
int32_t UnZigZag(uint32_t v) { return static_cast<int32_t>(v >> 1) ^ -static_cast<int32_t>(v & 1); }

// The point count, then the planes (see kCloudQuantumM).
std::vector<uint8_t> CloudPlanes(const log::sensor_msgs::PointCloud2& msg) {
  const PointCloud cloud = FromPointCloud2(msg);
  const std::size_t n = cloud.size();
  std::vector<uint8_t> out(4 + 13 * n);
  std::size_t at = 0;
  PutU32(static_cast<uint32_t>(n), &out, &at);
  uint8_t* planes = out.data() + at;
  for (int axis = 0; axis < 3; ++axis) {
    int32_t previous = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const int32_t q = static_cast<int32_t>(
          std::lround(static_cast<double>(cloud[i].p_submap_m[axis]) / kCloudQuantumM));
      const uint32_t z = ZigZag(q - previous);
      previous = q;
      for (int b = 0; b < 4; ++b) {
        planes[(static_cast<std::size_t>(axis) * 4 + static_cast<std::size_t>(b)) * n + i] =
            static_cast<uint8_t>(z >> (8 * b));
      }
    }
  }
  for (std::size_t i = 0; i < n; ++i) planes[12 * n + i] = cloud[i].obstacle ? 1 : 0;
  return out;
}

log::sensor_msgs::PointCloud2 ReadCloud(link::wire::Reader* r,
                                        const log::std_msgs::Header& header) {
  const uint32_t n = r->U32();
  if (r->failed() || static_cast<std::size_t>(n) * 13 > r->remaining()) {
    throw TeamMessageError("team submap: cloud truncated");
  }
  const std::span<const uint8_t> planes = r->Bytes(static_cast<std::size_t>(n) * 13);
  PointCloud cloud(n);
  for (int axis = 0; axis < 3; ++axis) {
    int32_t value = 0;
    for (std::size_t i = 0; i < n; ++i) {
      uint32_t z = 0;
      for (int b = 0; b < 4; ++b) {
        z |= static_cast<uint32_t>(
                 planes[(static_cast<std::size_t>(axis) * 4 + static_cast<std::size_t>(b)) * n + i])
             << (8 * b);
      }
      value += UnZigZag(z);
      cloud[i].p_submap_m[axis] = static_cast<float>(value * kCloudQuantumM);
    }
  }
  for (std::size_t i = 0; i < n; ++i)
    cloud[i].obstacle = planes[12 * static_cast<std::size_t>(n) + i] != 0;
  return ToPointCloud2(cloud, header);
}

}  // namespace

std::vector<uint8_t> EncodeSubmap(const TeamSubmap& submap, int level) {
  const std::vector<std::byte> info = log::SerializeMessage(submap.info);
  const std::vector<std::byte> octomap = log::SerializeMessage(submap.octomap);
  const std::vector<uint8_t> cloud = CloudPlanes(submap.cloud);
  std::vector<uint8_t> raw(8 + info.size() + octomap.size() + cloud.size());
  std::size_t at = 0;
  PutMessage(info, &raw, &at);
  PutMessage(octomap, &raw, &at);
  std::memcpy(raw.data() + at, cloud.data(), cloud.size());
  std::vector<uint8_t> out;
  link::wire::Writer w(&out);
  WriteHead(&w, Kind::kSubmap);
  w.U64(raw.size());
  const std::size_t head = out.size();
  out.resize(head + ZSTD_compressBound(raw.size()));
  // With the frame's content checksum: a damaged submap is refused rather
  // than decoded into a wrong map.
  ZSTD_CCtx* context = ZSTD_createCCtx();
  if (context == nullptr) throw TeamMessageError("team submap: zstd: no context");
  ZSTD_CCtx_setParameter(context, ZSTD_c_compressionLevel, level);
  ZSTD_CCtx_setParameter(context, ZSTD_c_checksumFlag, 1);
  const std::size_t n =
      ZSTD_compress2(context, out.data() + head, out.size() - head, raw.data(), raw.size());
  ZSTD_freeCCtx(context);
  if (ZSTD_isError(n)) {
    throw TeamMessageError(std::string("team submap: zstd: ") + ZSTD_getErrorName(n));
  }
  out.resize(head + n);
  return out;
}

TeamSubmap DecodeSubmap(std::span<const uint8_t> bytes) {
  link::wire::Reader r(bytes);
  ReadHead(&r, Kind::kSubmap);
  const uint64_t raw_size = r.U64();
  if (r.failed()) throw TeamMessageError("team submap: truncated header");
  if (raw_size > kMaxTeamSubmapBytes) {
    throw TeamMessageError("team submap: states " + std::to_string(raw_size) +
                           " bytes, more than the " + std::to_string(kMaxTeamSubmapBytes) +
                           " accepted");
  }
  const std::span<const uint8_t> compressed = r.Bytes(r.remaining());
  std::vector<uint8_t> raw(raw_size);
  const std::size_t n =
      ZSTD_decompress(raw.data(), raw.size(), compressed.data(), compressed.size());
  if (ZSTD_isError(n) || n != raw_size) {
    throw TeamMessageError(std::string("team submap: does not decompress to the ") +
                           std::to_string(raw_size) + " bytes it states" +
                           (ZSTD_isError(n) ? std::string(": ") + ZSTD_getErrorName(n) : ""));
  }
  TeamSubmap out;
  link::wire::Reader body(raw);
  ReadMessage(&body, "SubmapInfo", &out.info);
  ReadMessage(&body, "Octomap", &out.octomap);
  out.cloud = ReadCloud(&body, out.info.header);
  CheckEnd(body, Kind::kSubmap);
  return out;
}

}  // namespace rover::mapping
