#include "drivers/gpio/gpio_loopback_check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <span>
#include <stdexcept>
#include <vector>

#include "core/stats/percentile.h"
#include "drivers/gpio/gpio_camera_trigger.h"
#include "drivers/gpio/gpio_line_edge_source.h"

namespace rover::drivers {
namespace {

GpioCameraTriggerOptions TriggerOptions(const GpioLoopbackOptions& o) {
  GpioCameraTriggerOptions t;
  t.rate_hz = o.rate_hz;
  t.pulse_width = o.pulse_width;
  t.line = o.output_line;
  t.active_low = o.active_low;
  t.consumer = "rover-loopback-out";
  return t;
}

// A percentile of latencies, to the nanosecond.
Duration PercentileDuration(const std::vector<Duration>& latencies, double percent) {
  if (latencies.empty()) return Duration::Zero();
  std::vector<int64_t> ns(latencies.size());
  std::transform(latencies.begin(), latencies.end(), ns.begin(),
                 [](Duration d) { return d.nanoseconds(); });
  return Duration::Nanoseconds(
      std::llround(stats::Percentile(std::span<const int64_t>(ns), percent)));
}

std::string Micros(Duration d) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f us", d.ToMicroseconds());
  return text;
}

}  // namespace

void GpioLoopbackOptions::Validate() const {
  if (pulses < 1 || pulses > 1'000'000) {
    throw std::invalid_argument("GpioLoopbackOptions.pulses: expected 1 to 1000000, found " +
                                std::to_string(pulses));
  }
  if (edge_timeout <= Duration::Zero()) {
    throw std::invalid_argument("GpioLoopbackOptions.edge_timeout: expected > 0, found " +
                                edge_timeout.ToString());
  }
  if (max_latency < Duration::Zero()) {
    throw std::invalid_argument(
        "GpioLoopbackOptions.max_latency: expected >= 0 (0 = no limit), found " +
        max_latency.ToString());
  }
  TriggerOptions(*this).Validate();  // rate_hz and pulse_width, named as the trigger's
}

bool GpioLoopbackReport::passed() const {
  const bool latency_ok = options.max_latency == Duration::Zero() || rising_edges == 0 ||
                          latency_max <= options.max_latency;
  return pulses == options.pulses && trigger_failures == 0 && rising_edges == options.pulses &&
         falling_edges == options.pulses && missing_edges == 0 && unexpected_edges == 0 &&
         lost_edges == 0 && read_errors == 0 && latency_ok;
}

std::string GpioLoopbackReport::ToString() const {
  char line[256];
  std::string out;
  std::snprintf(line, sizeof line, "pulses: %u of %u at %g Hz, width %s, line %u -> line %u%s\n",
                pulses, options.pulses, options.rate_hz, options.pulse_width.ToString().c_str(),
                options.output_line, options.input_line, options.active_low ? " (active low)" : "");
  out += line;
  std::snprintf(line, sizeof line,
                "edges: rising %llu, falling %llu, missing %llu, unexpected %llu, lost %llu\n",
                static_cast<unsigned long long>(rising_edges),
                static_cast<unsigned long long>(falling_edges),
                static_cast<unsigned long long>(missing_edges),
                static_cast<unsigned long long>(unexpected_edges),
                static_cast<unsigned long long>(lost_edges));
  out += line;
  if (rising_edges > 0) {
    out += "latency (edge stamp - trigger stamp): min " + Micros(latency_min) + ", p50 " +
           Micros(latency_p50) + ", p99 " + Micros(latency_p99) + ", max " + Micros(latency_max) +
           "\n";
  }
  if (falling_edges > 0 && rising_edges > 0) {
    out += "width at the input: min " + Micros(width_min) + ", max " + Micros(width_max) + "\n";
  }
  std::snprintf(line, sizeof line,
                "trigger: skipped slots %llu, failed pulses %llu; input read errors %llu\n",
                static_cast<unsigned long long>(skipped_pulses),
                static_cast<unsigned long long>(trigger_failures),
                static_cast<unsigned long long>(read_errors));
  out += line;
  if (passed()) return out + "PASS";
  std::string why;
  if (missing_edges > 0 || rising_edges < options.pulses || falling_edges < options.pulses) {
    why += " missing edges (is the wire on the right pins?);";
  }
  if (unexpected_edges > 0) why += " unexpected edges (noise, bounce or a second driver?);";
  if (lost_edges > 0) why += " edges lost in the kernel;";
  if (trigger_failures > 0 || pulses < options.pulses) why += " trigger failures;";
  if (read_errors > 0) why += " input read errors;";
  if (options.max_latency > Duration::Zero() && latency_max > options.max_latency) {
    why += " latency above " + Micros(options.max_latency) + ";";
  }
  if (!why.empty()) why.pop_back();
  return out + "FAIL:" + why;
}

