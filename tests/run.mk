# SPDX-License-Identifier: BSD-3-Clause
# run.mk - `occmap run`, the onboard loop (issue 21), against a pymavlink autopilot stand-in over
# UDP loopback on the real TUM fr1_rpy sequence (tests/run_peer.py): SET_MESSAGE_INTERVAL
# retries and the pose filter, frames without a pose dropped (the pose history's rule) and the
# never-stop memory rule in a 32 KiB arena over all 500 frames (evictions and partial frames),
# stale-input silence (each configured input on its own: a rangefinder alone), range readings
# integrated with the pose at their own time, -o at SIGTERM and --save-every, the feed's jitter
# with mapping busy and the TIMESYNC offset. The C parts (TIMESYNC offset, pose filter and
# unpaired count, poses into the history): tests/test_run_mavlink.c.
RUN_DATA := ../shared/data/depth/tum_fr1_rpy
test-run-loop: $(BUILD)/occmap $(BUILD)/.deps-ok
	$(PY) tests/run_peer.py --occmap $(BUILD)/occmap --data $(RUN_DATA) --out $(BUILD)/run \
	  --tiny-arena 32K --test all
TEST_STEPS += test-run-loop
.PHONY: test-run-loop

# occmap run --can (DroneCAN range sensors in, Proximity out) and --config, on pydronecan's
# mcast: bus in a network namespace with only loopback (tests/run_can.sh, run_can_peer.py).
test-run-can: $(BUILD)/occmap $(BUILD)/can/wall.occ $(BUILD)/.deps-ok
	bash tests/run_can.sh $(PY) $(BUILD)/occmap $(BUILD)/can/wall.occ $(BUILD)/run
TEST_STEPS += test-run-can
.PHONY: test-run-can
