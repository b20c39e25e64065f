#include "mapping/compose/submap_log.h"

#include <deque>
#include <optional>
#include <set>
#include <stdexcept>

#include "core/geometry/yaw.h"
#include "core/log/mcap/mcap_reader.h"
#include "core/log/msgs/estimator_msgs.h"
#include "core/log/msgs/message_traits.h"
#include "core/log/msgs/octomap_msgs.h"
#include "core/log/msgs/sensor_msgs.h"
#include "mapping/submap/submap_messages.h"

namespace rover::mapping {
namespace {

// Submap messages share one header: (stamp, frame id).
struct HeaderKey {
  int64_t stamp_ns = 0;
  std::string frame_id;
  auto operator<=>(const HeaderKey&) const = default;
};

HeaderKey KeyOf(const log::std_msgs::Header& h) {
  return {log::FromRosTime(h.stamp).nanoseconds(), std::string(h.frame_id.view())};
}

std::string Where(const std::string& topic, uint64_t log_time) {
  return topic + " at " + std::to_string(static_cast<double>(log_time) * 1e-9) + " s";
}

log::McapReader OpenLog(const std::string& path) {
  try {
    return log::McapReader::Open(path);
  } catch (const std::exception& e) {
    throw std::runtime_error(path + ": not a readable MCAP log: " + e.what());
  }
}

Eigen::Isometry3d SwitchTransform(const log::rover_msgs::EstimatorFrameSwitch& s) {
  return GravityAlignedTransform(
      Eigen::Vector3d(s.p_old_new_m[0], s.p_old_new_m[1], s.p_old_new_m[2]), s.yaw_old_new_rad);
}

}  // namespace

namespace {

// The parts of the submaps read so far whose three messages have not all
// arrived; a submap is ready as soon as they have. Ready submaps are handed
// on outside the message decoding, so that what the callback throws is not
// taken for a bad message.
class PendingSubmaps {
 public:
  void AddInfo(const log::rover_msgs::SubmapInfo& info) {
    const HeaderKey key = KeyOf(info.header);
    Part& part = parts_[key];
    if (part.info) return;  // a repeated info: the first one counts
    part.info = info;
    info_order_.push_back(key);
    MoveIfComplete(key);
  }
  void AddOctree(const HeaderKey& key, std::shared_ptr<const octomap::OcTree> octree) {
    parts_[key].octree = std::move(octree);
    MoveIfComplete(key);
  }
  void AddCloud(const HeaderKey& key, std::shared_ptr<const PointCloud> cloud) {
    parts_[key].cloud = std::move(cloud);
    MoveIfComplete(key);
  }
  void HandOn(const std::function<void(LoggedSubmap&&)>& on_submap) {
    while (!ready_.empty()) {
      LoggedSubmap submap = std::move(ready_.front());
      ready_.pop_front();
      on_submap(std::move(submap));
    }
  }
  // A problem per submap left incomplete, in the order their info came;
  // parts that never got an info are not submaps and are not reported.
  void ReportIncomplete(std::vector<std::string>* problems) const {
    for (const HeaderKey& key : info_order_) {
      const auto it = parts_.find(key);
      if (it == parts_.end()) continue;  // complete, handed on
      problems->push_back("submap " + std::to_string(it->second.info->index) + " (" + key.frame_id +
                          "): its " + (it->second.octree ? "cloud" : "octree") +
                          " message is missing");
    }
  }

 private:
  struct Part {
    std::optional<log::rover_msgs::SubmapInfo> info;
    std::shared_ptr<const octomap::OcTree> octree;
    std::shared_ptr<const PointCloud> cloud;
  };
  void MoveIfComplete(const HeaderKey& key) {
    const auto it = parts_.find(key);
    Part& part = it->second;
    if (done_.count(key)) {  // a repeated message of a submap already out
      parts_.erase(it);
      return;
    }
    if (!part.info || !part.octree || !part.cloud) return;
    ready_.push_back(LoggedSubmap{*part.info, std::move(part.octree), std::move(part.cloud)});
    done_.insert(key);
    parts_.erase(it);
  }

