#include <fcntl.h>
#include <httplib.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <optional>
#include <system_error>
#include <thread>

#include "core/log/archive/log_name.h"
#include "core/log/archive/sha256.h"
#include "host/log/commands.h"
#include "host/log/format.h"
#include "host/log/log_service_client.h"

namespace rover::host {
namespace fs = std::filesystem;
namespace {

using Clock = std::chrono::steady_clock;

constexpr size_t kMaxErrorBodyBytes = 2048;
constexpr double kRedrawPeriodS = 0.1;
constexpr int kBarWidth = 24;

std::string ErrnoText(int err) { return std::error_code(err, std::generic_category()).message(); }

std::string Trimmed(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ')) s.pop_back();
  return s;
}

std::string FormatEta(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "--:--";
  const auto total_s = static_cast<long long>(std::llround(seconds));
  char text[32];
  if (total_s >= 3600) {
    std::snprintf(text, sizeof text, "%lld:%02lld:%02lld", total_s / 3600, (total_s / 60) % 60,
                  total_s % 60);
  } else {
    std::snprintf(text, sizeof text, "%lld:%02lld", total_s / 60, total_s % 60);
  }
  return text;
}

// Progress on stderr: one line redrawn in place on a terminal, otherwise a
// line at every 10 %. The rate counts this run's bytes only (not what a
// previous run left in the .part file).
class ProgressBar {
 public:
  ProgressBar(std::ostream& err, std::string name, uint64_t total_bytes, uint64_t start_bytes,
              bool tty)
      : err_(err),
        name_(std::move(name)),
        total_bytes_(total_bytes),
        start_bytes_(start_bytes),
        tty_(tty),
        start_(Clock::now()),
        last_draw_(start_),
        next_decile_(Decile(start_bytes) + 1) {}

  void Update(uint64_t done_bytes) {
    done_bytes_ = done_bytes;
    const Clock::time_point now = Clock::now();
    if (tty_) {
      if (std::chrono::duration<double>(now - last_draw_).count() >= kRedrawPeriodS ||
          done_bytes == total_bytes_) {
        Draw(now);
      }
    } else if (total_bytes_ > 0 && Decile(done_bytes) >= next_decile_) {
      next_decile_ = Decile(done_bytes) + 1;
      Draw(now);
    }
  }

  // A message on its own line (retries), without garbling the bar.
  void Note(const std::string& text) {
    if (tty_ && drawn_) err_ << "\n";
    drawn_ = false;
    err_ << text << "\n";
  }

  void Finish() {
    if (tty_) {
      Draw(Clock::now());
      err_ << "\n";
    }
    drawn_ = false;
  }

 private:
  int Decile(uint64_t done) const {
    return total_bytes_ == 0 ? 10 : static_cast<int>(done * 10 / total_bytes_);
  }

  void Draw(Clock::time_point now) {
    last_draw_ = now;
    const double elapsed_s = std::chrono::duration<double>(now - start_).count();
    const double rate =
        elapsed_s > 0 ? static_cast<double>(done_bytes_ - start_bytes_) / elapsed_s : 0.0;
    const double fraction =
        total_bytes_ == 0 ? 1.0
                          : static_cast<double>(done_bytes_) / static_cast<double>(total_bytes_);
    const double eta_s = rate > 0 ? static_cast<double>(total_bytes_ - done_bytes_) / rate
                                  : std::numeric_limits<double>::quiet_NaN();
    const std::string rate_text = FormatBytes(static_cast<uint64_t>(rate)) + "/s";
    char percent[16];
    std::snprintf(percent, sizeof percent, "%5.1f %%", 100.0 * fraction);
    if (tty_) {
      const int filled = static_cast<int>(fraction * kBarWidth);
      err_ << "\r" << name_ << " [" << std::string(static_cast<size_t>(filled), '#')
           << std::string(static_cast<size_t>(kBarWidth - filled), '-') << "] " << percent << "  "
           << FormatBytes(done_bytes_) << " / " << FormatBytes(total_bytes_) << "  " << rate_text
           << "  ETA " << FormatEta(eta_s) << "   " << std::flush;
      drawn_ = true;
    } else {
      err_ << name_ << ": " << percent << " (" << FormatBytes(done_bytes_) << " of "
           << FormatBytes(total_bytes_) << ") at " << rate_text << ", ETA " << FormatEta(eta_s)
           << "\n";
    }
  }

