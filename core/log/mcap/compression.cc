#include "core/log/mcap/compression.h"

#include <lz4frame.h>
#include <zstd.h>

#include <algorithm>

namespace rover::log {

std::string_view CompressionName(Compression compression) {
  switch (compression) {
    case Compression::kNone:
      return "";
    case Compression::kZstd:
      return "zstd";
    case Compression::kLz4:
      return "lz4";
  }
  return "";
}

namespace internal {
namespace {

// The best ratios the formats can reach: a zstd RLE block turns 4 bytes into
// 128 KiB (32768:1); an LZ4 sequence encodes at most ~255 bytes of match per
// input byte. A chunk claiming more than this (plus slack for frame headers)
// is damaged or hostile, and we refuse before allocating its output.
constexpr uint64_t kMaxZstdRatio = 32768;
constexpr uint64_t kMaxLz4Ratio = 1024;
constexpr uint64_t kRatioSlack = 4096;

LZ4F_preferences_t Lz4Preferences(size_t content_size) {
  LZ4F_preferences_t prefs{};
  // Storing the content size lets any reader size its buffer from the frame.
  prefs.frameInfo.contentSize = content_size;
  prefs.compressionLevel = 0;  // The fast default; the writer is a logging thread.
  return prefs;
}

}  // namespace

void ByteBuffer::ResizeUninitialized(size_t n) {
  if (n > capacity_) {
    data_.reset(new std::byte[n]);
    capacity_ = n;
  }
  size_ = n;
}

struct ChunkCompressor::Contexts {
  ZSTD_CCtx* zstd = nullptr;
  LZ4F_cctx* lz4 = nullptr;
  ~Contexts() {
    ZSTD_freeCCtx(zstd);
    if (lz4 != nullptr) LZ4F_freeCompressionContext(lz4);
  }
};

ChunkCompressor::ChunkCompressor(Compression compression, int zstd_level)
    : compression_(compression), zstd_level_(zstd_level), contexts_(new Contexts) {
  if (compression_ == Compression::kZstd) {
    if (zstd_level < ZSTD_minCLevel() || zstd_level > ZSTD_maxCLevel()) {
      throw McapError("zstd_level " + std::to_string(zstd_level) + " is outside [" +
                      std::to_string(ZSTD_minCLevel()) + ", " + std::to_string(ZSTD_maxCLevel()) +
                      "]");
    }
    contexts_->zstd = ZSTD_createCCtx();
    if (contexts_->zstd == nullptr) throw McapError("cannot create a zstd compression context");
  } else if (compression_ == Compression::kLz4) {
    if (LZ4F_isError(LZ4F_createCompressionContext(&contexts_->lz4, LZ4F_VERSION))) {
      throw McapError("cannot create an lz4 compression context");
    }
  }
}

ChunkCompressor::~ChunkCompressor() = default;

size_t ChunkCompressor::Bound(size_t n) const {
  switch (compression_) {
    case Compression::kNone:
      return n;
    case Compression::kZstd:
      return ZSTD_compressBound(n);
    case Compression::kLz4: {
      const LZ4F_preferences_t prefs = Lz4Preferences(n);
      return LZ4F_HEADER_SIZE_MAX + LZ4F_compressBound(n, &prefs) + LZ4F_compressBound(0, &prefs);
    }
  }
  return n;
}

size_t ChunkCompressor::Compress(std::span<const std::byte> src, std::span<std::byte> dst) {
  switch (compression_) {
    case Compression::kNone:
      if (dst.size() < src.size()) throw McapError("compression output buffer too small");
      std::copy(src.begin(), src.end(), dst.begin());
      return src.size();
    case Compression::kZstd: {
      const size_t n = ZSTD_compressCCtx(contexts_->zstd, dst.data(), dst.size(), src.data(),
                                         src.size(), zstd_level_);
      if (ZSTD_isError(n)) {
        throw McapError(std::string("zstd compression failed: ") + ZSTD_getErrorName(n));
      }
      return n;
    }
    case Compression::kLz4: {
      const LZ4F_preferences_t prefs = Lz4Preferences(src.size());
      size_t pos = LZ4F_compressBegin(contexts_->lz4, dst.data(), dst.size(), &prefs);
      if (!LZ4F_isError(pos)) {
        const size_t n = LZ4F_compressUpdate(contexts_->lz4, dst.data() + pos, dst.size() - pos,
                                             src.data(), src.size(), nullptr);
        if (LZ4F_isError(n)) {
          pos = n;
        } else {
          pos += n;
          const size_t end =
              LZ4F_compressEnd(contexts_->lz4, dst.data() + pos, dst.size() - pos, nullptr);
          pos = LZ4F_isError(end) ? end : pos + end;
        }
      }
      if (LZ4F_isError(pos)) {
        throw McapError(std::string("lz4 compression failed: ") + LZ4F_getErrorName(pos));
      }
      return pos;
    }
  }
  return 0;
}

struct ChunkDecompressor::Contexts {
  ZSTD_DCtx* zstd = nullptr;
  LZ4F_dctx* lz4 = nullptr;
  ~Contexts() {
    ZSTD_freeDCtx(zstd);
    if (lz4 != nullptr) LZ4F_freeDecompressionContext(lz4);
  }
};

ChunkDecompressor::ChunkDecompressor() : contexts_(new Contexts) {}
ChunkDecompressor::~ChunkDecompressor() = default;
ChunkDecompressor::ChunkDecompressor(ChunkDecompressor&&) noexcept = default;
ChunkDecompressor& ChunkDecompressor::operator=(ChunkDecompressor&&) noexcept = default;

bool ChunkDecompressor::Decompress(std::string_view compression, std::span<const std::byte> src,
                                   uint64_t uncompressed_size, ByteBuffer* out,
                                   std::string* error) {
  const bool zstd = compression == "zstd";
  const bool lz4 = compression == "lz4";
  if (!zstd && !lz4) {
    *error = "unsupported compression '" + std::string(compression) +
             "' (expected \"\", \"zstd\" or \"lz4\")";
    return false;
  }
  const uint64_t ratio = zstd ? kMaxZstdRatio : kMaxLz4Ratio;
  const uint64_t plausible = std::min<uint64_t>(
      kMaxUncompressedChunkSize, static_cast<uint64_t>(src.size()) * ratio + kRatioSlack);
  if (uncompressed_size > plausible) {
    *error = "declared uncompressed_size " + std::to_string(uncompressed_size) +
             " is implausible for " + std::to_string(src.size()) + " bytes of " +
             std::string(compression) + " data (limit " + std::to_string(plausible) + ")";
    return false;
  }
  const auto size = static_cast<size_t>(uncompressed_size);
  out->ResizeUninitialized(size);

  if (zstd) {
    if (contexts_->zstd == nullptr) contexts_->zstd = ZSTD_createDCtx();
    if (contexts_->zstd == nullptr) {
      *error = "cannot create a zstd decompression context";
      return false;
    }
    const size_t n =
        ZSTD_decompressDCtx(contexts_->zstd, out->data(), size, src.data(), src.size());
    if (ZSTD_isError(n)) {
      *error = std::string("zstd decompression failed: ") + ZSTD_getErrorName(n) +
               " (declared uncompressed_size " + std::to_string(size) + ")";
      return false;
    }
    if (n != size) {
      *error = "zstd data decompressed to " + std::to_string(n) +
               " bytes, expected uncompressed_size " + std::to_string(size);
      return false;
    }
    return true;
  }

  if (contexts_->lz4 == nullptr &&
      LZ4F_isError(LZ4F_createDecompressionContext(&contexts_->lz4, LZ4F_VERSION))) {
    contexts_->lz4 = nullptr;
    *error = "cannot create an lz4 decompression context";
    return false;
  }
  // A previous chunk may have left the context mid-frame after an error.
  LZ4F_resetDecompressionContext(contexts_->lz4);
  size_t in_pos = 0;
  size_t out_pos = 0;
  while (true) {
    size_t in_size = src.size() - in_pos;
    size_t out_size = size - out_pos;
    const size_t hint = LZ4F_decompress(contexts_->lz4, out->data() + out_pos, &out_size,
                                        src.data() + in_pos, &in_size, nullptr);
    if (LZ4F_isError(hint)) {
      *error = std::string("lz4 decompression failed at compressed byte ") +
               std::to_string(in_pos) + ": " + LZ4F_getErrorName(hint);
      return false;
    }
    in_pos += in_size;
    out_pos += out_size;
    if (hint == 0 && in_pos == src.size()) break;  // Last frame complete, input used up.
    if (hint != 0 && in_pos == src.size()) {
      *error = "lz4 data ends mid-frame after producing " + std::to_string(out_pos) +
               " of the declared " + std::to_string(size) + " bytes";
      return false;
    }
    if (in_size == 0 && out_size == 0) {
      *error = "lz4 data decompresses to more than the declared uncompressed_size " +
               std::to_string(size);
      return false;
    }
  }
  if (out_pos != size) {
    *error = "lz4 data decompressed to " + std::to_string(out_pos) +
             " bytes, expected uncompressed_size " + std::to_string(size);
    return false;
  }
  return true;
}

}  // namespace internal
}  // namespace rover::log
