#!/bin/sh
# roverd with the hardware board profile (firmware/config/bench.yaml) inside
# the HIL bench VM: its Xsens driver configures a simulated MTi on a pty pair
# (`rover-sim mti`) over Xbus, its SocketCAN driver receives the simulated
# wheel drives on vcan0 (`rover-sim can`), both streaming the `short`
# scenario in real time. Passes when roverd took every IMU sample at 400 Hz
# with none lost, decoded the wheel drives and fused them, logged it all,
# and the log replays bit-exactly.
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

# Both simulators build the same world first (slow under emulation); started
# together they stream at about the same time.
"$build/hil/sim/rover-sim" mti --scenario short --link "$work/mti0" --max-duration-s "$stream_s" \
  >"$out/mti.log" 2>&1 &
mti=$!
"$build/hil/sim/rover-sim" can --scenario short --interface vcan0 --max-duration-s "$stream_s" \
  >"$out/can.log" 2>&1 &
can=$!
i=0
while [ ! -e "$work/mti0" ]; do
  i=$((i + 1)); [ $i -lt 600 ] || fail "the simulated MTi did not come up (see mti.log)"
  sleep 0.1
done
"$build/firmware/roverd/roverd" --config firmware/config/bench.yaml --no-ipc >"$out/roverd.log" 2>&1 &
roverd=$!
wait $mti || fail "rover-sim mti failed: $(cat "$out/mti.log")"
wait $can || fail "rover-sim can failed: $(cat "$out/can.log")"
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
log=$(ls "$work"/logs/roverd-*.mcap)
"$build/host/replay/rover-replay" "$log" >"$out/replay.log" 2>&1 || fail "replay: $(cat "$out/replay.log")"
cat "$out/replay.log"
echo "roverd_on_bench: PASSED: $taken IMU samples (0 lost), $periods CAN periods, $wheels wheel speeds fused; log replays bit-exactly"
