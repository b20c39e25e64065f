#ifndef ROVER_FIRMWARE_MAPD_TAG_WORKER_H_
#define ROVER_FIRMWARE_MAPD_TAG_WORKER_H_

// mapd's tag thread: looks for the configured AprilTags in the rectified
// left image of mapped pairs, below mapd's own priority, so that detection
// never delays the mapping of stereo pairs. Only the newest image waits: if
// the thread is still busy when another arrives, the waiting one is dropped
// (counted). The main loop takes the results, logs every observation and
// turns the accepted ones into graph factors.

#include <Eigen/Geometry>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include <opencv2/core.hpp>

#include "mapping/graph/pose_graph.h"
#include "mapping/tags/tag_observer.h"

namespace rover::mapd {

/// What the tags were seen from: the image and the filter's estimate then.
struct TagSighting {
  int64_t stamp_ns = 0;   ///< the image's capture
  uint32_t frame_id = 0;  ///< the filter's local frame of the estimate
  Eigen::Isometry3d T_local_body = Eigen::Isometry3d::Identity();
  mapping::Matrix6d covariance = mapping::Matrix6d::Zero();  ///< of T_local_body
};

struct TagResult {
  TagSighting sighting;
  std::vector<mapping::TagObservation> observations;
};

struct TagWorkerStats {
  uint64_t submitted = 0;
  uint64_t dropped = 0;  ///< replaced while waiting: the thread was busy
  uint64_t processed = 0;
  uint64_t failed = 0;     ///< the observer threw (bad image)
  uint64_t not_ready = 0;  ///< handed over while detection is off (its set-up failed)
  mapping::TagObserverStats observer;
};

/// Reads (or builds) the error tables; runs on the tag thread, so that a
/// slow build never holds up mapping. Throws to switch detection off.
using TagTableLoader = std::function<std::vector<mapping::TagErrorTable>()>;

class TagWorker {
 public:
  /// Starts the thread, `nice_increment` below the caller's priority.
  TagWorker(const mapping::TagObserverOptions& options, const calib::RectifiedIntrinsics& camera,
            cv::Size image_size, const std::vector<mapping::TagErrorTable>& tables,
            int nice_increment);
  /// As above, with the tables from `load_tables`, called first on the
  /// thread (images handed over meanwhile wait as usual). If it or the
  /// observer's set-up throws, detection stays off, images are not kept
  /// (counted as not_ready) and TakeError says why.
  TagWorker(const mapping::TagObserverOptions& options, const calib::RectifiedIntrinsics& camera,
            cv::Size image_size, TagTableLoader load_tables, int nice_increment);
  ~TagWorker();
  TagWorker(const TagWorker&) = delete;
  TagWorker& operator=(const TagWorker&) = delete;

  /// Hands over a rectified image (copied) and its sighting.
  void Submit(const cv::Mat& rectified, const TagSighting& sighting);
  /// Why detection is off (once; nullopt while it is not).
  std::optional<std::string> TakeError();
  /// Results finished since the last call, oldest first.
  std::vector<TagResult> TakeResults();
  TagWorkerStats Stats() const;
  /// Waits until the submitted image (if any) is processed (tests, shutdown).
  void Flush();
  /// Stops the thread (idempotent; the destructor calls it).
  void Stop();

 private:
  void Run();
  /// Builds the observer on the thread; false (and error_ set) if it fails.
  bool SetUp();

  const mapping::TagObserverOptions options_;
  const calib::RectifiedIntrinsics camera_;
  const cv::Size image_size_;
  TagTableLoader load_tables_;
  std::unique_ptr<mapping::TagObserver> observer_;  // the worker thread's only
  const int nice_increment_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable idle_;
  cv::Mat pending_image_;
  std::optional<TagSighting> pending_;
  bool busy_ = false;
  bool stop_ = false;
  bool failed_ = false;  ///< the set-up failed: detection is off
  std::optional<std::string> error_;
  std::vector<TagResult> done_;
  TagWorkerStats stats_;
  std::thread thread_;  // last: started once everything above exists
};

}  // namespace rover::mapd

#endif  // ROVER_FIRMWARE_MAPD_TAG_WORKER_H_
