#include "firmware/runtime/log_service/log_service.h"

#include <httplib.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <system_error>
#include <thread>
#include <variant>
#include <vector>

#include "core/log/archive/log_listing.h"
#include "core/log/archive/sha256.h"
#include "firmware/runtime/log_service/http_range.h"
#include "firmware/runtime/log_service/log_catalog.h"
#include "firmware/runtime/log_service/rate_limiter.h"
#include "firmware/runtime/rt/thread_priority.h"

namespace rover::runtime {
namespace {

constexpr std::string_view kListingPath = "/logs";
constexpr std::string_view kLogPrefix = "/logs/";
constexpr size_t kMaxChunkBytes = 64 * 1024;
constexpr size_t kMinChunkBytes = 1024;
/// Extra workers beyond the transfer slots: listings and refusals (401, 503,
/// ...) are answered even while every slot is busy.
constexpr size_t kSpareWorkers = 2;
/// Idle keep-alive connections hold a worker; keep that short.
constexpr time_t kKeepAliveTimeoutS = 2;
constexpr size_t kKeepAliveMaxRequests = 100;
/// The service takes no request bodies.
constexpr size_t kMaxPayloadBytes = 4096;
constexpr auto kStartTimeout = std::chrono::seconds(10);

// `text` for an error message: printable ASCII as is, anything else as \xNN,
// at most 200 characters.
std::string Printable(std::string_view text) {
  static constexpr char kHex[] = "0123456789abcdef";
  std::string out;
  for (const char c : text.substr(0, 200)) {
    const auto u = static_cast<unsigned char>(c);
    if (u >= 0x20 && u < 0x7F) {
      out.push_back(c);
    } else {
      out += "\\x";
      out.push_back(kHex[u >> 4]);
      out.push_back(kHex[u & 0x0F]);
    }
  }
  if (text.size() > 200) out += "...";
  return out;
}

void SetError(httplib::Response& res, int status, const std::string& text) {
  res.status = status;
  res.set_content(text + "\n", "text/plain; charset=utf-8");
}

bool StartsWithBearer(std::string_view value) {
  constexpr std::string_view kScheme = "bearer ";
  if (value.size() < kScheme.size()) return false;
  for (size_t i = 0; i < kScheme.size(); ++i) {
    const char c =
        value[i] >= 'A' && value[i] <= 'Z' ? static_cast<char>(value[i] - 'A' + 'a') : value[i];
    if (c != kScheme[i]) return false;
  }
  return true;
}

struct AtomicCounters {
  std::atomic<uint64_t> requests{0};
  std::atomic<uint64_t> listings{0};
  std::atomic<uint64_t> transfers_started{0};
  std::atomic<uint64_t> transfers_completed{0};
  std::atomic<uint64_t> transfers_aborted{0};
  std::atomic<uint64_t> active_transfers{0};
  std::atomic<uint64_t> partial_responses{0};
  std::atomic<uint64_t> bytes_served{0};
  std::atomic<uint64_t> refused_unauthorized{0};
  std::atomic<uint64_t> refused_method{0};
  std::atomic<uint64_t> refused_bad_name{0};
  std::atomic<uint64_t> refused_not_found{0};
  std::atomic<uint64_t> refused_outside_folder{0};
  std::atomic<uint64_t> refused_busy{0};
  std::atomic<uint64_t> refused_range{0};
  std::atomic<uint64_t> internal_errors{0};
};

}  // namespace

struct LogService::Impl {
  struct Transfer;

  Impl(LogServiceOptions o, LogServiceHooks h) : options(std::move(o)), hooks(std::move(h)) {}

  void ApplyPriority();
  void Handle(const httplib::Request& req, httplib::Response& res);
  httplib::Server::HandlerResponse HandleLibraryError(const httplib::Request& req,
                                                      httplib::Response& res);
  bool Authorized(const httplib::Request& req, std::string* why) const;
  void ServeListing(httplib::Response& res);
  void ServeLog(const httplib::Request& req, httplib::Response& res, std::string_view name);
  bool TryAcquireSlot();

