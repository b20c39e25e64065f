#include "mapping/slam/graph_factor_record.h"

#include <charconv>
#include <cmath>

#include "mapping/graph/rover_graph.h"

namespace rover::mapping {
namespace {

constexpr int kFourDof[4] = {0, 1, 2, 5};

bool ParseInt(std::string_view text, int64_t* out) {
  if (text.empty()) return false;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), *out);
  return ec == std::errc() && end == text.data() + text.size();
}

void Require(bool ok, const GraphFactorRecord& r, const std::string& what) {
  if (!ok)
    throw GraphError("graph factor " + std::to_string(r.id) + " (" + r.Describe() + "): " + what);
}

}  // namespace

std::string_view ToString(FactorKind kind) {
  switch (kind) {
    case FactorKind::kPrior:
      return "prior";
    case FactorKind::kFrameSwitch:
      return "w";
    case FactorKind::kFilterPose:
      return "v";
    case FactorKind::kSubmapMatch:
      return "c";
    case FactorKind::kRobotDetection:
      return "d";
    case FactorKind::kLandmarkObservation:
      return "o";
  }
  return "?";
}

std::string GraphFactorRecord::Describe() const {
  std::string s = std::string(ToString(kind)) + " " + a.ToString();
  if (b) s += " -> " + b->ToString();
  return s;
}

Eigen::Matrix4d FourDofBlock(const Matrix6d& C) {
  Eigen::Matrix4d out;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) out(r, c) = C(kFourDof[r], kFourDof[c]);
  }
  return out;
}

GraphFactorRecord OriginPriorFactor(int robot, int64_t submap,
                                    const Eigen::Isometry3d& T_world_origin,
                                    const Matrix6d& covariance) {
  GraphFactorRecord r;
  r.kind = FactorKind::kPrior;
  r.a = GraphKey::Origin(robot, submap);
  r.T_a_b = T_world_origin;
  r.covariance = covariance;
  return r;
}

GraphFactorRecord FrameSwitchFactor(int robot, int64_t old_frame,
                                    const Eigen::Vector3d& p_old_new_m, double yaw_old_new_rad,
                                    const Eigen::Matrix4d& covariance) {
  GraphFactorRecord r;
  r.kind = FactorKind::kFrameSwitch;
  r.a = GraphKey::Origin(robot, old_frame);
  r.b = GraphKey::Origin(robot, old_frame + 1);
  r.T_a_b.linear() =
      Eigen::AngleAxisd(yaw_old_new_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  r.T_a_b.translation() = p_old_new_m;
  r.covariance.setZero();
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) r.covariance(kFourDof[i], kFourDof[j]) = covariance(i, j);
  }
  return r;
}

GraphFactorRecord SubmapMatchFactor(const GraphKey& origin_a, const GraphKey& origin_b,
                                    const Eigen::Isometry3d& T_a_b, const Matrix6d& covariance) {
  GraphFactorRecord r;
  r.kind = FactorKind::kSubmapMatch;
  r.a = origin_a;
  r.b = origin_b;
  r.T_a_b = T_a_b;
  r.covariance = covariance;
  r.robust = true;
  return r;
}

GraphFactorRecord FilterPoseFactor(int robot, int64_t submap, int64_t pose,
                                   const Eigen::Isometry3d& T_local_body,
                                   const Matrix6d& covariance) {
  GraphFactorRecord r;
  r.kind = FactorKind::kFilterPose;
  r.a = GraphKey::Origin(robot, submap);
  r.b = GraphKey::Pose(robot, pose);
  r.T_a_b = T_local_body;
  r.covariance = covariance;
  return r;
}

GraphFactorRecord LandmarkObservationFactor(int robot, int64_t pose, int64_t landmark,
                                            const Eigen::Isometry3d& T_body_cam,
                                            const Eigen::Isometry3d& T_cam_tag,
                                            const Matrix6d& covariance_cam_tag,
                                            const Eigen::Isometry3d& T_landmark_tag) {
  // A landmark's tag is a marker mounted on it: the same composition as a
  // robot detection, with the landmark in the target's place.
  const auto [T_body_landmark, covariance] =
      ComposeDetection(RobotDetection{T_body_cam, T_cam_tag, covariance_cam_tag, T_landmark_tag});
  GraphFactorRecord r;
  r.kind = FactorKind::kLandmarkObservation;
  r.a = GraphKey::Pose(robot, pose);
  r.b = GraphKey::Landmark(landmark);
  r.T_a_b = T_body_landmark;
  r.covariance = covariance;
  r.robust = true;
  return r;
}

GraphFactorRecord RobotDetectionFactor(int observer, int64_t observer_pose, int target,
                                       int64_t target_pose, const RobotDetection& detection) {
  const auto [T_body0_body1, covariance] = ComposeDetection(detection);
  GraphFactorRecord r;
  r.kind = FactorKind::kRobotDetection;
  r.a = GraphKey::Pose(observer, observer_pose);
  r.b = GraphKey::Pose(target, target_pose);
  r.T_a_b = T_body0_body1;
  r.covariance = covariance;
  r.robust = true;
  return r;
}

