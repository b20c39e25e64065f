// rover-filter-eval: runs the local reference filter on a simulated scenario
// (FilterFeed + RunFilter) and prints its accuracy, consistency and health.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <fstream>
#include <iostream>
#include <numbers>
#include <stdexcept>
#include <string>

#include "estimator/eskf/eskf_output.h"
#include "hil/sim/estimator_feed/filter_feed.h"
#include "hil/sim/estimator_feed/filter_run.h"
#include "hil/sim/scenario/scenario.h"

namespace {

using rover::estimator::InputKind;
using rover::estimator::RejectReason;

void PrintRejections(const rover::sim::FilterRunResult& r) {
  for (int k = 0; k < rover::estimator::kInputKindCount; ++k) {
    const auto kind = static_cast<InputKind>(k);
    std::printf("  %-14s accepted %7llu", rover::estimator::ToString(kind),
                static_cast<unsigned long long>(r.health.Accepted(kind)));
    for (int c = 0; c < rover::estimator::kRejectReasonCount; ++c) {
      const auto reason = static_cast<RejectReason>(c);
      const uint64_t n = r.health.Rejected(kind, reason);
      if (n > 0) {
        std::printf(", %s %llu", rover::estimator::ToString(reason),
                    static_cast<unsigned long long>(n));
      }
    }
    std::printf("\n");
  }
}

void WriteCsv(const std::string& path, const rover::sim::FilterFeed& feed,
              const rover::sim::FilterRunResult& r) {
  std::ofstream out(path);
  out << "t_s,frame,dp_x,dp_y,dp_z,dth_x,dth_y,dth_z,dv_x,dv_y,dv_z,dpg_x,dpg_y,dpg_z,"
         "sp_x,sp_y,sp_z,sth_x,sth_y,sth_z,nees_p,nees_a,nees_valid\n";
  out.precision(9);
  for (const rover::sim::FilterErrorSample& s : r.samples) {
    out << (s.stamp - feed.start()).ToSeconds() << ',' << s.frame_id;
    for (const Eigen::Vector3d* v : {&s.dp_local_m, &s.dtheta_rad, &s.dv_local_m_s, &s.dp_global_m,
                                     &s.sigma_p_m, &s.sigma_theta_rad}) {
      out << ',' << v->x() << ',' << v->y() << ',' << v->z();
    }
    out << ',' << s.nees_position << ',' << s.nees_attitude << ',' << s.nees_valid << '\n';
  }
  if (!out) throw std::runtime_error("cannot write " + path);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Runs the local reference filter on a simulated scenario and scores it"};
  std::string scenario_name = "short";
  uint64_t seed = 1;
  std::string preset = "realistic";
  bool no_wheels = false;
  double switch_m = 0.0;
  double duration_s = 0.0;
  double drop = 0.0;
  bool imu_white_only = false;
  std::string csv_path;
  app.add_option("--scenario", scenario_name, "scenario name")->capture_default_str();
  app.add_option("--seed", seed, "world and sensor seed")->capture_default_str();
  app.add_option("--preset", preset, "VO noise: ideal-consistent or realistic")
      ->capture_default_str();
  app.add_flag("--no-wheels", no_wheels, "leave the wheel speeds out");
  app.add_option("--switch-distance", switch_m, "frame switch every N metres (0: none)");
  app.add_option("--duration", duration_s, "simulated seconds (0: whole route)");
  app.add_option("--drop", drop, "VO frame drop probability");
  app.add_flag("--imu-white-only", imu_white_only,
               "simulate the IMU without scale-factor and misalignment errors (the filter's "
               "own error model)");
  app.add_option("--csv", csv_path, "write every output's errors and sigmas to this file");
  CLI11_PARSE(app, argc, argv);

  try {
    rover::sim::Scenario scenario = rover::sim::LoadScenario(
        rover::sim::FindScenario(rover::sim::DefaultScenarioDir(), scenario_name),
        rover::sim::DefaultSimConfigDir());
    if (imu_white_only) {
      for (rover::sim::ImuTriadErrors* e : {&scenario.imu.gyro, &scenario.imu.accel}) {
        e->scale_factor_error.setZero();
        e->misalignment_rad.setZero();
      }
    }
    rover::sim::FilterFeedOptions options;
    options.wheels_enabled = !no_wheels;
    options.frame_switch_distance_m = switch_m;
    options.max_duration_s = duration_s;
    options.vo.noise = rover::sim::VoNoiseModel::Preset(preset);
    options.vo.drop_probability = drop;

    const rover::Time t0 = rover::Time::Now();
    const rover::sim::FilterFeed feed(scenario, seed, options);
    const double feed_s = (rover::Time::Now() - t0).ToSeconds();
    const rover::sim::FilterRunResult r =
        rover::sim::RunFilter(feed, rover::sim::EskfOptionsForFeed(feed));

    const auto& c = feed.counts();
    std::printf("scenario %s, seed %llu, VO %s, wheels %s, switch every %.1f m\n",
                scenario.name.c_str(), static_cast<unsigned long long>(seed), preset.c_str(),
                no_wheels ? "off" : "on", switch_m);
    std::printf(
        "feed: %.1f s simulated, %zu inputs (imu %llu, wheels %llu, triggers %llu, "
        "VO %llu, keyframes %llu, dropped %llu, switches %llu), built in %.2f s\n",
        (feed.end() - feed.start()).ToSeconds(), feed.inputs().size(),
        static_cast<unsigned long long>(c.imu), static_cast<unsigned long long>(c.wheel_speeds),
        static_cast<unsigned long long>(c.clone_triggers),
        static_cast<unsigned long long>(c.relative_poses),
        static_cast<unsigned long long>(c.vo.keyframes),
        static_cast<unsigned long long>(c.vo.dropped),
        static_cast<unsigned long long>(c.frame_switches), feed_s);
    std::printf(
        "filter: %llu outputs, %llu switches, run + scoring %.2f s, all finite: %s, "
        "frame ids consistent: %s\n",
        static_cast<unsigned long long>(r.outputs),
        static_cast<unsigned long long>(r.frame_switches), r.run_wall_time_s,
        r.all_finite ? "yes" : "NO", r.frame_ids_consistent ? "yes" : "NO");
    const double pct = r.distance_m > 0 ? 100.0 / r.distance_m : 0.0;
    std::printf("distance %.2f m (from init at %.3f s)\n", r.distance_m,
                (r.init_stamp - feed.start()).ToSeconds());
    std::printf(
        "position error, per frame: final %.4f m (%.3f %%), mean %.4f m (%.3f %%), "
        "max %.4f m\n",
        r.final_position_error_m, r.final_position_error_m * pct, r.mean_position_error_m,
        r.mean_position_error_m * pct, r.max_position_error_m);
    std::printf(
        "position error, global:    final %.4f m (%.3f %%), mean %.4f m (%.3f %%), "
        "max %.4f m\n",
        r.final_global_position_error_m, r.final_global_position_error_m * pct,
        r.mean_global_position_error_m, r.mean_global_position_error_m * pct,
        r.max_global_position_error_m);
    std::printf("attitude error: final %.4f deg, max %.4f deg; velocity error max %.4f m/s\n",
                r.final_attitude_error_rad * 180.0 / std::numbers::pi,
                r.max_attitude_error_rad * 180.0 / std::numbers::pi, r.max_velocity_error_m_s);
    std::printf("mean NEES: position %.3f, attitude %.3f (3 if consistent; %llu samples)\n",
                r.mean_nees_position, r.mean_nees_attitude,
                static_cast<unsigned long long>(r.nees_samples));
    std::printf("clones: created %llu, marginalised %llu, evicted %llu; ZUPTs %llu\n",
                static_cast<unsigned long long>(r.health.clones_created),
                static_cast<unsigned long long>(r.health.clones_marginalised),
                static_cast<unsigned long long>(r.health.clones_evicted),
                static_cast<unsigned long long>(r.health.zero_velocity_updates));
    PrintRejections(r);
    int shown = 0;
    for (const rover::estimator::RejectRecord& rec : r.rejects) {
      if (rec.reason == RejectReason::kNotInitialised || shown == 20) continue;
      ++shown;
      std::printf("  rejected %s at %.3f s: %s", rover::estimator::ToString(rec.kind),
                  (rec.stamp - feed.start()).ToSeconds(), rover::estimator::ToString(rec.reason));
      if (rec.reason == RejectReason::kGated) {
        std::printf(" (d2 %.1f > %.1f)", rec.mahalanobis_sq, rec.gate);
      }
      std::printf("\n");
    }
    if (!csv_path.empty()) WriteCsv(csv_path, feed, r);
  } catch (const std::exception& e) {
    std::cerr << "rover-filter-eval: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
