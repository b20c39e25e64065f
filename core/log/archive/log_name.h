#ifndef ROVER_CORE_LOG_ARCHIVE_LOG_NAME_H_
#define ROVER_CORE_LOG_ARCHIVE_LOG_NAME_H_

// Which names the log service serves and the downloader writes: plain file
// names of MCAP logs, never paths.

#include <cstddef>
#include <string>
#include <string_view>

namespace rover::log {

/// Longest accepted log name, in bytes (the usual file system NAME_MAX).
inline constexpr size_t kMaxLogNameBytes = 255;

/// True when `name` is a plain MCAP log file name: 1 to 255 bytes of
/// [A-Za-z0-9._-], ending in ".mcap", with at least one character before it,
/// not starting with '.' or '-', and without "..". Such a name has no '/',
/// no NUL, no percent-escapes and no whitespace, so it can only name a file
/// directly inside the log folder. Otherwise returns false and, if `why` is
/// not null, sets it to what was expected and what was found.
bool IsValidLogName(std::string_view name, std::string* why = nullptr);

}  // namespace rover::log

#endif  // ROVER_CORE_LOG_ARCHIVE_LOG_NAME_H_
