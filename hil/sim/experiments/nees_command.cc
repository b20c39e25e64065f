#include "hil/sim/experiments/nees_command.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

#include "core/cli/report_format.h"
#include "core/stats/chi_square.h"
#include "estimator/eval/eval_error.h"

namespace rover::sim::experiments {

using cli::Fixed;
using cli::General;
using cli::kExitBadInput;
using cli::kExitCheckFailed;
using cli::kExitOk;
using cli::ResultLine;
using cli::Subcommand;
using cli::TextTable;
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kNeesDof = 3;

double Seconds(std::chrono::steady_clock::duration d) {
  return std::chrono::duration<double>(d).count();
}

bool Inside(double value, double lo, double hi) { return value >= lo && value <= hi; }

NeesRun RunOne(const sim::Scenario& scenario, const NeesCommandOptions& options, int index) {
  const auto t0 = std::chrono::steady_clock::now();
  NeesRun run;
  run.seed = RunSeed(options.seed, index);
  const sim::FilterFeed feed(scenario, run.seed, SimFeedOptions(options.setup));
  sim::FilterRunOptions run_options;
  run_options.nees_skip_s = options.nees_skip_s;
  run_options.keep_samples = true;
  const sim::FilterRunResult r =
      sim::RunFilter(feed, SimFilterOptions(feed, options.setup), run_options);

  run.distance_m = r.distance_m;
  run.final_error_m = r.outputs > 0 ? r.final_global_position_error_m : kNaN;
  run.nees_samples = r.nees_samples;
  run.nees_position = r.nees_samples > 0 ? r.mean_nees_position : kNaN;
  run.nees_attitude = r.nees_samples > 0 ? r.mean_nees_attitude : kNaN;
  run.rejections = RejectionsAfterInit(r);
  run.gated = GatedRejections(r);

  // The valid output nearest to each grid time, within half an IMU period.
  const double step_s = options.grid_step_s;
  const auto steps =
      static_cast<std::size_t>(std::floor((feed.end() - feed.start()).ToSeconds() / step_s) + 1.0);
  const double tolerance_s = 0.5 / scenario.imu.rate_hz;
  run.grid_position.assign(steps, kNaN);
  run.grid_attitude.assign(steps, kNaN);
  std::vector<double> offset(steps, std::numeric_limits<double>::infinity());
  for (const sim::FilterErrorSample& s : r.samples) {
    if (!s.nees_valid) continue;
    const double t = (s.stamp - feed.start()).ToSeconds();
    const double k = std::round(t / step_s);
    if (k < 0.0) continue;
    const auto i = static_cast<std::size_t>(k);
    const double d = std::abs(t - k * step_s);
    if (i >= steps || d > tolerance_s || d >= offset[i]) continue;
    offset[i] = d;
    run.grid_position[i] = s.nees_position;
    run.grid_attitude[i] = s.nees_attitude;
  }
  run.wall_time_s = Seconds(std::chrono::steady_clock::now() - t0);
  return run;
}

}  // namespace

