#!/usr/bin/env bash
# Starts, stops and checks an iceoryx RouDi daemon (iox-roudi) for development
# and bench work. On the rover, systemd runs RouDi instead
# (firmware/systemd/rover-roudi.service).
#
#   scripts/roudi.sh start     start in the background, wait until it accepts
#                              connections (no-op if ours is already running)
#   scripts/roudi.sh stop      stop it: SIGTERM (RouDi removes its shared memory
#                              and socket), SIGKILL after a timeout
#   scripts/roudi.sh status    exit 0 if running and ready, 3 if not (LSB)
#   scripts/roudi.sh restart   stop, then start
#
# All commands are idempotent. Environment:
#   ROVER_RUN_DIR         pidfile and log directory
#                         (default: $XDG_RUNTIME_DIR/rover or /tmp/rover-$UID)
#   ROUDI_CONFIG          RouDi TOML config (default: firmware/config/roudi.toml)
#   ROUDI_LOG_LEVEL       off|fatal|error|warning|info|debug|verbose (warning)
#   ROUDI_BIN             iox-roudi executable (default: iox-roudi from PATH)
#   ROUDI_TIMEOUT_S       start/stop timeout in seconds (default: 10)
#
# iceoryx 2.0 allows one RouDi per machine: `start` refuses to run if a RouDi
# that this script did not start is answering, and names its pid. Leftovers of
# a RouDi killed with SIGKILL (/dev/shm/iceoryx_mgmt, /tmp/roudi, lock files)
# are cleaned up by iox-roudi itself on the next start.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(dirname "$here")"

run_dir="${ROVER_RUN_DIR:-${XDG_RUNTIME_DIR:+$XDG_RUNTIME_DIR/rover}}"
run_dir="${run_dir:-/tmp/rover-$(id -u)}"
pidfile="$run_dir/roudi.pid"
logfile="$run_dir/roudi.log"
config="${ROUDI_CONFIG:-$root/firmware/config/roudi.toml}"
log_level="${ROUDI_LOG_LEVEL:-warning}"
roudi_bin="${ROUDI_BIN:-iox-roudi}"
timeout_s="${ROUDI_TIMEOUT_S:-10}"
# iceoryx 2.0 on Linux: RouDi's Unix-domain socket.
socket_path="/tmp/roudi"

log() { echo "roudi.sh: $*" >&2; }

# Pid from our pidfile if that process is alive (not a zombie) and is
# iox-roudi; else empty.
our_pid() {
  [[ -f "$pidfile" ]] || return 0
  local pid state
  pid="$(cat "$pidfile" 2>/dev/null || true)"
  [[ "$pid" =~ ^[0-9]+$ ]] || return 0
  [[ "$(cat "/proc/$pid/comm" 2>/dev/null)" == "iox-roudi" ]] || return 0
  # Field 3 of /proc/<pid>/stat is the state; comm (field 2) has no spaces here.
  state="$(awk '{print $3}' "/proc/$pid/stat" 2>/dev/null || true)"
  [[ -n "$state" && "$state" != "Z" ]] || return 0
  echo "$pid"
}

# True if `pid` is alive and not a zombie.
alive() {
  local state
  state="$(awk '{print $3}' "/proc/$1/stat" 2>/dev/null || true)"
  [[ -n "$state" && "$state" != "Z" ]]
}

# True if some process has a socket bound to RouDi's path. A socket file left
# by a killed RouDi is not listed in /proc/net/unix, so it does not count.
socket_bound() {
  grep -q " ${socket_path}\$" /proc/net/unix 2>/dev/null
}

other_roudi_pids() {
  pgrep -x iox-roudi 2>/dev/null | tr '\n' ' ' || true
}

cmd_status() {
  local pid
  pid="$(our_pid)"
  if [[ -n "$pid" ]] && socket_bound; then
    echo "running (pid $pid, log $logfile)"
    return 0
  fi
  if [[ -z "$pid" ]] && socket_bound; then
    echo "not running from this script, but another RouDi answers (pid $(other_roudi_pids))"
    return 3
  fi
  echo "not running"
  return 3
}

cmd_start() {
  local pid
  pid="$(our_pid)"
  if [[ -n "$pid" ]]; then
    if socket_bound; then
      log "already running (pid $pid)"
      return 0
    fi
    log "pid $pid is starting up; waiting for it"
  else
    if socket_bound; then
      log "another RouDi is running (pid $(other_roudi_pids)) and was not started by this script;"
      log "stop it first (e.g. systemctl stop rover-roudi). iceoryx allows one per machine."
      return 1
    fi
    if ! command -v "$roudi_bin" >/dev/null; then
      log "$roudi_bin not found (scripts/install_deps.sh installs it)"
      return 1
    fi
    local args=(-l "$log_level")
    if [[ -f "$config" ]]; then
      args+=(-c "$config")
    else
      log "no config at $config; using RouDi's built-in mempools"
    fi
    mkdir -p "$run_dir"
    rm -f "$pidfile"
    # setsid: detached from this shell's session, so closing the terminal
    # does not take RouDi down with it.
    setsid "$roudi_bin" "${args[@]}" </dev/null >"$logfile" 2>&1 &
    pid=$!
    echo "$pid" >"$pidfile"
  fi
  local deadline=$((SECONDS + timeout_s))
  until socket_bound; do
    if ! alive "$pid"; then
      log "iox-roudi exited during start-up; its log ($logfile):"
      tail -n 20 "$logfile" >&2 || true
      rm -f "$pidfile"
      return 1
    fi
    if ((SECONDS >= deadline)); then
      log "iox-roudi did not become ready within ${timeout_s}s; stopping it. Log:"
      tail -n 20 "$logfile" >&2 || true
      cmd_stop || true
      return 1
    fi
    sleep 0.05
  done
  log "running (pid $pid, log $logfile)"
}

cmd_stop() {
  local pid
  pid="$(our_pid)"
  if [[ -z "$pid" ]]; then
    rm -f "$pidfile"
    log "not running"
    return 0
  fi
  kill -TERM "$pid" 2>/dev/null || true
  local deadline=$((SECONDS + timeout_s))
  while alive "$pid"; do
    if ((SECONDS >= deadline)); then
      log "pid $pid ignored SIGTERM for ${timeout_s}s; sending SIGKILL"
      kill -KILL "$pid" 2>/dev/null || true
      break
    fi
    sleep 0.05
  done
  rm -f "$pidfile"
  log "stopped"
}

case "${1:-}" in
  start) cmd_start ;;
  stop) cmd_stop ;;
  status) cmd_status ;;
  restart) cmd_stop && cmd_start ;;
  *)
    echo "usage: $0 {start|stop|status|restart}" >&2
    exit 2
    ;;
esac
