#ifndef ROVER_HOST_LOG_LOG_SERVICE_CLIENT_H_
#define ROVER_HOST_LOG_LOG_SERVICE_CLIENT_H_

// Talking to the board's log service (firmware/runtime/log_service) from the
// host: where it is, which token to present, and its log listing.

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/log/archive/log_listing.h"

namespace httplib {
enum class Error;  // cpp-httplib's client error, kept out of this header.
}  // namespace httplib

namespace rover::host {

/// The service's address, from a URL "http://HOST:PORT".
struct LogServiceEndpoint {
  std::string host;
  int port = 0;
};

/// Bad command-line input (URL, token, name, folder): exit status 2.
class UsageError : public std::invalid_argument {
 public:
  using std::invalid_argument::invalid_argument;
};

/// The service could not be reached, or answered with an HTTP error.
class LogServiceError : public std::runtime_error {
 public:
  /// `http_status` 0 means no HTTP answer at all (connection, timeout, ...).
  LogServiceError(int http_status, const std::string& what)
      : std::runtime_error(what), http_status_(http_status) {}
  int http_status() const { return http_status_; }

 private:
  int http_status_;
};

/// Parses "http://HOST:PORT" with an optional trailing '/'. HOST is a name,
/// an IPv4 address or a bracketed IPv6 address; PORT is 1..65535. Throws
/// UsageError saying what was expected and what was found (https and paths
/// are refused: the service speaks plain HTTP on /logs).
LogServiceEndpoint ParseLogServiceUrl(const std::string& url);

/// The bearer token: `token` if given, else the contents of `token_file`
/// (surrounding whitespace stripped), else the environment variable
/// ROVER_LOG_TOKEN. Throws UsageError if both `token` and `token_file` are
/// given, the file cannot be read, or no non-empty token is found.
std::string ResolveLogToken(const std::string& token, const std::string& token_file);

/// Connection settings of every request.
struct LogServiceClientOptions {
  int connect_timeout_s = 5;
  int read_timeout_s = 30;  ///< Longest silence while waiting for bytes.
};

/// A cpp-httplib client error in words, e.g. "connection refused or host
/// unreachable (is the log service running at that address?)".
std::string DescribeTransportError(httplib::Error error);

/// GET /logs. Returns the parsed listing and, if `raw_json` is not null, the
/// body as received. Throws LogServiceError for a network failure or a
/// status other than 200 (with the service's error text), and
/// log::LogListingError for a malformed listing.
std::vector<log::LogListingEntry> FetchLogListing(const LogServiceEndpoint& endpoint,
                                                  const std::string& token,
                                                  const LogServiceClientOptions& options,
                                                  std::string* raw_json = nullptr);

}  // namespace rover::host

#endif  // ROVER_HOST_LOG_LOG_SERVICE_CLIENT_H_
