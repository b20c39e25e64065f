#!/usr/bin/env bash
# The team's radio link with real kernel parts: each rover in its own network
# namespace (rover1, rover2, ...), joined through veth pairs to one bridge,
# each rover's side shaped with tc netem (its egress: delay, loss, rate,
# outages as loss 100%). Needs root and a kernel with veth, bridge and
# sch_netem: the HIL bench VM has them (Debian's kernel); a host without
# sch_netem cannot shape.
#
#   team_link_netns.sh up N            rovers 1..N at 10.77.0.<i>/24 on interface r<i>
#   team_link_netns.sh shape I ARGS..  netem on rover I's egress, e.g.
#                                      shape 1 delay 2000ms loss 20% rate 240kbit
#   team_link_netns.sh down N          removes the namespaces and the bridge
#   team_link_netns.sh stats I         bytes and packets rover I sent and received
#
# Run a rover's process in its namespace with `ip netns exec rover<I> CMD`.
set -euo pipefail
export PATH=/usr/sbin:/sbin:/usr/bin:/bin:$PATH

die() { echo "team_link_netns: $*" >&2; exit 1; }
[[ $# -ge 2 ]] || die "usage: team_link_netns.sh up|down N | shape I NETEM-ARGS... | stats I"

case "$1" in
  up)
    n=$2
    ip link add teambr type bridge || die "cannot create the bridge (bridge module loaded? root?)"
    ip link set teambr up
    for ((i = 1; i <= n; ++i)); do
      ip netns add "rover$i"
      ip link add "r$i" type veth peer name "br$i"
      ip link set "r$i" netns "rover$i"
      ip link set "br$i" master teambr
      ip link set "br$i" up
      ip -n "rover$i" addr add "10.77.0.$i/24" dev "r$i"
      ip -n "rover$i" link set "r$i" up
      ip -n "rover$i" link set lo up
    done
    # Static neighbours, as on a radio network with fixed addresses: ARP over
    # the shaped link would add its own delay and loss to every exchange
    # after an outage long enough to age the entries out.
    for ((i = 1; i <= n; ++i)); do
      for ((j = 1; j <= n; ++j)); do
        ((i == j)) && continue
        mac=$(ip -n "rover$j" -o link show "r$j" | sed -n 's/.*link\/ether \([0-9a-f:]*\).*/\1/p')
        ip -n "rover$i" neigh replace "10.77.0.$j" lladdr "$mac" dev "r$i" nud permanent
      done
    done
    ;;
  shape)
    i=$2
    shift 2
    ip netns exec "rover$i" tc qdisc replace dev "r$i" root netem "$@" ||
      die "tc netem failed on rover $i (sch_netem missing? this host kernel has none: use the HIL VM)"
    ;;
  stats)
    ip -n "rover$2" -s link show "r$2"
    ;;
  down)
    n=$2
    for ((i = 1; i <= n; ++i)); do ip netns del "rover$i" 2>/dev/null || true; done
    ip link del teambr 2>/dev/null || true
    ;;
  *)
    die "unknown command $1"
    ;;
esac
