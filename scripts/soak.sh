#!/usr/bin/env bash
# Soak test: one long lockstep mission with the full roverd + mapd stack (the
# figure-eight-1km route driven LAPS times in one go), sampling both
# processes' resident memory. Passes if, from the first WARMUP_S seconds of
# wall time to the end of the drive (roverd-sim exits), neither process's
# RSS grew by more than MAX_GROWTH_PCT (medians of WINDOW_S seconds at each
# end, default 300), and the mission reports no IMU or frame drops. mapd's
# shutdown, when it composes the global map from its log and exports it, is
# sampled too and reported on its own ("export peak"): it holds the map,
# which grows with the ground covered, not with time. Not a CI test: one lap
# takes about 45 minutes on a machine like the CI's.
#
# Usage: scripts/soak.sh [--laps N] [--seed S] [--out DIR] [--period-s P]
#   --laps N        laps of the figure-eight (default 2: about 2 km, 90 minutes)
#   --seed S        world seed (default 1)
#   --out DIR       where the logs, the memory samples (rss.csv) and the
#                   summary go (default build/soak)
#   --period-s P    seconds between memory samples (default 30)
# Needs the dev build (./rover build dev).
set -euo pipefail

cd "$(dirname "$0")/.."
LAPS=2
SEED=1
OUT=build/soak
PERIOD_S=30
WARMUP_S=${WARMUP_S:-600}
WINDOW_S=${WINDOW_S:-300}
MAX_GROWTH_PCT=${MAX_GROWTH_PCT:-5}
while [[ $# -gt 0 ]]; do
  case "$1" in
    --laps) LAPS=$2; shift 2 ;;
    --seed) SEED=$2; shift 2 ;;
    --out) OUT=$2; shift 2 ;;
    --period-s) PERIOD_S=$2; shift 2 ;;
    -h|--help) sed -n '2,18p' "$0"; exit 0 ;;
    *) echo "soak: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
done
[[ "$LAPS" =~ ^[1-9][0-9]*$ ]] || { echo "soak: --laps expects a positive integer, got '$LAPS'" >&2; exit 2; }
BIN=build/dev
for b in hil/sim/mission/rover-launch hil/sim/mission/roverd-sim firmware/mapd/mapd; do
  [[ -x "$BIN/$b" ]] || { echo "soak: $BIN/$b missing: run ./rover build dev first" >&2; exit 2; }
done

mkdir -p "$OUT/scenarios"
OUT=$(cd "$OUT" && pwd)
# The soak scenario: figure-eight-1km with its waypoints repeated LAPS times.
SRC=hil/scenarios/figure-eight-1km.yaml
awk -v laps="$LAPS" '
  /^name:/ { print "name: figure-eight-soak"; next }
  /^description:/ { print "description: \"figure-eight-1km driven " laps " times\""; next }
  /^  waypoints:/ { print; inwp = 1; next }
  inwp && /^    - / { wp[n++] = $0; next }
  inwp { for (l = 0; l < laps; ++l) for (i = 0; i < n; ++i) print wp[i]; inwp = 0 }
  { print }
