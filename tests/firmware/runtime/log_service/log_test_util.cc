#include "tests/firmware/runtime/log_service/log_test_util.h"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <sstream>

namespace rover::runtime::testing {

TestLogWriter::TestLogWriter(const std::string& path, size_t payload_bytes)
    : writer_(log::McapWriterOptions{.compression = log::Compression::kNone,
                                     .chunk_size_bytes = uint64_t{1} << 30,
                                     .max_chunk_duration_ns = 0}),
      payload_bytes_(payload_bytes) {
  writer_.Open(path);
  channel_ = writer_.AddChannel(0, "/test/noise", "application/octet-stream");
}

void TestLogWriter::Write(int first, int count) {
  std::vector<std::byte> payload(payload_bytes_);
  for (int i = first; i < first + count; ++i) {
    uint32_t state = 2654435761U * static_cast<uint32_t>(i + 1);
    for (std::byte& b : payload) {
      state = state * 1664525U + 1013904223U;
      b = static_cast<std::byte>(state >> 24);
    }
    writer_.WriteMessage(channel_, static_cast<uint32_t>(i), MessageTimeNs(i), MessageTimeNs(i),
                         payload);
  }
}

void WriteCompleteLog(const std::string& path, int messages, int per_chunk, size_t payload_bytes) {
  TestLogWriter writer(path, payload_bytes);
  for (int i = 0; i < messages; i += per_chunk) {
    writer.Write(i, std::min(per_chunk, messages - i));
    writer.FlushChunk();
  }
  writer.Close();
}

std::vector<std::byte> ReadBytes(const std::string& path, std::optional<uint64_t> length) {
  std::ifstream in(path, std::ios::binary);
  EXPECT_TRUE(in) << "cannot read " << path;
  std::vector<char> chars((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (length) chars.resize(std::min<size_t>(chars.size(), static_cast<size_t>(*length)));
  std::vector<std::byte> bytes(chars.size());
  std::transform(chars.begin(), chars.end(), bytes.begin(),
                 [](char c) { return static_cast<std::byte>(c); });
  return bytes;
}

std::string ReadText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

void WriteBytes(const std::string& path, const std::vector<std::byte>& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()),
            static_cast<std::streamsize>(bytes.size()));
  ASSERT_TRUE(out.good()) << "cannot write " << path;
}

std::string CoreutilsSha256(const std::string& path, std::optional<uint64_t> length) {
  const std::string command =
      (length ? "head -c " + std::to_string(*length) + " '" + path + "' | sha256sum"
              : "sha256sum < '" + path + "'");
  FILE* pipe = ::popen(command.c_str(), "r");
  EXPECT_NE(pipe, nullptr) << command;
  if (pipe == nullptr) return {};
  char line[256] = {};
  const bool got = std::fgets(line, sizeof line, pipe) != nullptr;
  const int status = ::pclose(pipe);
  EXPECT_TRUE(got && status == 0) << command << " failed with status " << status;
  return std::string(line).substr(0, 64);
}

LogServiceOptions TestOptions(const std::string& folder) {
  LogServiceOptions options;
  options.bind_address = "127.0.0.1";
  options.port = 0;
  options.log_folder = folder;
  options.token = kToken;
  options.bandwidth_limit_bytes_per_s = 0;
  return options;
}

std::string RawResponse::Header(const std::string& name) const {
  std::istringstream lines(head);
  std::string lower_name = name;
  std::transform(lower_name.begin(), lower_name.end(), lower_name.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (std::string line; std::getline(lines, line);) {
    const size_t colon = line.find(':');
    if (colon == std::string::npos) continue;
    std::string key = line.substr(0, colon);
    std::transform(key.begin(), key.end(), key.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (key != lower_name) continue;
    std::string value = line.substr(colon + 1);
    while (!value.empty() && (value.back() == '\r' || value.back() == ' ')) value.pop_back();
    while (!value.empty() && value.front() == ' ') value.erase(0, 1);
    return value;
  }
  return {};
}

RawResponse RawHttp(int port, const std::string& request) {
  RawResponse response;
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  EXPECT_GE(fd, 0);
  if (fd < 0) return response;
  timeval timeout{.tv_sec = 30, .tv_usec = 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(static_cast<uint16_t>(port));
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
    ADD_FAILURE() << "cannot connect to 127.0.0.1:" << port;
    ::close(fd);
    return response;
  }
  size_t sent = 0;
  while (sent < request.size()) {
    const ssize_t n = ::send(fd, request.data() + sent, request.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) break;
    sent += static_cast<size_t>(n);
  }
  std::string all;
  char buffer[4096];
  for (;;) {
    const ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
    if (n <= 0) break;
    all.append(buffer, static_cast<size_t>(n));
  }
  ::close(fd);
  const size_t end = all.find("\r\n\r\n");
  response.head = all.substr(0, end);
  response.body = end == std::string::npos ? "" : all.substr(end + 4);
  if (all.starts_with("HTTP/1.1 ") && all.size() >= 12)
    response.status = std::stoi(all.substr(9, 3));
  return response;
}

RawResponse RawGet(int port, const std::string& target, std::optional<std::string> authorization,
                   const std::string& method, const std::string& extra_headers) {
  std::string request = method + " " + target + " HTTP/1.1\r\nHost: 127.0.0.1\r\n";
  const std::string auth = authorization ? *authorization : std::string("Bearer ") + kToken;
  if (!auth.empty()) request += "Authorization: " + auth + "\r\n";
  request += extra_headers + "Connection: close\r\n\r\n";
  return RawHttp(port, request);
}

}  // namespace rover::runtime::testing
