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
echo "== Team graph: Helmert blocking (one block per robot) against the full solve; online update"
"$build/bench/graph/bench_team_graph"
echo
echo "== Stereo matching on EuRoC (bench_stereo_matcher)"
"$build/bench/vo/bench_stereo_matcher"
echo
echo "== Stereo VO per frame by stage on EuRoC (bench_stereo_odometry; pass a dataset dir for simulator data)"
"$build/bench/vo/bench_stereo_odometry"
echo
echo "== Mapping: fast octree insertion vs insertPointCloud, SGBM at 752x480"
"$build/bench/mapping/bench_octree_insertion"
"$build/bench/mapping/bench_sgbm"
"$build/bench/mapping/bench_loop_match"
echo
echo "== Drivers: Xbus (Xsens MTi) decoding"
"$build/bench/drivers/bench_xbus_decode"
echo
echo "== Drivers: Aravis streaming from arv-fake-gv-camera-0.8 on loopback"
"$build/bench/drivers/bench_aravis_stream"
# The V4L2 and SocketCAN figures need vivid and vcan: inside the HIL bench VM
# (software emulation, so emulated-CPU figures).
initramfs="$build/hil/bench/hil_bench_initramfs.cpio.gz"
if [[ -f "$initramfs" ]]; then
  echo
  echo "== Drivers in the HIL bench VM: V4L2 from vivid (single-, then multi-planar), then SocketCAN on vcan0"
  "$root/hil/bench/run_in_vm.sh" --initramfs "$initramfs" --out "$build/bench-vm" --timeout-s 600 \
    -- sh -c "$build/bench/drivers/bench_v4l2_vivid && $build/bench/drivers/bench_v4l2_vivid --device /dev/video1 && $build/bench/drivers/bench_can_decode"
fi