' "$SRC" > "$OUT/scenarios/figure-eight-soak.yaml"
cp hil/scenarios/*.yaml "$OUT/scenarios/" 2>/dev/null || true

echo "soak: $LAPS lap(s) of the figure-eight, seed $SEED, logs in $OUT"
RUN_LOG="$OUT/mission.txt"
ROVER_SCENARIO_DIR="$OUT/scenarios" "$BIN/hil/sim/mission/rover-launch" \
  --roverd-sim "$BIN/hil/sim/mission/roverd-sim" --mapd "$BIN/firmware/mapd/mapd" \
  --roudi-config firmware/config/roudi.toml --config firmware/config/sim.yaml \
  --evaluate-map "$OUT" --run-dir "$OUT/run" -- \
  --sim figure-eight-soak --seed "$SEED" --out "$OUT" > "$RUN_LOG" 2>&1 &
LAUNCH=$!

rss_kb() {  # RSS of the newest process whose name is exactly $1 (not a compiler
  local pid  # building a file of the same name)
  pid=$(pgrep -n -x "$1" || true)
  [[ -n "$pid" ]] && awk '/^VmRSS:/ { print $2 }' "/proc/$pid/status" 2>/dev/null || echo 0
}

echo "wall_s,roverd_rss_kb,mapd_rss_kb,phase" > "$OUT/rss.csv"
START=$(date +%s)
SEEN_ROVERD=0
while kill -0 "$LAUNCH" 2>/dev/null; do
  # Short sleeps, so that the samples of a phase start on time.
  for (( i = 0; i < PERIOD_S * 5; ++i )); do
    kill -0 "$LAUNCH" 2>/dev/null || break
    sleep 0.2
  done
  now=$(( $(date +%s) - START ))
  r=$(rss_kb roverd-sim)
  m=$(rss_kb mapd)
  phase=drive
  if [[ "$r" != 0 ]]; then SEEN_ROVERD=1; elif [[ $SEEN_ROVERD == 1 ]]; then phase=shutdown; fi
  echo "$now,$r,$m,$phase" >> "$OUT/rss.csv"
  printf 'soak: %5d s  roverd %7d kB  mapd %7d kB  %-8s %s\n' "$now" "$r" "$m" "$phase" \
    "$(grep -a '^t ' "$RUN_LOG" | tail -1 | cut -c1-40)"
done
wait "$LAUNCH" || true

RESULT=$(grep -a '^RESULT' "$RUN_LOG" | tail -1 || true)
echo "$RESULT"
# Growth after the warm-up: the median of the samples in the WINDOW_S seconds
# after it against the median of the last WINDOW_S seconds of the drive. RSS
# swings by a few per cent with the work in flight (a match, a submap being
# finished), so single samples would judge the noise; the largest sample is
# reported too.
awk -F, -v warm="$WARMUP_S" -v max="$MAX_GROWTH_PCT" -v window="$WINDOW_S" '
  function median(a, n,    i, j, t) {
    for (i = 2; i <= n; i++) { t = a[i]; for (j = i - 1; j >= 1 && a[j] > t; j--) a[j + 1] = a[j]; a[j + 1] = t }
    return n % 2 ? a[(n + 1) / 2] : (a[n / 2] + a[n / 2 + 1]) / 2
  }
  NR == 1 { next }
  $4 == "shutdown" && $3 > export_peak { export_peak = $3 }
  $4 != "drive" || $2 == 0 || $3 == 0 || $1 < warm { next }
  { n++; t[n] = $1; r[n] = $2; m[n] = $3; if ($2 > rmax) rmax = $2; if ($3 > mmax) mmax = $3 }
  END {
    if (!n) { print "soak: the drive ended before the warm-up: no growth figure"; exit 1 }
    for (i = 1; i <= n; i++) {
      if (t[i] < warm + window) { a++; ra[a] = r[i]; ma[a] = m[i] }
      if (t[i] > t[n] - window) { b++; rb[b] = r[i]; mb[b] = m[i] }
    }
    r0 = median(ra, a); m0 = median(ma, a); r1 = median(rb, b); m1 = median(mb, b)
    rg = 100 * (r1 - r0) / r0; mg = 100 * (m1 - m0) / m0
    printf "soak: drive from %d s to %d s, medians of the first and last %d s: roverd %d -> %d kB (%+.1f %%, max %d), mapd %d -> %d kB (%+.1f %%, max %d)\n", warm, t[n], window, r0, r1, rg, rmax, m0, m1, mg, mmax
    if (export_peak > 0) printf "soak: mapd export peak at shutdown %d kB\n", export_peak
    exit (rg > max || mg > max) ? 1 : 0
  }' "$OUT/rss.csv" | tee "$OUT/summary.txt"
growth=${PIPESTATUS[0]}
# mapd's own account (its /diagnostics log): whether what grew is heap in use,
# free pages the allocator holds, or the shared IPC pool.
grep -a '^  memory: RSS' "$RUN_LOG" | sed 's/^  /soak: mapd /' | tee -a "$OUT/summary.txt" || true
drops_ok=1
[[ "$RESULT" =~ imu_drops=0\  && "$RESULT" =~ frame_drops=0\  ]] || drops_ok=0
if [[ $growth -ne 0 || $drops_ok -ne 1 ]]; then
  echo "soak: FAILED (memory growth above ${MAX_GROWTH_PCT} % or drops; see $OUT)" | tee -a "$OUT/summary.txt"
  exit 1
fi
echo "soak: passed" | tee -a "$OUT/summary.txt"