  const LogServiceOptions options;
  const LogServiceHooks hooks;
  std::string token;
  size_t chunk_bytes = kMaxChunkBytes;
  std::unique_ptr<LogCatalog> catalog;
  std::unique_ptr<RateLimiter> limiter;
  std::unique_ptr<httplib::Server> server;
  std::thread listener;
  std::atomic<bool> listener_done{false};
  std::atomic<bool> stopping{false};
  std::atomic<int> port{0};
  AtomicCounters counters;

  mutable std::mutex priority_mutex;
  std::string priority_warning;  // guarded by priority_mutex
};

// One admitted download: holds a transfer slot until the response is gone.
struct LogService::Impl::Transfer {
  Transfer(Impl* service, ServableLog log, uint64_t offset, uint64_t length)
      : impl(service),
        file(std::move(log.file)),
        name(std::move(log.name)),
        offset_bytes(offset),
        length_bytes(length) {}
  ~Transfer() { ReleaseSlot(); }
  Transfer(const Transfer&) = delete;
  Transfer& operator=(const Transfer&) = delete;

  // Content provider: sends the next chunk from `offset` (relative to the
  // start of the answered range). False ends the transfer and the connection.
  bool Send(size_t offset, size_t length, httplib::DataSink& sink) {
    if (impl->stopping.load()) return false;
    const size_t chunk = std::min(length, impl->chunk_bytes);
    const uint64_t at = offset_bytes + offset;
    if (impl->hooks.before_send && !impl->hooks.before_send(name, at)) return false;
    if (!impl->limiter->Acquire(chunk)) return false;
    buffer.resize(chunk);
    size_t done = 0;
    while (done < chunk) {
      const ssize_t got =
          ::pread(file->fd(), buffer.data() + done, chunk - done, static_cast<off_t>(at + done));
      if (got < 0 && errno == EINTR) continue;
      if (got <= 0) return false;  // Read error, or the file shrank: cut the transfer.
      done += static_cast<size_t>(got);
    }
    // The slot is given back as the last chunk is handed to the socket: a
    // client that has every byte always finds it free again (the transfer
    // may still be flushing that last chunk to a slow client).
    if (sent_bytes + chunk == length_bytes) ReleaseSlot();
    if (!sink.write(buffer.data(), chunk)) return false;
    sent_bytes += chunk;
    impl->counters.bytes_served.fetch_add(chunk);
    return true;
  }

  void ReleaseSlot() {
    if (!slot_released) impl->counters.active_transfers.fetch_sub(1);
    slot_released = true;
  }

  void Finish(bool success) {
    if (success && sent_bytes == length_bytes) {
      impl->counters.transfers_completed.fetch_add(1);
    } else {
      impl->counters.transfers_aborted.fetch_add(1);
    }
  }

