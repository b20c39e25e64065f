#ifndef ROVER_HOST_EVAL_VIO_COMMAND_H_
#define ROVER_HOST_EVAL_VIO_COMMAND_H_

// `rover-eval vio`: the command line of a VO + filter run on an EuRoC-layout
// dataset (vio_run.h) and its report (vio_report.h).

#include <CLI/CLI.hpp>

#include <ostream>

#include "core/cli/subcommand.h"
#include "host/eval/vio_run.h"

namespace rover::host::eval {

using cli::kExitBadInput;
using cli::kExitCheckFailed;
using cli::kExitOk;
using cli::Subcommand;

/// RunVioExperiment + PrintVioReport. Returns kExitOk; kExitCheckFailed
/// (after the report) if the filter never initialised; kExitBadInput with a
/// message "rover-eval vio: ..." on `err` for unusable input.
int RunVio(const VioCommandOptions& options, std::ostream& out, std::ostream& err);

/// Adds `rover-eval vio` to `app` (see subcommand.h).
Subcommand AddVioCommand(CLI::App& app);

}  // namespace rover::host::eval

#endif  // ROVER_HOST_EVAL_VIO_COMMAND_H_
