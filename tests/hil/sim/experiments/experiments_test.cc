// rover-sim filter and nees: the filter on the simulator (accuracy; Monte
// Carlo consistency; the command-line contract). Each test runs a few simulations of the `short`
// scenario (about 2.5 s each in the dev build, mostly world generation).

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "core/cli/subcommand.h"
#include "core/stats/chi_square.h"
#include "hil/sim/experiments/filter_command.h"
#include "hil/sim/experiments/nees_command.h"

namespace rover::sim::experiments {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::StartsWith;

// The last non-empty line of a report.
std::string LastLine(const std::string& report) {
  std::istringstream in(report);
  std::string line, last;
  while (std::getline(in, line)) {
    if (!line.empty()) last = line;
  }
  return last;
}

// The RESULT line's keys in order and their values.
struct ResultFields {
  std::vector<std::string> keys;
  std::map<std::string, std::string> values;
};

ResultFields ParseResult(const std::string& line) {
  ResultFields r;
  std::istringstream words(line);
  std::string word;
  words >> word;
  if (word != "RESULT") return r;
  while (words >> word) {
    const auto eq = word.find('=');
    if (eq == std::string::npos) continue;
    r.keys.push_back(word.substr(0, eq));
    r.values[word.substr(0, eq)] = word.substr(eq + 1);
  }
  return r;
}

// A number of the RESULT line ("nan" parses as NaN); throws if unparseable.
double Number(const ResultFields& r, const std::string& key) {
  const std::string& text = r.values.at(key);
  std::size_t used = 0;
  const double value = std::stod(text, &used);
  if (used != text.size()) throw std::invalid_argument(key + "=" + text);
  return value;
}

struct Report {
  int status = -1;
  std::string out;
  std::string err;
};

Report Nees(const NeesCommandOptions& options) {
  std::ostringstream out, err;
  Report r;
  r.status = RunNees(options, out, err);
  r.out = out.str();
  r.err = err.str();
  return r;
}

Report Sim(const FilterCommandOptions& options) {
  std::ostringstream out, err;
  Report r;
  r.status = RunFilterCommand(options, out, err);
  r.out = out.str();
  r.err = err.str();
  return r;
}

NeesCommandOptions SmallNees(int runs) {
  NeesCommandOptions o;  // defaults: short, ideal-consistent VO, no wheels
  o.runs = runs;
  o.seed = 1;
  o.jobs = 2;
  return o;
}

// The consistency claim on a small subset: 4 runs of `short` with the
// command's defaults; both Monte Carlo averages inside the 95 % bounds of
// chi2(12)/4.
TEST(RoverSimNees, AverageNeesOfFourRunsInsideBounds) {
  const NeesCommandOptions options = SmallNees(4);
  const Report r = Nees(options);
  ASSERT_EQ(r.status, kExitOk) << r.out << r.err;

  const ResultFields f = ParseResult(LastLine(r.out));
  ASSERT_EQ(f.keys, (std::vector<std::string>{"runs", "nees_pos_mean", "nees_att_mean", "bound_lo",
                                              "bound_hi"}))
      << LastLine(r.out);
  EXPECT_EQ(f.values.at("runs"), "4");
  const rover::stats::ChiSquareInterval bounds = rover::stats::AverageNeesBounds(3, 4, 0.95);
  EXPECT_NEAR(Number(f, "bound_lo"), bounds.lower, 1e-4);
  EXPECT_NEAR(Number(f, "bound_hi"), bounds.upper, 1e-4);
  const double pos = Number(f, "nees_pos_mean"), att = Number(f, "nees_att_mean");
  EXPECT_GE(pos, bounds.lower) << r.out;
  EXPECT_LE(pos, bounds.upper) << r.out;
  EXPECT_GE(att, bounds.lower) << r.out;
  EXPECT_LE(att, bounds.upper) << r.out;

  // The per-run table names every seed, and progress went to stderr.
  EXPECT_THAT(r.out, HasSubstr("seeds 1..4"));
  EXPECT_THAT(r.out, HasSubstr("check: PASS"));
  EXPECT_THAT(r.err, HasSubstr("run 4/4 done"));
  EXPECT_THAT(r.err, HasSubstr("ETA"));
}

// The check can fail: a filter told the VO is 10x more precise than it is
// (covariance_inflation 0.1) is overconfident, far above the upper bound.
TEST(RoverSimNees, OverconfidentFilterFailsTheCheck) {
  NeesCommandOptions options = SmallNees(2);
  options.setup.max_duration_s = 30.0;
  options.setup.vo_covariance_inflation = 0.1;
  const Report r = Nees(options);
  EXPECT_EQ(r.status, kExitCheckFailed) << r.out << r.err;
  const ResultFields f = ParseResult(LastLine(r.out));
  ASSERT_EQ(f.keys.size(), 5u) << LastLine(r.out);
  EXPECT_GT(Number(f, "nees_pos_mean"), 2.0 * Number(f, "bound_hi")) << r.out;
  EXPECT_THAT(r.out, HasSubstr("check: FAIL"));
}

// Same seed, same RESULT, whatever the number of threads; another seed differs.
TEST(RoverSimNees, DeterministicForAnyJobs) {
  NeesCommandOptions options = SmallNees(2);
  options.setup.max_duration_s = 20.0;
  options.jobs = 1;
  const Report one = Nees(options);
  options.jobs = 2;
  const Report two = Nees(options);
  options.seed = 7;
  const Report other = Nees(options);
  ASSERT_THAT(LastLine(one.out), StartsWith("RESULT runs=2 "));
  EXPECT_EQ(LastLine(one.out), LastLine(two.out));
  EXPECT_NE(LastLine(one.out), LastLine(other.out));
}

TEST(RoverSimNees, BadOptions) {
  NeesCommandOptions options = SmallNees(2);
  options.setup.scenario = "no-such-scenario";
  Report r = Nees(options);
  EXPECT_EQ(r.status, kExitBadInput);
  EXPECT_THAT(r.err, HasSubstr("rover-sim nees: "));
  options = SmallNees(2);
  options.confidence = 1.5;
  r = Nees(options);
  EXPECT_EQ(r.status, kExitBadInput);
  EXPECT_THAT(r.err, HasSubstr("confidence"));
}

// The sim RESULT line: every field, in order, parseable; plausible values.
TEST(RoverSimFilter, ResultLineOfShort) {
  FilterCommandOptions options;
  options.setup.scenario = "short";
  options.seed = 1;
  const Report r = Sim(options);
  ASSERT_EQ(r.status, kExitOk) << r.out << r.err;
  const ResultFields f = ParseResult(LastLine(r.out));
  ASSERT_EQ(f.keys, (std::vector<std::string>{"scenario", "runs", "distance_m", "final_err_m",
                                              "final_err_pct", "mean_err_pct", "ate_rmse_m",
                                              "rpe_trans_pct", "rpe_rot_deg_per_m", "nees_pos_mean",
                                              "nees_att_mean"}))
      << LastLine(r.out);
  EXPECT_EQ(f.values.at("scenario"), "short");
  EXPECT_EQ(f.values.at("runs"), "1");
  for (const std::string& key : f.keys) {
    if (key == "scenario") continue;
    double value = 0.0;
    ASSERT_NO_THROW(value = Number(f, key)) << key;
    EXPECT_TRUE(std::isfinite(value)) << key << " in " << LastLine(r.out);
    EXPECT_GE(value, 0.0) << key;
  }
  // `short` drives 5 + 2.5 + 3 m; the filter stays within a few % of it.
  EXPECT_NEAR(Number(f, "distance_m"), 10.5, 0.5);
  EXPECT_LT(Number(f, "final_err_pct"), 5.0);
  // final_err_pct is final_err_m over the distance.
  EXPECT_NEAR(Number(f, "final_err_pct"),
              100.0 * Number(f, "final_err_m") / Number(f, "distance_m"), 1e-3);
  EXPECT_THAT(r.out, HasSubstr("Absolute trajectory error"));
  EXPECT_THAT(r.out, HasSubstr("Relative pose error per segment length"));
  EXPECT_THAT(r.out, HasSubstr("note: the wheel model's"));  // wheels on by default
}

// Several runs: the means, identical with one or two threads; a route too
// short for every RPE segment gives "nan", never a missing field.
TEST(RoverSimFilter, SeveralRunsDeterministicAndNanForMissingRpe) {
  FilterCommandOptions options;
  options.setup.scenario = "short";
  options.setup.max_duration_s = 15.0;
  options.setup.wheels = false;
  options.segments_m = {50.0};
  options.runs = 2;
  options.jobs = 1;
  const Report one = Sim(options);
  options.jobs = 2;
  const Report two = Sim(options);
  ASSERT_EQ(one.status, kExitOk) << one.out << one.err;
  EXPECT_EQ(LastLine(one.out), LastLine(two.out));
  const ResultFields f = ParseResult(LastLine(one.out));
  ASSERT_EQ(f.keys.size(), 11u) << LastLine(one.out);
  EXPECT_EQ(f.values.at("runs"), "2");
  EXPECT_EQ(f.values.at("rpe_trans_pct"), "nan");
  EXPECT_EQ(f.values.at("rpe_rot_deg_per_m"), "nan");
  EXPECT_TRUE(std::isfinite(Number(f, "ate_rmse_m")));
  EXPECT_THAT(one.out, Not(HasSubstr("note: the wheel model's")));
}

TEST(RoverSimFilter, UnknownScenarioIsBadInput) {
  FilterCommandOptions options;
  options.setup.scenario = "no-such-scenario";
  const Report r = Sim(options);
  EXPECT_EQ(r.status, kExitBadInput);
  EXPECT_THAT(r.err, HasSubstr("rover-sim filter: "));
}

// The command lines: options reach the runs, bad values are parse errors.
TEST(RoverSimExperimentsCommandLine, NeesAndFilterParseTheirOptions) {
  {
    CLI::App app;
    AddNeesCommand(app);
    EXPECT_THROW(app.parse("nees --preset noisy"), CLI::ValidationError);
  }
  {
    CLI::App app;
    AddFilterCommand(app);
    EXPECT_THROW(app.parse("filter --wheels maybe"), CLI::ValidationError);
  }
  {
    CLI::App app;
    const Subcommand nees = AddNeesCommand(app);
    app.parse(
        "nees --scenario short --runs 1 --seed 3 --duration-s 5 --preset realistic --wheels on "
        "--confidence 0.9 --jobs 1");
    ASSERT_TRUE(nees.app->parsed());
    ::testing::internal::CaptureStdout();
    const int status = nees.run();
    const std::string report = ::testing::internal::GetCapturedStdout();
    EXPECT_NE(status, kExitBadInput) << report;
    EXPECT_THAT(report, HasSubstr("scenario short, 1 runs, seeds 3..3"));
    EXPECT_THAT(report, HasSubstr("VO preset realistic, wheels on"));
    const ResultFields f = ParseResult(LastLine(report));
    ASSERT_EQ(f.keys.size(), 5u) << report;
    EXPECT_NEAR(Number(f, "bound_hi"), rover::stats::AverageNeesBounds(3, 1, 0.9).upper, 1e-4);
  }
  {
    CLI::App app;
    const Subcommand sim = AddFilterCommand(app);
    app.parse("filter --scenario short --seed 2 --duration-s 5 --wheels off --segments 1,2");
    ASSERT_TRUE(sim.app->parsed());
    ::testing::internal::CaptureStdout();
    const int status = sim.run();
    const std::string report = ::testing::internal::GetCapturedStdout();
    EXPECT_EQ(status, kExitOk) << report;
    EXPECT_THAT(report, HasSubstr("1 run, seed 2"));
    EXPECT_THAT(report, HasSubstr("VO preset realistic, wheels off"));
    EXPECT_THAT(LastLine(report), StartsWith("RESULT scenario=short runs=1 "));
  }
}

}  // namespace
}  // namespace rover::sim::experiments
