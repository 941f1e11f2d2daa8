# SPDX-License-Identifier: BSD-3-Clause
# demo_run.mk - `make demo`: the onboard loop (`occmap run`, issue 21) on real data, checked by OctoMap.
#
# tools/demo_run.py starts tools/autopilot_standin.py (pymavlink playing ArduPilot on UDP loopback,
# streaming the recording's ground-truth poses), runs `occmap run --depth-dir` against it, and checks
# every OBSTACLE_DISTANCE it received with build/demo_ref (tools/demo_ref.cpp: OctoMap rebuilds the
# map from the frames the feed log names and computes the 72 sectors itself). Pictures and the
# telemetry summary go to build/demo/. Resolution 0.1 m and depth stride 4 (~14,600 points per frame)
# keep the whole demo to about a minute: the loop replays 16.6 s + 11 s of recording in real time and
# OctoMap rebuilds and checks the 500-frame run's ~170 messages in ~17 s.
DEMO_TUM := ../shared/data/depth/tum_fr1_rpy
DEMO_PIONEER := ../shared/data/depth/tum_fr2_pioneer_slam2
DEMO_RES := 0.1
DEMO_STRIDE := 4
# Agreement with OctoMap: a sector agrees when its value is explained by the reference within
# DEMO_TOL_M (2 voxels); the demo fails below DEMO_MIN_AGREE of all sectors or below
# DEMO_MIN_AGREE_SEEN of the sectors not unknown on both sides (most sectors of a forward camera
# are unknown on both: they alone would hide a wrong pose), or when more than 0.2 % read "no
# obstacle" with an obstacle within 2 m (tools/demo_ref.cpp). Measured: 99.8 / 98.7 % (fr1_rpy),
# 100 / 100 % (pioneer); a 20 ms attitude lag (fixed in run 636d669) scored 96.4 % overall, a
# 0.1 rad yaw error 91.9 / 61.7 % and 91.1 / 66.9 %.
DEMO_TOL_M := 0.2
DEMO_MIN_AGREE := 0.98
DEMO_MIN_AGREE_SEEN := 0.95
# The sector band is the camera's own voxel layer (+-0.05 m): a camera never sees the voxels right
# above and below itself, so with the default +-0.5 m band the vehicle's own column is unknown and
# every sector reads unknown (correct and fail-closed, but nothing to look at). Range 4 m = the
# depth range (--depth-max-m), so observed-free sectors exist. The pioneer frames are ~1.1 s apart:
# a 2.5 s sensor timeout keeps the feed from going stale between them.
DEMO_RUN_ARGS := --band-m 0.05 --max-m 4 --sensor-timeout-ms 2500
DEMO_PY = $(PY) tools/demo_run.py --occmap $(BUILD)/occmap --ref $(BUILD)/demo_ref --out $(BUILD)/demo \
  --res $(DEMO_RES) --stride $(DEMO_STRIDE) --tol-m $(DEMO_TOL_M) --min-agree $(DEMO_MIN_AGREE) \
  --min-agree-seen $(DEMO_MIN_AGREE_SEEN) \
  --run-args "$(DEMO_RUN_ARGS)"

$(BUILD)/demo_ref: tools/demo_ref.cpp | $(BUILD)/.deps-ok
	@mkdir -p $(dir $@)
	$(CXX) $(CXXWARN) -O2 -g -o $@ $< -loctomap -loctomath -lpng

# The whole recording (500 frames, 16.6 s), then the pioneer frames (10 frames, a robot driving).
demo-loop: $(BUILD)/occmap $(BUILD)/demo_ref $(BUILD)/.deps-ok
	@if [ ! -d $(DEMO_TUM) ]; then echo "SKIP: $(DEMO_TUM) absent (the demo replays ../shared data)"; exit 77; fi
	$(DEMO_PY) --depth-dir $(DEMO_TUM) --name fr1_rpy --timeout 90
	$(DEMO_PY) --depth-dir $(DEMO_PIONEER) --name pioneer --timeout 60
DEMO_STEPS += demo-loop
# The static-map demo (occmap feed on geb079.bt): tests/mavlink.mk's demo-mavlink.
demo-static: demo-mavlink

# make test: the stand-in's frame rules on hand-worked poses, then the pioneer frames through the
# whole loop (11 s of recording; unlike fr1_rpy's first seconds most of its sectors are observed,
# so a wrong pose fails it: a 0.1 rad yaw error scores 67 %), every message checked by OctoMap,
# and planted wrong distances the checker must refuse.
test-demo-loop: $(BUILD)/occmap $(BUILD)/demo_ref $(BUILD)/.deps-ok
	$(PY) tools/autopilot_standin.py --selftest
	@if [ ! -d $(DEMO_PIONEER) ]; then echo "SKIP: $(DEMO_PIONEER) absent (../shared)"; exit 77; fi
	$(DEMO_PY) --depth-dir $(DEMO_PIONEER) --plant --name test_loop --timeout 30
TEST_STEPS += test-demo-loop

.PHONY: demo-loop demo-static test-demo-loop
