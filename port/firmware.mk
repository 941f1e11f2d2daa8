# SPDX-License-Identifier: BSD-3-Clause
# firmware.mk - the firmware build (issue 8), on top of `make cross`:
#   - port/baremetal (weak CAN hooks, the example main) for Cortex-M4F and Cortex-M0+;
#   - build/fw/example_m4.elf: the example image (startup, linker script, static arena, test cloud,
#     DroneCAN through a stub driver) for qemu's mps2-an386 (Cortex-M4F), and its size table per
#     module (text / data / bss from the link map), the worst -fstack-usage frames and a
#     recursion check on the image's call graph (port/baremetal/fw_report.py);
#   - build/fw/m4_selftest.elf: the core's self-test (tests/can/m4_selftest.c).
# test-m4-qemu runs both images under qemu-system-arm with semihosting; their exit status is the
# verdict (a fault exits 100, a hang ends in timeout's 124).
APT_PKGS += qemu-system-arm gcc-arm-none-eabi libnewlib-arm-none-eabi

FW_DIR := $(BUILD)/fw
FW_LD := port/baremetal/mps2_an386.ld
FW_LDFLAGS = $(CROSS_M4) -T $(FW_LD) -nostartfiles --specs=nano.specs --specs=rdimon.specs \
              -Wl,--gc-sections
FW_PORT_SRC := port/baremetal/can_hooks.c port/baremetal/example_main.c
FW_M4_PORT_OBJ := $(FW_PORT_SRC:%.c=$(BUILD)/cross/m4/%.o) $(BUILD)/cross/m4/port/baremetal/startup_m4.o
FW_M0_PORT_OBJ := $(FW_PORT_SRC:%.c=$(BUILD)/cross/m0/%.o)
FW_SELFTEST_OBJ := $(BUILD)/cross/m4/tests/can/m4_selftest.o $(BUILD)/cross/m4/port/baremetal/startup_m4.o

$(BUILD)/cross/m4/port/baremetal/startup_m4.o: EXTRA_CFLAGS += -DOCC_BM_SEMIHOSTING=1

# The core for the images as an archive, so the link takes only the modules it needs.
$(FW_DIR)/libocc_m4.a: $(patsubst %.c,$(BUILD)/cross/m4/%.o,$(OCC_CORE_SRC) $(OCC_FEED_SRC))
	@mkdir -p $(dir $@)
	@rm -f $@
	arm-none-eabi-ar rcs $@ $^

$(FW_DIR)/example_m4.elf: $(FW_M4_PORT_OBJ) $(FW_DIR)/libocc_m4.a $(FW_LD)
	$(CROSS_CC) $(FW_LDFLAGS) -Wl,-Map=$@.map -o $@ $(FW_M4_PORT_OBJ) $(FW_DIR)/libocc_m4.a -lm

$(FW_DIR)/m4_selftest.elf: $(FW_SELFTEST_OBJ) $(FW_DIR)/libocc_m4.a $(FW_LD)
	$(CROSS_CC) $(FW_LDFLAGS) -Wl,-Map=$@.map -o $@ $(FW_SELFTEST_OBJ) $(FW_DIR)/libocc_m4.a -lm

# Printed by `make cross` (a prerequisite of cross-objs, so it runs before cross_report.sh).
firmware-report: $(FW_DIR)/example_m4.elf
	@python3 port/baremetal/fw_report.py $(FW_DIR)/example_m4.elf $(BUILD)/cross/m4

CROSS_EXTRA += $(FW_M4_PORT_OBJ) $(FW_M0_PORT_OBJ) $(FW_DIR)/example_m4.elf $(FW_DIR)/m4_selftest.elf \
               firmware-report

QEMU_ARM_RUN := timeout --foreground -k 2 60 qemu-system-arm -M mps2-an386 -nographic -monitor none \
                -serial null -semihosting-config enable=on,target=native -kernel
test-m4-qemu: $(FW_DIR)/m4_selftest.elf $(FW_DIR)/example_m4.elf
	@command -v qemu-system-arm >/dev/null || { echo "SKIP test-m4-qemu: qemu-system-arm not installed (environment limit)"; exit 0; }
	@set -e; for img in m4_selftest example_m4; do \
	  t0=$$(date +%s%N); rc=0; \
	  (cd $(FW_DIR) && $(QEMU_ARM_RUN) $$img.elf) || rc=$$?; \
	  echo "qemu-system-arm mps2-an386: $$img.elf exit $$rc in $$(( ($$(date +%s%N) - t0) / 1000000 )) ms"; \
	  [ $$rc -eq 0 ] || { echo "FAIL test-m4-qemu: $$img (100 = fault, 124 = hang, else failed checks)"; exit 1; }; \
	done
