/* Firmware example: load a baked mesh from flash through the C interface (no build, no copy)
 * and trace the check grid; print its hash over semihosting and exit with 0, or 1 on an
 * error. Run: qemu-system-arm -machine mps2-an386 -nographic
 *   -semihosting-config enable=on,target=native -kernel firmware.elf */
#include <stdint.h>
#include "raykernel.h"
#include "grid_hash.h"

extern const uint8_t baked_mesh[];
extern const uint32_t baked_mesh_len;

/* ARM semihosting: operation in r0, argument in r1, `bkpt 0xab`. */
static int semihost(int op, const void *arg) {
    register int r0 __asm__("r0") = op;
    register const void *r1 __asm__("r1") = arg;
    __asm__ volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}

static void put(const char *s) {
    semihost(0x04, s); /* SYS_WRITE0 */
}

static void put_hex(uint32_t x) {
    char s[11] = "0x";
    for (int i = 0; i < 8; i++) {
        s[2 + i] = "0123456789abcdef"[(x >> (28 - 4 * i)) & 0xf];
    }
    s[10] = 0;
    put(s);
}

static void __attribute__((noreturn)) exit_with(int failed) {
    /* SYS_EXIT: ADP_Stopped_ApplicationExit (QEMU exits 0) or ADP_Stopped_RunTimeErrorUnknown (1). */
    semihost(0x18, (const void *)(uintptr_t)(failed ? 0x20023 : 0x20026));
    for (;;) {
    }
}

int main(void) {
    RkAccel accel;
    RkStatus s = rk_load_baked(baked_mesh, baked_mesh_len, &accel);
    if (s != RK_STATUS_OK) {
        put("rk_load_baked: ");
        put(rk_status_name(s));
        put("\n");
        exit_with(1);
    }
    uint32_t h = rk_grid_hash(&accel, &s);
    if (s != RK_STATUS_OK) {
        put("trace: ");
        put(rk_status_name(s));
        put("\n");
        exit_with(1);
    }
    put("grid_hash ");
    put_hex(h);
    put("\n");
    exit_with(0);
}
