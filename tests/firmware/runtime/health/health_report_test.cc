#include "firmware/runtime/health/health_report.h"

#include <gtest/gtest.h>

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "core/log/cdr/cdr_reader.h"
#include "core/log/cdr/cdr_writer.h"

namespace rover::runtime {
namespace {

using log::diagnostic_msgs::DiagnosticArray;
using log::diagnostic_msgs::DiagnosticStatus;

// A healthy sensor as SensorMonitor::Snapshot would report it.
SensorHealth Healthy(const std::string& name, double rate_hz) {
  SensorHealth h;
  h.name = name;
  h.level = HealthLevel::kOk;
  h.nominal_rate_hz = rate_hz;
  h.samples = 4000;
  h.rate_hz = rate_hz;
  h.rate_window_s = 1.0;
  h.rate_window_samples = static_cast<uint64_t>(rate_hz);
  h.rate_judged = true;
  h.interval_s = 1.0;
  h.has_sample = true;
  h.since_last_sample_s = 0.002;
  h.latency_measured = true;
  h.latency.count = 400;
  h.latency.p50_ns = 85'000;
  h.latency.p99_ns = 120'000;
  h.latency.max_ns = 131'500;
  return h;
}

SensorHealth Stale(const std::string& name, double since_last_s) {
  SensorHealth h = Healthy(name, 100.0);
  h.level = HealthLevel::kStale;
  h.rate_hz = 0.0;
  h.since_last_sample_s = since_last_s;
  return h;
}

// The value of `key` in `status`, or "<missing>".
std::string ValueOf(const DiagnosticStatus& status, const std::string& key) {
  for (const auto& kv : status.values) {
    if (kv.key == key) return kv.value;
  }
  return "<missing>";
}

TEST(HealthReportTest, SensorStatusCarriesLevelMessageAndKeysWithUnits) {
  HealthReport report;
  SensorHealth imu = Healthy("imu", 400.0);
  imu.drops = 5;
  imu.longest_gap_s = 0.0075;
  report.AddSensor(imu);
  const DiagnosticArray array = report.ToDiagnosticArray(Time::FromNanoseconds(12'500'000'000));

  EXPECT_EQ(array.header.stamp.sec, 12);
  EXPECT_EQ(array.header.stamp.nanosec, 500'000'000u);
  ASSERT_EQ(array.status.size(), 1u);
  const DiagnosticStatus& s = array.status[0];
  EXPECT_EQ(s.name, "imu");
  EXPECT_EQ(s.level, DiagnosticStatus::kOk);
  EXPECT_EQ(s.message, "ok");
  EXPECT_EQ(ValueOf(s, "rate_hz"), "400.00");
  EXPECT_EQ(ValueOf(s, "nominal_rate_hz"), "400.00");
  EXPECT_EQ(ValueOf(s, "since_last_s"), "0.002");
  EXPECT_EQ(ValueOf(s, "drops"), "5");
  EXPECT_EQ(ValueOf(s, "new_drops"), "0");
  EXPECT_EQ(ValueOf(s, "longest_gap_s"), "0.007");
  EXPECT_EQ(ValueOf(s, "latency_count"), "400");
  EXPECT_EQ(ValueOf(s, "latency_p50_us"), "85.0");
  EXPECT_EQ(ValueOf(s, "latency_p99_us"), "120.0");
  EXPECT_EQ(ValueOf(s, "latency_max_us"), "131.5");
  EXPECT_EQ(ValueOf(s, "rate_judged"), "true");
}

TEST(HealthReportTest, NoLatencyKeysWhenLatencyIsNotMeasured) {
  HealthReport report;
  SensorHealth camera = Healthy("camera", 10.0);
  camera.latency_measured = false;
  report.AddSensor(camera);
  const DiagnosticStatus s = report.ToDiagnosticArray(Time::Zero()).status.at(0);
  EXPECT_EQ(ValueOf(s, "latency_p99_us"), "<missing>");
  EXPECT_EQ(ValueOf(s, "rate_hz"), "10.00");
}

TEST(HealthReportTest, OneLineSummarisesEverySensorInOrder) {
  HealthReport report;
  report.AddSensors(std::vector<SensorHealth>{Healthy("imu", 400.0), Healthy("camera", 10.0),
                                              Stale("can", 1.234)});
  EXPECT_EQ(report.OneLine(), "imu ok 400.0 Hz, camera ok 10.0 Hz, can STALE 1.2 s");
  EXPECT_EQ(report.WorstLevel(), DiagnosticStatus::kStale);
  const DiagnosticArray array = report.ToDiagnosticArray(Time::Zero());
  ASSERT_EQ(array.status.size(), 3u);
  EXPECT_EQ(array.status[2].message, "no sample for 1.2 s");
}

TEST(HealthReportTest, SensorThatNeverDeliveredSaysNoData) {
  HealthReport report;
  SensorHealth can = Stale("can", std::numeric_limits<double>::infinity());
  can.has_sample = false;
  report.AddSensor(can);
  EXPECT_EQ(report.OneLine(), "can STALE no data");
  const DiagnosticStatus s = report.ToDiagnosticArray(Time::Zero()).status.at(0);
  EXPECT_EQ(s.message, "no sample yet");
  EXPECT_EQ(ValueOf(s, "since_last_s"), "inf");
}

TEST(HealthReportTest, WarningsAndErrorsSayWhy) {
  HealthReport report;
  SensorHealth imu = Healthy("imu", 400.0);
  imu.level = HealthLevel::kWarn;
  imu.rate_hz = 350.0;
  imu.rate_low = true;
  imu.new_drops = 2;
  imu.new_gaps = 1;
  report.AddSensor(imu);
  SensorHealth can = Healthy("can", 100.0);
  can.level = HealthLevel::kError;
  can.new_errors = 1;
  report.AddSensor(can);

  EXPECT_EQ(report.OneLine(),
            "imu WARN 350.0/400.0 Hz (2 new drops, 1 new gap), can ERROR 100.0 Hz (1 new error)");
  const DiagnosticArray array = report.ToDiagnosticArray(Time::Zero());
  EXPECT_EQ(array.status[0].level, DiagnosticStatus::kWarn);
  EXPECT_EQ(array.status[0].message, "2 new drops; 1 new gap; rate 350.0 Hz, nominal 400.0 Hz");
  EXPECT_EQ(array.status[1].level, DiagnosticStatus::kError);
  EXPECT_EQ(array.status[1].message, "1 new error");
  EXPECT_EQ(report.WorstLevel(), DiagnosticStatus::kError);
}

TEST(HealthReportTest, FreeFormComponentsKeepTheirValuesInOrder) {
  HealthReport report;
  report.AddSensor(Healthy("imu", 400.0));
  report.AddStatus("estimator", HealthLevel::kWarn, "covariance growing",
                   {{"position_sigma_m", "0.41"}, {"loop_latency_us_p999", "212.0"}});
  report.AddStatus("logger", HealthLevel::kOk, "");

  EXPECT_EQ(report.size(), 3u);
  EXPECT_EQ(report.OneLine(), "imu ok 400.0 Hz, estimator WARN covariance growing, logger ok");
  EXPECT_EQ(report.WorstLevel(), DiagnosticStatus::kWarn);
  const DiagnosticArray array = report.ToDiagnosticArray(Time::Zero());
  const DiagnosticStatus& estimator = array.status.at(1);
  EXPECT_EQ(estimator.name, "estimator");
  EXPECT_EQ(estimator.level, DiagnosticStatus::kWarn);
  EXPECT_EQ(estimator.message, "covariance growing");
  ASSERT_EQ(estimator.values.size(), 2u);
  EXPECT_EQ(estimator.values[0].key, "position_sigma_m");
  EXPECT_EQ(estimator.values[0].value, "0.41");
  EXPECT_EQ(estimator.values[1].key, "loop_latency_us_p999");
}

TEST(HealthReportTest, EmptyReportIsOkAndClearForgetsEverything) {
  HealthReport report;
  EXPECT_EQ(report.WorstLevel(), DiagnosticStatus::kOk);
  EXPECT_EQ(report.OneLine(), "");
  EXPECT_TRUE(report.ToDiagnosticArray(Time::Zero()).status.empty());
  report.AddSensor(Stale("can", 3.0));
  report.Clear();
  EXPECT_EQ(report.size(), 0u);
  EXPECT_EQ(report.WorstLevel(), DiagnosticStatus::kOk);
}

TEST(HealthReportTest, DiagnosticArraySurvivesTheFlightLogEncoding) {
  HealthReport report;
  report.AddSensors(std::vector<SensorHealth>{Healthy("imu", 400.0), Stale("can", 1.5)});
  report.AddStatus("estimator", HealthLevel::kOk, "converged", {{"nis", "1.02"}});
  const DiagnosticArray array = report.ToDiagnosticArray(Time::FromSeconds(42.25));

  std::vector<std::byte> bytes;
  log::CdrWriter writer(&bytes);
  log::diagnostic_msgs::Serialize(array, writer);
  ASSERT_TRUE(writer.ok());
  log::CdrReader reader(bytes);
  DiagnosticArray decoded;
  ASSERT_TRUE(log::diagnostic_msgs::Deserialize(reader, &decoded));
  EXPECT_EQ(decoded, array);
}

// From monitor to status line, as the health thread does it.
TEST(HealthReportTest, MonitorSnapshotsFlowIntoTheReport) {
  SensorMonitor imu("imu", 400.0);
  SensorMonitor can("can", 100.0);
  const Time start = Time::FromSeconds(50.0);
  Time stamp = start;
  for (int i = 0; i <= 400; ++i) {
    imu.OnSample(stamp, stamp);
    stamp += Duration::Microseconds(2500);
  }
  const Time now = start + Duration::Seconds(1);
  HealthReport report;
  report.AddSensor(imu.Snapshot(now));
  report.AddSensor(can.Snapshot(now));
  EXPECT_EQ(report.OneLine(), "imu ok 400.0 Hz, can STALE no data");
  EXPECT_EQ(report.WorstLevel(), DiagnosticStatus::kStale);
}

}  // namespace
}  // namespace rover::runtime
