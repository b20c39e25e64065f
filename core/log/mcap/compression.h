#ifndef ROVER_CORE_LOG_MCAP_COMPRESSION_H_
#define ROVER_CORE_LOG_MCAP_COMPRESSION_H_

// Internal to core/log/mcap: chunk compression with reusable library contexts
// (zstd, LZ4 frame), so steady-state writing and reading does not allocate.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>

#include "core/log/mcap/mcap_types.h"

namespace rover::log::internal {

/// Largest uncompressed chunk the reader accepts (1 GiB). Bigger claims are
/// treated as damage, so a hostile length field cannot make us allocate more.
inline constexpr uint64_t kMaxUncompressedChunkSize = uint64_t{1} << 30;

/// A grow-only byte buffer that does not zero what it allocates, for
/// decompression targets that are fully overwritten anyway.
class ByteBuffer {
 public:
  std::byte* data() { return data_.get(); }
  const std::byte* data() const { return data_.get(); }
  size_t size() const { return size_; }
  /// Sets the size to `n`, reallocating (and dropping the contents) only when
  /// `n` exceeds the capacity.
  void ResizeUninitialized(size_t n);
  std::span<const std::byte> view() const { return {data_.get(), size_}; }

 private:
  std::unique_ptr<std::byte[]> data_;
  size_t size_ = 0;
  size_t capacity_ = 0;
};

/// Compresses whole chunks with one algorithm, reusing its context.
class ChunkCompressor {
 public:
  /// Throws McapError if the library context cannot be created or the zstd
  /// level is outside the library's range.
  ChunkCompressor(Compression compression, int zstd_level);
  ~ChunkCompressor();
  ChunkCompressor(const ChunkCompressor&) = delete;
  ChunkCompressor& operator=(const ChunkCompressor&) = delete;

  Compression compression() const { return compression_; }
  /// Worst-case compressed size of `n` input bytes.
  size_t Bound(size_t n) const;
  /// Compresses `src` into `dst` (which must hold Bound(src.size()) bytes) and
  /// returns the compressed size. Throws McapError on a library failure.
  size_t Compress(std::span<const std::byte> src, std::span<std::byte> dst);

 private:
  struct Contexts;
  Compression compression_;
  int zstd_level_;
  std::unique_ptr<Contexts> contexts_;
};

/// Decompresses chunk records, reusing its contexts. Never trusts sizes from
/// the file: the output must be exactly the declared size, which is capped.
class ChunkDecompressor {
 public:
  ChunkDecompressor();
  ~ChunkDecompressor();
  ChunkDecompressor(ChunkDecompressor&&) noexcept;
  ChunkDecompressor& operator=(ChunkDecompressor&&) noexcept;

  /// Decompresses `src` (compressed with `compression`: "zstd" or "lz4") into
  /// `out`, which must then hold exactly `uncompressed_size` bytes. On failure
  /// returns false and says why in `error` (unknown compression, implausible
  /// size, corrupt stream, size mismatch).
  bool Decompress(std::string_view compression, std::span<const std::byte> src,
                  uint64_t uncompressed_size, ByteBuffer* out, std::string* error);

 private:
  struct Contexts;
  std::unique_ptr<Contexts> contexts_;
};

}  // namespace rover::log::internal

#endif  // ROVER_CORE_LOG_MCAP_COMPRESSION_H_
