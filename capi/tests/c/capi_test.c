/* Host test of the C interface (gcc): every status named, builds in both modes and both tree
 * kinds answering alike, typed errors for bad arguments, refit equal to a rebuild, rendering
 * the check scene in tiles (also from several threads at once) with the kernel's bytes
 * (render_golden.h) and typed scene errors, and, given a baked file (argv[1]), loading it in
 * place and printing the check grid's hash (compared with argv[2] when given: the hash
 * `raykernel bake` printed for the tree it built).
 * Build: gcc -std=c11 -ffp-contract=off -I capi/include -I capi/examples/common
 *        capi/tests/c/capi_test.c target/debug/libraykernel_c.a -lpthread -ldl -lm */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <threads.h>
#include "raykernel.h"
#include "grid_hash.h"
#include "render_golden.h"
#include "render_scene.h"

#define CHECK(cond, ...)                                      \
    do {                                                      \
        if (!(cond)) {                                        \
            fprintf(stderr, "line %d: ", __LINE__);           \
            fprintf(stderr, __VA_ARGS__);                     \
            fprintf(stderr, "\n");                            \
            return 1;                                         \
        }                                                     \
    } while (0)

enum { G = 12, TRIS = 2 * G * G };

/* A height field over [-1.4, 1.4]^2, two triangles per cell, heights on a 1/8 grid; `lift`
 * moves every vertex up (refit tests). */
static void terrain(float *v, float lift) {
    int k = 0;
    for (int j = 0; j < G; j++) {
        for (int i = 0; i < G; i++) {
            float corner[4][3];
            for (int c = 0; c < 4; c++) {
                int x = i + (c & 1), y = j + (c >> 1);
                unsigned h = (unsigned)(x * 73856093u) ^ (unsigned)(y * 19349663u);
                corner[c][0] = -1.4f + 2.8f * (float)x / (float)G;
                corner[c][1] = -1.4f + 2.8f * (float)y / (float)G;
                corner[c][2] = (float)(int)(h % 17u) / 8.0f - 1.0f + lift;
            }
            const int tri[2][3] = {{0, 1, 2}, {1, 3, 2}};
            for (int t = 0; t < 2; t++) {
                for (int c = 0; c < 3; c++) {
                    memcpy(&v[k], corner[tri[t][c]], sizeof corner[0]);
                    k += 3;
                }
            }
        }
    }
}

/* Builds over `v` into fresh memory (kept in *memory) and returns the status. */
static RkStatus build(uint32_t mode, uint32_t kind, const float *v, void **memory, RkAccel *out) {
    size_t bytes = rk_build_bytes(mode, kind, TRIS);
    *memory = malloc(bytes);
    return rk_build(mode, kind, 0, v, TRIS, *memory, bytes, out);
}

static int test_names(void) {
    const char *unknown = rk_status_name(999);
    CHECK(strcmp(unknown, "unknown status") == 0, "999: %s", unknown);
    for (int s = 0; s <= RK_STATUS_ERR_BUFFER_TOO_SMALL; s++) {
        const char *name = rk_status_name(s);
        CHECK(name != NULL && strcmp(name, unknown) != 0, "status %d unnamed", s);
        for (int o = 0; o < s; o++) {
            CHECK(strcmp(name, rk_status_name(o)) != 0, "statuses %d and %d share a name", o, s);
        }
    }
    return 0;
}