GpioLoopbackCheck::GpioLoopbackCheck(GpioChip& output_chip, GpioChip& input_chip,
                                     const GpioLoopbackOptions& options)
    : output_chip_(output_chip), input_chip_(input_chip), options_(options) {
  options_.Validate();
  if (&output_chip == &input_chip && options.output_line == options.input_line) {
    throw std::invalid_argument(
        "GpioLoopbackOptions.input_line: expected a line other than the output line on the "
        "same chip, found " +
        std::to_string(options.input_line));
  }
}

GpioLoopbackReport GpioLoopbackCheck::Run() {
  GpioLoopbackReport report;
  report.options = options_;
  // The output first, so its request (driving the idle level) cannot show
  // up as an edge at the input.
  GpioCameraTrigger trigger(output_chip_, TriggerOptions(options_));
  GpioLineEdgeSourceOptions input;
  input.line = options_.input_line;
  input.consumer = "rover-loopback-in";
  input.edges = GpioEdges::kBoth;
  input.active_low = options_.active_low;
  input.nominal_period = trigger.period();
  GpioLineEdgeSource source(input_chip_, input);

  std::vector<Duration> latencies;
  std::vector<Duration> widths;
  latencies.reserve(options_.pulses);
  widths.reserve(options_.pulses);
  const Duration period = trigger.period();
  const Duration next_timeout = period * 2 + options_.pulse_width;
  GpioEdge edge;
  for (uint32_t i = 0; i < options_.pulses; ++i) {
    Time sent;
    if (trigger.Next(&sent, next_timeout) != ReadStatus::kOk) {
      ++report.trigger_failures;
      continue;
    }
    ++report.pulses;
    bool got_rise = false;
    bool got_fall = false;
    Time rise;
    while (!(got_rise && got_fall)) {
      const ReadStatus status = source.Wait(&edge, options_.edge_timeout);
      if (status != ReadStatus::kOk) break;
      // An edge from before this pulse's slot cannot belong to it.
      if (edge.stamp < sent - period / 2) {
        ++report.unexpected_edges;
        continue;
      }
      if (edge.rising && !got_rise && !got_fall) {
        got_rise = true;
        rise = edge.stamp;
        latencies.push_back(edge.stamp - sent);
      } else if (!edge.rising && !got_fall) {
        got_fall = true;
        if (got_rise) widths.push_back(edge.stamp - rise);
      } else {
        ++report.unexpected_edges;
      }
    }
    report.rising_edges += got_rise ? 1 : 0;
    report.falling_edges += got_fall ? 1 : 0;
    report.missing_edges += (got_rise ? 0U : 1U) + (got_fall ? 0U : 1U);
  }
  // Anything still arriving after the last pulse is an extra edge.
  while (source.Wait(&edge, options_.edge_timeout) == ReadStatus::kOk) ++report.unexpected_edges;

  report.lost_edges = source.lost_edges();
  report.read_errors = source.stats().read_errors;
  report.skipped_pulses = trigger.stats().skipped_pulses;
  std::sort(latencies.begin(), latencies.end());
  std::sort(widths.begin(), widths.end());
  if (!latencies.empty()) {
    report.latency_min = latencies.front();
    report.latency_p50 = PercentileDuration(latencies, 50.0);
    report.latency_p99 = PercentileDuration(latencies, 99.0);
    report.latency_max = latencies.back();
  }
  if (!widths.empty()) {
    report.width_min = widths.front();
    report.width_max = widths.back();
  }
  return report;
}

}  // namespace rover::drivers
