#include "mapping/graph/synthetic_submap_trajectory.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "core/geometry/so3.h"
#include "core/geometry/yaw.h"

namespace rover::mapping {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;

Eigen::Isometry3d MakePose(const Eigen::Vector3d& p, const Eigen::Matrix3d& R) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = p;
  return T;
}

double TerrainHeight(double x, double y) { return 1.5 * std::sin(x / 15.0) * std::cos(y / 20.0); }

}  // namespace

SyntheticSubmapTrajectory MakeSyntheticSubmapTrajectory(const SyntheticSubmapTrajectoryOptions& o,
                                                        uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  SyntheticSubmapTrajectory out;
  out.prior_covariance = 1e-8 * Matrix6d::Identity();

  // Ground truth: heading random walk, turned back towards the centre at the
  // border of the area.
  double x = 0.0, y = 0.0, yaw = 0.0;
  for (int i = 0; i < o.submaps; ++i) {
    out.T_world_origin.push_back(MakePose(Eigen::Vector3d(x, y, TerrainHeight(x, y)), Rz(yaw)));
    yaw += 0.35 * n01(rng);
    if (std::abs(x) > o.area_half_width_m || std::abs(y) > o.area_half_width_m) {
      const double to_centre = std::atan2(-y, -x);
      yaw = to_centre + 0.3 * n01(rng);
    }
    x += o.step_m * std::cos(yaw);
    y += o.step_m * std::sin(yaw);
  }

  const Eigen::Vector4d w_sigma(o.w_sigma_p_m, o.w_sigma_p_m, o.w_sigma_p_m, o.w_sigma_yaw_rad);
  Vector6d c_sigma;
  c_sigma << o.c_sigma_p_m, o.c_sigma_p_m, o.c_sigma_p_m, o.c_sigma_rot_rad, o.c_sigma_rot_rad,
      o.c_sigma_rot_rad;
  Vector6d v_sigma;
  v_sigma << 0.02, 0.02, 0.02, 0.002, 0.002, 0.002;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (int j = 1; j < o.submaps; ++j) {
    SyntheticSubmapStep step;
    step.submap = j;
    const Eigen::Isometry3d& prev = out.T_world_origin[static_cast<size_t>(j - 1)];
    const Eigen::Isometry3d& cur = out.T_world_origin[static_cast<size_t>(j)];
    const Eigen::Isometry3d w_true = prev.inverse() * cur;
    step.T_old_new = MakePose(
        w_true.translation() +
            Eigen::Vector3d(w_sigma[0] * n01(rng), w_sigma[1] * n01(rng), w_sigma[2] * n01(rng)),
        Rz(YawOf(w_true.linear()) + w_sigma[3] * n01(rng)));
    step.w_covariance = w_sigma.cwiseAbs2().asDiagonal();
    for (int k = 0; k < o.filter_poses_per_submap; ++k) {
      const Eigen::Isometry3d v_true = MakePose(
          Eigen::Vector3d(o.step_m * unit(rng), 0.3 * n01(rng), 0.1 * n01(rng)),
          Rz(0.2 * n01(rng)) * ExpSO3(Eigen::Vector3d(0.05 * n01(rng), 0.05 * n01(rng), 0)));
      step.T_local_body.push_back(MakePose(
          v_true.translation() + 0.02 * Eigen::Vector3d(n01(rng), n01(rng), n01(rng)),
          v_true.linear() * ExpSO3(0.002 * Eigen::Vector3d(n01(rng), n01(rng), n01(rng)))));
      step.v_covariance.push_back(Matrix6d(v_sigma.cwiseAbs2().asDiagonal()));
    }
    if (o.loop_every > 0 && j % o.loop_every == 0) {
      std::vector<int> candidates;
      for (int i = 0; i + o.min_loop_gap <= j; ++i) {
        if ((out.T_world_origin[static_cast<size_t>(i)].translation() - cur.translation()).norm() <
            o.loop_radius_m) {
          candidates.push_back(i);
        }
      }
      if (!candidates.empty()) {
        std::uniform_int_distribution<size_t> pick(0, candidates.size() - 1);
        const int i = candidates[pick(rng)];
        const Eigen::Isometry3d c_true = out.T_world_origin[static_cast<size_t>(i)].inverse() * cur;
        SyntheticLoop loop;
        loop.submap_a = i;
        loop.submap_b = j;
        loop.T_a_b = MakePose(
            c_true.translation() + Eigen::Vector3d(c_sigma[0] * n01(rng), c_sigma[1] * n01(rng),
                                                   c_sigma[2] * n01(rng)),
            c_true.linear() * ExpSO3(Eigen::Vector3d(c_sigma[3] * n01(rng), c_sigma[4] * n01(rng),
                                                     c_sigma[5] * n01(rng))));
        loop.covariance = c_sigma.cwiseAbs2().asDiagonal();
        step.loops.push_back(loop);
      }
    }
    out.steps.push_back(std::move(step));
  }
  return out;
}

void SyntheticSubmapTrajectory::AddPrior(RoverGraph* graph) const {
  graph->AddOriginPrior(0, T_world_origin.front(), prior_covariance);
}

int SyntheticSubmapTrajectory::AddStep(size_t i, RoverGraph* graph) const {
  const SyntheticSubmapStep& s = steps[i];
  graph->AddFrameSwitch(0, s.submap - 1, s.T_old_new, s.w_covariance);
  for (size_t k = 0; k < s.T_local_body.size(); ++k) {
    graph->AddFilterPose(0, s.submap, s.submap * 100 + static_cast<int64_t>(k), s.T_local_body[k],
                         s.v_covariance[k]);
  }
  for (const SyntheticLoop& c : s.loops) {
    graph->AddSubmapMatch(0, c.submap_a, 0, c.submap_b, c.T_a_b, c.covariance);
  }
  return static_cast<int>(s.loops.size());
}

int SyntheticSubmapTrajectory::LoopCount() const {
  int count = 0;
  for (const SyntheticSubmapStep& s : steps) count += static_cast<int>(s.loops.size());
  return count;
}

}  // namespace rover::mapping
