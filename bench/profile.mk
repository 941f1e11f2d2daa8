# SPDX-License-Identifier: BSD-3-Clause
# profile.mk - `make bench` step: where the integrators' time goes, in instructions (callgrind,
# so the same on any machine and not swayed by a shared one): SIMPLE on scan.dat at 0.1 m per
# voxel visit (issue 22's row below its target), PROJECTIVE on the 10 TUM pioneer frames per
# frame (issue 19: pyramid, end points, free-space walk, tree updates). bench/callgrind_phases.py
# splits each call into phases by the inclusive counts of the functions doing them and writes
# build/bench/rows/profile.json. Without ../shared the projective half prints SKIP and adds no
# row (the table then says "not measured").
PROFILE_DIR := $(BUILD)/bench/profile
bench-profile: $(BUILD)/occmap $(BUILD)/bench/projective $(BUILD)/data/scan.dat
	@mkdir -p $(PROFILE_DIR) $(BENCH_ROWS_DIR)
	valgrind --tool=callgrind --toggle-collect=occ_map_insert_cloud \
	  --callgrind-out-file=$(PROFILE_DIR)/simple.out ./$(BUILD)/occmap build \
	  --scan $(BUILD)/data/scan.dat --res 0.1 --method simple --json -o $(PROFILE_DIR)/simple.bt \
	  > $(PROFILE_DIR)/simple.json 2> $(PROFILE_DIR)/valgrind.log
	valgrind --tool=callgrind --toggle-collect=occ_map_insert_projective \
	  --callgrind-out-file=$(PROFILE_DIR)/projective.out ./$(BUILD)/bench/projective --proj-only \
	  --reps 1 > $(PROFILE_DIR)/projective.log 2>> $(PROFILE_DIR)/valgrind.log
	python3 bench/callgrind_phases.py --rows $(BENCH_ROWS_DIR)/profile.json \
	  --simple $(PROFILE_DIR)/simple.out $(PROFILE_DIR)/simple.json \
	  --projective $(PROFILE_DIR)/projective.out $(PROFILE_DIR)/projective.log
BENCH_STEPS += bench-profile
.PHONY: bench-profile
