#!/usr/bin/env bash
# Builds the HIL bench's initramfs: busybox-static as the whole userland, the
# bench's /init (guest_init.sh), and the kernel modules the scenarios need
# (vcan, can-raw, can-isotp, vivid, 9p over virtio; veth, bridge and sch_netem for
# the team link) with everything they
# depend on, taken from Debian's linux-image-amd64 so they match the guest
# kernel exactly.
#
# usage: make_initramfs.sh OUTPUT.cpio.gz [KERNEL_RELEASE]
set -euo pipefail

out="${1:?usage: make_initramfs.sh OUTPUT.cpio.gz [KERNEL_RELEASE]}"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
release="${2:-$("$here/guest_kernel.sh" release)}"
moddir="/lib/modules/$release"
busybox=/bin/busybox

[[ -f "$moddir/modules.dep" ]] || {
  echo "make_initramfs: no modules for kernel $release in $moddir (install linux-image-amd64: scripts/install_deps.sh)" >&2
  exit 1
}
file -L "$busybox" 2>/dev/null | grep -q "statically linked" || {
  echo "make_initramfs: $busybox is not the static busybox (install busybox-static)" >&2
  exit 1
}

# Modules in load order: each one after everything it depends on. The
# order of this list is the order of loading; virtio_pci must come before
# 9pnet_virtio, or the 9p transport finds no device.
wanted=(virtio_pci 9pnet_virtio 9p vcan can-raw can-isotp vivid veth sch_netem bridge)

declare -A placed=()
ordered=()
place() {  # depth-first over modules.dep: dependencies first
  local rel="$1"
  [[ -n "${placed[$rel]:-}" ]] && return
  placed[$rel]=1
  local deps
  deps=$(awk -v m="$rel:" '$1 == m { for (i = 2; i <= NF; ++i) print $i }' "$moddir/modules.dep")
  local dep
  for dep in $deps; do place "$dep"; done
  ordered+=("$rel")
}
for name in "${wanted[@]}"; do
  rel=$(awk -v n="/$name.ko:" 'index($1, n) { sub(":", "", $1); print $1; exit }' "$moddir/modules.dep")
  [[ -n "$rel" ]] || { echo "make_initramfs: module $name not found in $moddir/modules.dep" >&2; exit 1; }
  place "$rel"
done

stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
mkdir -p "$stage"/{bin,dev,proc,sys,host,out,modules}
cp "$busybox" "$stage/bin/busybox"
for applet in sh mount umount insmod mkdir cat echo poweroff sleep chroot ls dmesg sync; do
  ln -s busybox "$stage/bin/$applet"
done
: >"$stage/modules/order"
for rel in "${ordered[@]}"; do
  base=$(basename "$rel")
  cp "$moddir/$rel" "$stage/modules/$base"
  echo "$base" >>"$stage/modules/order"
done
cp "$here/guest_init.sh" "$stage/init"
chmod +x "$stage/init"
echo "$release" >"$stage/kernel_release"

mkdir -p "$(dirname "$out")"
tmp="$out.tmp.$$"
(cd "$stage" && find . -print0 | cpio --null -o -H newc --quiet | gzip -9) >"$tmp"
mv "$tmp" "$out"
echo "make_initramfs: $out (kernel $release, ${#ordered[@]} modules)"
