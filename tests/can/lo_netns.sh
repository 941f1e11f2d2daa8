#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Run a command inside a network namespace made for the test, with only loopback (multicast
# routed to lo), so no packet can leave the machine. Skips (exit 77) where no namespace can be
# made. Used by tests/can/mcast_netns.sh and tests/run_can.sh.
# usage: lo_netns.sh STEP_NAME COMMAND [ARGS...]
set -uo pipefail
name=$1; shift
if ! unshare -n true 2>/dev/null; then
  echo "SKIP $name: cannot create a network namespace here (unshare -n needs root or user namespaces; environment limit)"
  exit 77
fi
exec unshare -n bash -c '
  set -e
  ip link set lo up
  ip link set lo multicast on
  ip route add 224.0.0.0/4 dev lo
  ip -o link | grep -v "lo:" && { echo "unexpected interface in the namespace"; exit 1; }
  exec "$@"
' bash "$@"
