#!/usr/bin/env bash
# Runs every benchmark of a build tree and prints its figures. Targets are
# ratios against a reference measured in the same run (see each benchmark).
# usage: scripts/run_benchmarks.sh [BUILD_DIR]   (default build/release)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${1:-$root/build/release}"
scratch="$build/bench-scratch"   # on the project's disk, not a tmpfs
mkdir -p "$scratch"
echo "== SPSC ring (Google Benchmark)"
"$build/bench/ring/bench_spsc_ring" --benchmark_min_time=0.2
echo
echo "== Flight log"
"$build/bench/log/bench_log" --dir "$scratch"
rm -rf "$scratch"
echo
echo "== Local reference filter"
"$build/bench/estimator/bench_eskf"
echo
echo "== Pose graph (bench_graph; add --outliers for the false-loop-closure study)"
"$build/bench/graph/bench_graph"
echo
echo "== Stereo matching on EuRoC (bench_stereo_matcher)"
"$build/bench/vo/bench_stereo_matcher"
echo
echo "== Stereo VO per frame by stage on EuRoC (bench_stereo_odometry; pass a dataset dir for simulator data)"
"$build/bench/vo/bench_stereo_odometry"
