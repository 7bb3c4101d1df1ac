/* The render check: a small scene (a floor, a glossy wall, a moving mirror sphere, two diffuse
 * spheres, a glowing triangle, a rectangle and a point light; thin-lens camera) as C structs,
 * the same scene capi/tests/common/mod.rs gives the kernel's renderer, and the FNV-1a hash of a
 * rendered region. render_golden.h holds the hashes that test computed: C on any target can be
 * checked against the Rust side. No allocation (firmware): regions go through the caller's
 * buffers. Compile with -ffp-contract=off like every caller of the kernel. */
#ifndef RAYKERNEL_RENDER_SCENE_H
#define RAYKERNEL_RENDER_SCENE_H

#include <stdint.h>
#include "raykernel.h"
#include "grid_hash.h"

#define RK_TEST_WIDTH 24u
#define RK_TEST_HEIGHT 16u

static const float rk_test_floor[2 * 9] = {
    -2.0f, 0.0f, -2.0f, 2.0f, 0.0f, 2.0f, 2.0f, 0.0f, -2.0f,
    -2.0f, 0.0f, -2.0f, -2.0f, 0.0f, 2.0f, 2.0f, 0.0f, 2.0f,
};
static const float rk_test_wall[2 * 9] = {
    -2.0f, 0.0f, -2.0f, 2.0f, 0.0f, -2.0f, 2.0f, 2.0f, -2.0f,
    -2.0f, 0.0f, -2.0f, 2.0f, 2.0f, -2.0f, -2.0f, 2.0f, -2.0f,
};
static const float rk_test_glow[9] = {1.0f, 0.9f, -1.5f, 1.7f, 0.9f, -1.5f, 1.35f, 1.5f, -1.5f};
static const float rk_test_mirror_ball[4] = {-0.6f, 0.5f, 0.0f, 0.5f};
static const float rk_test_balls[2 * 4] = {0.7f, 0.35f, 0.4f, 0.35f, 0.15f, 0.15f, 1.1f, 0.15f};

static const RkObject rk_test_objects[5] = {
    {RK_SHAPE_TRIANGLES, 0, 2, rk_test_floor, {0.0f, 0.0f, 0.0f}},
    {RK_SHAPE_TRIANGLES, 1, 2, rk_test_wall, {0.0f, 0.0f, 0.0f}},
    {RK_SHAPE_SPHERES, 2, 1, rk_test_mirror_ball, {0.25f, 0.0f, 0.0f}},
    {RK_SHAPE_SPHERES, 4, 2, rk_test_balls, {0.0f, 0.0f, 0.0f}},
    {RK_SHAPE_TRIANGLES, 3, 1, rk_test_glow, {0.0f, 0.0f, 0.0f}},
};

static const RkMaterial rk_test_materials[5] = {
    {RK_MATERIAL_DIFFUSE, {0.7f, 0.7f, 0.7f}, 0.0f},
    {RK_MATERIAL_GLOSSY, {0.8f, 0.6f, 0.4f}, 40.0f},
    {RK_MATERIAL_MIRROR, {0.9f, 0.9f, 0.9f}, 0.0f},
    {RK_MATERIAL_EMISSIVE, {2.0f, 1.5f, 1.0f}, 0.0f},
    {RK_MATERIAL_DIFFUSE, {0.2f, 0.5f, 0.8f}, 0.0f},
};

static const RkLight rk_test_lights[2] = {
    {RK_LIGHT_RECT, {-0.5f, 2.5f, -0.5f}, {1.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 1.0f}, 0.0f,
     {10.0f, 10.0f, 10.0f}},
    {RK_LIGHT_POINT, {2.0f, 2.0f, 2.0f}, {0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 0.0f}, 0.0f,
     {1.5f, 1.5f, 1.5f}},
};

/* The scene in `mode` with accelerators of `kind` (0: the default). */
static RkScene rk_test_scene(uint32_t mode, uint32_t kind) {
    RkRenderSettings settings = rk_render_settings_default();
    settings.width = RK_TEST_WIDTH;
    settings.height = RK_TEST_HEIGHT;
    settings.spp = 4;
    settings.max_depth = 3;
    settings.sampler = RK_SAMPLER_STRATIFIED;
    settings.filter = RK_FILTER_TENT;
    settings.seed = 7;
    RkScene scene = {
        mode,
        kind,
        rk_test_objects,
        5,
        rk_test_materials,
        5,
        rk_test_lights,
        2,
        {{0.0f, 1.2f, 4.5f}, {0.0f, 0.6f, 0.0f}, {0.0f, 1.0f, 0.0f}, 45.0f, 0.02f, 4.5f},
        {0.05f, 0.06f, 0.08f},
        settings,
    };
    return scene;
}

/* Renders the `w x h` region at (x0, y0) in tiles of at most `tw x th` pixels (`tile`: room for
 * 3·tw·th bytes) into `region` (3·w·h bytes, row-major) and returns its FNV-1a hash; *status
 * gets the first error (RK_STATUS_OK if none). */
static uint32_t rk_test_render_hash(const RkRenderer *renderer, uint32_t x0, uint32_t y0, uint32_t w,
                                    uint32_t h, uint32_t tw, uint32_t th, uint8_t *tile,
                                    uint8_t *region, RkStatus *status) {
    *status = RK_STATUS_OK;
    for (uint32_t ty = 0; ty < h; ty += th) {
        for (uint32_t tx = 0; tx < w; tx += tw) {
            uint32_t cw = w - tx < tw ? w - tx : tw, ch = h - ty < th ? h - ty : th;
            RkStatus s = rk_render_tile(renderer, x0 + tx, y0 + ty, cw, ch, tile, 3u * cw * ch);
            if (s != RK_STATUS_OK) {
                *status = s;
                return 0;
            }
            for (uint32_t row = 0; row < ch; row++) {
                for (uint32_t b = 0; b < 3u * cw; b++) {
                    region[3u * ((ty + row) * w + tx) + b] = tile[3u * row * cw + b];
                }
            }
        }
    }
    uint32_t hash = 0x811c9dc5u;
    for (uint32_t i = 0; i < 3u * w * h; i++) {
        hash = rk_fnv1a(hash, region[i], 1);
    }
    return hash;
}

#endif
