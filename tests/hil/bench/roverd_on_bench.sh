#!/bin/sh
# roverd with the hardware board profile (firmware/config/bench.yaml) inside
# the HIL bench VM: its Xsens driver configures a simulated MTi on a pty pair
# (`rover-sim mti`) over Xbus, its SocketCAN driver receives the simulated
# wheel drives on vcan0 (`rover-sim can`), both streaming the `short`
# scenario in real time, and its stereo head is vivid's two capture nodes
# (one single-planar, one multi-planar; 2 fps). Passes when roverd took
# every IMU sample at 400 Hz with none lost, decoded the wheel drives and
# fused them, paired the two cameras' frames and handed them to the VO and
# the log, logged it all, and the log replays bit-exactly.
#
# usage (in the VM, from the source root): roverd_on_bench.sh BUILD_DIR OUT_DIR
set -eu
build="$1"
out="$2"
stream_s=15
work=/tmp/rover-bench
rm -rf "$work"
mkdir -p "$work/logs" "$out"

fail() { echo "roverd_on_bench: FAILED: $*"; exit 1; }

# Both simulators build the same world first (slow under emulation). The
# MTi streams for $stream_s s from roverd's GoToMeasurement, which roverd
# sends once every device is open and its threads are ready; the drives send
# from the moment their world is built, for the whole scenario (60 s, longer
# than roverd takes to start), and are stopped when the MTi is done.
"$build/hil/sim/rover-sim" mti --scenario short --link "$work/mti0" --max-duration-s "$stream_s" \
  >"$out/mti.log" 2>&1 &
mti=$!
"$build/hil/sim/rover-sim" can --scenario short --interface vcan0 >"$out/can.log" 2>&1 &
can=$!
i=0
while [ ! -e "$work/mti0" ]; do
  i=$((i + 1)); [ $i -lt 600 ] || fail "the simulated MTi did not come up (see mti.log)"
  sleep 0.1
done
"$build/firmware/roverd/roverd" --config firmware/config/bench.yaml --no-ipc >"$out/roverd.log" 2>&1 &
roverd=$!
wait $mti || fail "rover-sim mti failed: $(cat "$out/mti.log")"
kill -0 $can 2>/dev/null || fail "rover-sim can ended before the MTi did: $(cat "$out/can.log")"
kill $can
wait $can 2>/dev/null || true
sleep 1
kill -INT $roverd
wait $roverd || fail "roverd exited with status $?: $(cat "$out/roverd.log")"
cat "$out/mti.log" "$out/can.log" "$out/roverd.log"

sent=$(sed -n 's/^sent \([0-9]*\) MTData2 packets.*/\1/p' "$out/mti.log")
taken=$(sed -n 's/^  IMU     \([0-9]*\) samples, \([0-9]*\) dropped.*/\1/p' "$out/roverd.log")
dropped=$(sed -n 's/^  IMU     \([0-9]*\) samples, \([0-9]*\) dropped.*/\2/p' "$out/roverd.log")
periods=$(sed -n 's/^  CAN     \([0-9]*\) SYNC periods.*/\1/p' "$out/roverd.log")
wheels=$(sed -n 's/.*wheel speeds accepted \([0-9]*\).*/\1/p' "$out/roverd.log")
[ -n "$sent" ] && [ -n "$taken" ] || fail "could not read the sample counts"
[ "$taken" -eq "$sent" ] || fail "roverd took $taken IMU samples of $sent sent"
[ "$dropped" -eq 0 ] || fail "roverd lost $dropped IMU samples"
[ "$sent" -ge $((stream_s * 400 - 40)) ] || fail "only $sent IMU samples in ${stream_s} s"
[ "$periods" -ge $((stream_s * 100 / 2)) ] || fail "only $periods CAN SYNC periods decoded"
[ "$wheels" -gt 0 ] || fail "no wheel speeds fused"

# The stereo head: roverd ran at least as long as the simulators streamed.
grep -q "^  camera  V4L2 /dev/video0 + /dev/video1 (multi-planar), 640x480 GREY" "$out/roverd.log" ||
  fail "the stereo head was not opened as expected"
frames=$(sed -n 's/^  camera  \([0-9]*\) frames, \([0-9]*\) dropped.*/\1/p' "$out/roverd.log")
pairs=$(sed -n 's/^  stereo  \([0-9]*\) pairs.*/\1/p' "$out/roverd.log")
unpaired0=$(sed -n 's/.*; cam0 [0-9]* frames (\([0-9]*\) unpaired.*/\1/p' "$out/roverd.log")
unpaired1=$(sed -n 's/.*; cam1 [0-9]* frames (\([0-9]*\) unpaired.*/\1/p' "$out/roverd.log")
images=$(sed -n 's/.* \([0-9]*\) images logged.*/\1/p' "$out/roverd.log")
[ -n "$frames" ] && [ -n "$pairs" ] && [ -n "$unpaired0" ] && [ -n "$unpaired1" ] ||
  fail "could not read the camera counts"
[ "$pairs" -ge $((stream_s * 2 * 3 / 4)) ] || fail "only $pairs stereo pairs in over ${stream_s} s at 2 fps"
[ "$frames" -eq "$pairs" ] || fail "roverd took $frames frames of $pairs pairs"
# Free-running nodes: only the frames before both streams run are unpaired.
[ "$unpaired0" -le 2 ] && [ "$unpaired1" -le 2 ] ||
  fail "unpaired frames: cam0 $unpaired0, cam1 $unpaired1"
[ "$images" -gt 0 ] || fail "no thumbnails logged"
log=$(ls "$work"/logs/roverd-*.mcap)
cp "$log" "$out/roverd.mcap"  # for a look from the host (rover-log info)
"$build/host/replay/rover-replay" "$log" >"$out/replay.log" 2>&1 || fail "replay: $(cat "$out/replay.log")"
cat "$out/replay.log"
echo "roverd_on_bench: PASSED: $taken IMU samples (0 lost), $periods CAN periods, $wheels wheel speeds fused, $pairs stereo pairs; log replays bit-exactly"
