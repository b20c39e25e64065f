#ifndef ROVER_CORE_CLI_SUBCOMMAND_H_
#define ROVER_CORE_CLI_SUBCOMMAND_H_

// How a host tool's subcommands plug into its command line (rover-eval's,
// and the simulator's experiments in rover-sim).
//
// Each subcommand lives in its own NAME_command.{h,cc} and provides
//
//   /// Adds `rover-eval NAME` to `app`.
//   Subcommand AddNameCommand(CLI::App& app);
//
// which declares the subcommand and its options on `app` (storing the parsed
// values in state owned by the returned `run` function) and returns what to
// call when the user selected it. The command logic itself is a plain
// function writing to streams (e.g. RunAte(options, out, err)) so tests call
// it without a command line. rover_eval_main.cc calls every Add*Command once
// and runs the one that was parsed. To add a subcommand: write the two files,
// list the .cc in the tool's CMakeLists.txt and add one line to
// its main.

#include <CLI/CLI.hpp>

#include <functional>

namespace rover::cli {

/// Exit statuses of every subcommand.
inline constexpr int kExitOk = 0;
/// The evaluation ran but a check failed (for subcommands that check bounds).
inline constexpr int kExitCheckFailed = 1;
/// Bad usage or unusable input (missing file, bad format, no overlap).
inline constexpr int kExitBadInput = 2;

/// A registered subcommand.
struct Subcommand {
  CLI::App* app = nullptr;   ///< The subcommand's parser; `*app` is true once parsed.
  std::function<int()> run;  ///< Runs it with the parsed options; returns the exit status.
};

}  // namespace rover::cli

#endif  // ROVER_CORE_CLI_SUBCOMMAND_H_
