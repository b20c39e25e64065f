#include "firmware/mapd/tag_worker.h"

#include <exception>

#include "firmware/runtime/rt/thread_priority.h"

namespace rover::mapd {

TagWorker::TagWorker(const mapping::TagObserverOptions& options,
                     const calib::RectifiedIntrinsics& camera, cv::Size image_size,
                     const std::vector<mapping::TagErrorTable>& tables, int nice_increment)
    : TagWorker(options, camera, image_size, TagTableLoader([tables] { return tables; }),
                nice_increment) {}

TagWorker::TagWorker(const mapping::TagObserverOptions& options,
                     const calib::RectifiedIntrinsics& camera, cv::Size image_size,
                     TagTableLoader load_tables, int nice_increment)
    : options_(options),
      camera_(camera),
      image_size_(image_size),
      load_tables_(std::move(load_tables)),
      nice_increment_(nice_increment),
      thread_([this] { Run(); }) {}

TagWorker::~TagWorker() { Stop(); }

void TagWorker::Stop() {
  {
    const std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void TagWorker::Submit(const cv::Mat& rectified, const TagSighting& sighting) {
  {
    const std::lock_guard lock(mutex_);
    ++stats_.submitted;
    if (failed_) {
      ++stats_.not_ready;
      return;
    }
    if (pending_) ++stats_.dropped;
    rectified.copyTo(pending_image_);  // reuses the buffer once it has the size
    pending_ = sighting;
  }
  wake_.notify_all();
}

std::optional<std::string> TagWorker::TakeError() {
  const std::lock_guard lock(mutex_);
  std::optional<std::string> out;
  out.swap(error_);
  return out;
}

bool TagWorker::SetUp() {
  std::string error;
  try {
    observer_ =
        std::make_unique<mapping::TagObserver>(options_, camera_, image_size_, load_tables_());
  } catch (const std::exception& e) {
    error = e.what();
  }
  const std::lock_guard lock(mutex_);
  if (observer_) return true;
  error_ = "AprilTag detection off: " + error;
  failed_ = true;
  if (pending_) ++stats_.not_ready;
  pending_.reset();
  return false;
}

std::vector<TagResult> TagWorker::TakeResults() {
  const std::lock_guard lock(mutex_);
  std::vector<TagResult> out;
  out.swap(done_);
  return out;
}

TagWorkerStats TagWorker::Stats() const {
  const std::lock_guard lock(mutex_);
  return stats_;
}

void TagWorker::Flush() {
  std::unique_lock lock(mutex_);
  idle_.wait(lock, [&] { return stop_ || (!pending_ && !busy_); });
}

void TagWorker::Run() {
  // Below mapd's main loop; detection reads no files.
  runtime::LowerCurrentThreadPriority(nice_increment_, runtime::IoPriorityClass::kUnchanged, 0);
  if (!SetUp()) {
    idle_.notify_all();
    return;
  }
  cv::Mat image;
  std::unique_lock lock(mutex_);
  while (true) {
    wake_.wait(lock, [&] { return stop_ || pending_.has_value(); });
    if (stop_) return;
    TagResult result;
    result.sighting = *pending_;
    pending_.reset();
    cv::swap(image, pending_image_);
    busy_ = true;
    lock.unlock();
    bool failed = false;
    try {
      result.observations = observer_->Observe(image);
    } catch (const std::exception&) {
      failed = true;  // an image of the wrong size: counted, the next one may do
    }
    const mapping::TagObserverStats observer = observer_->stats();
    lock.lock();
    busy_ = false;
    stats_.observer = observer;
    if (failed) {
      ++stats_.failed;
    } else {
      ++stats_.processed;
      if (!result.observations.empty()) done_.push_back(std::move(result));
    }
    if (!pending_) idle_.notify_all();
  }
}

}  // namespace rover::mapd