NeesSummary RunNeesExperiment(const NeesCommandOptions& options, std::ostream& err) {
  options.setup.Validate();
  if (options.runs < 1) throw std::invalid_argument("--runs must be at least 1");
  if (options.jobs < 1) throw std::invalid_argument("--jobs must be at least 1");
  if (!(options.confidence > 0.0 && options.confidence < 1.0)) {
    throw std::invalid_argument("--confidence must be in (0, 1)");
  }
  if (!(options.grid_step_s > 0.0)) throw std::invalid_argument("grid step must be positive");
  if (!(options.nees_skip_s >= 0.0)) throw std::invalid_argument("NEES skip must not be negative");

  const sim::Scenario scenario = LoadSimScenario(options.setup);
  NeesSummary summary;
  summary.runs.resize(static_cast<std::size_t>(options.runs));
  RunInParallel(
      options.runs, options.jobs, "rover-sim nees",
      [&](int i) {
        NeesRun& run = summary.runs[static_cast<std::size_t>(i)];
        run = RunOne(scenario, options, i);
        return "seed " + std::to_string(run.seed) + ", NEES pos " + Fixed(run.nees_position, 2) +
               " att " + Fixed(run.nees_attitude, 2);
      },
      err);

  const rover::stats::ChiSquareInterval bounds =
      rover::stats::AverageNeesBounds(kNeesDof, options.runs, options.confidence);
  summary.bound_lo = bounds.lower;
  summary.bound_hi = bounds.upper;
  const double n = static_cast<double>(options.runs);
  double sum_p = 0.0, sum_a = 0.0;
  for (const NeesRun& r : summary.runs) {
    sum_p += r.nees_position;  // NaN (a run without valid samples) fails the check
    sum_a += r.nees_attitude;
  }
  summary.nees_position_mean = sum_p / n;
  summary.nees_attitude_mean = sum_a / n;
  summary.position_inside = Inside(summary.nees_position_mean, bounds.lower, bounds.upper);
  summary.attitude_inside = Inside(summary.nees_attitude_mean, bounds.lower, bounds.upper);

  // Per time step, over the steps where every run has a valid NEES.
  std::size_t steps = std::numeric_limits<std::size_t>::max();
  for (const NeesRun& r : summary.runs) steps = std::min(steps, r.grid_position.size());
  std::size_t used = 0, inside_p = 0, inside_a = 0;
  double grid_sum_p = 0.0, grid_sum_a = 0.0;
  for (std::size_t k = 0; k < steps; ++k) {
    double p = 0.0, a = 0.0;
    bool valid = true;
    for (const NeesRun& r : summary.runs) {
      valid = valid && std::isfinite(r.grid_position[k]) && std::isfinite(r.grid_attitude[k]);
      p += r.grid_position[k];
      a += r.grid_attitude[k];
    }
    if (!valid) continue;
    p /= n;
    a /= n;
    ++used;
    grid_sum_p += p;
    grid_sum_a += a;
    if (Inside(p, bounds.lower, bounds.upper)) ++inside_p;
    if (Inside(a, bounds.lower, bounds.upper)) ++inside_a;
  }
  summary.grid_steps = used;
  const double u = static_cast<double>(used);
  summary.grid_position_inside = used > 0 ? static_cast<double>(inside_p) / u : kNaN;
  summary.grid_attitude_inside = used > 0 ? static_cast<double>(inside_a) / u : kNaN;
  summary.grid_position_mean = used > 0 ? grid_sum_p / u : kNaN;
  summary.grid_attitude_mean = used > 0 ? grid_sum_a / u : kNaN;
  return summary;
}

