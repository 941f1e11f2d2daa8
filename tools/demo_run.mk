# demo_run.mk - `make demo`: the onboard loop (`occmap run`, issue 21) on real data, checked by OctoMap.
#
# tools/demo_run.py starts tools/autopilot_standin.py (pymavlink playing ArduPilot on UDP loopback,
# streaming the recording's ground-truth poses), runs `occmap run --depth-dir` against it, and checks
# every OBSTACLE_DISTANCE it received with build/demo_ref (tools/demo_ref.cpp: OctoMap rebuilds the
# map from the frames the feed log names and computes the 72 sectors itself). Pictures and the
# telemetry summary go to build/demo/. Resolution 0.1 m and depth stride 4 (~14,600 points per frame)
# keep the whole demo to about a minute: OctoMap inserts the 500 frames in ~40 s.
DEMO_TUM := ../shared/data/depth/tum_fr1_rpy
DEMO_PIONEER := ../shared/data/depth/tum_fr2_pioneer_slam2
DEMO_RES := 0.1
DEMO_STRIDE := 4
# Agreement with OctoMap: a sector agrees when its value is explained by the reference within
# DEMO_TOL_M (2 voxels); the demo fails below DEMO_MIN_AGREE of all sectors (tools/demo_ref.cpp).
DEMO_TOL_M := 0.2
DEMO_MIN_AGREE := 0.9
DEMO_RUN_ARGS :=
DEMO_PY = $(PY) tools/demo_run.py --occmap $(BUILD)/occmap --ref $(BUILD)/demo_ref --out $(BUILD)/demo \
  --res $(DEMO_RES) --stride $(DEMO_STRIDE) --tol-m $(DEMO_TOL_M) --min-agree $(DEMO_MIN_AGREE) \
  --run-args "$(DEMO_RUN_ARGS)"

$(BUILD)/demo_ref: tools/demo_ref.cpp
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

# make test: the stand-in, the checker and the pictures against tools/demo_fake_run.py (a python
# `occmap run` of the interface), with planted wrong distances the checker must refuse; then the
# first 60 frames through the real `occmap run` (skipped while the command does not exist).
test-demo-tools: $(BUILD)/occmap $(BUILD)/demo_ref $(BUILD)/.deps-ok
	@if [ ! -d $(DEMO_TUM) ]; then echo "SKIP: $(DEMO_TUM) absent (../shared)"; exit 77; fi
	$(PY) tools/autopilot_standin.py --selftest
	$(DEMO_PY) --depth-dir $(DEMO_TUM) --frames 40 --fake --plant --name test_fake --timeout 30
test-demo-loop: $(BUILD)/occmap $(BUILD)/demo_ref $(BUILD)/.deps-ok
	@if [ ! -d $(DEMO_TUM) ]; then echo "SKIP: $(DEMO_TUM) absent (../shared)"; exit 77; fi
	@if ! $(BUILD)/occmap run --help >/dev/null 2>&1; then echo "SKIP: occmap run does not exist yet (issue 21)"; exit 77; fi
	$(DEMO_PY) --depth-dir $(DEMO_TUM) --frames 60 --plant --name test_loop --timeout 30
TEST_STEPS += test-demo-tools test-demo-loop

.PHONY: demo-loop demo-static test-demo-tools test-demo-loop
