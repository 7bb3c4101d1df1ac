/* Minimal Cortex-M4F start-up: vector table, .data/.bss set-up, FPU on, then main. */
#include <stdint.h>

extern uint32_t _data_start, _data_end, _data_load, _bss_start, _bss_end, _stack_top;
int main(void);

void reset_handler(void) {
    uint32_t *src = &_data_load;
    for (uint32_t *dst = &_data_start; dst < &_data_end;) {
        *dst++ = *src++;
    }
    for (uint32_t *dst = &_bss_start; dst < &_bss_end;) {
        *dst++ = 0;
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