TEST_STEPS += test-m4-qemu

# ARMv6-M: the core built for Cortex-M0+ runs its self-test on qemu's microbit (Cortex-M0, the same
# instruction set; 16 KB RAM, so an 8 KB arena). qemu has no M0+ model. The self-test also paints
# the stack around a few calls: what they really used must stay within the static bounds.
FW_M0_LD := port/baremetal/microbit.ld
FW_M0_LDFLAGS = $(CROSS_M0) -T $(FW_M0_LD) -nostartfiles --specs=nano.specs --specs=rdimon.specs \
                 -Wl,--gc-sections
FW_M0_SELFTEST_OBJ := $(BUILD)/cross/m0/port/baremetal/m0_selftest.o $(BUILD)/cross/m0/port/baremetal/startup_m4.o
$(BUILD)/cross/m0/port/baremetal/startup_m4.o: EXTRA_CFLAGS += -DOCC_BM_SEMIHOSTING=1
$(FW_DIR)/libocc_m0.a: $(patsubst %.c,$(BUILD)/cross/m0/%.o,$(OCC_CORE_SRC) $(OCC_FEED_SRC))
	@mkdir -p $(dir $@)
	@rm -f $@
	arm-none-eabi-ar rcs $@ $^
$(FW_DIR)/m0_selftest.elf: $(FW_M0_SELFTEST_OBJ) $(FW_DIR)/libocc_m0.a $(FW_M0_LD)
	$(CROSS_CC) $(FW_M0_LDFLAGS) -Wl,-Map=$@.map -o $@ $(FW_M0_SELFTEST_OBJ) $(FW_DIR)/libocc_m0.a -lm
QEMU_M0_RUN := timeout --foreground -k 2 120 qemu-system-arm -M microbit -nographic -monitor none \
               -serial null -semihosting-config enable=on,target=native -kernel
test-m0-qemu: $(FW_DIR)/m0_selftest.elf
	@command -v qemu-system-arm >/dev/null || { echo "SKIP test-m0-qemu: qemu-system-arm not installed (environment limit)"; exit 77; }
	@t0=$$(date +%s%N); rc=0; (cd $(FW_DIR) && $(QEMU_M0_RUN) m0_selftest.elf > m0_selftest.log) || rc=$$?; \
	 cat $(FW_DIR)/m0_selftest.log; \
	 echo "qemu-system-arm microbit: m0_selftest.elf exit $$rc in $$(( ($$(date +%s%N) - t0) / 1000000 )) ms"; \
	 [ $$rc -eq 0 ] || { echo "FAIL test-m0-qemu: m0_selftest (100 = fault, 124 = hang, else failed checks)"; exit 1; }; \
	 python3 tests/stack_measured_check.py $(FW_DIR)/m0_selftest.log $(BUILD)/cross/m0/src "$(CROSS_M0)" \
	   $(BUILD)/cross/m0/port/baremetal/m0_selftest.su \
	   || { echo "FAIL test-m0-qemu: a call used more stack than its static bound"; exit 1; }; \
	 echo "PASS test-m0-qemu"
CROSS_EXTRA += $(FW_DIR)/m0_selftest.elf
TEST_STEPS += test-m0-qemu
.PHONY: firmware-report test-m4-qemu test-m0-qemu

# The stack budget (tests/stack_budget.py, run by make cross) reads the .ci call graphs that
# -fcallgraph-info=su writes next to each core object (only there: a compile from stdin would
# leave a--.ci in the tree); objects built before that flag are rebuilt once.
FW_CG_OBJ := $(foreach t,m4 m0,$(patsubst %.c,$(BUILD)/cross/$(t)/%.o,$(OCC_CORE_SRC) $(OCC_FEED_SRC)))
$(FW_CG_OBJ): EXTRA_CFLAGS += -fcallgraph-info=su
$(FW_DIR)/.callgraph-info:
	@mkdir -p $(dir $@)
	@touch $@
$(FW_CG_OBJ): $(FW_DIR)/.callgraph-info

# ---- make bench-m4: instruction counts per call on the emulated Cortex-M4F ----------------------
# A crop of OctoMap's geb079 (cropped on the host by port/baremetal/crop_map.c, embedded as a C
# array in build/fw), loaded with occ_io_load from flash into a static arena; qemu -icount
# shift=0 makes virtual time count instructions, read from the CMSDK dual timer around each call.
GEB079_BT := /usr/share/doc/liboctomap-dev/examples/data/geb079.bt
BENCH_M4_CROP := -2.0 -3.0 -0.4 4.0 3.0 2.8
$(BUILD)/fw/crop_map: $(BUILD)/relhost/port/baremetal/crop_map.o $(BUILD)/relhost/port/posix/file_io.o $(BUILD)/libocc.a
	@mkdir -p $(dir $@)
	$(CC) -o $@ $^ -lm
