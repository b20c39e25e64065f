#include "core/log/archive/sha256.h"

#include <fcntl.h>
#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <stdexcept>
#include <system_error>
#include <vector>

namespace rover::log {
namespace {

constexpr size_t kReadBlockBytes = 256 * 1024;

std::string ErrnoText(int err) { return std::error_code(err, std::generic_category()).message(); }

EVP_MD_CTX* NewContext() {
  EVP_MD_CTX* ctx = EVP_MD_CTX_new();
  if (ctx == nullptr) throw std::runtime_error("SHA-256: EVP_MD_CTX_new failed (out of memory)");
  if (EVP_DigestInit_ex(ctx, EVP_sha256(), nullptr) != 1) {
    EVP_MD_CTX_free(ctx);
    throw std::runtime_error("SHA-256: EVP_DigestInit_ex(EVP_sha256) failed");
  }
  return ctx;
}

}  // namespace

Sha256::Sha256() : ctx_(NewContext()) {}

Sha256::Sha256(const Sha256& other) : ctx_(EVP_MD_CTX_new()), size_bytes_(other.size_bytes_) {
  if (ctx_ == nullptr || EVP_MD_CTX_copy_ex(ctx_, other.ctx_) != 1) {
    EVP_MD_CTX_free(ctx_);
    throw std::runtime_error("SHA-256: copying the hash state failed");
  }
}

Sha256& Sha256::operator=(const Sha256& other) {
  if (this != &other) {
    if (EVP_MD_CTX_copy_ex(ctx_, other.ctx_) != 1) {
      throw std::runtime_error("SHA-256: copying the hash state failed");
    }
    size_bytes_ = other.size_bytes_;
  }
  return *this;
}

Sha256::~Sha256() { EVP_MD_CTX_free(ctx_); }

void Sha256::Update(std::span<const std::byte> bytes) {
  if (bytes.empty()) return;
  if (EVP_DigestUpdate(ctx_, bytes.data(), bytes.size()) != 1) {
    throw std::runtime_error("SHA-256: EVP_DigestUpdate failed");
  }
  size_bytes_ += bytes.size();
}

void Sha256::Update(std::string_view text) { Update(std::as_bytes(std::span(text))); }

Sha256Digest Sha256::Digest() const {
  Sha256 copy(*this);
  Sha256Digest digest{};
  unsigned int length = 0;
  if (EVP_DigestFinal_ex(copy.ctx_, digest.data(), &length) != 1 || length != digest.size()) {
    throw std::runtime_error("SHA-256: EVP_DigestFinal_ex failed: expected a 32-byte digest, got " +
                             std::to_string(length) + " bytes");
  }
  return digest;
}

std::string Sha256::HexDigest() const { return ToHex(Digest()); }

std::string ToHex(const Sha256Digest& digest) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string hex;
  hex.reserve(2 * digest.size());
  for (const uint8_t b : digest) {
    hex.push_back(kHex[b >> 4]);
    hex.push_back(kHex[b & 0x0F]);
  }
  return hex;
}

std::string Sha256Hex(std::span<const std::byte> bytes) {
  Sha256 sha;
  sha.Update(bytes);
  return sha.HexDigest();
}

void Sha256UpdateFromFile(int fd, uint64_t offset_bytes, uint64_t length_bytes,
                          const std::string& name, Sha256* sha) {
  std::vector<std::byte> buffer(static_cast<size_t>(
      std::min<uint64_t>(kReadBlockBytes, std::max<uint64_t>(length_bytes, 1))));
  uint64_t done = 0;
  while (done < length_bytes) {
    const size_t want = static_cast<size_t>(std::min<uint64_t>(buffer.size(), length_bytes - done));
    const ssize_t got = ::pread(fd, buffer.data(), want, static_cast<off_t>(offset_bytes + done));
    if (got < 0) {
      if (errno == EINTR) continue;
      throw std::runtime_error("SHA-256 of " + name + ": read at offset " +
                               std::to_string(offset_bytes + done) +
                               " failed: " + ErrnoText(errno));
    }
    if (got == 0) {
      throw std::runtime_error(
          "SHA-256 of " + name + ": expected " + std::to_string(offset_bytes + length_bytes) +
          " bytes, found the file ends at " + std::to_string(offset_bytes + done));
    }
    sha->Update(std::span(buffer.data(), static_cast<size_t>(got)));
    done += static_cast<uint64_t>(got);
  }
}

std::string Sha256FileHex(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw std::runtime_error("cannot open " + path + ": " + ErrnoText(errno));
  Sha256 sha;
  try {
    std::vector<std::byte> buffer(kReadBlockBytes);
    for (;;) {
      const ssize_t got = ::read(fd, buffer.data(), buffer.size());
      if (got < 0) {
        if (errno == EINTR) continue;
        throw std::runtime_error("cannot read " + path + ": " + ErrnoText(errno));
      }
      if (got == 0) break;
      sha.Update(std::span(buffer.data(), static_cast<size_t>(got)));
    }
  } catch (...) {
    ::close(fd);
    throw;
  }
  ::close(fd);
  return sha.HexDigest();
}

bool ConstantTimeEquals(std::string_view a, std::string_view b) {
  Sha256 ha;
  ha.Update(a);
  Sha256 hb;
  hb.Update(b);
  const Sha256Digest da = ha.Digest();
  const Sha256Digest db = hb.Digest();
  return CRYPTO_memcmp(da.data(), db.data(), da.size()) == 0;
}

}  // namespace rover::log
