#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Run tests/can/mcast_peer.py inside a network namespace made for the test, with only loopback
# (multicast routed to lo), so no packet can leave the machine.
# usage: mcast_netns.sh OCCMAP MAP PYTHON
set -uo pipefail
occmap=$1; map=$2; py=$3
here=$(cd "$(dirname "$0")" && pwd)
if ! unshare -n true 2>/dev/null; then
  echo "SKIP can-mcast: cannot create a network namespace here (unshare -n needs root or user namespaces; environment limit)"
  exit 77
fi
exec unshare -n bash -c '
  set -e
  ip link set lo up
  ip link set lo multicast on
  ip route add 224.0.0.0/4 dev lo
  ip -o link | grep -v "lo:" && { echo "unexpected interface in the namespace"; exit 1; }
  exec "$0" "$1" "$2" "$3"
' "$py" "$here/mcast_peer.py" "$occmap" "$map"