static int test_builds_and_errors(void) {
    static float v[9 * TRIS], moved[9 * TRIS];
    terrain(v, 0.0f);
    terrain(moved, 0.75f);
    const uint32_t modes[2] = {RK_MODE_F32, RK_MODE_FIXED};
    for (int m = 0; m < 2; m++) {
        uint32_t hashes[2];
        for (uint32_t kind = RK_KIND_BVH; kind <= RK_KIND_BVH4; kind++) {
            void *memory;
            RkAccel accel;
            RkStatus s = build(modes[m], kind, v, &memory, &accel);
            CHECK(s == RK_STATUS_OK, "build mode %u kind %u: %s", modes[m], kind, rk_status_name(s));
            uint32_t h = rk_grid_hash(&accel, &s);
            CHECK(s == RK_STATUS_OK, "trace: %s", rk_status_name(s));
            hashes[kind - 1] = h;
            /* One ray straight down onto the terrain hits; one away from it misses. */
            RkRay down = {{0.1f, 0.2f, 5.0f}, {0.0f, 0.0f, -1.0f}, 0.0f, 1.0f / 0.0f};
            RkRay away = {{0.1f, 0.2f, 5.0f}, {0.0f, 0.0f, 1.0f}, 0.0f, 1.0f / 0.0f};
            RkHit hit;
            bool any;
            CHECK(rk_intersect(&accel, &down, &hit) == RK_STATUS_OK && hit.prim < TRIS, "down");
            CHECK(hit.t > 3.0f && hit.t < 7.0f && hit.u >= 0.0f && hit.v >= 0.0f, "t %f", hit.t);
            CHECK(rk_occluded(&accel, &down, &any) == RK_STATUS_OK && any, "down: any hit");
            CHECK(rk_intersect(&accel, &away, &hit) == RK_STATUS_OK && hit.prim == RK_NO_HIT, "up");
            CHECK(rk_occluded(&accel, &away, &any) == RK_STATUS_OK && !any, "up: any hit");
            RkRay bad = {{0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 0.0f}, 0.0f, 1.0f};
            CHECK(rk_intersect(&accel, &bad, &hit) == RK_STATUS_ERR_BAD_RAY, "zero direction");
            /* Refit to the moved terrain equals a build over it. */
            void *fresh_memory;
            RkAccel fresh;
            CHECK(build(modes[m], kind, moved, &fresh_memory, &fresh) == RK_STATUS_OK, "rebuild");
            s = rk_refit(&accel, moved, TRIS);
            CHECK(s == RK_STATUS_OK, "refit: %s", rk_status_name(s));
            RkStatus s1, s2;
            uint32_t refit_hash = rk_grid_hash(&accel, &s1), fresh_hash = rk_grid_hash(&fresh, &s2);
            CHECK(s1 == RK_STATUS_OK && s2 == RK_STATUS_OK, "trace after refit");
            CHECK(refit_hash == fresh_hash, "refit %08x != rebuild %08x", refit_hash, fresh_hash);
            CHECK(refit_hash != h, "the motion changed nothing");
            CHECK(rk_refit(&accel, moved, TRIS - 1) == RK_STATUS_ERR_NOT_REFITTABLE, "count");
            free(memory);
            free(fresh_memory);
        }
        CHECK(hashes[0] == hashes[1], "mode %u: bvh %08x != bvh4 %08x", modes[m], hashes[0], hashes[1]);
        printf("mode %u: grid hash %08x (bvh and bvh4)\n", modes[m], hashes[0]);
    }
    /* Typed errors. */
    size_t bytes = rk_build_bytes(RK_MODE_F32, RK_KIND_BVH, TRIS);
    void *memory = malloc(bytes);
    RkAccel accel;
    CHECK(rk_build_bytes(7, RK_KIND_BVH, TRIS) == 0 && rk_build_bytes(RK_MODE_F32, 9, 1) == 0, "sizes");
    CHECK(rk_build(RK_MODE_F32, RK_KIND_BVH, 0, v, TRIS, memory, bytes - 128, &accel) ==
              RK_STATUS_ERR_MEMORY_TOO_SMALL, "memory too small");
    CHECK(rk_build(3, RK_KIND_BVH, 0, v, TRIS, memory, bytes, &accel) == RK_STATUS_ERR_BAD_ARGUMENT, "mode");
    CHECK(rk_build(RK_MODE_F32, RK_KIND_BVH, 65, v, TRIS, memory, bytes, &accel) ==
              RK_STATUS_ERR_BAD_ARGUMENT, "leaf size");
    CHECK(rk_build(RK_MODE_F32, RK_KIND_BVH, 0, NULL, TRIS, memory, bytes, &accel) == RK_STATUS_ERR_NULL, "null");
    static float bad[9 * TRIS];
    memcpy(bad, v, sizeof bad);
    bad[9 * 5 + 4] = 1.0f / 0.0f;
    CHECK(rk_build(RK_MODE_F32, RK_KIND_BVH, 0, bad, TRIS, memory, bytes, &accel) ==
              RK_STATUS_ERR_BAD_TRIANGLE, "infinite vertex");
    bad[9 * 5 + 4] = 9000.0f;
    CHECK(rk_build(RK_MODE_FIXED, RK_KIND_BVH, 0, bad, TRIS, memory, rk_build_bytes(RK_MODE_FIXED, RK_KIND_BVH, TRIS),
                   &accel) == RK_STATUS_ERR_BAD_TRIANGLE || bytes < rk_build_bytes(RK_MODE_FIXED, RK_KIND_BVH, TRIS),
          "vertex beyond the fixed-point range");
    RkAccel zero;
    memset(&zero, 0, sizeof zero);
    RkRay ray = {{0.0f, 0.0f, -10.0f}, {0.0f, 0.0f, 1.0f}, 0.0f, 1.0f / 0.0f};
    RkHit hit;
    CHECK(rk_intersect(&zero, &ray, &hit) == RK_STATUS_ERR_NOT_INITIALISED, "uninitialised");
    CHECK(rk_intersect(NULL, &ray, &hit) == RK_STATUS_ERR_NULL, "null accel");
    free(memory);
    return 0;
}

