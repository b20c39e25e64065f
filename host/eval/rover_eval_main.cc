// rover-eval: trajectory evaluation for the state estimator (ATE, RPE, NEES) on
// logs and datasets. Experiments that drive the simulator are rover-sim's.

#include <CLI/CLI.hpp>

#include <vector>

#include "core/cli/subcommand.h"
#include "host/eval/ate_command.h"
#include "host/eval/vio_command.h"

int main(int argc, char** argv) {
  namespace eval = rover::host::eval;
  CLI::App app{
      "rover-eval: evaluate estimated trajectories against ground truth (ate), and the stereo\n"
      "VO with the local reference filter on EuRoC-layout datasets (vio).\n"
      "The filter on the simulator and the map of a simulated mission are scored by\n"
      "`rover-sim filter`, `rover-sim nees` and `rover-sim map`.\n"
      "Reads TUM files, EuRoC and OpenVINS CSVs and rover flight logs (MCAP, with the\n"
      "estimator's frame switches chained). Exit status: 0 ok, 1 a check failed,\n"
      "2 bad usage or unusable input."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "rover-eval 0.1.0");

  // One line per subcommand; each lives in its own *_command.{h,cc}.
  const std::vector<rover::cli::Subcommand> subcommands = {
      eval::AddAteCommand(app),
      eval::AddVioCommand(app),
  };

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int status = app.exit(e);
    return status == 0 ? 0 : rover::cli::kExitBadInput;
  }
  for (const rover::cli::Subcommand& s : subcommands) {
    if (s.app->parsed()) return s.run();
  }
  return rover::cli::kExitBadInput;
}
