#include "core/ipc/iceoryx_transport.h"

#include <errno.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <mutex>
#include <thread>

#include "iceoryx_hoofs/log/logmanager.hpp"
#include "iceoryx_posh/iceoryx_posh_types.hpp"
#include "iceoryx_posh/mepoo/chunk_header.hpp"
#include "iceoryx_posh/popo/untyped_publisher.hpp"
#include "iceoryx_posh/popo/untyped_subscriber.hpp"
#include "iceoryx_posh/runtime/posh_runtime.hpp"
#include "iceoryx_posh/runtime/service_discovery.hpp"

namespace rover::ipc {
namespace {

// iceoryx 2.0 on Linux: platform::IOX_UDS_SOCKET_PATH_PREFIX + the RouDi
// channel name (iox::roudi::IPC_CHANNEL_ROUDI_NAME).
constexpr std::string_view kRouDiSocketPath = "/tmp/roudi";

// The process-wide runtime (iceoryx allows exactly one, created once).
std::mutex g_runtime_mutex;
std::string g_runtime_name;  // Empty until initRuntime succeeded.

// Result of one non-blocking connection attempt to RouDi's datagram socket.
enum class Probe { kAnswering, kAbsent, kNoPermission };

Probe ProbeRouDi() {
  const int fd = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) {
    return Probe::kAbsent;
  }
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  std::memcpy(address.sun_path, kRouDiSocketPath.data(), kRouDiSocketPath.size());
  // connect() on a datagram socket only checks that a socket is bound to the
  // path: a file left behind by a killed RouDi gives ECONNREFUSED.
  const int rc = ::connect(fd, reinterpret_cast<const sockaddr*>(&address), sizeof(address));
  const int connect_errno = errno;
  ::close(fd);
  if (rc == 0) {
    return Probe::kAnswering;
  }
  return connect_errno == EACCES || connect_errno == EPERM ? Probe::kNoPermission : Probe::kAbsent;
}

bool IsValidRuntimeName(std::string_view name) {
  if (name.empty() || name.size() > iox::MAX_RUNTIME_NAME_LENGTH) {
    return false;
  }
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '-';
  });
}

bool ParseLogLevel(std::string_view text, iox::log::LogLevel* level) {
  static constexpr std::pair<std::string_view, iox::log::LogLevel> kLevels[] = {
      {"off", iox::log::LogLevel::kOff},        {"fatal", iox::log::LogLevel::kFatal},
      {"error", iox::log::LogLevel::kError},    {"warning", iox::log::LogLevel::kWarn},
      {"info", iox::log::LogLevel::kInfo},      {"debug", iox::log::LogLevel::kDebug},
      {"verbose", iox::log::LogLevel::kVerbose}};
  for (const auto& [name, value] : kLevels) {
    if (name == text) {
      *level = value;
      return true;
    }
  }
  return false;
}

iox::capro::IdString_t ToIdString(const std::string& text) {
  // Topic::Parse guarantees at most 100 characters, the capacity.
  return iox::capro::IdString_t(iox::cxx::TruncateToCapacity, text.c_str(), text.size());
}

iox::capro::ServiceDescription ToServiceDescription(const Topic& topic) {
  return iox::capro::ServiceDescription(ToIdString(topic.service()), ToIdString(topic.instance()),
                                        ToIdString(topic.event()));
}

// GCC 12 reports -Wnull-dereference inside iceoryx's cxx::expected once
// loan() and take() are inlined here: a false positive in the library's
// templates (the error object is built in place), attributed to our call
// sites, so it is silenced for the two port classes only.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wnull-dereference"

class IceoryxPublisher final : public RawPublisher {
 public:
  IceoryxPublisher(const Topic& topic, const MessageLayout& layout,
                   const iox::popo::PublisherOptions& options)
      : RawPublisher(layout),
        size_bytes_(static_cast<uint32_t>(layout.size_bytes)),
        alignment_bytes_(static_cast<uint32_t>(layout.alignment_bytes)),
        publisher_(ToServiceDescription(topic), options) {}

