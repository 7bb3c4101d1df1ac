/* The benchmark's binding to Embree 3: one device on one thread, a triangle scene built at a
 * chosen quality, and closest-hit / any-hit loops over 32-byte ray records, one rtcIntersect1
 * or rtcOccluded1 call per record with the record's origin, direction, tnear and tfar as given.
 *
 * Memory: the device's memory monitor sums every allocation Embree reports (net of frees);
 * the vertex and index buffers are the caller's (shared), so what a scene adds is Embree's
 * own structure.
 */
#include <embree3/rtcore.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

typedef struct {
    RTCDevice device;
    int64_t bytes; /* allocated now, net of frees */
    int64_t peak;  /* the largest `bytes` since the last reset */
} rkb_embree;

static bool rkb_monitor(void *user, ssize_t bytes, bool post) {
    rkb_embree *e = (rkb_embree *)user;
    (void)post;
    e->bytes += (int64_t)bytes;
    if (e->bytes > e->peak) {
        e->peak = e->bytes;
    }
    return true;
}

/* A device traced and built on one thread; NULL if Embree cannot make one. */
rkb_embree *rkb_embree_new(void) {
    rkb_embree *e = (rkb_embree *)calloc(1, sizeof(rkb_embree));
    if (e == NULL) {
        return NULL;
    }
    e->device = rtcNewDevice("threads=1,set_affinity=0");
    if (e->device == NULL) {
        free(e);
        return NULL;
    }
    rtcSetDeviceMemoryMonitorFunction(e->device, rkb_monitor, e);
    return e;
}

void rkb_embree_free(rkb_embree *e) {
    if (e != NULL) {
        rtcReleaseDevice(e->device);
        free(e);
    }
}

/* Bytes allocated now, and resets the peak to them. */
int64_t rkb_embree_bytes(rkb_embree *e) {
    e->peak = e->bytes;
    return e->bytes;
}

/* The largest allocation total since the last rkb_embree_bytes. */
int64_t rkb_embree_peak(const rkb_embree *e) { return e->peak; }

/* Builds a scene of `tri_count` triangles over `vertices` (x, y, z floats; the buffer must
 * hold one float more than the vertices, as Embree reads 16 bytes per vertex) and `indices`
 * (three per triangle), at `quality` (RTC_BUILD_QUALITY_*), in Embree's robust mode
 * (RTC_SCENE_FLAG_ROBUST) when `robust` is not zero. Both buffers must outlive the scene.
 * NULL if Embree reports an error. */
RTCScene rkb_embree_build(rkb_embree *e, const float *vertices, size_t vertex_count,
                          const uint32_t *indices, size_t tri_count, int quality, int robust) {
    RTCScene scene = rtcNewScene(e->device);
    if (robust) {
        rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    }
    rtcSetSceneBuildQuality(scene, (enum RTCBuildQuality)quality);
    RTCGeometry geom = rtcNewGeometry(e->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetGeometryBuildQuality(geom, (enum RTCBuildQuality)quality);
    rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, vertices, 0,
                               3 * sizeof(float), vertex_count);
    rtcSetSharedGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, indices, 0,
                               3 * sizeof(uint32_t), tri_count);
    rtcCommitGeometry(geom);
    rtcAttachGeometry(scene, geom);
    rtcReleaseGeometry(geom);
    rtcCommitScene(scene);
    if (rtcGetDeviceError(e->device) != RTC_ERROR_NONE) {
        rtcReleaseScene(scene);
        return NULL;
    }
    return scene;
}

void rkb_embree_scene_free(RTCScene scene) { rtcReleaseScene(scene); }

/* The intersection context for a ray set: Embree's default (incoherent), or its coherent
 * flag when `coherent` is not zero. */
static void rkb_context(struct RTCIntersectContext *context, int coherent) {
    rtcInitIntersectContext(context);
    if (coherent) {
        context->flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    }
}

/* Closest hit of each of `count` records (8 floats each: origin, direction, tmin, tmax):
 * t and primitive id per record (+inf and 0xFFFFFFFF on a miss). */
void rkb_embree_closest(RTCScene scene, const float *records, size_t count, int coherent,
                        float *t_out, uint32_t *prim_out) {
    struct RTCIntersectContext context;
    rkb_context(&context, coherent);
    for (size_t k = 0; k < count; k++) {
        const float *r = records + 8 * k;
        struct RTCRayHit rh;
        rh.ray.org_x = r[0];
        rh.ray.org_y = r[1];
        rh.ray.org_z = r[2];
        rh.ray.tnear = r[6];
        rh.ray.dir_x = r[3];
        rh.ray.dir_y = r[4];
        rh.ray.dir_z = r[5];
        rh.ray.time = 0.0f;
        rh.ray.tfar = r[7];
        rh.ray.mask = 0xFFFFFFFFu;
        rh.ray.id = 0;
        rh.ray.flags = 0;
        rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
        rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(scene, &context, &rh);
        if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
            t_out[k] = INFINITY;
            prim_out[k] = 0xFFFFFFFFu;
        } else {
            t_out[k] = rh.ray.tfar;
            prim_out[k] = rh.hit.primID;
        }
    }
}

/* Any hit of each of `count` records: how many are occluded. */
size_t rkb_embree_occluded(RTCScene scene, const float *records, size_t count, int coherent) {
    struct RTCIntersectContext context;
    rkb_context(&context, coherent);
    size_t occluded = 0;
    for (size_t i = 0; i < count; i++) {
        const float *r = records + 8 * i;
        struct RTCRay ray;
        ray.org_x = r[0];
        ray.org_y = r[1];
        ray.org_z = r[2];
        ray.tnear = r[6];
        ray.dir_x = r[3];
        ray.dir_y = r[4];
        ray.dir_z = r[5];
        ray.time = 0.0f;
        ray.tfar = r[7];
        ray.mask = 0xFFFFFFFFu;
        ray.id = 0;
        ray.flags = 0;
        rtcOccluded1(scene, &context, &ray);
        /* Embree marks an occluded ray by setting tfar to -inf. */
        occluded += ray.tfar < 0.0f ? 1 : 0;
    }
    return occluded;
}
