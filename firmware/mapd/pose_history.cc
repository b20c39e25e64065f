#include "firmware/mapd/pose_history.h"

#include <stdexcept>

namespace rover::mapd {

PoseHistory::PoseHistory(std::size_t capacity) : ring_(capacity) {
  if (capacity == 0) throw std::invalid_argument("PoseHistory: capacity must be > 0, got 0");
}

bool PoseHistory::Add(const StampedPose& pose) {
  if (size_ > 0 && pose.stamp < Get(size_ - 1).stamp) return false;
  ring_[head_] = pose;
  head_ = (head_ + 1) % ring_.size();
  if (size_ < ring_.size()) ++size_;
  return true;
}

const StampedPose& PoseHistory::Get(std::size_t i) const {
  return ring_[(head_ + ring_.size() - size_ + i) % ring_.size()];
}

std::optional<Time> PoseHistory::newest() const {
  if (size_ == 0) return std::nullopt;
  return Get(size_ - 1).stamp;
}

std::optional<Time> PoseHistory::oldest() const {
  if (size_ == 0) return std::nullopt;
  return Get(0).stamp;
}

std::optional<StampedPose> PoseHistory::At(Time stamp) const {
  if (size_ == 0 || stamp < Get(0).stamp || Get(size_ - 1).stamp < stamp) return std::nullopt;
  // Binary search for the first estimate at or after `stamp`.
  std::size_t lo = 0;
  std::size_t hi = size_ - 1;
  while (lo < hi) {
    const std::size_t mid = (lo + hi) / 2;
    if (Get(mid).stamp < stamp) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  const StampedPose& b = Get(lo);
  if (b.stamp == stamp || lo == 0) return b;
  const StampedPose& a = Get(lo - 1);
  if (a.frame_id != b.frame_id) return std::nullopt;
  const double span_s = (b.stamp - a.stamp).ToSeconds();
  const double t = span_s > 0.0 ? (stamp - a.stamp).ToSeconds() / span_s : 0.0;
  StampedPose out;
  out.stamp = stamp;
  out.frame_id = b.frame_id;
  // Within a frame the filter's uncertainty only grows between estimates 2.5
  // ms apart: the later one's bounds the interpolated pose's.
  out.covariance = b.covariance;
  const Eigen::Quaterniond qa(a.T_local_body.linear());
  const Eigen::Quaterniond qb(b.T_local_body.linear());
  out.T_local_body.linear() = qa.slerp(t, qb).toRotationMatrix();
  out.T_local_body.translation() =
      (1.0 - t) * a.T_local_body.translation() + t * b.T_local_body.translation();
  return out;
}

}  // namespace rover::mapd
