#!/bin/sh
# /init of the HIL bench guest (busybox sh). Loads the bench's kernel modules,
# mounts the host's root filesystem read-only over 9p (virtio) and the
# bench's output folder writable on top of its own path, creates vcan0/vcan1,
# then runs the scenario's command script chrooted into the host filesystem,
# so the project's binaries and the host's libraries run unchanged. The exit
# status goes to <out>/guest_status, and the guest powers off.
#
# Kernel command line: rover.out=<host path of the output folder>

export PATH=/bin
mount -t proc proc /proc
mount -t sysfs sysfs /sys
mount -t devtmpfs devtmpfs /dev

say() { echo "hil-guest: $*" >/dev/console; }
fail() { say "FAILED: $*"; sync; poweroff -f; sleep 5; }

out=""
for word in $(cat /proc/cmdline); do
  case "$word" in rover.out=*) out="${word#rover.out=}" ;; esac
done
[ -n "$out" ] || fail "no rover.out= on the kernel command line"

while read -r module; do
  case "$module" in
    # Two capture nodes: /dev/video0 single-planar, /dev/video1 multi-planar
    # (as tests/hil/bench/v4l2_vivid_test.cc reloads it).
    vivid.ko) params="n_devs=2 node_types=0x1,0x1 multiplanar=1,2" ;;
    *) params="" ;;
  esac
  insmod "/modules/$module" $params || fail "insmod $module"
done </modules/order

# multidevs=remap on the host side keeps inode numbers unique across the
# host's several filesystems; cache=none keeps the read-only view exact.
mount -t 9p -o trans=virtio,version=9p2000.L,ro hostroot /host || fail "mount hostroot (9p)"
for fs in "proc /host/proc" "sysfs /host/sys" "devtmpfs /host/dev" "tmpfs /host/tmp" "tmpfs /host/run"; do
  set -- $fs
  mount -t "$1" "$1" "$2" || fail "mount $1 on $2"
done
mkdir -p /host/dev/pts /host/dev/shm
mount -t devpts devpts /host/dev/pts
mount -t tmpfs tmpfs /host/dev/shm
# The output share is bound at its host path last: that path may lie under
# /tmp, which is the guest's own tmpfs (mkdir works there, and a path on the
# read-only host view exists already).
mount -t 9p -o trans=virtio,version=9p2000.L,rw hilout /out || fail "mount hilout (9p)"
mkdir -p "/host$out" 2>/dev/null
mount -o bind /out "/host$out" || fail "bind the output folder on $out"

ip=/usr/sbin/ip
[ -x "/host$ip" ] || ip=/sbin/ip
chroot /host "$ip" link set lo up || fail "ip link set lo up"
for dev in vcan0 vcan1; do
  chroot /host "$ip" link add dev "$dev" type vcan || fail "ip link add $dev type vcan"
  chroot /host "$ip" link set "$dev" up || fail "ip link set $dev up"
done

say "kernel $(cat /kernel_release) up; running $out/command.sh"
chroot /host /bin/sh "$out/command.sh" </dev/null >/dev/console 2>&1
status=$?
echo "$status" >"/host$out/guest_status"
sync
say "command exited with status $status"
poweroff -f
sleep 5
