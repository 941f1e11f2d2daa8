#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Run tests/run_can_peer.py (occmap run --can on pydronecan's mcast: bus) inside a network
# namespace made for the test with only loopback (multicast routed to lo): no packet leaves the
# machine (tests/can/lo_netns.sh, as tests/can/mcast_netns.sh; no vcan: the module may be absent).
# usage: run_can.sh PYTHON OCCMAP WALL_MAP OUTDIR
set -uo pipefail
py=$1; occmap=$2; map=$3; out=$4
here=$(cd "$(dirname "$0")" && pwd)
exec bash "$here/can/lo_netns.sh" run-can "$py" "$here/run_can_peer.py" "$occmap" "$map" "$out"