/* Initialises a renderer for `scene` into fresh memory (kept in *memory). */
static RkStatus render_init(const RkScene *scene, void **memory, RkRenderer *out, RkSceneError *error) {
    size_t bytes = rk_render_bytes(scene);
    *memory = malloc(bytes > 0 ? bytes : 1);
    return rk_renderer_init(scene, *memory, bytes, out, error);
}

static int test_render(void) {
    static uint8_t tile[3 * 64], image[3 * RK_TEST_WIDTH * RK_TEST_HEIGHT];
    const uint32_t modes[2] = {RK_MODE_F32, RK_MODE_FIXED};
    const uint32_t image_hash[2] = {RK_TEST_IMAGE_HASH_F32, RK_TEST_IMAGE_HASH_FIXED};
    const uint32_t tile_hash[2] = {RK_TEST_TILE_HASH_F32, RK_TEST_TILE_HASH_FIXED};
    for (int m = 0; m < 2; m++) {
        for (uint32_t kind = 0; kind <= RK_KIND_BVH4; kind++) {
            RkScene scene = rk_test_scene(modes[m], kind);
            void *memory;
            RkRenderer r;
            RkSceneError e;
            RkStatus s = render_init(&scene, &memory, &r, &e);
            CHECK(s == RK_STATUS_OK, "render init mode %u kind %u: %s (item %u index %u field %s)", modes[m],
                  kind, rk_status_name(s), e.item, e.index, e.field);
            /* The whole image in 5 x 3 tiles, and the check tile in one call. */
            uint32_t h = rk_test_render_hash(&r, 0, 0, RK_TEST_WIDTH, RK_TEST_HEIGHT, 5, 3, tile, image, &s);
            CHECK(s == RK_STATUS_OK, "render: %s", rk_status_name(s));
            CHECK(h == image_hash[m], "mode %u kind %u: image hash %08x, the kernel's %08x", modes[m], kind, h,
                  image_hash[m]);
            h = rk_test_render_hash(&r, RK_TEST_TILE_X, RK_TEST_TILE_Y, RK_TEST_TILE_W, RK_TEST_TILE_H,
                                    RK_TEST_TILE_W, RK_TEST_TILE_H, tile, image, &s);
            CHECK(s == RK_STATUS_OK && h == tile_hash[m], "mode %u kind %u: tile hash %08x, the kernel's %08x",
                  modes[m], kind, h, tile_hash[m]);
            CHECK(rk_render_tile(&r, RK_TEST_WIDTH - 1, 0, 2, 1, tile, sizeof tile) == RK_STATUS_ERR_BAD_TILE,
                  "tile outside the image");
            CHECK(rk_render_tile(&r, 0, 0, 8, 8, tile, sizeof tile - 1) == RK_STATUS_ERR_BUFFER_TOO_SMALL,
                  "buffer too small");
            free(memory);
        }
        RkScene scene = rk_test_scene(modes[m], 0);
        printf("mode %u: render hash %08x, tile %08x (bvh and bvh4); renderer memory %zu bytes\n", modes[m],
               image_hash[m], tile_hash[m], rk_render_bytes(&scene));
    }
    /* Typed scene errors name the value at fault. */
    RkScene scene = rk_test_scene(RK_MODE_F32, 0);
    RkObject objects[5];
    memcpy(objects, rk_test_objects, sizeof objects);
    objects[3].material = 9;
    scene.objects = objects;
    void *memory;
    RkRenderer r;
    RkSceneError e;
    RkStatus s = render_init(&scene, &memory, &r, &e);
    CHECK(s == RK_STATUS_ERR_BAD_INDEX && e.item == RK_ITEM_OBJECT && e.index == 3 && strcmp(e.field, "material") == 0,
          "bad material index: %s, item %u index %u field %s", rk_status_name(s), e.item, e.index, e.field);
    CHECK(rk_render_tile(&r, 0, 0, 1, 1, tile, 3) == RK_STATUS_ERR_NOT_INITIALISED, "renderer after a failed init");
    free(memory);
    scene = rk_test_scene(RK_MODE_F32, 0);
    scene.camera.vfov_deg = 180.0f;
    s = render_init(&scene, &memory, &r, &e);
    CHECK(s == RK_STATUS_ERR_OUT_OF_RANGE && e.item == RK_ITEM_CAMERA && strcmp(e.field, "vfov_deg") == 0,
          "field of view: %s, field %s", rk_status_name(s), e.field);
    free(memory);
    scene = rk_test_scene(RK_MODE_FIXED, 0);
    static float far[2 * 9];
    memcpy(far, rk_test_floor, sizeof far);
    far[9] = 9000.0f;
    memcpy(objects, rk_test_objects, sizeof objects);
    objects[0].data = far;
    scene.objects = objects;
    s = render_init(&scene, &memory, &r, &e);
    CHECK(s == RK_STATUS_ERR_BAD_TRIANGLE && e.item == RK_ITEM_OBJECT && e.index == 0,
          "vertex beyond the fixed-point range: %s", rk_status_name(s));
    free(memory);
    scene = rk_test_scene(RK_MODE_F32, 0);
    size_t bytes = rk_render_bytes(&scene);
    memory = malloc(bytes);
    CHECK(rk_renderer_init(&scene, memory, bytes / 2, &r, NULL) == RK_STATUS_ERR_MEMORY_TOO_SMALL, "small memory");
    CHECK(rk_renderer_init(NULL, memory, bytes, &r, NULL) == RK_STATUS_ERR_NULL, "null scene");
    CHECK(rk_render_bytes(NULL) == 0, "null scene: no size");
    free(memory);
    return 0;
}

