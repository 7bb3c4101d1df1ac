/* Minimal Cortex-M4F start-up: vector table, .data/.bss set-up, FPU on, then main. */
#include <stdint.h>

#include "stack_paint.h"

int main(void);

void reset_handler(void) {
    uint32_t *src = &_data_load;
    for (uint32_t *dst = &_data_start; dst < &_data_end;) {
        *dst++ = *src++;
    }
    for (uint32_t *dst = &_bss_start; dst < &_bss_end;) {
        *dst++ = 0;
    }
    /* Paint the free RAM between .bss and the stack, so main can measure the stack it used. */
    uint32_t *sp;
    __asm__ volatile("mov %0, sp" : "=r"(sp));
    for (uint32_t *p = &_bss_end; p < sp - 16;) {
        *p++ = STACK_PAINT;
    }
    /* CPACR: full access to coprocessors 10 and 11 (the FPU). */
    *(volatile uint32_t *)0xE000ED88u |= 0xFu << 20;
    __asm__ volatile("dsb\n isb");
    main();
    for (;;) {
    }
}

static void fault_handler(void) {
    /* SYS_EXIT with ADP_Stopped_RunTimeErrorUnknown: QEMU exits 1. */
    register int r0 __asm__("r0") = 0x18;
    register int r1 __asm__("r1") = 0x20023;
    __asm__ volatile("bkpt 0xab" : : "r"(r0), "r"(r1));
    for (;;) {
    }
}

__attribute__((section(".vectors"), used)) static const void *const vectors[16] = {
    &_stack_top,     reset_handler,   fault_handler, fault_handler,
    fault_handler,   fault_handler,   fault_handler, 0,
    0,               0,               0,             fault_handler,
    fault_handler,   0,               fault_handler, fault_handler,
};
