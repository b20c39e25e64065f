// rover-eval: trajectory evaluation for the state estimator (ATE, RPE, NEES).

#include <CLI/CLI.hpp>

#include <vector>

#include "host/eval/ate_command.h"
#include "host/eval/map_command.h"
#include "host/eval/nees_command.h"
#include "host/eval/sim_command.h"
#include "host/eval/subcommand.h"
#include "host/eval/vio_command.h"

int main(int argc, char** argv) {
  namespace eval = rover::host::eval;
  CLI::App app{
      "rover-eval: evaluate estimated trajectories against ground truth, and the local\n"
      "reference filter on the simulator (sim: accuracy, nees: Monte Carlo consistency), and\n"
      "the stereo VO with the filter on EuRoC-layout datasets (vio), and the map of a simulated\n"
      "mission against the simulator's ground truth (map).\n"
      "Reads TUM files, EuRoC and OpenVINS CSVs and rover flight logs (MCAP, with the\n"
      "estimator's frame switches chained). Exit status: 0 ok, 1 a check failed,\n"
      "2 bad usage or unusable input."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "rover-eval 0.1.0");

  // One line per subcommand; each lives in its own *_command.{h,cc}.
  const std::vector<eval::Subcommand> subcommands = {
      eval::AddAteCommand(app), eval::AddMapCommand(app), eval::AddNeesCommand(app),
      eval::AddSimCommand(app), eval::AddVioCommand(app),
  };

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int status = app.exit(e);
    return status == 0 ? 0 : eval::kExitBadInput;
  }
  for (const eval::Subcommand& s : subcommands) {
    if (s.app->parsed()) return s.run();
  }
  return eval::kExitBadInput;
}
