#ifndef ROVER_CORE_IPC_ICEORYX_TRANSPORT_H_
#define ROVER_CORE_IPC_ICEORYX_TRANSPORT_H_

// Transport over iceoryx 2.0 shared memory (zero-copy between processes).
//
// Needs a running RouDi daemon (iox-roudi; scripts/roudi.sh or the
// rover-roudi systemd unit). iceoryx allows one runtime per process, created
// once and never torn down, so every IceoryxTransport in a process shares it.
//
// Publishers are iox::popo::UntypedPublisher: Loan() returns the shared-memory
// chunk, so PublishInPlace writes a message exactly once; Publish(const T&)
// is one memcpy into the chunk. Subscribers are UntypedSubscriber with
// DISCARD_OLDEST_DATA queues, which gives the overflow semantics documented
// in transport.h. iceoryx headers stay out of this header so users of
// rover_ipc do not need them.
//
// RouDi absence: iceoryx's PoshRuntime::initRuntime waits for RouDi for up to
// 60 s and then terminates the process. Create() therefore first probes
// RouDi's socket itself, with the caller's timeout, and fails cleanly if
// nobody answers. (If RouDi dies in the microseconds between probe and
// registration, iceoryx's own wait still applies.) If RouDi goes away later,
// the runtime cannot reconnect: restart the process.

#include <memory>
#include <string>
#include <string_view>

#include "core/ipc/transport.h"
#include "core/time/time.h"

namespace rover::ipc {

class IceoryxTransport final : public Transport {
 public:
  struct Options {
    /// Name this process registers with RouDi: [A-Za-z0-9_-], 1..100
    /// characters, unique among running processes (RouDi treats a second
    /// registration under a live name as a restart of the first process).
    std::string runtime_name;
    /// How long Create() waits for RouDi to accept connections.
    Duration roudi_wait_timeout = Duration::Seconds(5);
    /// Verbosity of iceoryx's own logging: "off", "fatal", "error",
    /// "warning", "info", "debug" or "verbose". Applied on first Create().
    std::string iceoryx_log_level = "warning";
  };

  /// Connects this process to RouDi. The first successful call initialises
  /// the process-wide iceoryx runtime; later calls must use the same
  /// runtime_name and share it. Returns nullptr, with the reason in `*error`
  /// if given, if the options are invalid, RouDi does not answer within
  /// roudi_wait_timeout, or a runtime with another name exists. Blocks up to
  /// roudi_wait_timeout; call at start-up, not from a real-time thread.
  static std::unique_ptr<IceoryxTransport> Create(const Options& options,
                                                  std::string* error = nullptr);

  /// True if a RouDi daemon currently accepts connections on
  /// RouDiSocketPath(). Never blocks.
  static bool IsRouDiRunning();

  /// The Unix-domain socket RouDi listens on ("/tmp/roudi" for iceoryx 2.0
  /// on Linux).
  static std::string_view RouDiSocketPath();

  std::string_view name() const override { return "iceoryx"; }

  /// Creates an iceoryx publisher (history capped at 16). Fails for invalid
  /// layouts.
  std::unique_ptr<RawPublisher> MakeRawPublisher(const Topic& topic, const MessageLayout& layout,
                                                 const PublisherOptions& options,
                                                 std::string* error) override;
  /// Creates an iceoryx subscriber (queue capped at 256). Fails for invalid
  /// layouts or options.
  std::unique_ptr<RawSubscriber> MakeRawSubscriber(const Topic& topic, const MessageLayout& layout,
                                                   const SubscriberOptions& options,
                                                   std::string* error) override;

 private:
  IceoryxTransport() = default;
};

}  // namespace rover::ipc

#endif  // ROVER_CORE_IPC_ICEORYX_TRANSPORT_H_
