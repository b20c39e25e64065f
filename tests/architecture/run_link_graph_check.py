#!/usr/bin/env python3
"""Configures the project into a scratch folder and checks its link graph.

The test architecture_link_graph runs this: a configure of its own (no
compiling) with tests and benchmarks off, so the graph holds the shipped
targets only, then scripts/check_link_graph.py on the graph and the target map
that configure wrote. Exit status: the checker's (0 clean, 1 violations, 2
unreadable input), or 2 when the configure fails.
"""

import argparse
import os
import subprocess
import sys

# Graph options CMake reads from the build folder: external and interface
# libraries are what the must-not-reach rules look for; the per-target files
# (one or two per target) are not needed.
GRAPHVIZ_OPTIONS = """\
set(GRAPHVIZ_EXTERNAL_LIBS TRUE)
set(GRAPHVIZ_INTERFACE_LIBS TRUE)
set(GRAPHVIZ_GENERATE_PER_TARGET FALSE)
set(GRAPHVIZ_GENERATE_DEPENDERS FALSE)
"""


def parse_args(argv):
    """Parses the command line; arguments after `--` go to the cmake configure."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cmake", default="cmake", help="cmake executable")
    parser.add_argument("--source", required=True, help="project root")
    parser.add_argument("--build", required=True, help="scratch build folder (reconfigured from scratch)")
    parser.add_argument("--rules", required=True, help="rules file")
    parser.add_argument("cmake_args", nargs="*", help="extra configure arguments, after --")
    return parser.parse_args(argv)


def configure(args):
    """Runs the fresh configure that writes the graph; returns the .dot path or None."""
    os.makedirs(args.build, exist_ok=True)
    with open(os.path.join(args.build, "CMakeGraphVizOptions.cmake"), "w", encoding="utf-8") as stream:
        stream.write(GRAPHVIZ_OPTIONS)
    dot = os.path.join(args.build, "rover.dot")
    # --fresh: options left in an old cache (by hand, or by an earlier version
    # of this test) must not change the graph.
    command = [args.cmake, "--fresh", "-S", args.source, "-B", args.build, "-G", "Ninja",
               "-DROVER_BUILD_TESTS=OFF", "-DROVER_BUILD_BENCHMARKS=OFF", "-DROVER_CCACHE=OFF",
               f"--graphviz={dot}", *args.cmake_args]
    print("+ " + " ".join(command), flush=True)
    result = subprocess.run(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, check=False)
    if result.returncode != 0:
        print(result.stdout)
        print(f"run_link_graph_check: configure failed (exit {result.returncode})", file=sys.stderr)
        return None
    return dot


def main(argv=None):
    """Configures, then hands the graph to the checker; returns the exit status."""
    args = parse_args(argv)
    dot = configure(args)
    if dot is None:
        return 2
    checker = os.path.join(args.source, "scripts", "check_link_graph.py")
    targets = os.path.join(args.build, "rover_targets.tsv")
    command = [sys.executable, checker, "--dot", dot, "--targets", targets, "--rules", args.rules]
    print("+ " + " ".join(command), flush=True)
    return subprocess.run(command, check=False).returncode


if __name__ == "__main__":
    sys.exit(main())