  std::map<HeaderKey, Part> parts_;
  std::set<HeaderKey> done_;
  std::vector<HeaderKey> info_order_;
  std::deque<LoggedSubmap> ready_;
};

}  // namespace

SubmapLog ForEachLoggedSubmap(const std::string& path,
                              const std::function<void(LoggedSubmap&&)>& on_submap) {
  log::McapReader reader = OpenLog(path);
  std::map<uint16_t, std::string> topics;
  for (const auto& [id, channel] : reader.channels()) topics[id] = channel.topic;
  SubmapLog out;
  PendingSubmaps pending;
  reader.ForEachMessage([&](const log::MessageView& m) {
    const std::string& topic = topics[m.channel_id];
    std::string error;
    try {
      if (topic == kSubmapInfoTopic) {
        log::rover_msgs::SubmapInfo info;
        if (log::DeserializeMessage(m.data, &info, &error)) pending.AddInfo(info);
      } else if (topic == kSubmapOctomapTopic) {
        log::octomap_msgs::Octomap msg;
        if (log::DeserializeMessage(m.data, &msg, &error)) {
          pending.AddOctree(KeyOf(msg.header), FromOctomapMsg(msg));
        }
      } else if (topic == kSubmapCloudTopic) {
        log::sensor_msgs::PointCloud2 msg;
        if (log::DeserializeMessage(m.data, &msg, &error)) {
          pending.AddCloud(KeyOf(msg.header),
                           std::make_shared<const PointCloud>(FromPointCloud2(msg)));
        }
      } else if (topic == kTraversabilityTopic) {
        ++out.traversability_grids;
      }
    } catch (const std::exception& e) {
      error = e.what();
    }
    if (!error.empty()) out.problems.push_back(Where(topic, m.log_time) + ": " + error);
    pending.HandOn(on_submap);
    return true;
  });
  for (const log::Damage& d : reader.damage()) {
    out.problems.push_back(path + ": damaged at byte " + std::to_string(d.offset) + ": " + d.what);
  }
  pending.ReportIncomplete(&out.problems);
  for (const log::Metadata& m : reader.metadata()) {
    if (m.name == "mapd_statistics") out.statistics = m.metadata;
  }
  return out;
}

SubmapLog ReadSubmapLog(const std::string& path) {
  std::vector<LoggedSubmap> submaps;
  SubmapLog out = ForEachLoggedSubmap(
      path, [&](LoggedSubmap&& submap) { submaps.push_back(std::move(submap)); });
  out.submaps = std::move(submaps);
  return out;
}

std::map<uint32_t, Eigen::Isometry3d> ReadFrameOrigins(const std::string& roverd_log_path) {
  log::McapReader reader = OpenLog(roverd_log_path);
  std::map<uint16_t, bool> is_switch;
  for (const auto& [id, channel] : reader.channels()) {
    is_switch[id] = channel.topic == "/estimator/frame_switch_record";
  }
  std::map<uint32_t, Eigen::Isometry3d> origins = {{0u, Eigen::Isometry3d::Identity()}};
  std::string problem;
  log::ReadOptions in_time_order;
  in_time_order.order = log::ReadOptions::Order::kLogTime;
  reader.ForEachMessage(
      [&](const log::MessageView& m) {
        if (!is_switch[m.channel_id]) return true;
        log::rover_msgs::EstimatorFrameSwitch s;
        std::string error;
        if (!log::DeserializeMessage(m.data, &s, &error)) {
          problem = "a frame switch record does not decode: " + error;
          return false;
        }
        const auto old_frame = origins.find(s.old_frame_id);
        if (old_frame == origins.end()) {
          problem = "the switch " + std::to_string(s.old_frame_id) + " -> " +
                    std::to_string(s.new_frame_id) + " starts in a frame never reached";
          return false;
        }
        origins[s.new_frame_id] = old_frame->second * SwitchTransform(s);
        return true;
      },
      in_time_order);
  if (!problem.empty()) throw std::runtime_error(roverd_log_path + ": " + problem);
  return origins;
}

SubmapPlacements PlaceLoggedSubmaps(const std::vector<SubmapLog>& logs,
                                    const std::map<uint32_t, Eigen::Isometry3d>& origins) {
  SubmapPlacements p;
  for (const SubmapLog& l : logs) {
    if (!l.submaps.empty()) {
      p.resolution_m = l.submaps.front().octree->getResolution();
      break;
    }
  }
  for (std::size_t l = 0; l < logs.size(); ++l) {
    for (std::size_t s = 0; s < logs[l].submaps.size(); ++s) {
      const LoggedSubmap& submap = logs[l].submaps[s];
      const double resolution_m = submap.octree->getResolution();
      const auto origin = origins.find(submap.info.frame_id);
      if (origin == origins.end()) {
        p.unplaced.push_back({l, s, UnplacedSubmap::Reason::kNoOrigin, resolution_m});
      } else if (resolution_m != p.resolution_m) {
        p.unplaced.push_back({l, s, UnplacedSubmap::Reason::kResolution, resolution_m});
      } else {
        p.placed.push_back({l, s, origin->second});
      }
    }
  }
  return p;
}

std::size_t AddLoggedSubmaps(const std::vector<SubmapLog>& logs,
                             const std::map<uint32_t, Eigen::Isometry3d>& origins,
                             MapComposer* composer) {
  const SubmapPlacements placements = PlaceLoggedSubmaps(logs, origins);
  uint32_t id = 0;
  for (const SubmapPlacement& p : placements.placed) {
    const LoggedSubmap& s = logs[p.log].submaps[p.submap];
    composer->SetSubmap(id++, s.octree, s.cloud, p.T_map_submap);
  }
  return placements.unplaced.size();
}

}  // namespace rover::mapping
