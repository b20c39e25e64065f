#ifndef ROVER_FIRMWARE_RUNTIME_LOG_SERVICE_LOG_CATALOG_H_
#define ROVER_FIRMWARE_RUNTIME_LOG_SERVICE_LOG_CATALOG_H_

// The logs of one folder as the log service sees them: which names resolve
// to a servable file inside the folder, and (cached per file) how many bytes
// of each may be served with their SHA-256 and time range.

#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "core/log/archive/log_listing.h"
#include "core/log/archive/mcap_servable.h"

namespace rover::runtime {

/// A read-only file descriptor, closed when the last owner lets go.
class LogFile {
 public:
  /// Takes ownership of the open descriptor `fd`.
  explicit LogFile(int fd) : fd_(fd) {}
  /// Closes the descriptor.
  ~LogFile();
  LogFile(const LogFile&) = delete;
  LogFile& operator=(const LogFile&) = delete;
  /// The descriptor, valid while this object lives.
  int fd() const { return fd_; }

 private:
  int fd_;
};

/// A log ready to be served: its open file and what of it is servable.
struct ServableLog {
  std::string name;
  std::shared_ptr<LogFile> file;
  log::McapServableInfo info;
};

/// Why a name was refused, and the text for the client.
struct LogRefusal {
  enum class Reason {
    kBadName,        ///< Not a plain MCAP file name (log::IsValidLogName).
    kNotFound,       ///< No such file, a dangling link, or not a regular file.
    kOutsideFolder,  ///< A symbolic link that resolves outside the log folder.
    kUnreadable,     ///< The file exists but could not be opened or read.
  };
  Reason reason = Reason::kNotFound;
  std::string message;
};

class LogCatalog {
 public:
  /// Serves the logs of `folder`. Throws std::runtime_error if it is not an
  /// existing directory.
  explicit LogCatalog(const std::string& folder);

  /// Every servable log of the folder, sorted by name: files (or links that
  /// stay inside the folder) whose names pass log::IsValidLogName(). Other
  /// files are left out silently; unreadable ones too, with the reason kept
  /// for last_error().
  std::vector<log::LogListingEntry> List();

  /// Resolves `name` inside the folder, opens it and brings its servable
  /// length and SHA-256 up to date.
  std::variant<ServableLog, LogRefusal> Open(std::string_view name);

  /// The most recent problem List() skipped a file for; empty if none.
  std::string last_error() const;

  /// The log folder, canonical (symbolic links resolved).
  const std::filesystem::path& folder() const { return folder_; }

 private:
  struct Entry {
    std::mutex mutex;
    log::McapServableTracker tracker;  // guarded by mutex
  };

  std::variant<std::shared_ptr<LogFile>, LogRefusal> Resolve(std::string_view name) const;
  std::shared_ptr<Entry> EntryFor(const std::string& name);

  std::filesystem::path folder_;  // canonical
  mutable std::mutex mutex_;
  std::map<std::string, std::shared_ptr<Entry>> entries_;  // guarded by mutex_
  std::string last_error_;                                 // guarded by mutex_
};

}  // namespace rover::runtime

#endif  // ROVER_FIRMWARE_RUNTIME_LOG_SERVICE_LOG_CATALOG_H_