int RunNees(const NeesCommandOptions& options, std::ostream& out, std::ostream& err) {
  const auto wall_start = std::chrono::steady_clock::now();
  NeesSummary s;
  std::string wheel_note;
  std::string scenario_name = options.setup.scenario;
  try {
    s = RunNeesExperiment(options, err);
    wheel_note = WheelSeedNote(options.setup, LoadSimScenario(options.setup));
  } catch (const std::exception& e) {
    err << "rover-sim nees: " << e.what() << "\n";
    return kExitBadInput;
  }
  const double wall_s = Seconds(std::chrono::steady_clock::now() - wall_start);

  out << "rover-sim nees: Monte Carlo consistency of the local reference filter\n";
  out << "scenario " << scenario_name << ", " << options.runs << " runs, seeds " << options.seed
      << ".." << RunSeed(options.seed, options.runs - 1) << "\n";
  out << "setup: " << options.setup.Describe() << "\n";
  out << "seeds: run i (0-based) uses seed S + i for the world, every IMU stream (noise, bias "
         "walks, turn-on biases, timing jitter) and the VO's noise, drops and latency\n";
  if (!wheel_note.empty()) out << wheel_note << "\n";
  out << "\n";

  TextTable table({"run", "seed", "distance [m]", "final err [m]", "final err [%]", "NEES pos",
                   "NEES att", "samples", "rejections", "gated"});
  for (std::size_t i = 0; i < s.runs.size(); ++i) {
    const NeesRun& r = s.runs[i];
    table.AddRow({std::to_string(i + 1), std::to_string(r.seed), Fixed(r.distance_m, 2),
                  Fixed(r.final_error_m, 4),
                  Fixed(r.distance_m > 0.0 ? 100.0 * r.final_error_m / r.distance_m : kNaN, 3),
                  Fixed(r.nees_position, 3), Fixed(r.nees_attitude, 3),
                  std::to_string(r.nees_samples), std::to_string(r.rejections),
                  std::to_string(r.gated)});
  }
  out << table.ToString();

  const std::string conf = General(100.0 * options.confidence) + " %";
  out << "\nMonte Carlo average over " << options.runs << " runs of the per-run time-averaged NEES"
      << " (3 dof each; bounds: chi2(" << kNeesDof * options.runs << ")/" << options.runs << " at "
      << conf << ")\n";
  TextTable summary(
      {"", "mean", "expected", "bound lo", "bound hi", "inside", "per-step mean", "steps inside"});
  const auto row = [&](const char* name, double mean, bool inside, double grid_mean,
                       double grid_inside) {
    summary.AddRow({name, Fixed(mean, 3), "3", Fixed(s.bound_lo, 3), Fixed(s.bound_hi, 3),
                    inside ? "yes" : "NO", Fixed(grid_mean, 3),
                    Fixed(100.0 * grid_inside, 1) + " %"});
  };
  row("position", s.nees_position_mean, s.position_inside, s.grid_position_mean,
      s.grid_position_inside);
  row("attitude", s.nees_attitude_mean, s.attitude_inside, s.grid_attitude_mean,
      s.grid_attitude_inside);
  out << summary.ToString();
  out << "  per step: the NEES averaged over the runs at each of " << s.grid_steps
      << " time steps (every " << General(options.grid_step_s)
      << " s, valid in every run) against the same bounds; about " << conf
      << " of the steps are inside for a consistent filter (neighbouring steps are correlated)\n";
  out << "  each run's NEES is its time average over the valid outputs (from "
      << General(options.nees_skip_s)
      << " s after initialisation); that average is at most as spread as one chi2(3) sample, "
         "so the bounds are conservative for it\n";
  out << "check: " << (s.Passed() ? "PASS" : "FAIL") << " (position average "
      << (s.position_inside ? "inside" : "OUTSIDE") << ", attitude average "
      << (s.attitude_inside ? "inside" : "OUTSIDE") << " the bounds); wall time "
      << Fixed(wall_s, 1) << " s (" << options.jobs << (options.jobs == 1 ? " job" : " jobs")
      << ")\n";
  out << "\n"
      << ResultLine({
             {"runs", std::to_string(options.runs)},
             {"nees_pos_mean", General(s.nees_position_mean)},
             {"nees_att_mean", General(s.nees_attitude_mean)},
             {"bound_lo", General(s.bound_lo)},
             {"bound_hi", General(s.bound_hi)},
         })
      << "\n";
  return s.Passed() ? kExitOk : kExitCheckFailed;
}

Subcommand AddNeesCommand(CLI::App& app) {
  struct State {
    NeesCommandOptions options;
    std::string wheels = "off";
  };
  auto state = std::make_shared<State>();
  NeesCommandOptions& o = state->options;

  CLI::App* cmd = app.add_subcommand(
      "nees",
      "Monte Carlo consistency of the local reference filter on the simulator: N seeded runs\n"
      "(run i uses seed S + i), the filter alone, VO relative poses drawn from their stated\n"
      "covariance. Prints the NEES of every run, the Monte Carlo averages of the position and\n"
      "attitude NEES against the chi-square bounds (exit status 1 if outside) and the\n"
      "fraction of time steps inside them. Defaults: the ideal-consistent VO preset without\n"
      "wheel speeds, the setup the filter's models match best.");
  cmd->add_option("--scenario", o.setup.scenario, "scenario name")->capture_default_str();
  cmd->add_option("--runs", o.runs, "number of runs")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--seed", o.seed, "seed of the first run")->capture_default_str();
  AddSimSetupOptions(cmd, &o.setup, &state->wheels, &o.jobs);
  cmd->add_option("--confidence", o.confidence, "two-sided confidence of the bounds")
      ->check(CLI::Range(0.5, 0.9999))
      ->capture_default_str();
  cmd->add_option("--grid-step-s", o.grid_step_s, "time step of the per-step comparison [s]")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();

  Subcommand sub;
  sub.app = cmd;
  sub.run = [state]() {
    state->options.setup.wheels = state->wheels == "on";
    return RunNees(state->options, std::cout, std::cerr);
  };
  return sub;
}

}  // namespace rover::sim::experiments
