#include "host/log/log_service_client.h"

#include <httplib.h>

#include <cstdlib>
#include <fstream>
#include <sstream>

namespace rover::host {
namespace {

constexpr size_t kMaxListingBytes = 64 << 20;
constexpr size_t kMaxErrorBodyBytes = 2048;

std::string Trimmed(std::string s) {
  const auto is_space = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
  while (!s.empty() && is_space(s.back())) s.pop_back();
  size_t first = 0;
  while (first < s.size() && is_space(s[first])) ++first;
  return s.substr(first);
}

}  // namespace

std::string DescribeTransportError(httplib::Error error) {
  switch (error) {
    case httplib::Error::Connection:
      return "cannot connect (is the log service running at that address and port?)";
    case httplib::Error::ConnectionTimeout:
      return "timed out connecting (is the board reachable?)";
    case httplib::Error::Read:
      return "the connection was cut or went silent while receiving";
    case httplib::Error::Write:
      return "the connection was cut while sending the request";
    case httplib::Error::Canceled:
      return "the transfer was stopped";
    case httplib::Error::BindIPAddress:
      return "cannot bind the local address";
    default:
      return "HTTP client error: " + httplib::to_string(error);
  }
}

LogServiceEndpoint ParseLogServiceUrl(const std::string& url) {
  const std::string expected = "expected --url http://HOST:PORT (e.g. http://192.168.1.20:8086)";
  constexpr std::string_view kScheme = "http://";
  if (!url.starts_with(kScheme)) {
    throw UsageError(expected + ", found \"" + url + "\" (the log service speaks plain HTTP)");
  }
  std::string rest = url.substr(kScheme.size());
  if (rest.ends_with('/')) rest.pop_back();
  if (rest.find('/') != std::string::npos || rest.find('?') != std::string::npos ||
      rest.find('@') != std::string::npos) {
    throw UsageError(expected + " without a path, query or user, found \"" + url + "\"");
  }
  LogServiceEndpoint endpoint;
  size_t colon = std::string::npos;
  if (rest.starts_with('[')) {  // [IPv6]:port
    const size_t close = rest.find(']');
    if (close == std::string::npos || close + 1 >= rest.size() || rest[close + 1] != ':') {
      throw UsageError(expected + ", found \"" + url + "\"");
    }
    endpoint.host = rest.substr(1, close - 1);
    colon = close + 1;
  } else {
    colon = rest.rfind(':');
    if (colon == std::string::npos) {
      throw UsageError(expected + ", found no port in \"" + url + "\"");
    }
    endpoint.host = rest.substr(0, colon);
  }
  const std::string port_text = rest.substr(colon + 1);
  int port = 0;
  bool digits = !port_text.empty() && port_text.size() <= 5;
  for (const char c : port_text) {
    if (c < '0' || c > '9') digits = false;
  }
  if (digits) port = std::stoi(port_text);
  if (endpoint.host.empty() || !digits || port < 1 || port > 65535) {
    throw UsageError(expected + " with a host and a port 1..65535, found \"" + url + "\"");
  }
  endpoint.port = port;
  return endpoint;
}

std::string ResolveLogToken(const std::string& token, const std::string& token_file) {
  if (!token.empty() && !token_file.empty()) {
    throw UsageError("expected one of --token and --token-file, found both");
  }
  std::string value;
  std::string source;
  if (!token.empty()) {
    value = token;
    source = "--token";
  } else if (!token_file.empty()) {
    std::ifstream in(token_file, std::ios::binary);
    if (!in) throw UsageError("cannot read the token file " + token_file);
    std::ostringstream text;
    text << in.rdbuf();
    value = text.str();
    source = "token file " + token_file;
  } else if (const char* env = std::getenv("ROVER_LOG_TOKEN"); env != nullptr) {
    value = env;
    source = "ROVER_LOG_TOKEN";
  } else {
    throw UsageError(
        "expected the service's bearer token from --token-file FILE, --token TOKEN or the "
        "environment variable ROVER_LOG_TOKEN, found none of them");
  }
  value = Trimmed(value);
  if (value.empty()) throw UsageError("expected a non-empty token in " + source + ", found none");
  return value;
}

std::vector<log::LogListingEntry> FetchLogListing(const LogServiceEndpoint& endpoint,
                                                  const std::string& token,
                                                  const LogServiceClientOptions& options,
                                                  std::string* raw_json) {
  httplib::Client client(endpoint.host, endpoint.port);
  client.set_connection_timeout(options.connect_timeout_s, 0);
  client.set_read_timeout(options.read_timeout_s, 0);
  client.set_bearer_token_auth(token);
  std::string body;
  bool too_large = false;
  auto result = client.Get("/logs", [&](const char* data, size_t n) {
    if (body.size() + n > kMaxListingBytes) {
      too_large = true;
      return false;
    }
    body.append(data, n);
    return true;
  });
  const std::string where = "http://" + endpoint.host + ":" + std::to_string(endpoint.port);
  if (too_large) {
    throw LogServiceError(
        0, "the listing from " + where + " exceeds " + std::to_string(kMaxListingBytes) + " bytes");
  }
  if (!result) {
    throw LogServiceError(0, "cannot get the log listing from " + where + ": " +
                                 DescribeTransportError(result.error()));
  }
  if (result->status != 200) {
    throw LogServiceError(result->status, "the log service at " + where + " answered " +
                                              std::to_string(result->status) + " to GET /logs: " +
                                              Trimmed(body.substr(0, kMaxErrorBodyBytes)));
  }
  if (raw_json != nullptr) *raw_json = body;
  return log::ParseLogListingJson(body);
}

}  // namespace rover::host
