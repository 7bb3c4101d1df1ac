/* Stack measurement: start-up paints the free RAM between .bss and the stack with STACK_PAINT;
 * stack_used() finds the deepest word the stack overwrote since. */
#ifndef RAYKERNEL_STACK_PAINT_H
#define RAYKERNEL_STACK_PAINT_H

#include <stdint.h>

#define STACK_PAINT 0x5a5aa5a5u

extern uint32_t _data_start, _data_end, _data_load, _bss_start, _bss_end, _stack_top;

/* Bytes of stack used so far (the highest unpainted word's distance from the top). */
static inline uint32_t stack_used(void) {
    const uint32_t *p = &_bss_end;
    while (p < &_stack_top && *p == STACK_PAINT) {
        p++;
    }
    return (uint32_t)((uintptr_t)&_stack_top - (uintptr_t)p);
}

#endif
