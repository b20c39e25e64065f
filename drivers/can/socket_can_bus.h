#ifndef ROVER_DRIVERS_CAN_SOCKET_CAN_BUS_H_
#define ROVER_DRIVERS_CAN_SOCKET_CAN_BUS_H_

// A Linux SocketCAN interface (can0 on a board, vcan0 on the HIL bench) as a
// CanBus, through a raw CAN socket:
//  - kernel receive timestamps (SO_TIMESTAMPNS), moved from CLOCK_REALTIME,
//    where the kernel stamps them, onto CLOCK_MONOTONIC;
//  - kernel-side acceptance filters (CAN_RAW_FILTER), so traffic of other
//    nodes never wakes the CAN thread;
//  - error frames (CAN_RAW_ERR_FILTER) turned into counters and a health
//    state: error warning / passive, bus-off, and back to active when the
//    controller restarts;
//  - frames the kernel dropped for a full receive queue (SO_RXQ_OVFL);
//  - an interface that goes down (ENETDOWN, or removed: ENODEV) is reopened
//    with backoff, from within Receive(), bounded by its timeout.
// After construction nothing allocates: Receive() and Send() are real-time
// safe (no locks, no heap, at most `timeout` of blocking). Receive() belongs
// to one thread (it reopens the socket); Send() may be called from another,
// and health() and stats() from any.

#include <atomic>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/time/realtime_to_monotonic.h"
#include "drivers/can/can_bus.h"

namespace rover::drivers {

class CanError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One kernel acceptance filter: a frame passes when
/// (frame id & mask) == (id & mask), or the opposite with `inverted`.
struct CanFilter {
  uint32_t id = 0;
  uint32_t mask = 0x7FF;
  bool inverted = false;
};

struct SocketCanOptions {
  /// Network interface: can0, vcan0, ...
  std::string interface = "can0";
  /// Kernel acceptance filters; empty: every data frame.
  std::vector<CanFilter> filters;
  /// Receive the controller's error frames (bus-off, error passive, ...).
  bool error_frames = true;
  /// Socket receive buffer in bytes (the kernel doubles it for its own
  /// bookkeeping); 0 keeps the system default. Set with SO_RCVBUFFORCE when
  /// the process may (CAP_NET_ADMIN), else with SO_RCVBUF, which the kernel
  /// silently caps at net.core.rmem_max (about 208 KiB by default, some 250
  /// CAN frames); check receive_buffer_bytes() on the open bus.
  int receive_buffer_bytes = 0;
  /// Backoff between attempts to reopen an interface that went away: starts
  /// at `reopen_backoff_initial`, doubles up to `reopen_backoff_max`.
  Duration reopen_backoff_initial = Duration::Milliseconds(100);
  Duration reopen_backoff_max = Duration::Seconds(2);

  /// Filters that pass the wheel drives' protocol only (DESIGN.md): SYNC,
  /// TPDO1 of nodes 1..4 and heartbeats of nodes 1..4.
  static std::vector<CanFilter> WheelDriveFilters();