  Impl* impl;
  std::shared_ptr<LogFile> file;
  std::string name;
  uint64_t offset_bytes;
  uint64_t length_bytes;
  uint64_t sent_bytes = 0;
  bool slot_released = false;
  std::vector<char> buffer;
};

void LogService::Impl::ApplyPriority() {
  thread_local bool applied = false;
  if (applied) return;
  applied = true;
  const std::string problem =
      LowerCurrentThreadPriority(options.nice, options.io_class, options.io_level);
  if (problem.empty()) return;
  std::lock_guard lock(priority_mutex);
  if (priority_warning.empty()) {
    priority_warning = problem;
    std::fprintf(stderr,
                 "log service: cannot lower the service threads' priority (%s); serving "
                 "at the inherited priority\n",
                 problem.c_str());
  }
}

bool LogService::Impl::Authorized(const httplib::Request& req, std::string* why) const {
  if (!req.has_header("Authorization")) {
    *why = "found no Authorization header";
    return false;
  }
  const std::string value = req.get_header_value("Authorization");
  if (!StartsWithBearer(value)) {
    *why = "found another authorization scheme";
    return false;
  }
  std::string_view presented = std::string_view(value).substr(7);
  while (!presented.empty() && presented.front() == ' ') presented.remove_prefix(1);
  while (!presented.empty() && presented.back() == ' ') presented.remove_suffix(1);
  if (!log::ConstantTimeEquals(presented, token)) {
    *why = "found a token that does not match";
    return false;
  }
  return true;
}

bool LogService::Impl::TryAcquireSlot() {
  const auto limit = static_cast<uint64_t>(options.max_concurrent_transfers);
  uint64_t active = counters.active_transfers.load();
  while (active < limit) {
    if (counters.active_transfers.compare_exchange_weak(active, active + 1)) return true;
  }
  return false;
}

void LogService::Impl::Handle(const httplib::Request& req, httplib::Response& res) {
  counters.requests.fetch_add(1);
  ApplyPriority();
  try {
    std::string why;
    if (!Authorized(req, &why)) {
      counters.refused_unauthorized.fetch_add(1);
      res.set_header("WWW-Authenticate", "Bearer realm=\"rover-logs\"");
      SetError(res, 401,
               "401 Unauthorized: expected \"Authorization: Bearer <token>\" with the "
               "service's token, " +
                   why);
      return;
    }
    if (req.method != "GET" && req.method != "HEAD") {
      counters.refused_method.fetch_add(1);
      res.set_header("Allow", "GET, HEAD");
      SetError(res, 405,
               "405 Method Not Allowed: the log service is read-only; expected GET or "
               "HEAD, found " +
                   Printable(req.method));
      return;
    }
    const std::string_view path = req.path;
    if (path == kListingPath || path == kLogPrefix) {
      ServeListing(res);
    } else if (path.starts_with(kLogPrefix)) {
      ServeLog(req, res, path.substr(kLogPrefix.size()));
    } else {
      counters.refused_not_found.fetch_add(1);
      SetError(res, 404, "404 Not Found: expected /logs or /logs/NAME, found " + Printable(path));
    }
  } catch (const std::exception& e) {
    counters.internal_errors.fetch_add(1);
    SetError(res, 500, std::string("500 Internal Server Error: ") + e.what());
  }
}

// cpp-httplib answers some requests itself, before the pre-routing handler
// sees them; those answers that pass through its error handler come here (in
// 0.11: a malformed Range header, 416). They carry no log data, but every
// request must still be authenticated: once its headers were read, a request
// without the token gets 401 here too. The service's own error answers
// always have a body and are left alone.
httplib::Server::HandlerResponse LogService::Impl::HandleLibraryError(const httplib::Request& req,
                                                                      httplib::Response& res) {
  if (!res.body.empty()) return httplib::Server::HandlerResponse::Unhandled;
  counters.requests.fetch_add(1);
  // Nothing of a refused request may be sent as a range of this body.
  const_cast<httplib::Request&>(req).ranges.clear();
  std::string why;
  if (!req.headers.empty() && !Authorized(req, &why)) {
    counters.refused_unauthorized.fetch_add(1);
    res.set_header("WWW-Authenticate", "Bearer realm=\"rover-logs\"");
    SetError(res, 401,
             "401 Unauthorized: expected \"Authorization: Bearer <token>\" with the "
             "service's token, " +
                 why);
    return httplib::Server::HandlerResponse::Handled;
  }
  if (res.status == 416) {
    counters.refused_range.fetch_add(1);
    SetError(res, 416,
             "416 Range Not Satisfiable: expected a Range header of the form bytes=a-b, "
             "bytes=a- or bytes=-n, found \"" +
                 Printable(req.get_header_value("Range")) + "\"");
  } else {
    SetError(res, res.status,
             std::to_string(res.status) +
                 ": expected an HTTP/1.1 request such as \"GET /logs HTTP/1.1\" "
                 "with a known method and a URI under 8 KiB, found a request "
                 "the HTTP library could not accept");
  }
  return httplib::Server::HandlerResponse::Handled;
}

void LogService::Impl::ServeListing(httplib::Response& res) {
  counters.listings.fetch_add(1);
  res.status = 200;
  res.set_header("Cache-Control", "no-store");
  res.set_content(log::LogListingToJson(catalog->List()), "application/json");
}

void LogService::Impl::ServeLog(const httplib::Request& req, httplib::Response& res,
                                std::string_view name) {
  auto opened = catalog->Open(name);
  if (const auto* refusal = std::get_if<LogRefusal>(&opened)) {
    switch (refusal->reason) {
      case LogRefusal::Reason::kBadName:
        counters.refused_bad_name.fetch_add(1);
        return SetError(res, 400, "400 Bad Request: " + refusal->message);
      case LogRefusal::Reason::kNotFound:
        counters.refused_not_found.fetch_add(1);
        return SetError(res, 404, "404 Not Found: " + refusal->message);
      case LogRefusal::Reason::kOutsideFolder:
        counters.refused_outside_folder.fetch_add(1);
        return SetError(res, 403, "403 Forbidden: " + refusal->message);
      case LogRefusal::Reason::kUnreadable:
        counters.internal_errors.fetch_add(1);
        return SetError(res, 500, "500 Internal Server Error: " + refusal->message);
    }
  }
  ServableLog log = std::get<ServableLog>(std::move(opened));
  const uint64_t size = log.info.servable_length_bytes;
  res.set_header("Accept-Ranges", "bytes");
  res.set_header("ETag", "\"" + log.info.sha256 + "\"");
  res.set_header("Cache-Control", "no-store");
  res.set_header("X-Rover-Log-Complete", log.info.complete ? "true" : "false");

  // The service answers Range itself (clamping, 416); cpp-httplib must not
  // apply the ranges it parsed a second time. The request object is not
  // const in cpp-httplib, only the handler's view of it.
  const ByteRangeRequest range = ParseRangeHeader(req.get_header_value("Range"), size);
  const_cast<httplib::Request&>(req).ranges.clear();
  if (range.kind == ByteRangeRequest::Kind::kUnsatisfiable) {
    counters.refused_range.fetch_add(1);
    res.set_header("Content-Range", "bytes */" + std::to_string(size));
    return SetError(res, 416,
                    "416 Range Not Satisfiable: expected a range starting below the " +
                        std::to_string(size) + " servable bytes of " + log.name + ", found \"" +
                        Printable(req.get_header_value("Range")) + "\"");
  }
  const bool partial = range.kind == ByteRangeRequest::Kind::kPartial;
  const uint64_t offset = partial ? range.offset_bytes : 0;
  const uint64_t length = partial ? range.length_bytes : size;
  const int status = partial ? 206 : 200;
  if (partial) {
    res.set_header("Content-Range", "bytes " + std::to_string(offset) + "-" +
                                        std::to_string(offset + length - 1) + "/" +
                                        std::to_string(size));
  }
  if (req.method == "HEAD" || length == 0) {
    res.status = status;
    if (partial) counters.partial_responses.fetch_add(1);
    if (req.method == "HEAD") {
      res.set_header("Content-Type", "application/octet-stream");
      res.set_header("Content-Length", std::to_string(length));
    } else {
      res.set_content("", "application/octet-stream");
    }
    return;
  }
  if (!TryAcquireSlot()) {
    counters.refused_busy.fetch_add(1);
    res.set_header("Retry-After", std::to_string(options.retry_after_s));
    return SetError(res, 503,
                    "503 Service Unavailable: expected a free transfer slot, found all " +
                        std::to_string(options.max_concurrent_transfers) + " busy; retry after " +
                        std::to_string(options.retry_after_s) + " s");
  }
  // From here the slot belongs to the transfer and is released with it.
  auto transfer = std::make_shared<Transfer>(this, std::move(log), offset, length);
  counters.transfers_started.fetch_add(1);
  if (partial) counters.partial_responses.fetch_add(1);
  res.status = status;
  res.set_content_provider(
      static_cast<size_t>(length), "application/octet-stream",
      [transfer](size_t off, size_t len, httplib::DataSink& sink) {
        return transfer->Send(off, len, sink);
      },
      [transfer](bool success) { transfer->Finish(success); });
}

LogService::LogService(LogServiceOptions options, LogServiceHooks hooks)
    : impl_(std::make_unique<Impl>(std::move(options), std::move(hooks))) {}

LogService::~LogService() { Stop(); }

void LogService::Start() {
  Impl& s = *impl_;
  if (s.server) throw std::runtime_error("log service: Start() called while it is running");
  s.options.Validate();
  s.token = s.options.LoadToken();
  s.catalog = std::make_unique<LogCatalog>(s.options.log_folder);
  s.limiter = std::make_unique<RateLimiter>(s.options.bandwidth_limit_bytes_per_s);
  const uint64_t rate = s.options.bandwidth_limit_bytes_per_s;
  // At least ~20 pacing steps per second under a limit.
  s.chunk_bytes =
      rate == 0
          ? kMaxChunkBytes
          : static_cast<size_t>(std::clamp<uint64_t>(rate / 20, kMinChunkBytes, kMaxChunkBytes));
  s.stopping = false;
  s.listener_done = false;

  auto server = std::make_unique<httplib::Server>();
  const size_t workers = static_cast<size_t>(s.options.max_concurrent_transfers) + kSpareWorkers;
  server->new_task_queue = [workers] { return new httplib::ThreadPool(workers); };
  // SO_REUSEADDR only: cpp-httplib's default SO_REUSEPORT would let a second
  // process bind the same port and take a share of the connections.
  server->set_socket_options([](socket_t sock) {
    int yes = 1;
    ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });
  server->set_keep_alive_timeout(kKeepAliveTimeoutS);
  server->set_keep_alive_max_count(kKeepAliveMaxRequests);
  server->set_read_timeout(s.options.read_timeout_s, 0);
  server->set_write_timeout(s.options.write_timeout_s, 0);
  server->set_payload_max_length(kMaxPayloadBytes);
  server->set_pre_routing_handler([&s](const httplib::Request& req, httplib::Response& res) {
    s.Handle(req, res);
    return httplib::Server::HandlerResponse::Handled;
  });
  server->set_error_handler(httplib::Server::HandlerWithResponse(
      [&s](const httplib::Request& req, httplib::Response& res) {
        return s.HandleLibraryError(req, res);
      }));

  errno = 0;
  int bound = -1;
  if (s.options.port == 0) {
    bound = server->bind_to_any_port(s.options.bind_address);
  } else if (server->bind_to_port(s.options.bind_address, s.options.port)) {
    bound = s.options.port;
  }
  if (bound <= 0) {
    const int err = errno;
    throw std::runtime_error(
        "log service: cannot listen on " + s.options.bind_address + ":" +
        std::to_string(s.options.port) + ": expected a local IP address " + "and a free port" +
        (err != 0 ? ", found: " + std::error_code(err, std::generic_category()).message()
                  : std::string()));
  }
  s.port = bound;
  s.server = std::move(server);
  s.listener = std::thread([&s] {
    s.ApplyPriority();
    s.server->listen_after_bind();
    s.listener_done = true;
  });
  // cpp-httplib's stop() only acts once the accept loop runs; wait for it so
  // that Stop() can never miss it. (The socket already listens, so no client
  // is turned away meanwhile.)
  const auto deadline = std::chrono::steady_clock::now() + kStartTimeout;
  while (!s.server->is_running()) {
    if (s.listener_done || std::chrono::steady_clock::now() > deadline) {
      s.server->stop();
      s.listener.join();
      s.server.reset();
      s.port = 0;
      throw std::runtime_error("log service: the HTTP server on " + s.options.bind_address + ":" +
                               std::to_string(bound) + " did not start accepting connections");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

void LogService::Stop() {
  Impl& s = *impl_;
  if (!s.server) return;
  s.stopping = true;
  s.limiter->Cancel();
  s.server->stop();
  if (s.listener.joinable()) s.listener.join();
  s.server.reset();
  s.limiter.reset();
  s.catalog.reset();
  s.port = 0;
}

bool LogService::running() const { return impl_->server != nullptr; }

int LogService::port() const { return impl_->port.load(); }

LogServiceCounters LogService::counters() const {
  const AtomicCounters& c = impl_->counters;
  return {.requests = c.requests.load(),
          .listings = c.listings.load(),
          .transfers_started = c.transfers_started.load(),
          .transfers_completed = c.transfers_completed.load(),
          .transfers_aborted = c.transfers_aborted.load(),
          .active_transfers = c.active_transfers.load(),
          .partial_responses = c.partial_responses.load(),
          .bytes_served = c.bytes_served.load(),
          .refused_unauthorized = c.refused_unauthorized.load(),
          .refused_method = c.refused_method.load(),
          .refused_bad_name = c.refused_bad_name.load(),
          .refused_not_found = c.refused_not_found.load(),
          .refused_outside_folder = c.refused_outside_folder.load(),
          .refused_busy = c.refused_busy.load(),
          .refused_range = c.refused_range.load(),
          .internal_errors = c.internal_errors.load()};
}

std::string LogService::priority_warning() const {
  std::lock_guard lock(impl_->priority_mutex);
  return impl_->priority_warning;
}

}  // namespace rover::runtime
