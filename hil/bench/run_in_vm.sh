#!/usr/bin/env bash
# Runs one command inside the HIL bench VM: Debian's kernel under
# qemu-system-x86_64 (TCG software emulation: KVM is not available on CI
# machines), the bench initramfs, the host's filesystem read-only over 9p and
# OUT writable at the same path. The command sees vcan0, vcan1 and vivid's
# /dev/video0 (single-planar) and /dev/video1 (multi-planar), and runs as
# root in the guest; it may write to OUT. Prints the guest console and exits
# with the command's status (or 90+ for bench failures, see below).
#
# usage: run_in_vm.sh --initramfs FILE --out DIR [--memory-mb N] [--cpus N]
#                     [--timeout-s S] [--env NAME=VALUE]... -- COMMAND [ARGS...]
#
# exit status: the command's own, or
#   91  qemu or the guest failed before the command ran (see the console)
#   92  the VM did not finish within --timeout-s (killed)
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
initramfs="" out="" memory_mb=768 cpus=1 timeout_s=300
envs=()
usage() { sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; }
while (($#)); do
  case "$1" in
    --initramfs) initramfs="$2"; shift 2 ;;
    --out) out="$2"; shift 2 ;;
    --memory-mb) memory_mb="$2"; shift 2 ;;
    --cpus) cpus="$2"; shift 2 ;;
    --timeout-s) timeout_s="$2"; shift 2 ;;
    --env) envs+=("$2"); shift 2 ;;
    -h|--help) usage; exit 0 ;;
    --) shift; break ;;
    *) echo "run_in_vm: unknown option '$1' (see --help)" >&2; exit 2 ;;
  esac
done
(($#)) || { echo "run_in_vm: no command given after --" >&2; exit 2; }
[[ -f "$initramfs" ]] || { echo "run_in_vm: initramfs '$initramfs' not found (build target hil_bench_initramfs)" >&2; exit 2; }
[[ -n "$out" ]] || { echo "run_in_vm: --out DIR is required" >&2; exit 2; }
command -v qemu-system-x86_64 >/dev/null || { echo "run_in_vm: qemu-system-x86_64 not installed (scripts/install_deps.sh)" >&2; exit 2; }

kernel="$("$here/guest_kernel.sh" image)"
mkdir -p "$out"
out="$(cd "$out" && pwd -P)"
rm -f "$out/guest_status"

# The command script runs in the guest, chrooted to the host's root: same
# paths, same binaries, same working directory.
{
  echo "#!/bin/sh"
  echo "cd $(printf '%q' "$(pwd -P)") || exit 90"
  for kv in "${envs[@]}"; do echo "export $(printf '%q' "$kv")"; done
  printf 'exec'; printf ' %q' "$@"; echo
} >"$out/command.sh"

start_s=$SECONDS
set +e
timeout --kill-after=5 "$timeout_s" qemu-system-x86_64 \
  -machine q35 -accel tcg -cpu max -smp "$cpus" -m "$memory_mb" \
  -nographic -no-reboot -serial mon:stdio -nodefaults \
  -kernel "$kernel" -initrd "$initramfs" \
  -append "console=ttyS0 quiet loglevel=3 panic=-1 rover.out=$out" \
  -virtfs local,path=/,mount_tag=hostroot,security_model=none,readonly=on,multidevs=remap \
  -virtfs "local,path=$out,mount_tag=hilout,security_model=none,multidevs=remap" \
  </dev/null
qemu_status=$?
set -e
elapsed_s=$((SECONDS - start_s))
if ((qemu_status == 124 || qemu_status == 137)); then
  echo "run_in_vm: the VM did not finish within ${timeout_s} s; killed" >&2
  exit 92
fi
if [[ ! -f "$out/guest_status" ]]; then
  echo "run_in_vm: the guest never ran the command (qemu exit status $qemu_status after ${elapsed_s} s); see the console above" >&2
  exit 91
fi
status="$(cat "$out/guest_status")"
echo "run_in_vm: command exited with status $status after ${elapsed_s} s in the VM"
exit "$status"
