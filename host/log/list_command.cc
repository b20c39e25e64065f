#include <algorithm>
#include <cstdio>
#include <vector>

#include "host/log/commands.h"
#include "host/log/format.h"
#include "host/log/log_service_client.h"

namespace rover::host {
namespace {

constexpr size_t kShaPrefixChars = 12;

std::string Duration(const log::LogListingEntry& e) {
  if (!e.start_time_ns || !e.end_time_ns || *e.end_time_ns < *e.start_time_ns) return "-";
  char text[32];
  std::snprintf(text, sizeof text, "%.3f s",
                static_cast<double>(*e.end_time_ns - *e.start_time_ns) * 1e-9);
  return text;
}

}  // namespace

int RunList(const ListOptions& options, std::ostream& out, std::ostream& err) {
  LogServiceEndpoint endpoint;
  std::string token;
  try {
    endpoint = ParseLogServiceUrl(options.access.url);
    token = ResolveLogToken(options.access.token, options.access.token_file);
  } catch (const UsageError& e) {
    err << "rover-log list: " << e.what() << "\n";
    return 2;
  }
  std::vector<log::LogListingEntry> entries;
  std::string json;
  try {
    entries = FetchLogListing(endpoint, token,
                              {.connect_timeout_s = options.access.connect_timeout_s,
                               .read_timeout_s = options.access.read_timeout_s},
                              &json);
  } catch (const LogServiceError& e) {
    err << "rover-log list: " << e.what() << "\n";
    return e.http_status() == 401 ? 2 : 1;
  } catch (const std::exception& e) {
    err << "rover-log list: " << e.what() << "\n";
    return 1;
  }
  if (options.json) {
    out << json;
    return 0;
  }

  const std::vector<std::string> header = {"NAME",           "SIZE",  "DURATION",
                                           "FIRST LOG TIME", "STATE", "SHA256"};
  std::vector<std::vector<std::string>> rows = {header};
  for (const log::LogListingEntry& e : entries) {
    rows.push_back({e.name, FormatBytes(e.size_bytes), Duration(e),
                    e.start_time_ns ? FormatLogTime(*e.start_time_ns) : "-",
                    e.complete ? "complete" : "in-progress", e.sha256.substr(0, kShaPrefixChars)});
  }
  std::vector<size_t> widths(header.size(), 0);
  for (const auto& row : rows) {
    for (size_t c = 0; c < row.size(); ++c) widths[c] = std::max(widths[c], row[c].size());
  }
  for (const auto& row : rows) {
    std::string line;
    for (size_t c = 0; c < row.size(); ++c) {
      line += row[c];
      if (c + 1 < row.size()) line += std::string(widths[c] - row[c].size() + 2, ' ');
    }
    out << line << "\n";
  }
  out << entries.size() << (entries.size() == 1 ? " log" : " logs")
      << " (times are log times on the rover's monotonic clock; in-progress logs are listed up "
         "to their last complete record)\n";
  return 0;
}

}  // namespace rover::host
