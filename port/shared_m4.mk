# SPDX-License-Identifier: BSD-3-Clause
# shared_m4.mk - the shared map (issue 20) on an emulated Cortex-M4F: a writer in thread mode and
# a reader in the SysTick interrupt preempting it at pseudo-random points
# (port/baremetal/shared_isr_main.c, its own vector table), the writer integrating part of the
# real scan.dat with eviction. The image's exit status is the number of failures (mismatches,
# no eviction ...); the interrupt's worst-case time is printed. Two images: the default atomics
# (__atomic builtins: DMB + LDR/STR) and OCC_SHARED_SINGLE_CORE=1 (volatile + compiler barrier),
# whose shared.o is linked ahead of the core archive (only src/core/shared.c uses the atomics).
# Uses firmware.mk's core archive and linker script. Recursive (=) variables: this fragment is
# read before the Makefile defines CROSS_M4 and CROSS_COMMON.
SHARED_M4_OBJ := $(BUILD)/cross/m4/port/baremetal/shared_isr_main.o \
                 $(BUILD)/cross/m4/$(FW_DIR)/gen/shared_isr_scan.o
# The real points: every 8th point of OctoMap's scan.dat (11026 points, 132 KB of flash) as
# float triples in a generated C file (never in the tree).
SHARED_M4_SCAN_STEP := 8
$(FW_DIR)/gen/shared_isr_scan.bin: $(BUILD)/data/scan.dat port/baremetal/scan_subset.py
	@mkdir -p $(dir $@)
	python3 port/baremetal/scan_subset.py $< $@ $(SHARED_M4_SCAN_STEP)
$(FW_DIR)/gen/shared_isr_scan.c: $(FW_DIR)/gen/shared_isr_scan.bin port/baremetal/embed_bytes.py
	python3 port/baremetal/embed_bytes.py $< $@ shared_isr_scan
SHARED_M4_SINGLE_OBJ := $(BUILD)/cross/m4single/src/core/shared.o
SHARED_M4_LDFLAGS = $(CROSS_M4) -T $(FW_LD) -nostartfiles --specs=nano.specs --specs=rdimon.specs \
  -Wl,--gc-sections -Wl,--entry=shared_isr_reset
$(SHARED_M4_SINGLE_OBJ): src/core/shared.c | $(FW_HEADERS)
	@mkdir -p $(dir $@)
	$(CROSS_CC) $(CROSS_COMMON) $(CROSS_M4) -DOCC_SHARED_SINGLE_CORE=1 -MMD -MP -c $< -o $@
$(FW_DIR)/shared_isr_m4.elf: $(SHARED_M4_OBJ) $(FW_DIR)/libocc_m4.a $(FW_LD)
	$(CROSS_CC) $(SHARED_M4_LDFLAGS) -o $@ $(SHARED_M4_OBJ) $(FW_DIR)/libocc_m4.a -lm
$(FW_DIR)/shared_isr_m4_single.elf: $(SHARED_M4_OBJ) $(SHARED_M4_SINGLE_OBJ) $(FW_DIR)/libocc_m4.a $(FW_LD)
	$(CROSS_CC) $(SHARED_M4_LDFLAGS) -o $@ $(SHARED_M4_OBJ) $(SHARED_M4_SINGLE_OBJ) $(FW_DIR)/libocc_m4.a -lm

# -icount shift=0: qemu's virtual clock advances 1 ns per guest instruction, so SysTick's 25 MHz
# ticks count instructions (40 per tick) and the interrupt's worst case is deterministic.
SHARED_M4_QEMU := timeout --foreground -k 2 120 qemu-system-arm -M mps2-an386 -icount shift=0 \
  -nographic -monitor none -serial null -semihosting-config enable=on,target=native -kernel
TEST_STEPS += test-shared-m4
test-shared-m4: $(FW_DIR)/shared_isr_m4.elf $(FW_DIR)/shared_isr_m4_single.elf
	@command -v qemu-system-arm >/dev/null || { echo "SKIP test-shared-m4: qemu-system-arm not installed (environment limit)"; exit 77; }
	@for img in shared_isr_m4 shared_isr_m4_single; do rc=0; echo "$$img:"; \
	  (cd $(FW_DIR) && $(SHARED_M4_QEMU) $$img.elf) || rc=$$?; \
	  [ $$rc -eq 0 ] && echo "PASS test-shared-m4 $$img" || { echo "FAIL test-shared-m4 $$img: exit $$rc (100 = fault, 124 = hang, else mismatches)"; exit 1; }; \
	done
.PHONY: test-shared-m4
