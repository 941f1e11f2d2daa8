/* SPDX-License-Identifier: BSD-3-Clause */
/* startup_m4.c - Cortex-M reset code for the example image and the qemu self-tests (M4F; the
 * same file serves ARMv6-M, which has no FPU to enable): vector table, FPU on, .data copied,
 * .bss cleared, main() called. With OCC_BM_SEMIHOSTING the
 * image talks to the debugger / qemu (printf, exit status); a fault exits with status 100. */
#include <stdint.h>
#include <stdlib.h>

extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _estack;
int main(void);
void occ_bm_reset(void);
void occ_bm_fault(void);
void occ_bm_idle_irq(void);

#if defined(OCC_BM_SEMIHOSTING) && OCC_BM_SEMIHOSTING
extern void initialise_monitor_handles(void);
#endif

typedef void (*occ_vector_t)(void);

/* The initial stack pointer, then 15 system handlers (NMI, HardFault, MemManage, BusFault,
 * UsageFault, 4 reserved, SVCall, DebugMon, reserved, PendSV, SysTick). No peripheral IRQs. */
typedef struct {
    uint32_t *initial_sp;
    occ_vector_t handlers[15];
} occ_vector_table_t;

__attribute__((section(".isr_vector"), used)) const occ_vector_table_t occ_bm_vectors = {
    &_estack,
    {occ_bm_reset, occ_bm_fault, occ_bm_fault, occ_bm_fault, occ_bm_fault, occ_bm_fault, 0, 0,
     0, 0, occ_bm_idle_irq, occ_bm_idle_irq, 0, occ_bm_idle_irq, occ_bm_idle_irq}};

void occ_bm_idle_irq(void)
{
}

void occ_bm_fault(void)
{
#if defined(OCC_BM_SEMIHOSTING) && OCC_BM_SEMIHOSTING
    exit(100);
#else
    for (;;) {
    }
#endif
}

void occ_bm_reset(void)
{
#if defined(__ARM_FP)
    /* CP10 and CP11 full access before any floating-point instruction. */
    volatile uint32_t *const cpacr = (volatile uint32_t *)0xE000ED88u;
    *cpacr |= 0xFu << 20;
    __asm__ volatile("dsb\n\tisb" ::: "memory");
#endif
    const uint32_t *src = &_sidata;
    for (uint32_t *dst = &_sdata; dst < &_edata;) {
        *dst++ = *src++;
    }
    for (uint32_t *dst = &_sbss; dst < &_ebss;) {
        *dst++ = 0u;
    }
#if defined(OCC_BM_SEMIHOSTING) && OCC_BM_SEMIHOSTING
    initialise_monitor_handles();
    exit(main());
#else
    (void)main();
    for (;;) {
    }
#endif
}
