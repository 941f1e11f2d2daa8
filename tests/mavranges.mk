# SPDX-License-Identifier: BSD-3-Clause
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
# `occmap build --tlog` on the real log: every sonar reading integrated, the map saved and read
# back with the same statistics.
test-build-tlog: $(BUILD)/occmap
	@if [ ! -f $(MAV_TLOG) ]; then echo "SKIP: $(MAV_TLOG) absent"; exit 0; fi; \
	  $(BUILD)/occmap build --tlog $(MAV_TLOG) --res 0.5 --json -o $(MAV_REF)/ardusub.occ \
	    > $(MAV_REF)/build_tlog.json && \
	  $(BUILD)/occmap info $(MAV_REF)/ardusub.occ --json > $(MAV_REF)/build_tlog_info.json && \
	  python3 -c 'import json, sys; b = json.load(open(sys.argv[1])); i = json.load(open(sys.argv[2])); \
	    assert b["readings"] == 919 and b["integrated"] == 919 and b["no_pose"] == 0, b; \
	    assert b["beams_hit"] == 919 and b["own_refused"] == 0 and b["position_msg"] == 33, b; \
	    assert b["occupied_voxels"] > 100 and b["bbox_min"][2] > -42.0, b; \
	    assert i["occupied_voxels"] == b["occupied_voxels"] and i["free_voxels"] == b["free_voxels"], i; \
	    print("PASS build --tlog: %d readings, %d occupied / %d free voxels, deepest %.2f m" % \
	      (b["integrated"], b["occupied_voxels"], b["free_voxels"], b["bbox_min"][2]))' \
	    $(MAV_REF)/build_tlog.json $(MAV_REF)/build_tlog_info.json
TEST_STEPS += test-build-tlog
.PHONY: test-build-tlog
# A small log pymavlink packs (OBSTACLE_DISTANCE, our own echo, a reading before any pose).
$(MAV_REF)/synth.tlog: tools/mav_tlog_synth.py $(BUILD)/.deps-ok
	@mkdir -p $(dir $@)
	$(PY) tools/mav_tlog_synth.py $@
TEST_BUILD_EXTRA += $(MAV_REF)/synth.tlog

# The README's rangefinder snippet compiles under the core's warnings against libocc.a and
# integrates a downward reading with the pose from a two-sample history (tests/readme_ranges.sh).
ranges-readme: $(BUILD)/libocc.a
	bash tests/readme_ranges.sh $(BUILD)
TEST_STEPS += ranges-readme
.PHONY: ranges-readme
