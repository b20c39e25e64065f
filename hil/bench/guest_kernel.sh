#!/usr/bin/env bash
# The guest kernel of the HIL bench: the newest Debian linux-image-amd64
# kernel installed under /boot that also has its modules.
#   guest_kernel.sh release   -> e.g. 6.1.0-56-amd64
#   guest_kernel.sh image     -> e.g. /boot/vmlinuz-6.1.0-56-amd64
set -euo pipefail
best=""
for image in /boot/vmlinuz-*-amd64; do
  [[ -e "$image" ]] || continue
  release="${image#/boot/vmlinuz-}"
  [[ -f "/lib/modules/$release/modules.dep" ]] || continue
  if [[ -z "$best" ]] || dpkg --compare-versions "$release" gt "$best"; then best="$release"; fi
done
[[ -n "$best" ]] || {
  echo "guest_kernel: no Debian amd64 kernel with modules under /boot (install linux-image-amd64)" >&2
  exit 1
}
case "${1:-release}" in
  release) echo "$best" ;;
  image) echo "/boot/vmlinuz-$best" ;;
  *) echo "guest_kernel: unknown query '$1' (release | image)" >&2; exit 2 ;;
esac