  bool Publish(const void* message) override {
    void* chunk = Loan();
    if (chunk == nullptr) {
      return false;
    }
    std::memcpy(chunk, message, size_bytes_);
    PublishLoaned(chunk);
    return true;
  }

  void* Loan() override {
    auto chunk = publisher_.loan(size_bytes_, alignment_bytes_);
    if (chunk.has_error()) {
      CountDropped();
      return nullptr;
    }
    return chunk.value();
  }

  void PublishLoaned(void* loaned) override {
    publisher_.publish(loaned);
    CountPublished();
  }

  void ReleaseLoan(void* loaned) override { publisher_.release(loaned); }

  bool HasSubscribers() const override { return publisher_.hasSubscribers(); }

 private:
  uint32_t size_bytes_;
  uint32_t alignment_bytes_;
  iox::popo::UntypedPublisher publisher_;
};

// iceoryx 2.0 reports a subscriber as SUBSCRIBED as soon as RouDi knows it,
// publisher or not; whether somebody offers the topic is only in RouDi's
// service registry. One registry reader per process suffices. Constructed
// after the runtime (on first use), so destroyed before it.
iox::runtime::ServiceDiscovery& Discovery() {
  static iox::runtime::ServiceDiscovery discovery;
  return discovery;
}

class IceoryxSubscriber final : public RawSubscriber {
 public:
  IceoryxSubscriber(const Topic& topic, const MessageLayout& layout,
                    const iox::popo::SubscriberOptions& options)
      : RawSubscriber(layout),
        service_(ToServiceDescription(topic)),
        subscriber_(service_, options) {}

  bool TryTake(void* out) override {
    // Each iteration consumes one chunk, so the loop ends within the queue
    // capacity even if every chunk has the wrong size.
    for (;;) {
      auto chunk = subscriber_.take();
      if (chunk.has_error()) {
        return false;  // NO_CHUNK_AVAILABLE (we never hold chunks).
      }
      const void* payload = chunk.value();
      const bool size_matches =
          iox::mepoo::ChunkHeader::fromUserPayload(payload)->userPayloadSize() ==
          layout().size_bytes;
      if (size_matches) {
        std::memcpy(out, payload, layout().size_bytes);
      }
      subscriber_.release(payload);
      if (size_matches) {
        CountTaken();
        return true;
      }
      wrong_size_seen_ = true;
    }
  }

  bool HasMissedData() override {
    const bool overflowed = subscriber_.hasMissedData();
    return std::exchange(wrong_size_seen_, false) || overflowed;
  }

  bool HasPublishers() const override {
    if (subscriber_.getSubscriptionState() != iox::SubscribeState::SUBSCRIBED) {
      return false;
    }
    bool offered = false;
    Discovery().findService(
        service_.getServiceIDString(), service_.getInstanceIDString(), service_.getEventIDString(),
        [&offered](const iox::capro::ServiceDescription&) { offered = true; },
        iox::popo::MessagingPattern::PUB_SUB);
    return offered;
  }

 private:
  iox::capro::ServiceDescription service_;
  iox::popo::UntypedSubscriber subscriber_;
  bool wrong_size_seen_ = false;
};

#pragma GCC diagnostic pop

}  // namespace

std::string_view IceoryxTransport::RouDiSocketPath() { return kRouDiSocketPath; }

bool IceoryxTransport::IsRouDiRunning() { return ProbeRouDi() == Probe::kAnswering; }

