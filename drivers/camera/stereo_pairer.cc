#include "drivers/camera/stereo_pairer.h"

#include <stdexcept>
#include <string>

namespace rover::drivers {
namespace {

constexpr int kMaxPairsInFlight = 64;

// now + timeout, saturating for Duration::Max() (a day is forever here).
Time DeadlineAfter(Duration timeout) {
  const Duration longest = Duration::Seconds(86'400);
  if (timeout < Duration::Zero()) timeout = Duration::Zero();
  return Time::Now() + (timeout > longest ? longest : timeout);
}

const StereoPairerOptions& Validated(const StereoPairerOptions& options) {
  options.Validate();
  return options;
}

}  // namespace

void StereoPairerOptions::Validate() const {
  if (stamp_tolerance <= Duration::Zero()) {
    throw std::invalid_argument("StereoPairerOptions.stamp_tolerance: expected > 0, found " +
                                stamp_tolerance.ToString());
  }
  if (max_pairs_in_flight < 1 || max_pairs_in_flight > kMaxPairsInFlight) {
    throw std::invalid_argument("StereoPairerOptions.max_pairs_in_flight: expected 1 to " +
                                std::to_string(kMaxPairsInFlight) + ", found " +
                                std::to_string(max_pairs_in_flight));
  }
}

StereoPairer::StereoPairer(MonoCamera* cam0, MonoCamera* cam1, const StereoPairerOptions& options)
    : cameras_{cam0, cam1},
      options_(Validated(options)),
      slots_(static_cast<std::size_t>(options.max_pairs_in_flight)) {
  if (cam0 == nullptr || cam1 == nullptr || cam0 == cam1) {
    throw std::invalid_argument("StereoPairer: expected two distinct cameras, found " +
                                std::string(cam0 == nullptr || cam1 == nullptr
                                                ? "a null camera"
                                                : "the same camera twice"));
  }
}

StereoPairer::~StereoPairer() {
  for (int cam = 0; cam < 2; ++cam) {
    if (held_[cam]) cameras_[cam]->Release(heads_[cam]);
  }
  for (const Slot& slot : slots_) {
    if (!slot.used) continue;
    cameras_[0]->Release(slot.frames[0]);
    cameras_[1]->Release(slot.frames[1]);
  }
}

int StereoPairer::pairs_in_flight() const {
  int n = 0;
  for (const Slot& slot : slots_) n += slot.used ? 1 : 0;
  return n;
}

ReadStatus StereoPairer::Next(StereoFrame* frame, Duration timeout) {
  if (pairs_in_flight() == options_.max_pairs_in_flight) {
    ++stats_.in_flight_overflows;
    return ReadStatus::kError;
  }
  const Time deadline = DeadlineAfter(timeout);
  const Duration tolerance = options_.stamp_tolerance;
  // Each pass either pairs the heads or drops one of them, so the loop ends
  // when the cameras run dry (kTimeout) or a pair is made.
  for (;;) {
    for (int cam = 0; cam < 2; ++cam) {
      const ReadStatus status = FillHead(cam, deadline);
      if (status != ReadStatus::kOk) return status;
    }
    const Duration skew = heads_[1].stamp - heads_[0].stamp;
    const bool stamps_match = skew >= -tolerance && skew <= tolerance;
    // Unsigned difference: counters are free-running and may wrap.
    const uint64_t counter_offset = heads_[1].sequence - heads_[0].sequence;
    if (stamps_match) {
      if (offset_known_ && counter_offset != offset_) ++stats_.offset_changes;
      offset_ = counter_offset;
      offset_known_ = true;
      return Emit(frame);
    }
    if (offset_known_ && counter_offset == offset_) {
      ++stats_.stamp_mismatches;
      offset_known_ = false;
    }
    // The older frame's partner would have come before the other head,
    // which the other (in-order) stream has already passed.
    DropHead(heads_[0].stamp < heads_[1].stamp ? 0 : 1);
  }
}

ReadStatus StereoPairer::FillHead(int cam, Time deadline) {
  StereoPairerCameraStats& counters = stats_.camera[cam];
  while (!held_[cam]) {
    const Time now = Time::Now();
    const Duration remaining = deadline > now ? deadline - now : Duration::Zero();
    CameraFrame frame;
    const ReadStatus status = cameras_[cam]->Next(&frame, remaining);
    if (status == ReadStatus::kTimeout) {
      ++counters.timeouts;
      return status;
    }
    if (status != ReadStatus::kOk) {
      if (status == ReadStatus::kError) ++counters.errors;
      return status;
    }
    ++counters.frames;
    counters.device_dropped += frame.dropped_before;
    if (have_last_[cam] && frame.stamp <= last_stamp_[cam]) {
      ++counters.out_of_order;
      cameras_[cam]->Release(frame);
      continue;
    }
    if (have_last_[cam] && frame.sequence <= last_sequence_[cam]) {
      ++counters.sequence_resets;
      offset_known_ = false;
    }
    have_last_[cam] = true;
    last_stamp_[cam] = frame.stamp;
    last_sequence_[cam] = frame.sequence;
    heads_[cam] = frame;
    held_[cam] = true;
  }
  return ReadStatus::kOk;
}

void StereoPairer::DropHead(int cam) {
  cameras_[cam]->Release(heads_[cam]);
  held_[cam] = false;
  ++stats_.camera[cam].unpaired;
}

ReadStatus StereoPairer::Emit(StereoFrame* frame) {
  Slot* slot = nullptr;
  for (Slot& candidate : slots_) {
    if (!candidate.used) {
      slot = &candidate;
      break;
    }
  }
  // Next() checked for a free slot before reading anything.
  if (have_pair_) {
    const uint64_t sequence0 = heads_[0].sequence;
    pair_sequence_ +=
        sequence0 > last_paired_sequence0_ ? sequence0 - last_paired_sequence0_ : uint64_t{1};
  } else {
    have_pair_ = true;
    pair_sequence_ = 0;
  }
  last_paired_sequence0_ = heads_[0].sequence;
  slot->used = true;
  slot->sequence = pair_sequence_;
  slot->frames[0] = heads_[0];
  slot->frames[1] = heads_[1];
  held_[0] = false;
  held_[1] = false;
  ++stats_.pairs;
  ++stats_.camera[0].paired;
  ++stats_.camera[1].paired;
  frame->stamp = heads_[0].stamp;
  frame->sequence = pair_sequence_;
  frame->cam0 = heads_[0].image;
  frame->cam1 = heads_[1].image;
  return ReadStatus::kOk;
}

void StereoPairer::Release(const StereoFrame& frame) {
  for (Slot& slot : slots_) {
    if (slot.used && slot.sequence == frame.sequence) {
      cameras_[0]->Release(slot.frames[0]);
      cameras_[1]->Release(slot.frames[1]);
      slot.used = false;
      return;
    }
  }
  ++stats_.unknown_releases;
}

}  // namespace rover::drivers
