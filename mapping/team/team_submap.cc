#include "mapping/team/team_submap.h"

#include <zstd.h>

#include <string>

#include "core/log/msgs/message_traits.h"
#include "mapping/team/message_head.h"

namespace rover::mapping {
namespace {

using team_internal::CheckEnd;
using team_internal::Kind;
using team_internal::ReadHead;
using team_internal::WriteHead;

template <typename M>
void AppendMessage(const M& msg, link::wire::Writer* w) {
  const std::vector<std::byte> cdr = log::SerializeMessage(msg);
  w->U32(static_cast<uint32_t>(cdr.size()));
  w->Bytes(std::span(reinterpret_cast<const uint8_t*>(cdr.data()), cdr.size()));
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

}  // namespace

std::vector<uint8_t> EncodeSubmap(const TeamSubmap& submap, int level) {
  std::vector<uint8_t> raw;
  link::wire::Writer body(&raw);
  AppendMessage(submap.info, &body);
  AppendMessage(submap.octomap, &body);
  AppendMessage(submap.cloud, &body);
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
  ReadMessage(&body, "PointCloud2", &out.cloud);
  CheckEnd(body, Kind::kSubmap);
  return out;
}

}  // namespace rover::mapping