std::unique_ptr<IceoryxTransport> IceoryxTransport::Create(const Options& options,
                                                           std::string* error) {
  if (!IsValidRuntimeName(options.runtime_name)) {
    SetError(error, "invalid iceoryx runtime name '" + options.runtime_name +
                        "': use 1..100 characters of [A-Za-z0-9_-]");
    return nullptr;
  }
  iox::log::LogLevel log_level = iox::log::LogLevel::kWarn;
  if (!ParseLogLevel(options.iceoryx_log_level, &log_level)) {
    SetError(error, "invalid iceoryx log level '" + options.iceoryx_log_level + "'");
    return nullptr;
  }

  std::lock_guard<std::mutex> lock(g_runtime_mutex);
  if (!g_runtime_name.empty()) {
    if (g_runtime_name != options.runtime_name) {
      SetError(error, "this process is already registered with RouDi as '" + g_runtime_name +
                          "'; iceoryx allows one runtime per process");
      return nullptr;
    }
    if (!IsRouDiRunning()) {
      SetError(error, "RouDi is gone; an iceoryx runtime cannot reconnect, restart the process");
      return nullptr;
    }
    return std::unique_ptr<IceoryxTransport>(new IceoryxTransport());
  }

  // Wait for RouDi ourselves, with our timeout, instead of inside
  // initRuntime (60 s, then the process is terminated).
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::nanoseconds(options.roudi_wait_timeout.nanoseconds());
  Probe probe = ProbeRouDi();
  while (probe == Probe::kAbsent && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    probe = ProbeRouDi();
  }
  if (probe != Probe::kAnswering) {
    SetError(error,
             std::string("RouDi is not ") +
                 (probe == Probe::kNoPermission ? "accessible (permission denied)" : "running") +
                 ": nothing answered on " + std::string(kRouDiSocketPath) + " within " +
                 options.roudi_wait_timeout.ToString() +
                 ". Start it with scripts/roudi.sh start (or the rover-roudi service).");
    return nullptr;
  }

  iox::log::LogManager::GetLogManager().SetDefaultLogLevel(log_level,
                                                           iox::log::LogLevelOutput::kHideLogLevel);
  iox::runtime::PoshRuntime::initRuntime(iox::RuntimeName_t(
      iox::cxx::TruncateToCapacity, options.runtime_name.c_str(), options.runtime_name.size()));
  g_runtime_name = options.runtime_name;
  return std::unique_ptr<IceoryxTransport>(new IceoryxTransport());
}

std::unique_ptr<RawPublisher> IceoryxTransport::MakeRawPublisher(const Topic& topic,
                                                                 const MessageLayout& layout,
                                                                 const PublisherOptions& options,
                                                                 std::string* error) {
  if (!ValidateLayout(layout, error)) {
    return nullptr;
  }
  iox::popo::PublisherOptions iox_options;
  iox_options.historyCapacity =
      std::min<uint64_t>(options.history_capacity, iox::MAX_PUBLISHER_HISTORY);
  // Never wait for a slow subscriber: its queue drops the oldest message.
  iox_options.subscriberTooSlowPolicy = iox::popo::ConsumerTooSlowPolicy::DISCARD_OLDEST_DATA;
  return std::make_unique<IceoryxPublisher>(topic, layout, iox_options);
}

std::unique_ptr<RawSubscriber> IceoryxTransport::MakeRawSubscriber(const Topic& topic,
                                                                   const MessageLayout& layout,
                                                                   const SubscriberOptions& options,
                                                                   std::string* error) {
  if (!ValidateLayout(layout, error) || !ValidateSubscriberOptions(options, error)) {
    return nullptr;
  }
  iox::popo::SubscriberOptions iox_options;
  iox_options.queueCapacity =
      std::min<uint64_t>(options.queue_capacity, iox::MAX_SUBSCRIBER_QUEUE_CAPACITY);
  iox_options.historyRequest = options.history_request;
  iox_options.queueFullPolicy = iox::popo::QueueFullPolicy::DISCARD_OLDEST_DATA;
  return std::make_unique<IceoryxSubscriber>(topic, layout, iox_options);
}

}  // namespace rover::ipc
