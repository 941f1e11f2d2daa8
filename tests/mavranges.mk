# mavranges.mk - MAVLink range messages (DISTANCE_SENSOR, OBSTACLE_DISTANCE, _3D) as beams: the
# frames pymavlink builds for test_mavlink_ranges.c.
$(MAV_REF)/ranges_frames.bin: tools/mav_ranges_golden.py $(BUILD)/.deps-ok
	@mkdir -p $(dir $@)
	$(PY) tools/mav_ranges_golden.py $@ $(MAV_REF)/ranges_frames.txt
TEST_BUILD_EXTRA += $(MAV_REF)/ranges_frames.bin
# The real ArduSub log's sonar readings as pymavlink alone places them (test_tlog_ranges.c).
$(MAV_REF)/sonar_ref.txt: tools/mav_tlog_sonar_ref.py $(BUILD)/.deps-ok
	@mkdir -p $(dir $@)
	$(PY) tools/mav_tlog_sonar_ref.py $(MAV_TLOG) $@
TEST_BUILD_EXTRA += $(MAV_REF)/sonar_ref.txt
