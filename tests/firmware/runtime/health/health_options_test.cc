#include "firmware/runtime/health/health_options.h"

#include <gtest/gtest.h>

#include <limits>
#include <stdexcept>
#include <string>

#include "core/config/config.h"

namespace rover::runtime {
namespace {

// Loads the `health` section of `yaml` and returns the ConfigError text
// ("" if none).
std::string LoadError(const std::string& yaml) {
  try {
    const ConfigNode root = ConfigNode::LoadString(yaml, "board.yaml");
    HealthOptions::Load(root.Child("health"));
    return "";
  } catch (const ConfigError& e) {
    return e.what();
  }
}

TEST(HealthOptionsTest, LoadsEveryKey) {
  const ConfigNode root = ConfigNode::LoadString(
      "health:\n  period_s: 0.5\n  stale_after_s: 2.0\n  rate_warn_fraction: 0.8\n"
      "  watchdog: false\n",
      "board.yaml");
  const HealthOptions o = HealthOptions::Load(root.Child("health"));
  EXPECT_DOUBLE_EQ(o.period_s, 0.5);
  EXPECT_DOUBLE_EQ(o.stale_after_s, 2.0);
  EXPECT_DOUBLE_EQ(o.rate_warn_fraction, 0.8);
  EXPECT_FALSE(o.watchdog);
  EXPECT_EQ(o.period(), Duration::Milliseconds(500));
  root.CheckNoUnknownKeysRecursive();
}

TEST(HealthOptionsTest, AbsentKeysTakeTheDefaults) {
  const ConfigNode root = ConfigNode::LoadString("health: {}\n", "board.yaml");
  const HealthOptions o = HealthOptions::Load(root.Child("health"));
  EXPECT_DOUBLE_EQ(o.period_s, 1.0);
  EXPECT_DOUBLE_EQ(o.stale_after_s, 1.0);
  EXPECT_DOUBLE_EQ(o.rate_warn_fraction, 0.9);
  EXPECT_TRUE(o.watchdog);
  EXPECT_NO_THROW(o.Validate());
}

TEST(HealthOptionsTest, BadValuesNameTheKeyWithExpectedAndFound) {
  EXPECT_EQ(LoadError("health:\n  period_s: 0\n"),
            "board.yaml:2: health.period_s: expected a number in [0.01, 60], found 0");
  EXPECT_EQ(LoadError("health:\n  stale_after_s: 0\n"),
            "board.yaml:2: health.stale_after_s: expected a time in (0, 60] s, found 0");
  EXPECT_EQ(LoadError("health:\n  period_s: 1\n  stale_after_s: 90.5\n"),
            "board.yaml:3: health.stale_after_s: expected a time in (0, 60] s, found 90.5");
  EXPECT_EQ(LoadError("health:\n  rate_warn_fraction: 1.5\n"),
            "board.yaml:2: health.rate_warn_fraction: expected a number in [0, 1], found 1.5");
  EXPECT_NE(LoadError("health:\n  watchdog: 1\n").find("board.yaml:2: health.watchdog: expected"),
            std::string::npos);
}

TEST(HealthOptionsTest, TypoIsReportedAsUnknownKey) {
  const ConfigNode root = ConfigNode::LoadString("health:\n  stale_after: 2.0\n", "board.yaml");
  HealthOptions::Load(root.Child("health"));
  try {
    root.CheckNoUnknownKeysRecursive();
    FAIL() << "the misspelt key was accepted";
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("health.stale_after"), std::string::npos) << what;
    EXPECT_NE(what.find("stale_after_s"), std::string::npos) << what;  // The hint.
  }
}

TEST(HealthOptionsTest, ValidateThrowsInvalidArgumentWithTheKey) {
  HealthOptions o;
  o.period_s = std::numeric_limits<double>::quiet_NaN();
  try {
    o.Validate();
    FAIL() << "NaN period accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()),
              "health.period_s: expected a period in [0.01, 60] s, found nan");
  }
  o = {};
  o.rate_warn_fraction = -0.1;
  EXPECT_THROW(o.Validate(), std::invalid_argument);
}

TEST(HealthOptionsTest, SensorMonitorOptionsFollowTheHealthOptions) {
  HealthOptions o;
  o.stale_after_s = 2.5;
  o.rate_warn_fraction = 0.75;
  const SensorMonitorOptions m = o.sensor_monitor_options();
  EXPECT_EQ(m.stale_after, Duration::Milliseconds(2500));
  EXPECT_DOUBLE_EQ(m.rate_warn_fraction, 0.75);
  EXPECT_EQ(m.gap_factor, SensorMonitorOptions{}.gap_factor);
  EXPECT_NO_THROW(m.Validate());
}

}  // namespace
}  // namespace rover::runtime
