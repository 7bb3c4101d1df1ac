/* Firmware example: load a baked mesh from flash through the C interface (no build, no copy)
 * and trace the check grid, printing its hash; then build the render check scene into static
 * memory and render its check tile in both number modes, printing each hash and comparing it
 * with the kernel's (render_golden.h), and the stack each part used. Output over semihosting;
 * exits with 0, or 1 on an error or a differing tile. Run: qemu-system-arm -machine mps2-an386 -nographic
 *   -semihosting-config enable=on,target=native -kernel firmware.elf */
#include <stdint.h>
#include "raykernel.h"
#include "grid_hash.h"
#include "render_golden.h"
#include "render_scene.h"
#include "stack_paint.h"

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

static void put_dec(uint32_t x) {
    char s[11];
    int i = 10;
    s[i] = 0;
    do {
        s[--i] = (char)('0' + x % 10u);
        x /= 10u;
    } while (x != 0);
    put(&s[i]);
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

/* Caller memory of the renderer (any alignment works: rk_renderer_init aligns inside it). */
static uint8_t render_memory[16 * 1024];

/* Renders the check tile of the render scene in `mode`; 0 if its hash is the kernel's. */
static int render_check(uint32_t mode, const char *name, uint32_t expect) {
    static uint8_t tile[3 * RK_TEST_TILE_W * RK_TEST_TILE_H], region[3 * RK_TEST_TILE_W * RK_TEST_TILE_H];
    RkScene scene = rk_test_scene(mode, 0);
    size_t bytes = rk_render_bytes(&scene);
    if (bytes == 0) {
        put("rk_render_bytes: scene unusable, or its mode and kind not linked\n");
        return 1;
    }
    if (bytes > sizeof render_memory) {
        put("render memory: too small\n");
        return 1;
    }
    RkRenderer renderer;
    RkSceneError error;
    RkStatus s = rk_renderer_init(&scene, render_memory, sizeof render_memory, &renderer, &error);
    if (s == RK_STATUS_OK) {
        uint32_t h = rk_test_render_hash(&renderer, RK_TEST_TILE_X, RK_TEST_TILE_Y, RK_TEST_TILE_W,
                                         RK_TEST_TILE_H, RK_TEST_TILE_W, RK_TEST_TILE_H, tile, region, &s);
        if (s == RK_STATUS_OK) {
            put("render_tile_hash ");
            put(name);
            put(" ");
            put_hex(h);
            put(h == expect ? " (the kernel's), renderer memory " : " differs from the kernel's\n");
            if (h == expect) {
                put_dec((uint32_t)bytes);
                put(" bytes\n");
            }
            return h != expect;
        }
    }
    put("render: ");
    put(rk_status_name(s));
    put("\n");
    return 1;
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
    put("stack used by load + trace: ");
    put_dec(stack_used());
    put(" bytes\n");
    int failed = render_check(RK_MODE_F32, "f32", RK_TEST_TILE_HASH_F32);
    failed |= render_check(RK_MODE_FIXED, "fixed", RK_TEST_TILE_HASH_FIXED);
    put("stack used with init + render: ");
    put_dec(stack_used());
    put(" bytes\n");
    exit_with(failed);
}
