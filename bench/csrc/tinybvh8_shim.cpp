// tinybvh's 8-wide CPU BVH (BVH8_CPU: AVX2, leaves of four triangles) for the benchmark's
// rounds: built once, traced over rays built beforehand, one call per pass.
//
// The implementation is compiled here from the header the tinybvh-rs crate ships (its path
// comes from build.rs), in a namespace of its own, so that it links beside the copy tinybvh-rs
// compiles for the BVH2 peer. Same compiler flags as tinybvh-rs: C++20, -march=native.
#define tinybvh rkb_tinybvh
#define TINYBVH_IMPLEMENTATION
#include "tiny_bvh.h"
#undef tinybvh

#include <cstddef>
#include <cstdint>
#include <vector>

namespace {
struct Tiny8 {
    std::vector<rkb_tinybvh::bvhvec4> verts;
    rkb_tinybvh::BVH8_CPU bvh;
    std::vector<rkb_tinybvh::Ray> rays;
};
}  // namespace

extern "C" {

// Builds over `tris` triangles given as 9 floats each (three vertices), with `BuildHQ`
// (spatial splits) when `hq` is nonzero, else `Build`. Null where tinybvh's 8-wide query is
// not compiled (it needs AVX2 and FMA; elsewhere tinybvh stops the process when it is called).
void* rkb_tiny8_new(const float* tris, uint32_t count, int hq) {
#if !defined BVH_USEAVX2 || defined BVH_USENEON
    (void)tris, (void)count, (void)hq;
    return nullptr;
#endif
    auto* t = new Tiny8();
    t->verts.resize(static_cast<size_t>(count) * 3);
    for (size_t i = 0; i < t->verts.size(); i++) {
        t->verts[i] = rkb_tinybvh::bvhvec4(tris[3 * i], tris[3 * i + 1], tris[3 * i + 2], 0.0f);
    }
    if (hq) {
        t->bvh.BuildHQ(t->verts.data(), count);
    } else {
        t->bvh.Build(t->verts.data(), count);
    }
    return t;
}

// Rays as tinybvh's constructor makes them (direction normalised, reciprocals); `t_max` is
// the distance a hit must be below.
void rkb_tiny8_set_rays(void* p, const float* origin, const float* dir, const float* t_max,
                        uint32_t n) {
    auto* t = static_cast<Tiny8*>(p);
    t->rays.clear();
    t->rays.reserve(n);
    for (uint32_t i = 0; i < n; i++) {
        rkb_tinybvh::bvhvec3 o(origin[3 * i], origin[3 * i + 1], origin[3 * i + 2]);
        rkb_tinybvh::bvhvec3 d(dir[3 * i], dir[3 * i + 1], dir[3 * i + 2]);
        t->rays.emplace_back(o, d, t_max[i]);
    }
}

// One closest-hit pass over the rays; writes each ray's hit distance and triangle (the
// distance unchanged and the id `UINT32_MAX` on a miss).
void rkb_tiny8_trace(void* p, float* t_out, uint32_t* prim_out) {
    auto* t = static_cast<Tiny8*>(p);
    for (size_t i = 0; i < t->rays.size(); i++) {
        rkb_tinybvh::Ray r = t->rays[i];
        t->bvh.Intersect(r);
        const bool hit = r.hit.t < t->rays[i].hit.t;
        t_out[i] = r.hit.t;
        prim_out[i] = hit ? r.hit.prim : UINT32_MAX;
    }
}

void rkb_tiny8_free(void* p) { delete static_cast<Tiny8*>(p); }
}
