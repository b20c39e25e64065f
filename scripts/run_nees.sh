#!/usr/bin/env bash
# Runs the full Monte Carlo consistency experiment of the local reference
# filter: `rover-sim nees --scenario short --runs 25 --seed 1`, and
# prints the NEES of every run, the Monte Carlo averages against the 95 %
# chi-square bounds and the RESULT line. Builds nothing.
#
# usage: scripts/run_nees.sh [rover-sim nees options...]
#   Options are passed through; --scenario, --runs and --seed default to
#   short, 25 and 1 when not given. Examples:
#     scripts/run_nees.sh --jobs 2
#     scripts/run_nees.sh --preset realistic --wheels on
# The binary is $ROVER_BUILD_DIR/hil/sim/rover-sim if ROVER_BUILD_DIR is
# set, else the first of build/dev and build/release that has one with the
# nees subcommand.
# Exit status: rover-sim's (0 inside the bounds, 1 outside, 2 bad usage).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

candidates=()
if [[ -n "${ROVER_BUILD_DIR:-}" ]]; then candidates+=("$ROVER_BUILD_DIR"); fi
candidates+=("$root/build/dev" "$root/build/release")
# The first candidate whose rover-sim has the nees subcommand.
binary=""
stale=()
for dir in "${candidates[@]}"; do
  candidate="$dir/hil/sim/rover-sim"
  [[ -x "$candidate" ]] || continue
  help="$("$candidate" --help 2> /dev/null || true)"
  if grep -Eq '^  nees( |$)' <<< "$help"; then
    binary="$candidate"
    break
  fi
  stale+=("$candidate")
done
if [[ -z "$binary" ]]; then
  echo "run_nees.sh: no rover-sim with the nees subcommand in ${candidates[*]}" \
    "${stale[*]:+(out of date: ${stale[*]})}; build the rover-sim target first" >&2
  exit 2
fi

# Defaults for the options the caller did not give (either --opt value or --opt=value).
given() {
  local name="$1" arg
  shift
  for arg in "$@"; do
    if [[ "$arg" == "$name" || "$arg" == "$name="* ]]; then return 0; fi
  done
  return 1
}
args=()
given --scenario "$@" || args+=(--scenario short)
given --runs "$@" || args+=(--runs 25)
given --seed "$@" || args+=(--seed 1)

echo "== $binary nees ${args[*]} $*"
exec "$binary" nees "${args[@]}" "$@"
