#include "firmware/mapd/loop_closer.h"

#include <malloc.h>

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <tuple>

#include "firmware/runtime/rt/thread_priority.h"
#include "mapping/graph/pose_uncertainty.h"

namespace rover::mapd {
namespace {

// Below mapd's main loop, and the spill file's reads and writes below the
// log's. Raising one's own nice value cannot fail; nothing to report.
void LowerPriority(int nice) {
  runtime::LowerCurrentThreadPriority(nice, runtime::IoPriorityClass::kBestEffort, 7);
}

double MsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

bool FiniteCovariance(const mapping::Matrix6d& c) { return c.allFinite(); }

}  // namespace

void LoopCloserOptions::Validate() const {
  data.Validate();
  pairing.Validate();
  matcher.Validate();
  store.Validate();
  if (max_queued_pairs < 1 || max_queued_pairs > 1000) {
    throw std::invalid_argument("LoopCloserOptions.max_queued_pairs: expected 1..1000, found " +
                                std::to_string(max_queued_pairs));
  }
  if (nice_increment < 0 || nice_increment > 19) {
    throw std::invalid_argument("LoopCloserOptions.nice_increment: expected 0..19, found " +
                                std::to_string(nice_increment));
  }
}

LoopCloserOptions LoopCloserOptions::Load(const ConfigNode& node) {
  LoopCloserOptions o;
  if (node.Has("data")) o.data = mapping::SubmapMatchDataOptions::Load(node.Child("data"));
  // A child map sets the keys it names; the others keep mapd's defaults.
  if (node.Has("pairing")) {
    o.pairing = mapping::SubmapPairingOptions::Load(node.Child("pairing"), o.pairing);
  }
  if (node.Has("matcher")) {
    o.matcher = mapping::SubmapMatcherOptions::Load(node.Child("matcher"), o.matcher);
  }
  o.max_queued_pairs = node.Get<int>("max_queued_pairs", o.max_queued_pairs);
  o.nice_increment = node.Get<int>("nice_increment", o.nice_increment);
  if (node.Has("store")) {
    const ConfigNode store = node.Child("store");
    o.store.resident_submaps = store.Get<int>("resident_submaps", o.store.resident_submaps);
    o.store.spill_directory = store.Get<std::string>("spill_directory", o.store.spill_directory);
  }
  o.Validate();
  return o;
}

LoopCloser::LoopCloser(const LoopCloserOptions& options, int robot)
    : options_((options.Validate(), options)),
      robot_(robot),
      matcher_(options.matcher),
      pairing_(options.pairing),
      store_(options.store, options.data),
      pairing_thread_([this] { RunPairing(); }),
      matching_thread_([this] { RunMatching(); }) {}

LoopCloser::~LoopCloser() { Stop(); }

void LoopCloser::AddSubmap(std::shared_ptr<const mapping::Submap> submap) {
  if (!submap) return;
  {
    const std::lock_guard lock(mutex_);
    const mapping::SubmapId id{robot_, submap->frame_id()};
    waiting_.push_back(Waiting{id, std::move(submap), nullptr, nullptr});
    ++stats_.submaps;
  }
  wake_pairing_.notify_all();
}

void LoopCloser::AddTeamSubmap(const mapping::SubmapId& id,
                               std::shared_ptr<const octomap::OcTree> octree,
                               std::shared_ptr<const mapping::PointCloud> cloud) {
  if (!octree || !cloud || id.robot == robot_) return;
  {
    const std::lock_guard lock(mutex_);
    waiting_.push_back(Waiting{id, nullptr, std::move(octree), std::move(cloud)});
    ++stats_.submaps;
    ++stats_.team_submaps;
  }
  wake_pairing_.notify_all();
}

void LoopCloser::UpdateOrigins(const std::map<int64_t, OptimisedOrigin>& origins,
                               const std::map<mapping::SubmapId, OptimisedOrigin>& team_origins) {
  {
    const std::lock_guard lock(mutex_);
    origins_ = team_origins;
    for (const auto& [frame, origin] : origins) origins_[mapping::SubmapId{robot_, frame}] = origin;
    origins_changed_ = true;
  }
  wake_pairing_.notify_all();
}

void LoopCloser::AddClaim(const mapping::SubmapId& a, const mapping::SubmapId& b, int claimant) {
  if (claimant == robot_) return;
  const std::lock_guard lock(mutex_);
  const auto [it, added] = claimed_.emplace(KeyOf(a, b), claimant);
  if (!added) it->second = std::min(it->second, claimant);
}

std::vector<std::pair<mapping::SubmapId, mapping::SubmapId>> LoopCloser::TakeClaims() {
  const std::lock_guard lock(mutex_);
  std::vector<PairKey> out;
  out.swap(claims_out_);
  return out;
}

std::vector<LoopMatch> LoopCloser::TakeMatches() {
  const std::lock_guard lock(mutex_);
  std::vector<LoopMatch> out;
  out.swap(done_);
  return out;
}

std::vector<std::string> LoopCloser::TakeProblems() {
  const std::lock_guard lock(mutex_);
  std::vector<std::string> out;
  out.swap(problems_);
  return out;
}

LoopCloserStats LoopCloser::Stats() const {
  const std::lock_guard lock(mutex_);
  LoopCloserStats stats = stats_;
  stats.store = store_.Stats();
  return stats;
}

bool LoopCloser::PairingIdle() const {
  return waiting_.empty() && !preparing_ && !origins_changed_ && !slot_freed_ && queue_.empty() &&
         !matching_;
}

void LoopCloser::Flush() {
  std::unique_lock lock(mutex_);
  idle_.wait(lock, [&] { return stop_ || PairingIdle(); });
}

void LoopCloser::Stop() {
  {
    const std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_pairing_.notify_all();
  wake_matching_.notify_all();
  idle_.notify_all();
  if (pairing_thread_.joinable()) pairing_thread_.join();
  if (matching_thread_.joinable()) matching_thread_.join();
}

void LoopCloser::RunPairing() {
  LowerPriority(options_.nice_increment);
  std::unique_lock lock(mutex_);
  while (true) {
    wake_pairing_.wait(
        lock, [&] { return stop_ || !waiting_.empty() || origins_changed_ || slot_freed_; });
    if (stop_) return;
    slot_freed_ = false;
    PrepareWaiting(&lock);
    if (stop_) return;
    SyncPairing();
    QueuePairs();
    if (PairingIdle()) idle_.notify_all();
  }
}

void LoopCloser::PrepareWaiting(std::unique_lock<std::mutex>* lock) {
  while (!waiting_.empty() && !stop_) {
    Waiting w = std::move(waiting_.front());
    waiting_.pop_front();
    preparing_ = true;
    lock->unlock();
    std::shared_ptr<const mapping::SubmapMatchData> data;
    std::string problem;
    try {
      data = w.submap ? mapping::SubmapMatchData::Build(w.submap->cloud(), w.submap->octree(),
                                                        options_.data)
                      : mapping::SubmapMatchData::Build(*w.cloud, *w.octree, options_.data);
    } catch (const std::exception& e) {
      problem = "loop closures: submap " + w.id.ToString() + " has no matching data: " + e.what();
    }
    const mapping::SubmapId id = w.id;
    w = Waiting{};     // the octree and cloud are no longer needed here
    ::malloc_trim(0);  // nor the build's transients: see RunMatching
    lock->lock();
    preparing_ = false;
    if (!data) {
      ++stats_.submaps_failed;
      problems_.push_back(std::move(problem));
      continue;
    }
    stats_.data_ms.push_back(data->build_ms());
    if (data->suitable()) ++stats_.submaps_suitable;
    prepared_[id] = Prepared{};
    try {
      store_.Put(StoreKey(id), std::move(data));
    } catch (const std::exception& e) {  // stored all the same, in memory
      problems_.push_back(std::string("loop closures: ") + e.what());
    }
  }
}

std::shared_ptr<const mapping::SubmapMatchData> LoopCloser::StoredData(
    const mapping::SubmapId& id) {
  try {
    return store_.Get(StoreKey(id));
  } catch (const std::exception& e) {
    problems_.push_back("loop closures: submap " + id.ToString() +
                        " leaves the pairing: " + e.what());
    return nullptr;
  }
}

void LoopCloser::SyncPairing() {
  const bool changed = origins_changed_;
  origins_changed_ = false;
  for (auto& [id, p] : prepared_) {
    const auto origin = origins_.find(id);
    if (origin == origins_.end() || !FiniteCovariance(origin->second.covariance)) continue;
    if (!p.paired) {
      p.paired = true;
      const std::shared_ptr<const mapping::SubmapMatchData> data = StoredData(id);
      if (!data) continue;
      try {
        pairing_.AddSubmap(id, *data, origin->second.T_world_origin, origin->second.covariance);
        p.in_pairing = true;
      } catch (const std::exception& e) {
        problems_.push_back("loop closures: submap " + id.ToString() +
                            " left out of the pairing: " + e.what());
      }
      // The pairing keeps what it needs of an unsuitable submap.
      if (!p.in_pairing || !data->suitable()) store_.Erase(StoreKey(id));
    } else if (changed && p.in_pairing) {
      try {
        pairing_.UpdateOrigin(id, origin->second.T_world_origin, origin->second.covariance);
      } catch (const std::exception& e) {
        problems_.push_back("loop closures: origin " + id.ToString() + " not updated: " + e.what());
      }
    }
  }
}

void LoopCloser::QueuePairs() {
  while (queue_.size() < static_cast<std::size_t>(options_.max_queued_pairs)) {
    std::optional<mapping::SubmapPair> next = pairing_.Next();
    if (!next) break;
    const bool own_a = next->a.robot == robot_;
    const bool own_b = next->b.robot == robot_;
    // Two other rovers' submaps: theirs to match. One whose data cannot be
    // read back is not matched at all (noted as a problem).
    if ((!own_a && !own_b) || !store_.Contains(StoreKey(next->a)) ||
        !store_.Contains(StoreKey(next->b))) {
      continue;
    }
    if (own_a != own_b) {
      if (claimed_.count(KeyOf(next->a, next->b)) > 0) {
        ++stats_.pairs_claimed_by_others;
        continue;
      }
      claims_out_.push_back(KeyOf(next->a, next->b));
    }
    if (!own_a) {
      // This rover's submap first: the factor is this rover's.
      std::swap(next->a, next->b);
      std::tie(next->prior.T_a_b, next->prior.covariance) =
          mapping::InvertUncertainPose(next->prior.T_a_b, next->prior.covariance);
    }
    std::shared_ptr<const mapping::SubmapMatchData> a = StoredData(next->a);
    std::shared_ptr<const mapping::SubmapMatchData> b = StoredData(next->b);
    if (!a || !b) continue;
    queue_.push_back(QueuedPair{*next, std::move(a), std::move(b)});
  }
  if (!queue_.empty()) wake_matching_.notify_all();
}

void LoopCloser::RunMatching() {
  LowerPriority(options_.nice_increment);
  std::unique_lock lock(mutex_);
  while (true) {
    wake_matching_.wait(lock, [&] { return stop_ || !queue_.empty(); });
    if (stop_) return;
    QueuedPair job = std::move(queue_.front());
    queue_.pop_front();
    matching_ = true;
    lock.unlock();
    const auto start = std::chrono::steady_clock::now();
    LoopMatch m;
    m.a = job.pair.a;
    m.b = job.pair.b;
    m.prior = job.pair.prior;
    try {
      const mapping::SubmapMatchResult r = matcher_.Match(*job.a, *job.b, job.pair.prior);
      m.accepted = r.accepted;
      m.rejection = r.rejection;
      m.T_a_b = r.T_a_b;
      m.covariance = r.covariance;
      m.inliers = static_cast<int>(r.inliers.size());
      m.from_prior = r.from_prior;
      m.rmse_m = r.icp.rmse_m;
    } catch (const std::exception& e) {
      m.rejection = std::string("matcher failed: ") + e.what();
    }
    m.match_ms = MsSince(start);
    job = QueuedPair{};
    // The match's transients (correspondences, trees, ICP buffers) are
    // freed: return their pages now rather than at the next finished
    // submap, so that mapd's footprint between matches is what it holds.
    ::malloc_trim(0);
    lock.lock();
    matching_ = false;
    const bool team = m.a.robot != m.b.robot;
    if (team) {
      // Both rovers started on this pair before either heard the other's
      // claim: the lower id's match counts.
      const auto claim = claimed_.find(KeyOf(m.a, m.b));
      if (claim != claimed_.end() && claim->second < robot_ && m.accepted) {
        m.accepted = false;
        m.rejection = "robot " + std::to_string(claim->second) + " claimed this pair first";
      }
      ++stats_.team_pairs_matched;
      if (m.accepted) ++stats_.team_matches_accepted;
    }
    ++stats_.pairs_matched;
    if (m.accepted) ++stats_.matches_accepted;
    stats_.match_ms.push_back(m.match_ms);
    done_.push_back(std::move(m));
    slot_freed_ = true;
    wake_pairing_.notify_all();
    if (PairingIdle()) idle_.notify_all();
  }
}

}  // namespace rover::mapd