  std::ostream& err_;
  const std::string name_;
  const uint64_t total_bytes_;
  const uint64_t start_bytes_;
  const bool tty_;
  const Clock::time_point start_;
  Clock::time_point last_draw_;
  int next_decile_;
  uint64_t done_bytes_ = 0;
  bool drawn_ = false;
};

// What one ranged GET achieved.
struct Attempt {
  enum class Outcome {
    kDone,       ///< Every listed byte is in the .part file.
    kTransient,  ///< Cut, timeout, 5xx, 503: worth retrying.
    kFatal,      ///< Retrying cannot help (401, 404, 416, bad answer).
  };
  Outcome outcome = Outcome::kTransient;
  int status = 0;
  std::string error;
  uint64_t received_bytes = 0;
  std::optional<double> retry_after_s;
};

// Sends GET /logs/NAME for bytes [*have_bytes, total_bytes) and appends them to `fd`.
Attempt FetchRange(const LogServiceEndpoint& endpoint, const std::string& token,
                   const LogServiceAccess& access, const std::string& name, uint64_t total_bytes,
                   int fd, uint64_t* have_bytes, ProgressBar* progress) {
  Attempt attempt;
  httplib::Client client(endpoint.host, endpoint.port);
  client.set_connection_timeout(access.connect_timeout_s, 0);
  client.set_read_timeout(access.read_timeout_s, 0);
  client.set_bearer_token_auth(token);
  const std::string range =
      "bytes=" + std::to_string(*have_bytes) + "-" + std::to_string(total_bytes - 1);
  const httplib::Headers headers = {{"Range", range}};
  std::string error_body;
  std::string write_error;
  std::string answer_error;
  bool accept_body = false;

  auto result = client.Get(
      "/logs/" + name, headers,
      [&](const httplib::Response& res) {
        attempt.status = res.status;
        if (res.has_header("Retry-After")) {
          const std::string text = res.get_header_value("Retry-After");
          if (!text.empty() && text.find_first_not_of("0123456789") == std::string::npos &&
              text.size() < 7) {
            attempt.retry_after_s = std::stod(text);
          }
        }
        if (res.status == 206) {
          const std::string expected = "bytes " + std::to_string(*have_bytes) + "-";
          const std::string content_range = res.get_header_value("Content-Range");
          if (!content_range.starts_with(expected)) {
            answer_error = "expected a Content-Range starting with \"" + expected + "\", found \"" +
                           content_range + "\"";
            return false;
          }
          accept_body = true;
        } else if (res.status == 200) {
          // The service ignored the range: the body starts at byte 0.
          if (*have_bytes > 0 && ::ftruncate(fd, 0) != 0) {
            write_error = "cannot truncate the .part file: " + ErrnoText(errno);
            return false;
          }
          *have_bytes = 0;
          accept_body = true;
        }
        return true;
      },
      [&](const char* data, size_t n) {
        if (!accept_body) {
          error_body.append(data, std::min(n, kMaxErrorBodyBytes -
                                                  std::min(kMaxErrorBodyBytes, error_body.size())));
          return true;
        }
        // Never write past the listed size (a growing log may serve more).
        const auto take = static_cast<size_t>(std::min<uint64_t>(n, total_bytes - *have_bytes));
        size_t written = 0;
        while (written < take) {
          const ssize_t w = ::pwrite(fd, data + written, take - written,
                                     static_cast<off_t>(*have_bytes + written));
          if (w < 0 && errno == EINTR) continue;
          if (w <= 0) {
            write_error = "cannot write the .part file: " + ErrnoText(errno);
            return false;
          }
          written += static_cast<size_t>(w);
        }
        *have_bytes += take;
        attempt.received_bytes += take;
        progress->Update(*have_bytes);
        return *have_bytes < total_bytes;
      });

  if (!write_error.empty()) {
    attempt.outcome = Attempt::Outcome::kFatal;
    attempt.error = write_error;
    return attempt;
  }
  if (!answer_error.empty()) {
    attempt.outcome = Attempt::Outcome::kFatal;
    attempt.error = "unexpected answer from the log service: " + answer_error;
    return attempt;
  }
  if (*have_bytes == total_bytes && accept_body) {
    attempt.outcome = Attempt::Outcome::kDone;
    return attempt;
  }
  if (!result) {
    attempt.error = DescribeTransportError(result.error());
    return attempt;  // Transient: connection refused, cut, timeout.
  }
  const int status = result->status;
  const std::string text = Trimmed(error_body);
  if (status == 200 || status == 206) {
    attempt.error = "the answer ended after " + std::to_string(*have_bytes) + " of " +
                    std::to_string(total_bytes) + " bytes";
    return attempt;
  }
  attempt.error = "HTTP " + std::to_string(status) + (text.empty() ? "" : ": " + text);
  if (status == 503 || status >= 500) return attempt;
  attempt.outcome = Attempt::Outcome::kFatal;
  return attempt;
}

bool SyncDirectory(const fs::path& dir) {
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return false;
  const bool ok = ::fsync(fd) == 0;
  ::close(fd);
  return ok;
}

}  // namespace

int RunDownload(const DownloadOptions& options, std::ostream& out, std::ostream& err) {
  const std::string tool = "rover-log download: ";
  LogServiceEndpoint endpoint;
  std::string token;
  try {
    std::string why;
    if (!log::IsValidLogName(options.name, &why)) throw UsageError("log name: " + why);
    if (options.retries < 0) {
      throw UsageError("expected --retries >= 0, found " + std::to_string(options.retries));
    }
    endpoint = ParseLogServiceUrl(options.access.url);
    token = ResolveLogToken(options.access.token, options.access.token_file);
  } catch (const UsageError& e) {
    err << tool << e.what() << "\n";
    return 2;
  }
  const fs::path dir = options.out_dir.empty() ? fs::path(".") : fs::path(options.out_dir);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (!fs::is_directory(dir, ec)) {
    err << tool << "expected --out to be a folder (created if missing), found " << dir.string()
        << " is not one" << (ec ? ": " + ec.message() : std::string()) << "\n";
    return 2;
  }
  const fs::path final_path = dir / options.name;
  const fs::path part_path = dir / (options.name + ".part");

  // What to fetch: the listed size and hash.
  log::LogListingEntry entry;
  {
    std::optional<log::LogListingEntry> found;
    std::string last_error;
    for (int failures = 0; !found; ++failures) {
      try {
        for (const auto& e : FetchLogListing(endpoint, token,
                                             {.connect_timeout_s = options.access.connect_timeout_s,
                                             .read_timeout_s = options.access.read_timeout_s})) {
          if (e.name == options.name) found = e;
        }
        if (!found) {
          err << tool << "expected the service to list " << options.name
              << ", found no such log (see rover-log list)\n";
          return 2;
        }
      } catch (const LogServiceError& e) {
        if (e.http_status() == 401) {
          err << tool << e.what() << "\n";
          return 2;
        }
        if ((e.http_status() != 0 && e.http_status() < 500) || failures >= options.retries) {
          err << tool << e.what() << "\n";
          return 1;
        }
        const double wait_s =
            std::min(options.max_backoff_s, options.initial_backoff_s * std::pow(2.0, failures));
        err << tool << e.what() << "; retrying in " << wait_s << " s\n";
        std::this_thread::sleep_for(std::chrono::duration<double>(wait_s));
      } catch (const std::exception& e) {
        err << tool << e.what() << "\n";
        return 1;
      }
    }
    entry = *found;
  }
  if (options.hooks.after_listing) options.hooks.after_listing();
  const uint64_t total_bytes = entry.size_bytes;

  // O_NOFOLLOW: never write through a link planted under the .part name.
  const int fd = ::open(part_path.c_str(), O_WRONLY | O_CREAT | O_CLOEXEC | O_NOFOLLOW, 0644);
  if (fd < 0) {
    err << tool << "cannot create " << part_path.string() << ": " << ErrnoText(errno) << "\n";
    return 1;
  }
  // One download per .part file at a time.
  if (::flock(fd, LOCK_EX | LOCK_NB) != 0) {
    err << tool << "expected no other download into " << part_path.string()
        << ", found it locked by another rover-log download\n";
    ::close(fd);
    return 1;
  }
  // Resume from what an earlier run left.
  struct stat st {};
  uint64_t have_bytes = ::fstat(fd, &st) == 0 ? static_cast<uint64_t>(st.st_size) : 0;
  if (have_bytes > total_bytes) {
    out << "discarding " << part_path.string() << ": it holds " << have_bytes
        << " bytes, more than the " << total_bytes << " listed\n";
    have_bytes = 0;
  } else if (have_bytes > 0) {
    out << "resuming " << options.name << " at byte " << have_bytes << " of " << total_bytes
        << "\n";
  }
  if (::ftruncate(fd, static_cast<off_t>(have_bytes)) != 0) {
    err << tool << "cannot resize " << part_path.string() << ": " << ErrnoText(errno) << "\n";
    ::close(fd);
    return 1;
  }

  ProgressBar progress(err, options.name, total_bytes, have_bytes, options.progress_tty);
  int failures = 0;
  while (have_bytes < total_bytes) {
    const Attempt attempt = FetchRange(endpoint, token, options.access, options.name, total_bytes,
                                       fd, &have_bytes, &progress);
    if (attempt.outcome == Attempt::Outcome::kDone) break;
    if (attempt.outcome == Attempt::Outcome::kFatal) {
      progress.Note(tool + "GET /logs/" + options.name + " failed: " + attempt.error);
      ::close(fd);
      if (attempt.status == 416) {
        fs::remove(part_path, ec);
        err << tool << "the service now serves fewer bytes than listed; deleted "
            << part_path.string() << ", run the command again\n";
      } else {
        err << tool << part_path.string() << " keeps the first " << have_bytes
            << " bytes; run the same command to resume\n";
      }
      return attempt.status == 401 ? 2 : 1;
    }
    failures = attempt.received_bytes > 0 ? 0 : failures + 1;
    if (failures > options.retries) {
      progress.Note(tool + "giving up after " + std::to_string(options.retries) +
                    " retries without progress: " + attempt.error);
      ::close(fd);
      err << tool << part_path.string() << " keeps the first " << have_bytes
          << " bytes; run the same command to resume\n";
      return 1;
    }
    double wait_s = std::min(options.max_backoff_s,
                             options.initial_backoff_s * std::pow(2.0, std::max(0, failures - 1)));
    if (attempt.retry_after_s) wait_s = std::min(options.max_backoff_s, *attempt.retry_after_s);
    char wait_text[32];
    std::snprintf(wait_text, sizeof wait_text, "%.1f", wait_s);
    progress.Note(tool + "transfer interrupted at byte " + std::to_string(have_bytes) + " of " +
                  std::to_string(total_bytes) + " (" + attempt.error + "); resuming with a Range " +
                  "request in " + wait_text + " s");
    std::this_thread::sleep_for(std::chrono::duration<double>(wait_s));
  }
  progress.Finish();
  // The lock is held (fd open) until the file has its final name.
  struct FdCloser {
    int fd;
    ~FdCloser() { ::close(fd); }
  } closer{fd};
  if (::fsync(fd) != 0) {
    err << tool << "cannot write " << part_path.string() << ": " << ErrnoText(errno) << "\n";
    return 1;
  }

  if (options.hooks.before_verify) options.hooks.before_verify(part_path.string());
  std::string found_sha;
  try {
    found_sha = log::Sha256FileHex(part_path.string());
  } catch (const std::exception& e) {
    err << tool << e.what() << "\n";
    return 1;
  }
  if (found_sha != entry.sha256) {
    fs::remove(part_path, ec);
    err << tool << "SHA-256 mismatch for " << options.name << ": expected " << entry.sha256
        << " (from the listing), found " << found_sha << " (downloaded " << total_bytes
        << " bytes); deleted " << part_path.string() << ", nothing was saved as "
        << final_path.string() << "\n";
    return 1;
  }
  // Atomic: DIR/NAME appears complete and verified, or not at all (an older
  // DIR/NAME is replaced only now).
  fs::rename(part_path, final_path, ec);
  if (ec) {
    err << tool << "cannot rename " << part_path.string() << " to " << final_path.string() << ": "
        << ec.message() << "\n";
    return 1;
  }
  SyncDirectory(dir);
  out << "downloaded " << options.name << " (" << FormatBytes(total_bytes) << ", "
      << (entry.complete ? "complete" : "in-progress log, up to its last complete record")
      << ") to " << final_path.string() << "\nsha256 " << found_sha << " verified\n";
  return 0;
}

}  // namespace rover::host
