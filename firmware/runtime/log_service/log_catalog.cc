#include "firmware/runtime/log_service/log_catalog.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <set>
#include <stdexcept>
#include <system_error>

#include "core/log/archive/log_name.h"

namespace rover::runtime {
namespace fs = std::filesystem;
namespace {

std::string ErrnoText(int err) { return std::error_code(err, std::generic_category()).message(); }

// True when `path` (canonical) lies strictly below `folder` (canonical).
bool IsInside(const fs::path& folder, const fs::path& path) {
  auto f = folder.begin();
  auto p = path.begin();
  for (; f != folder.end(); ++f, ++p) {
    if (p == path.end() || *f != *p) return false;
  }
  return p != path.end();
}

}  // namespace

LogFile::~LogFile() {
  if (fd_ >= 0) ::close(fd_);
}

LogCatalog::LogCatalog(const std::string& folder) {
  std::error_code ec;
  folder_ = fs::canonical(folder, ec);
  if (ec || !fs::is_directory(folder_, ec)) {
    throw std::runtime_error("log service: expected the log folder " + folder +
                             " to be an existing directory, found " +
                             (ec ? ec.message() : std::string("another kind of file")));
  }
}

std::variant<std::shared_ptr<LogFile>, LogRefusal> LogCatalog::Resolve(
    std::string_view name) const {
  using Reason = LogRefusal::Reason;
  std::string why;
  if (!log::IsValidLogName(name, &why)) return LogRefusal{Reason::kBadName, why};
  const std::string shown(name);
  fs::path path = folder_ / fs::path(shown);
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0) {
    const int err = errno;
    if (err == ENOENT) {
      return LogRefusal{Reason::kNotFound, "expected a log " + shown + ", found no such file"};
    }
    return LogRefusal{Reason::kUnreadable, shown + ": " + ErrnoText(err)};
  }
  if (S_ISLNK(st.st_mode)) {
    std::error_code ec;
    const fs::path target = fs::canonical(path, ec);
    if (ec) {
      return LogRefusal{Reason::kNotFound,
                        "expected a log " + shown + ", found a symbolic link to a missing file"};
    }
    if (!IsInside(folder_, target)) {
      return LogRefusal{
          Reason::kOutsideFolder,
          "refused: " + shown + " is a symbolic link that leads outside the log folder"};
    }
    path = target;
  }
  // O_NOFOLLOW: a link swapped in after the checks above is refused, not
  // followed; O_NONBLOCK: a FIFO does not hang the open.
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK);
  if (fd < 0) {
    const int err = errno;
    if (err == ELOOP) {
      return LogRefusal{Reason::kOutsideFolder,
                        "refused: " + shown + " became a symbolic link while being opened"};
    }
    if (err == ENOENT) {
      return LogRefusal{Reason::kNotFound, "expected a log " + shown + ", found no such file"};
    }
    return LogRefusal{Reason::kUnreadable, "cannot open " + shown + ": " + ErrnoText(err)};
  }
  auto file = std::make_shared<LogFile>(fd);
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    return LogRefusal{Reason::kNotFound,
                      "expected a log " + shown + ", found something that is not a regular file"};
  }
  return file;
}

std::shared_ptr<LogCatalog::Entry> LogCatalog::EntryFor(const std::string& name) {
  std::lock_guard lock(mutex_);
  std::shared_ptr<Entry>& entry = entries_[name];
  if (!entry) entry = std::make_shared<Entry>();
  return entry;
}

std::vector<log::LogListingEntry> LogCatalog::List() {
  std::vector<std::string> names;
  std::error_code ec;
  for (fs::directory_iterator it(folder_, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (log::IsValidLogName(name)) names.push_back(name);
  }
  if (ec) {
    throw std::runtime_error("log service: cannot list the log folder " + folder_.string() + ": " +
                             ec.message());
  }
  std::sort(names.begin(), names.end());

  std::vector<log::LogListingEntry> listing;
  for (const std::string& name : names) {
    auto opened = Open(name);
    if (auto* refusal = std::get_if<LogRefusal>(&opened)) {
      if (refusal->reason == LogRefusal::Reason::kUnreadable) {
        std::lock_guard lock(mutex_);
        last_error_ = refusal->message;
      }
      continue;
    }
    const ServableLog& log = std::get<ServableLog>(opened);
    listing.push_back({.name = name,
                       .size_bytes = log.info.servable_length_bytes,
                       .start_time_ns = log.info.start_time_ns,
                       .end_time_ns = log.info.end_time_ns,
                       .sha256 = log.info.sha256,
                       .complete = log.info.complete});
  }

  // Forget files that are gone.
  const std::set<std::string> present(names.begin(), names.end());
  std::lock_guard lock(mutex_);
  std::erase_if(entries_, [&](const auto& item) { return !present.contains(item.first); });
  return listing;
}

std::variant<ServableLog, LogRefusal> LogCatalog::Open(std::string_view name) {
  auto resolved = Resolve(name);
  if (auto* refusal = std::get_if<LogRefusal>(&resolved)) return *refusal;
  ServableLog log;
  log.name = std::string(name);
  log.file = std::get<std::shared_ptr<LogFile>>(resolved);
  const std::shared_ptr<Entry> entry = EntryFor(log.name);
  std::lock_guard lock(entry->mutex);
  try {
    log.info = entry->tracker.Update(log.file->fd(), log.name);
  } catch (const std::exception& e) {
    entry->tracker.Reset();
    return LogRefusal{LogRefusal::Reason::kUnreadable, e.what()};
  }
  return log;
}

std::string LogCatalog::last_error() const {
  std::lock_guard lock(mutex_);
  return last_error_;
}

}  // namespace rover::runtime
