#include "drivers/imu/xbus_parser.h"

#include <algorithm>
#include <cstring>

namespace rover::drivers {

XbusParser::XbusParser(std::size_t max_payload_bytes)
    : max_payload_bytes_(max_payload_bytes),
      capacity_(2 * xbus::FrameBytes(max_payload_bytes)),
      buffer_(new uint8_t[capacity_]) {}

void XbusParser::Compact() {
  if (begin_ == 0) return;
  const std::size_t n = end_ - begin_;
  if (n > 0) std::memmove(buffer_.get(), buffer_.get() + begin_, n);
  begin_ = 0;
  end_ = n;
}

std::size_t XbusParser::Feed(std::span<const uint8_t> bytes) {
  if (capacity_ - end_ < bytes.size()) Compact();
  const std::size_t n = std::min(bytes.size(), capacity_ - end_);
  if (n > 0) std::memcpy(buffer_.get() + end_, bytes.data(), n);
  end_ += n;
  return n;
}

std::span<uint8_t> XbusParser::WritableSpace() {
  // Compacting only when less than a frame is free keeps memmove rare: in
  // steady state the unconsumed tail is a fraction of one frame.
  if (capacity_ - end_ < xbus::FrameBytes(max_payload_bytes_)) Compact();
  return {buffer_.get() + end_, capacity_ - end_};
}

void XbusParser::Commit(std::size_t n) { end_ += std::min(n, capacity_ - end_); }

void XbusParser::Reset() {
  begin_ = end_ = 0;
  in_sync_ = true;
}

void XbusParser::LoseSync() {
  if (in_sync_) ++stats_.resyncs;
  in_sync_ = false;
}

void XbusParser::Drop(std::size_t n) {
  LoseSync();
  stats_.garbage_bytes += n;
  begin_ += n;
}

bool XbusParser::Next(xbus::Message* message) {
  const uint8_t* const b = buffer_.get();
  for (;;) {
    // Find the preamble pair. A lone 0xFA at the very end may be the start
    // of a frame whose bus id has not arrived yet: keep it.
    std::size_t i = begin_;
    while (i < end_) {
      if (b[i] == xbus::kPreamble && (i + 1 == end_ || b[i + 1] == xbus::kMasterBusId)) break;
      ++i;
    }
    if (i > begin_) Drop(i - begin_);
    const std::size_t available = end_ - begin_;
    if (available < xbus::kHeaderBytes) return false;

    const uint8_t* f = b + begin_;
    std::size_t length = f[3];
    std::size_t header = xbus::kHeaderBytes;
    if (length == xbus::kExtendedLength) {
      if (available < xbus::kExtendedHeaderBytes) return false;
      length = xbus::ReadU16(f + 4);
      header = xbus::kExtendedHeaderBytes;
    }
    if (length > max_payload_bytes_) {
      ++stats_.oversize_frames;
      Drop(1);
      continue;
    }
    const std::size_t frame_bytes = header + length + 1;
    if (available < frame_bytes) {
      // The buffer holds two maximum frames and the parser keeps at most one
      // incomplete candidate, so the rest of this one will fit.
      if (begin_ + frame_bytes > capacity_) Compact();
      return false;
    }
    unsigned sum = 0;
    for (std::size_t k = 1; k < frame_bytes; ++k) sum += f[k];
    if ((sum & 0xFFu) != 0) {
      ++stats_.checksum_errors;
      Drop(1);
      continue;
    }
    message->bus_id = f[1];
    message->mid = f[2];
    message->payload = std::span<const uint8_t>(f + header, length);
    begin_ += frame_bytes;
    in_sync_ = true;
    ++stats_.frames;
    return true;
  }
}

}  // namespace rover::drivers
