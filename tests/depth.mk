# SPDX-License-Identifier: BSD-3-Clause
# depth.mk - `occmap build --depth-dir` on the two TUM layouts (issue 18): the groundtruth
# sequence (tum_fr1_rpy: 500 frames, 4 in the motion-capture gap dropped, freiburg1 intrinsics)
# and the association layout (pioneer_slam2, nothing dropped); a sequence dir without its
# ground truth is a runtime error. Skips (exit 77) when ../shared is absent.
DEPTH_DATA := ../shared/data/depth
depth-cli: $(BUILD)/occmap
	@if [ ! -d $(DEPTH_DATA)/tum_fr1_rpy ]; then echo "SKIP: $(DEPTH_DATA) absent (needs ../shared)"; exit 77; fi
	@out=$$(./$(BUILD)/occmap build --depth-dir $(DEPTH_DATA)/tum_fr1_rpy --stride 16 --res 0.2 \
	    --max-range 4 --json 2>/dev/null) && echo "$$out" && \
	  for k in '"scans": 496' '"frames_dropped": 4' '"depth_layout": "groundtruth"' \
	           '"intrinsics": [517.3, 516.5, 318.6, 255.3]'; do \
	    echo "$$out" | grep -qF "$$k" || { echo "FAIL: missing $$k"; exit 1; }; done && \
	  out=$$(./$(BUILD)/occmap build --depth-dir $(DEPTH_DATA)/tum_fr2_pioneer_slam2 --stride 32 \
	    --json 2>/dev/null) && \
	  for k in '"scans": 10' '"frames_dropped": 0' '"depth_layout": "association"'; do \
	    echo "$$out" | grep -qF "$$k" || { echo "FAIL: pioneer: missing $$k"; exit 1; }; done && \
	  tmp=$$(mktemp -d) && head -8 $(DEPTH_DATA)/tum_fr1_rpy/depth.txt > $$tmp/depth.txt && \
	  { ./$(BUILD)/occmap build --depth-dir $$tmp --json >/dev/null 2>$$tmp/err; rc=$$?; } ; \
	  grep -q groundtruth.txt $$tmp/err; found=$$?; rm -rf $$tmp; \
	  test $$rc -eq 1 -a $$found -eq 0 || { echo "FAIL: no groundtruth.txt: exit $$rc"; exit 1; }; \
	  echo "PASS: depth-cli"
TEST_STEPS += depth-cli
.PHONY: depth-cli

# The README's depth-camera snippet compiles under the core's warnings against libocc.a and
# integrates a frame: a flat wall ahead of the camera, its pose from a two-sample history.
depth-readme: $(BUILD)/libocc.a
	bash tests/readme_depth.sh $(BUILD)
TEST_STEPS += depth-readme
.PHONY: depth-readme
