#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Run tests/run_can_peer.py (occmap run --can on pydronecan's mcast: bus) inside a network
# namespace made for the test with only loopback (multicast routed to lo): no packet leaves the
# machine. The pattern of tests/can/mcast_netns.sh (no vcan here: the kernel module may be absent).
# usage: run_can.sh PYTHON OCCMAP WALL_MAP OUTDIR
set -uo pipefail
py=$1; occmap=$2; map=$3; out=$4
here=$(cd "$(dirname "$0")" && pwd)
if ! unshare -n true 2>/dev/null; then
  echo "SKIP run-can: cannot create a network namespace here (unshare -n needs root or user namespaces; environment limit)"
  exit 77
fi
exec unshare -n bash -c '
  set -e
  ip link set lo up
  ip link set lo multicast on
  ip route add 224.0.0.0/4 dev lo
  ip -o link | grep -v "lo:" && { echo "unexpected interface in the namespace"; exit 1; }
  exec "$0" "$1" "$2" "$3" "$4"
' "$py" "$here/run_can_peer.py" "$occmap" "$map" "$out"