$(FW_DIR)/geb079_crop.occ: $(BUILD)/fw/crop_map port/firmware.mk
	@test -f $(GEB079_BT) || { echo "SKIP bench-m4: $(GEB079_BT) absent (liboctomap-dev)"; exit 77; }
	$(BUILD)/fw/crop_map $(GEB079_BT) $@ $(BENCH_M4_CROP)
$(FW_DIR)/geb079_crop.c: $(FW_DIR)/geb079_crop.occ port/baremetal/embed_bytes.py
	python3 port/baremetal/embed_bytes.py $< $@ occ_bench_map \
	  occ_bench_box_min=$(subst $(eval) ,$(comma),$(wordlist 1,3,$(BENCH_M4_CROP))) \
	  occ_bench_box_max=$(subst $(eval) ,$(comma),$(wordlist 4,6,$(BENCH_M4_CROP)))
comma := ,
FW_BENCH_OBJ := $(BUILD)/cross/m4/port/baremetal/bench_m4.o $(BUILD)/cross/m4/$(FW_DIR)/geb079_crop.o \
                $(BUILD)/cross/m4/port/baremetal/startup_m4.o
$(FW_DIR)/bench_m4.elf: $(FW_BENCH_OBJ) $(FW_DIR)/libocc_m4.a $(FW_LD)
	$(CROSS_CC) $(FW_LDFLAGS) -u _printf_float -Wl,-Map=$@.map -o $@ $(FW_BENCH_OBJ) $(FW_DIR)/libocc_m4.a -lm
QEMU_M4_ICOUNT := timeout --foreground -k 2 300 qemu-system-arm -M mps2-an386 -icount shift=0 \
                  -nographic -monitor none -serial null -semihosting-config enable=on,target=native -kernel
# The output also goes to build/fw/bench_m4.log, which `make fw-readme` reads.
bench-m4: $(FW_DIR)/bench_m4.elf
	@command -v qemu-system-arm >/dev/null || { echo "SKIP bench-m4: qemu-system-arm not installed"; exit 77; }
	@set -o pipefail; cd $(FW_DIR) && $(QEMU_M4_ICOUNT) bench_m4.elf | tee bench_m4.log.tmp
	@mv $(FW_DIR)/bench_m4.log.tmp $(FW_DIR)/bench_m4.log
BENCH_STEPS += bench-m4
.PHONY: bench-m4

# ---- the firmware numbers of the READMEs (port/baremetal/fw_table.py) -------------------------
#   make fw-readme      after make cross (and make bench-m4: without its log the committed bench
#                       rows are kept): port/baremetal/results/firmware.json from what they
#                       measured, then README.md's Firmware tables and port/baremetal/README's
#                       "How big" list rendered from it; commit the three together.
#   make test-fw-table  both README sections are what the committed results render, a changed
#                       digit fails that check, and the results do not understate a stack bound
#                       the current build has (tests/fw_table_check.py).
FW_RESULTS := port/baremetal/results/firmware.json
fw-readme:
	@[ -f $(FW_DIR)/stack.json ] || { echo "fw-readme: no $(FW_DIR)/stack.json: run make cross"; exit 1; }
	@python3 port/baremetal/fw_table.py collect --stack $(FW_DIR)/stack.json --cross $(BUILD)/cross \
	  --image $(FW_DIR)/example_m4.elf --bench $(FW_DIR)/bench_m4.log --out $(FW_RESULTS)
	@python3 port/baremetal/fw_table.py readme --results $(FW_RESULTS) --readme README.md \
	  --port-readme port/baremetal/README --write
	@echo "fw-readme: commit $(FW_RESULTS), README.md and port/baremetal/README together"
test-fw-table:
	@python3 tests/fw_table_check.py $(BUILD)
TEST_STEPS += test-fw-table
.PHONY: fw-readme test-fw-table

# The stack-budget checker against hand-made call graphs with hand-computed answers (a planted
# entry point over its class limit, a budget above its class limit, an unstated entry point and
# a statement without a work bound must each fail).
test-stack-budget:
	@python3 tests/stack_budget_check.py
TEST_STEPS += test-stack-budget
.PHONY: test-stack-budget
