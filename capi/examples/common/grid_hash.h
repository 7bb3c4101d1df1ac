/* The check grid: 32 x 32 rays from (0, 0, -10) towards (x, y, 0) for x, y in a 3 x 3 square
 * around the axis, each traced for the closest hit and any hit; the hash is FNV-1a (32-bit)
 * over, per ray in row order, the hit's triangle index and the bits of its distance (both
 * little-endian u32; RK_NO_HIT and 0 for a miss) and one byte for the any-hit answer.
 * `raykernel bake` prints the same hash of the tree it built (`grid_hash`), so C on any target can
 * be checked against the Rust side. Compile with -ffp-contract=off: the ray directions must be
 * the separately rounded float operations written here. */
#ifndef RAYKERNEL_GRID_HASH_H
#define RAYKERNEL_GRID_HASH_H

#include <stdint.h>
#include "raykernel.h"

#define RK_GRID_N 32

static uint32_t rk_fnv1a(uint32_t h, uint32_t word, int bytes) {
    for (int i = 0; i < bytes; i++) {
        h ^= (word >> (8 * i)) & 0xffu;
        h *= 0x01000193u;
    }
    return h;
}

/* Hash of the check grid through `accel`; *status gets the first error (RK_STATUS_OK if none). */
static uint32_t rk_grid_hash(const RkAccel *accel, RkStatus *status) {
    uint32_t h = 0x811c9dc5u;
    *status = RK_STATUS_OK;
    for (int j = 0; j < RK_GRID_N; j++) {
        for (int i = 0; i < RK_GRID_N; i++) {
            float x = -1.5f + 3.0f * ((float)i + 0.5f) / (float)RK_GRID_N;
            float y = -1.5f + 3.0f * ((float)j + 0.5f) / (float)RK_GRID_N;
            RkRay ray = {{0.0f, 0.0f, -10.0f}, {x, y, 10.0f}, 0.0f, __builtin_inff()};
            RkHit hit;
            bool any = false;
            RkStatus s = rk_intersect(accel, &ray, &hit);
            if (s == RK_STATUS_OK) {
                s = rk_occluded(accel, &ray, &any);
            }
            if (s != RK_STATUS_OK) {
                *status = s;
                return 0;
            }
            union {
                float f;
                uint32_t u;
            } t = {hit.t};
            uint32_t t_bits = hit.prim != RK_NO_HIT ? t.u : 0u;
            h = rk_fnv1a(h, hit.prim, 4);
            h = rk_fnv1a(h, t_bits, 4);
            h = rk_fnv1a(h, any ? 1u : 0u, 1);
        }
    }
    return h;
}

#endif
