#include "firmware/mapd/slam_worker.h"

#include <chrono>

#include "core/geometry/so3.h"
#include "firmware/runtime/rt/thread_priority.h"

namespace rover::mapd {
namespace {

// Marginal covariance of T_a * Z from T_a's ([dt world; dphi right]) and Z's
// ([dp frame a; dtheta right]), to first order.
mapping::Matrix6d ComposeCovariance(const Eigen::Isometry3d& T_a, const mapping::Matrix6d& C_a,
                                    const Eigen::Isometry3d& Z, const mapping::Matrix6d& C_z) {
  mapping::Matrix6d J_a = mapping::Matrix6d::Identity();
  J_a.topRightCorner<3, 3>() = -T_a.linear() * skew(Z.translation());
  J_a.bottomRightCorner<3, 3>() = Z.linear().transpose();
  mapping::Matrix6d J_z = mapping::Matrix6d::Identity();
  J_z.topLeftCorner<3, 3>() = T_a.linear();
  return J_a * C_a * J_a.transpose() + J_z * C_z * J_z.transpose();
}

}  // namespace

SlamWorker::SlamWorker(const mapping::RoverGraphOptions& options, int robot)
    : robot_(robot), graph_(options), thread_([this] { Run(); }) {}

SlamWorker::~SlamWorker() { Stop(); }

void SlamWorker::Submit(const mapping::GraphFactorRecord& factor) {
  {
    const std::lock_guard lock(mutex_);
    inbox_.push_back(factor);
  }
  wake_.notify_all();
}

void SlamWorker::SetFilterPose(int64_t stamp_ns, uint32_t frame_id,
                               const Eigen::Isometry3d& T_local_body,
                               const mapping::Matrix6d& covariance) {
  {
    const std::lock_guard lock(mutex_);
    filter_pose_ = FilterPose{stamp_ns, frame_id, T_local_body, covariance};
    pose_changed_ = true;
  }
  wake_.notify_all();
}

SlamSnapshot SlamWorker::Latest() const {
  const std::lock_guard lock(mutex_);
  return latest_;
}

SlamStats SlamWorker::Stats() const {
  const std::lock_guard lock(mutex_);
  return stats_;
}

std::vector<std::string> SlamWorker::TakeProblems() {
  const std::lock_guard lock(mutex_);
  std::vector<std::string> out;
  out.swap(problems_);
  return out;
}

void SlamWorker::Flush() {
  std::unique_lock lock(mutex_);
  idle_.wait(lock, [&] { return stop_ || (inbox_.empty() && !busy_ && !refining_); });
}

void SlamWorker::Stop() {
  {
    const std::lock_guard lock(mutex_);
    if (stop_ && !thread_.joinable()) return;
    stop_ = true;
  }
  wake_.notify_all();
  idle_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void SlamWorker::Run() {
  // Below mapd's main loop: the graph may wait, the stereo pairs may not.
  // Raising one's own nice value cannot fail; nothing to report.
  runtime::LowerCurrentThreadPriority(10, runtime::IoPriorityClass::kUnchanged, 0);
  std::unique_lock lock(mutex_);
  while (true) {
    // With nothing new to add, a one-step update that left the graph short
    // of convergence goes on here, one step per pass, so that new factors
    // never wait behind more than one step.
    wake_.wait(lock, [&] { return stop_ || !inbox_.empty() || pose_changed_ || refining_; });
    if (stop_) return;
    std::deque<mapping::GraphFactorRecord> batch;
    batch.swap(inbox_);
    pose_changed_ = false;
    busy_ = true;
    lock.unlock();
    const bool refine = batch.empty() && graph_.NeedsRefinement();
    UpdateOnce(&batch, refine);
    const bool refining = graph_.NeedsRefinement();
    lock.lock();
    busy_ = false;
    refining_ = refining;
    if (inbox_.empty() && !refining_) idle_.notify_all();
  }
}

void SlamWorker::UpdateOnce(std::deque<mapping::GraphFactorRecord>* batch, bool refine) {
  std::vector<std::string> problems;
  uint64_t added = 0;
  int64_t stamp_ns = 0;
  for (const mapping::GraphFactorRecord& f : *batch) {
    try {
      mapping::AddToGraph(f, &graph_);
      ++added;
      stamp_ns = std::max(stamp_ns, f.stamp_ns);
    } catch (const std::exception& e) {
      problems.push_back(std::string("factor left out: ") + e.what());
    }
  }
  std::optional<FilterPose> pose;
  {
    const std::lock_guard lock(mutex_);
    pose = filter_pose_;
  }
  SlamSnapshot snap;
  const auto start = std::chrono::steady_clock::now();
  bool ok = true;
  if (added > 0 || latest_.update == 0 || refine) {
    try {
      snap.summary = added > 0 || !refine ? graph_.Optimize() : graph_.Refine();
    } catch (const std::exception& e) {
      ok = false;
      problems.push_back(std::string("graph update failed: ") + e.what());
    }
  }
  if (ok && !snap.summary.covariance_error.empty()) {
    problems.push_back("graph update: " + snap.summary.covariance_error);
  }
  if (ok && snap.summary.unanchored.size() != unanchored_reported_) {
    unanchored_reported_ = snap.summary.unanchored.size();
    if (unanchored_reported_ > 0) {
      std::string names;
      for (std::size_t k = 0; k < unanchored_reported_ && k < 8; ++k) {
        names += (k ? ", " : "") + snap.summary.unanchored[k].ToString();
      }
      problems.push_back(std::to_string(unanchored_reported_) +
                         " variable(s) no prior reaches, left out until a factor links them: " +
                         names + (unanchored_reported_ > 8 ? ", ..." : ""));
    }
  }
  if (ok) {
    for (const mapping::GraphKey& key : graph_.Keys()) {
      if (key.type != mapping::GraphKey::Type::kOrigin) continue;
      OptimisedOrigin o;
      try {
        o.T_world_origin = graph_.Estimate(key);
      } catch (const std::exception&) {
        continue;  // unanchored
      }
      try {
        o.covariance = graph_.OriginCovariance(key.robot, key.index);
      } catch (const std::exception&) {
        // Not computed (option off): left zero.
      }
      if (key.robot == robot_) {
        snap.origins[key.index] = o;
      } else {
        snap.team_origins[mapping::SubmapId{key.robot, key.index}] = o;
      }
    }
    if (pose) {
      const auto origin = snap.origins.find(pose->frame_id);
      if (origin != snap.origins.end()) {
        snap.T_world_body = origin->second.T_world_origin * pose->T_local_body;
        snap.global_pose_stamp_ns = pose->stamp_ns;
        snap.global_pose_frame_id = pose->frame_id;
        snap.global_pose_covariance =
            ComposeCovariance(origin->second.T_world_origin, origin->second.covariance,
                              pose->T_local_body, pose->covariance);
        stamp_ns = std::max(stamp_ns, pose->stamp_ns);
      }
    }
  }
  const double ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  const std::lock_guard lock(mutex_);
  stats_.factors_added += added;
  stats_.factors_refused += batch->size() - added;
  for (std::string& p : problems) problems_.push_back(std::move(p));
  if (!ok) {
    ++stats_.update_errors;
    return;
  }
  if (added > 0) {
    ++stats_.updates;
    if (snap.summary.solved) ++stats_.solves;
    stats_.update_ms.push_back(ms);
  } else if (refine) {
    ++stats_.refinements;
  }
  snap.update = latest_.update + 1;
  snap.origins_update =
      added > 0 || refine || latest_.update == 0 ? snap.update : latest_.origins_update;
  snap.stamp_ns = std::max(stamp_ns, latest_.stamp_ns);
  snap.update_ms = ms;
  if (added == 0 && !refine) snap.summary = latest_.summary;
  latest_ = std::move(snap);
}

}  // namespace rover::mapd