void AddToGraph(const GraphFactorRecord& r, RoverGraph* graph) {
  using Type = GraphKey::Type;
  const bool binary = r.b.has_value();
  switch (r.kind) {
    case FactorKind::kPrior:
      Require(!binary, r, "a prior has one key");
      graph->AddPrior(r.a, r.T_a_b, r.covariance);
      return;
    case FactorKind::kFrameSwitch:
      Require(binary && r.a.type == Type::kOrigin && r.b->type == Type::kOrigin &&
                  r.a.robot == r.b->robot && r.b->index == r.a.index + 1,
              r, "expected a switch from origin s<r>_<i> to s<r>_<i+1>");
      graph->AddFrameSwitch(r.a.robot, r.a.index, r.T_a_b, FourDofBlock(r.covariance));
      return;
    case FactorKind::kFilterPose:
      Require(binary && r.a.type == Type::kOrigin && r.b->type == Type::kPose &&
                  r.a.robot == r.b->robot,
              r, "expected origin -> pose of one robot");
      graph->AddFilterPose(r.a.robot, r.a.index, r.b->index, r.T_a_b, r.covariance);
      return;
    case FactorKind::kSubmapMatch:
      Require(binary && r.a.type == Type::kOrigin && r.b->type == Type::kOrigin, r,
              "expected origin -> origin");
      graph->AddSubmapMatch(r.a.robot, r.a.index, r.b->robot, r.b->index, r.T_a_b, r.covariance);
      return;
    case FactorKind::kRobotDetection:
    case FactorKind::kLandmarkObservation:
      Require(binary, r, "expected two keys");
      graph->AddBetween(r.a, *r.b, r.T_a_b, r.covariance, true);
      return;
  }
  Require(false, r, "unknown kind");
}

log::rover_msgs::GraphFactor ToMsg(const GraphFactorRecord& r, std::string_view frame_id) {
  log::rover_msgs::GraphFactor m;
  m.header.stamp = log::ToRosTime(Time::FromNanoseconds(r.stamp_ns));
  m.header.frame_id = log::FrameId::Truncated(std::string(frame_id));
  m.id = r.id;
  m.kind = static_cast<uint8_t>(r.kind);
  m.key_a = r.a.ToString();
  m.key_b = r.b ? r.b->ToString() : std::string();
  const Eigen::Vector3d p = r.T_a_b.translation();
  const Eigen::Quaterniond q(r.T_a_b.linear());
  m.p_a_b_m = {p.x(), p.y(), p.z()};
  m.q_a_b_wxyz = {q.w(), q.x(), q.y(), q.z()};
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j)
      m.covariance[static_cast<std::size_t>(6 * i + j)] = r.covariance(i, j);
  }
  m.robust = r.robust;
  return m;
}

GraphFactorRecord FromMsg(const log::rover_msgs::GraphFactor& m) {
  GraphFactorRecord r;
  r.id = m.id;
  r.stamp_ns = log::FromRosTime(m.header.stamp).nanoseconds();
  const auto fail = [&](const std::string& what) {
    throw GraphError("graph factor " + std::to_string(m.id) + ": " + what);
  };
  if (m.kind > static_cast<uint8_t>(FactorKind::kLandmarkObservation)) {
    fail("kind: expected 0..5, found " + std::to_string(m.kind));
  }
  r.kind = static_cast<FactorKind>(m.kind);
  const std::optional<GraphKey> a = ParseGraphKey(m.key_a);
  if (!a) fail("key_a: expected a key like s0_3, found '" + m.key_a + "'");
  r.a = *a;
  if (!m.key_b.empty()) {
    const std::optional<GraphKey> b = ParseGraphKey(m.key_b);
    if (!b) fail("key_b: expected a key like s0_4, found '" + m.key_b + "'");
    r.b = *b;
  }
  const Eigen::Quaterniond q(m.q_a_b_wxyz[0], m.q_a_b_wxyz[1], m.q_a_b_wxyz[2], m.q_a_b_wxyz[3]);
  const double norm = q.norm();
  if (!std::isfinite(norm) || std::abs(norm - 1.0) > 1e-6) {
    fail("q_a_b_wxyz: expected a unit quaternion, found norm " + std::to_string(norm));
  }
  r.T_a_b.linear() = q.normalized().toRotationMatrix();
  r.T_a_b.translation() = Eigen::Vector3d(m.p_a_b_m[0], m.p_a_b_m[1], m.p_a_b_m[2]);
  if (!r.T_a_b.translation().allFinite()) fail("p_a_b_m: not finite");
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j)
      r.covariance(i, j) = m.covariance[static_cast<std::size_t>(6 * i + j)];
  }
  if (!r.covariance.allFinite()) fail("covariance: not finite");
  r.robust = m.robust;
  return r;
}

std::optional<GraphKey> ParseGraphKey(std::string_view text) {
  if (text.size() < 2) return std::nullopt;
  const char type = text[0];
  const std::string_view rest = text.substr(1);
  int64_t index = 0;
  if (type == 'l') {
    if (!ParseInt(rest, &index)) return std::nullopt;
    return GraphKey::Landmark(index);
  }
  if (type != 's' && type != 'x') return std::nullopt;
  const std::size_t underscore = rest.find('_');
  int64_t robot = 0;
  if (underscore == std::string_view::npos || !ParseInt(rest.substr(0, underscore), &robot) ||
      !ParseInt(rest.substr(underscore + 1), &index) || robot < 0 || robot > INT32_MAX) {
    return std::nullopt;
  }
  return type == 's' ? GraphKey::Origin(static_cast<int>(robot), index)
                     : GraphKey::Pose(static_cast<int>(robot), index);
}

}  // namespace rover::mapping
