#ifndef ROVER_CORE_LOG_ARCHIVE_SHA256_H_
#define ROVER_CORE_LOG_ARCHIVE_SHA256_H_

// SHA-256 (FIPS 180-4) over OpenSSL's EVP interface, for the checksums of
// served flight logs. Incremental and copyable, so a caller can keep the
// state at a prefix of a growing file and extend it later.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

struct evp_md_ctx_st;  // OpenSSL's EVP_MD_CTX, kept out of this header.

namespace rover::log {

/// The 32 bytes of a SHA-256 digest.
using Sha256Digest = std::array<uint8_t, 32>;

/// Incremental SHA-256. Throws std::runtime_error if OpenSSL fails (only on
/// allocation failure in practice).
class Sha256 {
 public:
  /// An empty hash state (the digest of no bytes).
  Sha256();
  /// Copies the state: both objects then continue independently.
  Sha256(const Sha256& other);
  /// As the copy constructor.
  Sha256& operator=(const Sha256& other);
  ~Sha256();

  /// Absorbs `bytes`.
  void Update(std::span<const std::byte> bytes);
  /// Absorbs the bytes of `text`.
  void Update(std::string_view text);
  /// The digest of everything absorbed so far. The state is unchanged, so
  /// more bytes may follow.
  Sha256Digest Digest() const;
  /// Digest() as 64 lowercase hex characters.
  std::string HexDigest() const;
  /// Number of bytes absorbed so far.
  uint64_t size_bytes() const { return size_bytes_; }

 private:
  evp_md_ctx_st* ctx_ = nullptr;
  uint64_t size_bytes_ = 0;
};

/// `digest` as 64 lowercase hex characters.
std::string ToHex(const Sha256Digest& digest);

/// SHA-256 of `bytes` as lowercase hex.
std::string Sha256Hex(std::span<const std::byte> bytes);

/// Absorbs bytes [offset_bytes, offset_bytes + length_bytes) of the open file
/// `fd` into `sha` with pread(2), never loading the file into memory. Throws
/// std::runtime_error naming `name` if the file is shorter than that range or
/// a read fails.
void Sha256UpdateFromFile(int fd, uint64_t offset_bytes, uint64_t length_bytes,
                          const std::string& name, Sha256* sha);

/// SHA-256 of the whole file at `path` as lowercase hex. Throws
/// std::runtime_error if it cannot be read.
std::string Sha256FileHex(const std::string& path);

/// True when `a` and `b` are equal, in time independent of where they differ
/// and of their lengths (both are hashed, then compared with CRYPTO_memcmp).
/// For secrets such as bearer tokens.
bool ConstantTimeEquals(std::string_view a, std::string_view b);

}  // namespace rover::log

#endif  // ROVER_CORE_LOG_ARCHIVE_SHA256_H_