enum { THREADS = 4 };

typedef struct {
    const RkRenderer *renderer;
    int first_row;
    uint8_t *image;
    RkStatus status;
} RowJob;

/* Renders every THREADS-th row, from `first_row`, straight into its place in the image. */
static int render_rows(void *arg) {
    RowJob *job = arg;
    job->status = RK_STATUS_OK;
    for (uint32_t y = (uint32_t)job->first_row; y < RK_TEST_HEIGHT; y += THREADS) {
        uint8_t *row = job->image + 3u * y * RK_TEST_WIDTH;
        RkStatus s = rk_render_tile(job->renderer, 0, y, RK_TEST_WIDTH, 1, row, 3u * RK_TEST_WIDTH);
        if (s != RK_STATUS_OK) {
            job->status = s;
        }
    }
    return 0;
}

/* One renderer, tiles rendered by several threads at once: the kernel's image. */
static int test_render_threads(void) {
    static uint8_t image[3 * RK_TEST_WIDTH * RK_TEST_HEIGHT];
    RkScene scene = rk_test_scene(RK_MODE_FIXED, RK_KIND_BVH4);
    void *memory;
    RkRenderer r;
    RkSceneError e;
    RkStatus s = render_init(&scene, &memory, &r, &e);
    CHECK(s == RK_STATUS_OK, "render init: %s", rk_status_name(s));
    thrd_t threads[THREADS];
    RowJob jobs[THREADS];
    for (int t = 0; t < THREADS; t++) {
        jobs[t] = (RowJob){&r, t, image, RK_STATUS_OK};
        CHECK(thrd_create(&threads[t], render_rows, &jobs[t]) == thrd_success, "thread %d", t);
    }
    for (int t = 0; t < THREADS; t++) {
        thrd_join(threads[t], NULL);
        CHECK(jobs[t].status == RK_STATUS_OK, "thread %d: %s", t, rk_status_name(jobs[t].status));
    }
    uint32_t h = 0x811c9dc5u;
    for (size_t i = 0; i < sizeof image; i++) {
        h = rk_fnv1a(h, image[i], 1);
    }
    CHECK(h == RK_TEST_IMAGE_HASH_FIXED, "%d threads: image hash %08x, the kernel's %08x", THREADS, h,
          RK_TEST_IMAGE_HASH_FIXED);
    printf("render on %d threads at once: the kernel's image\n", THREADS);
    free(memory);
    return 0;
}

