#!/usr/bin/env bash
# SPDX-License-Identifier: BSD-3-Clause
# Run tests/can/mcast_peer.py inside a network namespace made for the test, with only loopback
# (multicast routed to lo), so no packet can leave the machine.
# usage: mcast_netns.sh OCCMAP MAP PYTHON
set -uo pipefail
occmap=$1; map=$2; py=$3
here=$(cd "$(dirname "$0")" && pwd)
exec bash "$here/lo_netns.sh" can-mcast "$py" "$here/mcast_peer.py" "$occmap" "$map"
