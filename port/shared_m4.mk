# shared_m4.mk - the shared map (issue 20) on an emulated Cortex-M4F: a writer in thread mode and
# a reader in the SysTick interrupt preempting it at pseudo-random points
# (port/baremetal/shared_isr_main.c, its own vector table). The image's exit status is the number
# of mismatches; the interrupt's worst-case time is printed. Uses firmware.mk's core archive,
# linker script and qemu command.
SHARED_M4_ELF := $(FW_DIR)/shared_isr_m4.elf
SHARED_M4_OBJ := $(BUILD)/cross/m4/port/baremetal/shared_isr_main.o
$(SHARED_M4_ELF): $(SHARED_M4_OBJ) $(FW_DIR)/libocc_m4.a $(FW_LD)
	$(CROSS_CC) $(CROSS_M4) -T $(FW_LD) -nostartfiles --specs=nano.specs --specs=rdimon.specs \
	  -Wl,--gc-sections -Wl,--entry=shared_isr_reset -o $@ $(SHARED_M4_OBJ) $(FW_DIR)/libocc_m4.a -lm

# -icount shift=0: qemu's virtual clock advances 1 ns per guest instruction, so SysTick's 25 MHz
# ticks count instructions (40 per tick) and the interrupt's worst case is deterministic.
SHARED_M4_QEMU := timeout --foreground -k 2 120 qemu-system-arm -M mps2-an386 -icount shift=0 \
  -nographic -monitor none -serial null -semihosting-config enable=on,target=native -kernel
TEST_STEPS += test-shared-m4
test-shared-m4: $(SHARED_M4_ELF)
	@command -v qemu-system-arm >/dev/null || { echo "SKIP test-shared-m4: qemu-system-arm not installed (environment limit)"; exit 77; }
	@rc=0; (cd $(FW_DIR) && $(SHARED_M4_QEMU) $(notdir $(SHARED_M4_ELF))) || rc=$$?; \
	  [ $$rc -eq 0 ] && echo "PASS test-shared-m4" || { echo "FAIL test-shared-m4: exit $$rc (100 = fault, 124 = hang, else mismatches)"; exit 1; }
.PHONY: test-shared-m4