static int test_baked(const char *path, const char *expect) {
    FILE *f = fopen(path, "rb");
    CHECK(f != NULL, "cannot open %s", path);
    fseek(f, 0, SEEK_END);
    long len = ftell(f);
    fseek(f, 0, SEEK_SET);
    size_t align = rk_baked_align();
    unsigned char *buf = aligned_alloc(align, ((size_t)len + 2 * align) / align * align);
    CHECK(buf != NULL && fread(buf, 1, (size_t)len, f) == (size_t)len, "read %s", path);
    fclose(f);
    RkAccel accel;
    RkStatus s = rk_load_baked(buf, (size_t)len, &accel);
    CHECK(s == RK_STATUS_OK, "load %s: %s", path, rk_status_name(s));
    uint32_t h = rk_grid_hash(&accel, &s);
    CHECK(s == RK_STATUS_OK, "trace: %s", rk_status_name(s));
    printf("grid_hash %08x\n", h);
    if (expect != NULL) {
        unsigned long want = strtoul(expect, NULL, 16);
        CHECK(h == (uint32_t)want, "hash %08x, raykernel bake said %08lx", h, want);
    }
    static float v[9 * TRIS];
    CHECK(rk_refit(&accel, v, TRIS) == RK_STATUS_ERR_NOT_REFITTABLE, "refit of baked bytes");
    /* Misaligned, corrupted, truncated. */
    memmove(buf + 4, buf, (size_t)len);
    CHECK(rk_load_baked(buf + 4, (size_t)len, &accel) == RK_STATUS_ERR_MISALIGNED, "misaligned");
    memmove(buf, buf + 4, (size_t)len);
    buf[len - 1] ^= 0x40;
    CHECK(rk_load_baked(buf, (size_t)len, &accel) == RK_STATUS_ERR_BAD_FILE, "corrupted");
    buf[len - 1] ^= 0x40;
    CHECK(rk_load_baked(buf, (size_t)len - 1, &accel) == RK_STATUS_ERR_BAD_FILE, "truncated");
    CHECK(rk_load_baked(buf, (size_t)len, &accel) == RK_STATUS_OK, "reload");
    free(buf);
    return 0;
}

int main(int argc, char **argv) {
    if (test_names() || test_builds_and_errors() || test_render() || test_render_threads()) {
        return 1;
    }
    if (argc > 1 && test_baked(argv[1], argc > 2 ? argv[2] : NULL)) {
        return 1;
    }
    printf("capi_test: ok\n");
    return 0;
}
