#ifndef ROVER_HOST_LOG_FORMAT_H_
#define ROVER_HOST_LOG_FORMAT_H_

// Small text formatting helpers shared by the rover-log subcommands.

#include <cstdint>
#include <string>

namespace rover::host {

/// "3.21 MiB", "512 B".
std::string FormatBytes(uint64_t bytes);

/// A log time (ns on CLOCK_MONOTONIC) as "1234.567890123 s".
std::string FormatLogTime(uint64_t log_time_ns);

}  // namespace rover::host

#endif  // ROVER_HOST_LOG_FORMAT_H_
