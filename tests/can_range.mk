# SPDX-License-Identifier: BSD-3-Clause
# can_range.mk - the DroneCAN range-sensor input's peer data (issue 18): pydronecan builds
# uavcan.equipment.range_sensor.Measurement transfers (tests/can/range_frames.py) that
# tests/test_dronecan_range.c reassembles and decodes (it skips, counted, without the file).
CAN_RANGE_FRAMES := $(BUILD)/can/range_frames.txt

$(CAN_RANGE_FRAMES): tests/can/range_frames.py $(BUILD)/.deps-ok
	@mkdir -p $(dir $@)
	$(PY) tests/can/range_frames.py 300 > $@.tmp && mv $@.tmp $@

TEST_BUILD_EXTRA += $(CAN_RANGE_FRAMES)
