// rover-gpio-loopback: checks a board's GPIO path with a loopback wire.
//
// The output line is pulsed by the camera trigger driver (absolute-deadline
// pulses, as roverd triggers the stereo head) and the input line is read by
// the edge source (kernel-stamped edges, as roverd reads IMU data-ready).
// Every pulse must come back as one rising and one falling edge; the latency
// printed is the input edge's kernel stamp minus the trigger's stamp.
//
// Exit status: 0 if every edge arrived (and the latency limit held), 1 if the
// check failed, 2 if a chip or line could not be opened or an option is out
// of range.

#include <CLI/CLI.hpp>

#include <cmath>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>

#include "drivers/gpio/gpio_chip.h"
#include "drivers/gpio/gpio_loopback_check.h"
#include "drivers/gpio/libgpiod_chip.h"

namespace {

struct Args {
  std::string chip = "gpiochip0";
  std::string input_chip;  // empty: the output's chip
  uint32_t output_line = 17;
  uint32_t input_line = 27;
  uint32_t pulses = 100;
  double rate_hz = 10.0;
  double width_ms = 1.0;
  bool active_low = false;
  double edge_timeout_ms = 100.0;
  double max_latency_us = 0.0;
};

int Run(const Args& args) {
  rover::drivers::GpioLoopbackOptions options;
  options.output_line = args.output_line;
  options.input_line = args.input_line;
  options.pulses = args.pulses;
  options.rate_hz = args.rate_hz;
  options.pulse_width = rover::Duration::FromSeconds(args.width_ms * 1e-3);
  options.active_low = args.active_low;
  options.edge_timeout = rover::Duration::FromSeconds(args.edge_timeout_ms * 1e-3);
  options.max_latency = rover::Duration::FromSeconds(args.max_latency_us * 1e-6);
  const bool same_chip = args.input_chip.empty() || args.input_chip == args.chip;
  if (same_chip && options.output_line == options.input_line) {
    std::cerr << "rover-gpio-loopback: --out and --in must be different lines\n";
    return 2;
  }
  try {
    rover::drivers::LibgpiodChip output_chip(args.chip);
    std::unique_ptr<rover::drivers::LibgpiodChip> other_chip;
    if (!same_chip) other_chip = std::make_unique<rover::drivers::LibgpiodChip>(args.input_chip);
    rover::drivers::GpioChip& input_chip =
        other_chip ? static_cast<rover::drivers::GpioChip&>(*other_chip) : output_chip;
    std::cout << "output: " << output_chip.name() << " line " << options.output_line
              << "; input: " << input_chip.name() << " line " << options.input_line << "\n";
    rover::drivers::GpioLoopbackCheck check(output_chip, input_chip, options);
    const rover::drivers::GpioLoopbackReport report = check.Run();
    std::cout << report.ToString() << "\n";
    return report.passed() ? 0 : 1;
  } catch (const rover::drivers::GpioError& e) {
    std::cerr << "rover-gpio-loopback: " << e.what() << "\n";
    return 2;
  } catch (const std::invalid_argument& e) {
    std::cerr << "rover-gpio-loopback: " << e.what() << "\n";
    return 2;
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Checks a board's GPIO trigger and edge path with a loopback wire.\n\n"
      "Wire the output line to the input line (same voltage domain, e.g. a\n"
      "jumper between two header pins; a 1 kOhm series resistor protects\n"
      "against both being outputs). The output is pulsed N times by the\n"
      "camera trigger driver; every pulse must arrive at the input as one\n"
      "rising and one falling edge. Prints edge counts, lost edges and the\n"
      "latency (input edge kernel stamp - trigger stamp) p50/p99/max.\n\n"
      "Exit status: 0 pass, 1 check failed, 2 chip/line/option error.\n\n"
      "Example: rover-gpio-loopback --chip gpiochip0 --out 17 --in 27 --count 1000 "
      "--rate-hz 50",
      "rover-gpio-loopback"};
  Args args;
  app.add_option("--chip", args.chip,
                 "GPIO chip of the output line: path (/dev/gpiochip0), name (gpiochip0) or "
                 "label (see gpiodetect)")
      ->capture_default_str();
  app.add_option("--in-chip", args.input_chip,
                 "GPIO chip of the input line if it differs from --chip");
  app.add_option("--out", args.output_line, "output line offset (gpioinfo numbering)")
      ->capture_default_str();
  app.add_option("--in", args.input_line, "input line offset, wired to the output")
      ->capture_default_str();
  app.add_option("-n,--count", args.pulses, "pulses to send (1 to 1000000)")->capture_default_str();
  app.add_option("--rate-hz", args.rate_hz, "pulse rate in Hz (1 to 100)")->capture_default_str();
  app.add_option("--width-ms", args.width_ms, "pulse width in milliseconds (< one period)")
      ->capture_default_str();
  app.add_flag("--active-low", args.active_low,
               "treat both lines as active low (the pulse goes low)");
  app.add_option("--edge-timeout-ms", args.edge_timeout_ms,
                 "how long each edge may take to arrive before it counts as missing")
      ->capture_default_str();
  app.add_option("--max-latency-us", args.max_latency_us,
                 "fail if the largest latency exceeds this (0: report only)")
      ->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help prints and succeeds; any other parse error is a usage error (2).
    const int status = app.exit(e);
    return status == 0 ? 0 : 2;
  }
  if (!std::isfinite(args.width_ms) || !std::isfinite(args.edge_timeout_ms) ||
      !std::isfinite(args.max_latency_us)) {
    std::cerr << "rover-gpio-loopback: --width-ms, --edge-timeout-ms and --max-latency-us must "
                 "be finite\n";
    return 2;
  }
  return Run(args);
}
