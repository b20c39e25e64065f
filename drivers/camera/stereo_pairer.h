#ifndef ROVER_DRIVERS_CAMERA_STEREO_PAIRER_H_
#define ROVER_DRIVERS_CAMERA_STEREO_PAIRER_H_

// Two hardware-triggered MonoCameras as one StereoCameraDriver: frames of
// the same trigger edge are paired, frames without a partner are released
// and counted.
//
// Pairing. Each camera delivers its frames in order; the pairer holds at
// most one unpaired frame per camera (the head of each stream) and compares
// the two heads:
//  - Two frames belong to one trigger when their stamps differ by at most
//    `stamp_tolerance` and their device counters differ by the learned
//    offset (sequence1 - sequence0, learned from the first stamp match: the
//    counters start independently).
//  - Counters at the offset but stamps apart: not a pair (a stamp glitch or
//    an uncounted loss shifted the counters); counted in stamp_mismatches,
//    the offset is forgotten, and the older frame is dropped.
//  - Stamps together but counters off the offset: the counters changed (a
//    camera restarted, or lost a frame its counter did not show); the
//    stamps, measured per frame, win over the learned offset: the pair is
//    made, the offset relearned and offset_changes counted.
//  - Otherwise the frame with the older stamp has lost its partner (the
//    other stream has moved past it): it is released and counted unpaired.
// So a frame is never paired across triggers as long as stamp_tolerance is
// below half the trigger period (2 ms against 10 ms at 100 Hz).
//
// Reordering limits: a frame stamped no later than the previous frame of the
// same camera is released at once (out_of_order): streams are never
// reordered. The two streams may lag each other by any number of frames;
// the lagging stream's older frames are dropped as unpaired.
//
// Output. The pair's stamp is cam0's stamp: both cameras start exposing at
// the same trigger edge, and using one camera keeps the stamp on a single
// clock mapping (averaging would mix two device-clock fits on Aravis).
// The pair's sequence is the trigger count: 0 for the first pair, then
// advanced by cam0's counter, so a gap of n means n - 1 triggers without a
// pair (after a counter reset it advances by 1).
//
// Real time: Next() and Release() do not allocate or lock (the in-flight
// table is sized at construction); Next() blocks at most `timeout` beyond
// what the cameras' own Next() overrun.

#include <cstdint>
#include <vector>

#include "core/time/time.h"
#include "drivers/camera/mono_camera.h"
#include "drivers/camera/stereo_camera_driver.h"

namespace rover::drivers {

struct StereoPairerOptions {
  /// Largest stamp difference of two frames of one trigger, > 0 and well
  /// below half the trigger period.
  Duration stamp_tolerance = Duration::Milliseconds(2);
  /// Pairs handed out by Next() and not yet released, in [1, 64]; Next()
  /// fails with kError when all are out (the cameras' pools are finite too).
  int max_pairs_in_flight = 4;

  /// Throws std::invalid_argument "StereoPairerOptions.<field>: expected
  /// ..., found ..." for the first field out of range.
  void Validate() const;
};

/// Counters of one camera of the pair.
struct StereoPairerCameraStats {
  uint64_t frames = 0;           ///< frames received from the camera
  uint64_t paired = 0;           ///< frames handed out in a pair
  uint64_t unpaired = 0;         ///< frames released without a partner
  uint64_t out_of_order = 0;     ///< frames released for a stamp not after the previous one
  uint64_t device_dropped = 0;   ///< frames the driver reported lost (dropped_before)
  uint64_t sequence_resets = 0;  ///< counter went backwards while the stamp advanced
  uint64_t timeouts = 0;         ///< camera Next() calls that timed out
  uint64_t errors = 0;           ///< camera Next() calls that failed
};

/// Counters of the pairer. Read them from the thread calling Next().
struct StereoPairerStats {
  uint64_t pairs = 0;                ///< pairs handed out
  uint64_t offset_changes = 0;       ///< counter offset relearned from matching stamps
  uint64_t stamp_mismatches = 0;     ///< counters at the offset, stamps apart
  uint64_t in_flight_overflows = 0;  ///< Next() refused: every pair slot unreleased
  uint64_t unknown_releases = 0;     ///< Release() of a frame not in flight
  StereoPairerCameraStats camera[2];
};

class StereoPairer final : public StereoCameraDriver {
 public:
  /// Pairs `cam0` (the reference camera, left) and `cam1`; both must
  /// outlive the pairer and be triggered by the same edge. Validates
  /// `options` (std::invalid_argument).
  StereoPairer(MonoCamera* cam0, MonoCamera* cam1, const StereoPairerOptions& options = {});
  /// Releases the frames still held and those still in flight.
  ~StereoPairer() override;
  StereoPairer(const StereoPairer&) = delete;
  StereoPairer& operator=(const StereoPairer&) = delete;

  /// Waits up to `timeout` for the next pair (see the file comment). Returns
  /// kTimeout if a camera had nothing in time (a held head frame stays held
  /// for the next call), the camera's status if one failed or ended, and
  /// kError if max_pairs_in_flight pairs are still unreleased. No
  /// allocation, no lock.
  ReadStatus Next(StereoFrame* frame, Duration timeout) override;

  /// Releases both camera frames of a pair returned by Next(); a frame not
  /// in flight is counted in unknown_releases and ignored.
  void Release(const StereoFrame& frame) override;

  const StereoPairerStats& stats() const { return stats_; }
  /// Pairs handed out and not yet released.
  int pairs_in_flight() const;

 private:
  struct Slot {
    bool used = false;
    uint64_t sequence = 0;
    CameraFrame frames[2];
  };

  // Makes sure camera `cam` has a head frame, reading until one arrives in
  // order or `deadline` passes.
  ReadStatus FillHead(int cam, Time deadline);
  void DropHead(int cam);
  ReadStatus Emit(StereoFrame* frame);

  MonoCamera* cameras_[2];
  StereoPairerOptions options_;
  StereoPairerStats stats_;
  std::vector<Slot> slots_;
  CameraFrame heads_[2];
  bool held_[2] = {false, false};
  bool have_last_[2] = {false, false};
  Time last_stamp_[2];
  uint64_t last_sequence_[2] = {0, 0};
  bool offset_known_ = false;
  uint64_t offset_ = 0;  // sequence1 - sequence0, modulo 2^64
  bool have_pair_ = false;
  uint64_t pair_sequence_ = 0;
  uint64_t last_paired_sequence0_ = 0;
};

}  // namespace rover::drivers

#endif  // ROVER_DRIVERS_CAMERA_STEREO_PAIRER_H_