  /// Throws std::invalid_argument naming the field that is out of range.
  void Validate() const;
};

/// The bus as the controller reports it through error frames.
enum class CanBusHealth : uint8_t {
  kActive,        ///< error active: all well
  kErrorWarning,  ///< an error counter reached 96
  kErrorPassive,  ///< an error counter reached 128: the node no longer sends error flags
  kBusOff,        ///< the controller left the bus (transmit error counter > 255)
  kDown,          ///< the interface is down or gone; being reopened
};

/// "active", "error-warning", "error-passive", "bus-off", "down".
const char* ToString(CanBusHealth health);

/// Counters since construction.
struct SocketCanStats {
  uint64_t frames = 0;               ///< data frames delivered
  uint64_t error_frames = 0;         ///< error frames received (all classes)
  uint64_t bus_off = 0;              ///< bus-off events
  uint64_t restarts = 0;             ///< controller restarts after bus-off
  uint64_t controller_problems = 0;  ///< error warning/passive and rx/tx overflow reports
  uint64_t protocol_errors = 0;      ///< protocol violations, missing ACK, bus errors
  uint64_t kernel_drops = 0;         ///< frames dropped by a full socket receive queue
  uint64_t ignored = 0;              ///< remote and 29-bit frames (not our protocol)
  uint64_t timeouts = 0;
  uint64_t read_errors = 0;
  uint64_t send_failures = 0;
  uint64_t reopens = 0;  ///< successful reopens after the interface went away
};

class SocketCanBus final : public CanBus {
 public:
  /// Opens, configures and binds a raw CAN socket on `options.interface`.
  /// Throws std::invalid_argument for bad options and CanError naming the
  /// interface and the system error (no such device, no CAN support in the
  /// kernel, ...).
  explicit SocketCanBus(const SocketCanOptions& options);
  /// Every frame, no filters, error frames on.
  explicit SocketCanBus(const std::string& interface);
  ~SocketCanBus() override;
  SocketCanBus(const SocketCanBus&) = delete;
  SocketCanBus& operator=(const SocketCanBus&) = delete;

  /// Waits up to `timeout` for the next data frame, stamped with its kernel
  /// receive time on CLOCK_MONOTONIC. Error frames met on the way update the
  /// health and counters and are not returned. kError when the interface is
  /// down (it is reopened on later calls).
  ReadStatus Receive(CanFrame* frame, Duration timeout) override;
  /// Replaces the socket with a fresh one, so that the frames queued since
  /// construction (and the kernel drops among them) are forgotten. If the
  /// interface is gone by now, Receive() reopens it as after any outage.
  void Start() override;
  /// Writes one frame; false (and counted) if the kernel refuses it, e.g.
  /// with a full transmit queue (ENOBUFS) or while the interface is down.
  bool Send(const CanFrame& frame) override;

  /// Health as of the last error frame or data frame; any thread.
  CanBusHealth health() const { return health_.load(std::memory_order_relaxed); }
  /// A consistent-enough copy of the counters; any thread.
  SocketCanStats stats() const;
  const std::string& interface() const { return options_.interface; }
  /// The receive buffer the kernel actually granted (SO_RCVBUF read back,
  /// doubled as the kernel reports it); 0 while the interface is down.
  /// A system call: for start-up checks and diagnostics, owner thread only.
  int receive_buffer_bytes() const;

 private:
  /// Opens, configures and binds the socket; returns the fd, or -1 with
  /// errno and *step naming what failed.
  int OpenSocket(const char** step) const;
  void MarkDown();
  /// Sleeps until the next reopen attempt or `deadline`, whichever is first,
  /// then tries; true once the socket is open again.
  bool WaitAndReopen(Time deadline);
  /// Receives one frame from the open socket; kTimeout if none is queued.
  ReadStatus ReceiveOne(CanFrame* frame, bool* data_frame);
  void HandleErrorFrame(uint32_t can_id, const uint8_t* data);

  SocketCanOptions options_;
  std::vector<unsigned char> kernel_filters_;  ///< struct can_filter[], built once
  int fd_ = -1;
  Time next_reopen_;
  Duration backoff_;
  uint32_t last_drop_count_ = 0;
  RealtimeToMonotonic to_monotonic_;  ///< the kernel's receive stamps are realtime
  int64_t last_stamp_ns_ = 0;
  std::atomic<CanBusHealth> health_{CanBusHealth::kActive};
  std::atomic<uint64_t> frames_{0}, error_frames_{0}, bus_off_{0}, restarts_{0},
      controller_problems_{0}, protocol_errors_{0}, kernel_drops_{0}, ignored_{0}, timeouts_{0},
      read_errors_{0}, send_failures_{0}, reopens_{0};
  alignas(8) unsigned char control_[128]{};
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_CAN_SOCKET_CAN_BUS_H_
