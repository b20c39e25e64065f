#include "firmware/runtime/log_service/log_service_options.h"

#include <fstream>
#include <sstream>
#include <stdexcept>

namespace rover::runtime {
namespace {

void CheckRange(const char* key, int64_t value, int64_t lo, int64_t hi) {
  if (value < lo || value > hi) {
    throw std::invalid_argument("log_service." + std::string(key) + ": expected " +
                                std::to_string(lo) + ".." + std::to_string(hi) + ", found " +
                                std::to_string(value));
  }
}

bool IsTokenChar(char c) {
  const auto u = static_cast<unsigned char>(c);
  return u > 0x20 && u < 0x7F;
}

}  // namespace

LogServiceOptions LogServiceOptions::Load(const ConfigNode& n) {
  LogServiceOptions o;
  o.bind_address = n.Get<std::string>("bind_address", o.bind_address);
  o.port = n.GetInRange<int>("port", 0, 65535, o.port);
  o.log_folder = n.Get<std::string>("log_folder");
  o.token = n.Get<std::string>("token", o.token);
  o.token_file = n.Get<std::string>("token_file", o.token_file);
  if (o.token.empty() == o.token_file.empty()) {
    n.Fail("token_file", "expected exactly one of token and token_file, found " +
                             std::string(o.token.empty() ? "neither" : "both"));
  }
  o.max_concurrent_transfers =
      n.GetInRange<int>("max_concurrent_transfers", 1, 64, o.max_concurrent_transfers);
  o.bandwidth_limit_bytes_per_s = n.GetInRange<uint64_t>(
      "bandwidth_limit_bytes_per_s", 0, uint64_t{10'000'000'000}, o.bandwidth_limit_bytes_per_s);
  o.nice = n.GetInRange<int>("nice", -20, 19, o.nice);
  o.io_class = n.GetEnum<IoPriorityClass>("io_class",
                                          {{"idle", IoPriorityClass::kIdle},
                                           {"best_effort", IoPriorityClass::kBestEffort},
                                           {"unchanged", IoPriorityClass::kUnchanged}},
                                          o.io_class);
  o.io_level = n.GetInRange<int>("io_level", 0, 7, o.io_level);
  o.retry_after_s = n.GetInRange<int>("retry_after_s", 1, 3600, o.retry_after_s);
  o.read_timeout_s = n.GetInRange<int>("read_timeout_s", 1, 600, o.read_timeout_s);
  o.write_timeout_s = n.GetInRange<int>("write_timeout_s", 1, 600, o.write_timeout_s);
  try {
    o.Validate();
  } catch (const std::invalid_argument& e) {
    n.Fail("", e.what());
  }
  return o;
}

void LogServiceOptions::Validate() const {
  if (bind_address.empty()) {
    throw std::invalid_argument(
        "log_service.bind_address: expected an IP address, found an empty string");
  }
  CheckRange("port", port, 0, 65535);
  if (log_folder.empty()) {
    throw std::invalid_argument(
        "log_service.log_folder: expected the folder of the flight logs, found an empty path");
  }
  if (token.empty() == token_file.empty()) {
    throw std::invalid_argument(
        "log_service: expected exactly one of token and token_file, found " +
        std::string(token.empty() ? "neither" : "both"));
  }
  CheckRange("max_concurrent_transfers", max_concurrent_transfers, 1, 64);
  CheckRange("nice", nice, -20, 19);
  CheckRange("io_level", io_level, 0, 7);
  CheckRange("retry_after_s", retry_after_s, 1, 3600);
  CheckRange("read_timeout_s", read_timeout_s, 1, 600);
  CheckRange("write_timeout_s", write_timeout_s, 1, 600);
}

std::string LogServiceOptions::LoadToken() const {
  std::string value = token;
  std::string source = "log_service.token";
  if (!token_file.empty()) {
    source = "token file " + token_file;
    std::ifstream in(token_file, std::ios::binary);
    if (!in) throw std::runtime_error("cannot read the " + source);
    std::ostringstream text;
    text << in.rdbuf();
    value = text.str();
    const auto is_space = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; };
    while (!value.empty() && is_space(value.back())) value.pop_back();
    size_t first = 0;
    while (first < value.size() && is_space(value[first])) ++first;
    value.erase(0, first);
  }
  if (value.empty()) {
    throw std::runtime_error("log service: expected a non-empty bearer token in the " + source +
                             ", found none");
  }
  for (size_t i = 0; i < value.size(); ++i) {
    if (!IsTokenChar(value[i])) {
      throw std::runtime_error(
          "log service: expected a bearer token of printable ASCII without "
          "spaces in the " +
          source + ", found byte " + std::to_string(static_cast<unsigned char>(value[i])) +
          " at position " + std::to_string(i));
    }
  }
  return value;
}

}  // namespace rover::runtime
