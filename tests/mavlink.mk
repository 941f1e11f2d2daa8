# SPDX-License-Identifier: BSD-3-Clause
# mavlink.mk - the MAVLink front end: generated C headers, tests, fuzzing, the demo.
#
# The MAVLink C headers are generated at build time by pymavlink's mavgen (pinned in the venv)
# from the XML dialects inside the pymavlink wheel; never committed. ardupilotmega.xml includes
# common.xml, so the parser knows every message ArduPilot and PX4 stream.
MAVGEN_DIR := $(BUILD)/gen/mavlink
MAVGEN_STAMP := $(MAVGEN_DIR)/.stamp
MAVGEN_DIALECT := ardupilotmega
# MAVLINK_FLAGS only for the sources that include generated headers (directly or through
# tests/support/mav_frames.h), in every build of them (rel, asan, host, cross, i386, lint). The
# includers are found by their #include lines, so a new one needs no edit here.
MAVLINK_FLAGS := -isystem $(MAVGEN_DIR)
MAVLINK_INCLUDERS := $(basename $(shell grep -lE '^\#include "((ardupilotmega|common|standard|minimal)/|support/mav_frames.h)' \
  src/*/*.c tools/*.c port/*/*.c tests/*.c tests/mavlink/*.c 2>/dev/null))
$(foreach f,$(MAVLINK_INCLUDERS),%/$(f).o %/$(f).analyzer.ok): EXTRA_CFLAGS += $(MAVLINK_FLAGS)

$(MAVGEN_STAMP): | $(BUILD)/.deps-ok
	@rm -rf $(MAVGEN_DIR).tmp && mkdir -p $(MAVGEN_DIR).tmp
	@xml=$$($(PY) -c 'import os, pymavlink; print(os.path.join(os.path.dirname(pymavlink.__file__), "dialects", "v20", "$(MAVGEN_DIALECT).xml"))') && \
	  echo "mavgen: $$xml -> $(MAVGEN_DIR)" && \
	  $(PY) -m pymavlink.tools.mavgen --lang=C --wire-protocol=2.0 --output=$(MAVGEN_DIR).tmp "$$xml" >/dev/null
	@rm -rf $(MAVGEN_DIR) && mv $(MAVGEN_DIR).tmp $(MAVGEN_DIR) && touch $@
mavgen: $(MAVGEN_STAMP)

# Every object of the feed (host, sanitizer, cross), the tools, ports and tests waits for them.
MAV_USERS := $(OCC_FEED_SRC) $(TOOL_SRC) $(PORT_SRC) $(TEST_C) $(wildcard tests/mavlink/*.c)
$(OCC_FEED_SRC:%.c=$(BUILD)/rel/%.o) $(OCC_FEED_SRC:%.c=$(BUILD)/asan/%.o): $(MAVGEN_STAMP)
$(OCC_FEED_SRC:%.c=$(BUILD)/pic/%.o): $(MAVGEN_STAMP)
$(OCC_FEED_SRC:%.c=$(BUILD)/cross/m4/%.o) $(OCC_FEED_SRC:%.c=$(BUILD)/cross/m0/%.o): $(MAVGEN_STAMP)
$(MAV_USERS:%.c=$(BUILD)/relhost/%.o) $(MAV_USERS:%.c=$(BUILD)/asanhost/%.o): $(MAVGEN_STAMP)
CROSS_EXTRA += $(BUILD)/cross/m4/port/baremetal/mavlink_hooks.o $(BUILD)/cross/m0/port/baremetal/mavlink_hooks.o

# ---- reference data from pymavlink (the C tests compare against these files) -------------------
MAV_TLOG := ../shared/data/mavlink/ardusub_2023-04-18_11-03-34.tlog
MAV_REF := $(BUILD)/mavlink
$(MAV_REF)/tlog_ref.txt: tools/mav_tlog_ref.py $(BUILD)/.deps-ok
	@mkdir -p $(dir $@)
	$(PY) tools/mav_tlog_ref.py $(MAV_TLOG) $@
$(MAV_REF)/py_frames.bin: tools/mav_golden.py $(BUILD)/.deps-ok
	@mkdir -p $(dir $@)
	$(PY) tools/mav_golden.py $@ $(MAV_REF)/py_frames.txt
TEST_BUILD_EXTRA += $(MAV_REF)/tlog_ref.txt $(MAV_REF)/py_frames.bin $(MAV_REF)/mav_dump

# A small host program that writes C-encoded frames for pymavlink to check.
$(MAV_REF)/mav_dump: $(BUILD)/asanhost/tests/mavlink/mav_dump.o $(BUILD)/asan/libocc.a
	$(CC) $(SAN) -o $@ $^ -lm

# C encoder -> pymavlink decoder, field by field.
test-mavlink-roundtrip: $(MAV_REF)/mav_dump $(BUILD)/.deps-ok
	$(MAV_REF)/mav_dump $(MAV_REF)/c_frames.bin $(MAV_REF)/c_frames.txt
	$(PY) tools/mav_check_c_frames.py $(MAV_REF)/c_frames.bin $(MAV_REF)/c_frames.txt
# occmap feed over UDP loopback against a pymavlink peer playing ArduPilot: SET_MESSAGE_INTERVAL
# requests (and a logged refusal), poses only from the autopilot, OBSTACLE_DISTANCE out checked
# against sector_ref.py and through ArduPilot's face rule (issue 16's geb079 case), heartbeat
# rate, the stale-pose timeout.
test-mavlink-udp: $(BUILD)/occmap $(BUILD)/.deps-ok
	$(PY) tools/mav_feed_peer.py --occmap $(BUILD)/occmap --test
TEST_STEPS += test-mavlink-roundtrip test-mavlink-udp

# ---- fuzzing (clang libFuzzer) ------------------------------------------------------------------
FUZZ_MAV := $(BUILD)/fuzz/fuzz_mavlink
$(FUZZ_MAV): tests/mavlink/fuzz_mavlink.c src/mavlink/mavlink.c include/occmap/occ_mavlink.h $(MAVGEN_STAMP)
	@mkdir -p $(dir $@)
	clang -std=c99 -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all \
	  $(INC) $(MAVLINK_FLAGS) -o $@ tests/mavlink/fuzz_mavlink.c src/mavlink/mavlink.c
fuzz-mavlink: $(FUZZ_MAV) $(MAV_REF)/py_frames.bin
	@mkdir -p $(BUILD)/fuzz/corpus-mavlink
	@cp -f $(MAV_REF)/py_frames.bin $(BUILD)/fuzz/corpus-mavlink/seed-pymavlink.bin
	@if [ -f $(MAV_TLOG) ]; then head -c 4096 $(MAV_TLOG) > $(BUILD)/fuzz/corpus-mavlink/seed-tlog.bin; fi
	$(FUZZ_MAV) -max_total_time=$${FUZZ_SECONDS:-15} -max_len=1024 -print_final_stats=1 \
	  $(BUILD)/fuzz/corpus-mavlink 2>&1 | tail -n 25
FUZZ_STEPS += fuzz-mavlink
test-mavlink-fuzz: $(FUZZ_MAV)
	@$(MAKE) --no-print-directory fuzz-mavlink FUZZ_SECONDS=10
TEST_STEPS += test-mavlink-fuzz

# ---- the demo -----------------------------------------------------------------------------------
DEMO_MAP := /usr/share/doc/liboctomap-dev/examples/data/geb079.bt
demo-mavlink: $(BUILD)/occmap $(BUILD)/.deps-ok
	@mkdir -p $(BUILD)/demo
	$(PY) tools/mav_demo.py --occmap $(BUILD)/occmap --map $(DEMO_MAP) --out $(BUILD)/demo
# make demo-static (tools/demo_run.mk) runs it; make demo is the loop demo.

.PHONY: mavgen test-mavlink-roundtrip test-mavlink-udp fuzz-mavlink test-mavlink-fuzz demo-mavlink
