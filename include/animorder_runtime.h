/* animorder_runtime.h — pick the index buffer to draw, at run time. Single header, C99/C++,
 * no dependencies, no allocation. Han & Sander 2017 §3.3: a lookup table per clip indexed by
 * keyframe and the view direction's polar and azimuth angles, rounded to the nearest cell.
 *
 * The sidecar file `NAME.animorder.bin` that `animorder optimize` writes holds, little-endian:
 *
 *   header   "AOR1", u32 version (1), u32 buffer_count, u32 index_count, u32 clip_count
 *   clips    clip_count × { u32 keyframes, u32 theta_steps, u32 phi_steps, f32 sample_rate,
 *                           u32 buffer_base, u32 cells_offset, u32 centres_offset, u32 reserved }
 *   buffers  buffer_count × index_count u32 indices (whole index buffer, primitives in order)
 *   per clip cells: keyframes × theta_steps × phi_steps u8 (buffer id within the clip's set)
 *            centres: keyframes × 3 f32 (the frame's bounding-box centre, model space)
 *
 * Cell (f, i, j) stands for θ = i·π/(theta_steps − 1) from +Y and φ = j·2π/phi_steps from +Z
 * towards +X. The buffer to draw is buffer_base + cell.
 *
 * In exactly one C or C++ file:  #define ANIMORDER_RUNTIME_IMPLEMENTATION
 *                                #include "animorder_runtime.h"
 *
 *   animorder_runtime rt;
 *   if (animorder_runtime_open(&rt, bytes, size) != 0) { ...corrupt or truncated... }
 *   int buffer = animorder_select_time(&rt, clip, seconds, camera_position, NULL);
 *   const uint32_t* indices = animorder_buffer(&rt, buffer);   // rt.index_count indices
 */
#ifndef ANIMORDER_RUNTIME_H
#define ANIMORDER_RUNTIME_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct animorder_runtime {
    const unsigned char* data;
    size_t size;
    uint32_t buffer_count;
    uint32_t index_count;
    uint32_t clip_count;
} animorder_runtime;

/* 0 on success; a negative code when the bytes are not a valid, complete sidecar:
 *   -1 bad magic or version,
 *   -2 truncated (header, clip records or index buffers past the end; NULL rt or data),
 *   -3 a clip's table or centres out of bounds, overlapping, or with impossible dimensions
 *      (keyframes 0, theta_steps < 2, phi_steps 0),
 *   -4 a value out of range: no buffer or more than INT_MAX buffers, an index count that is not
 *      whole triangles (a multiple of 3), a clip's buffer set or a cell naming a buffer >=
 *      buffer_count, a sample rate that is not a positive finite number.
 * Every size and offset is checked without overflow, whatever the header says. On failure `rt` is
 * zeroed (no clips, no buffers), so the queries below answer -1 / NULL for it. The bytes are not
 * copied: they must outlive `rt`. */
int animorder_runtime_open(animorder_runtime* rt, const void* data, size_t size);

/* The buffer id for a clip at a keyframe (clip-local, rounded to the nearest and clamped to the
 * clip's keyframes; NaN gives the first) seen from `camera` (model space). `centre` is the frame's
 * bounding-sphere centre in model space; NULL uses the one stored for the keyframe. Returns -1 for
 * a NULL or unopened runtime, a bad clip, a NULL camera, a camera at the centre, or a camera or
 * centre that is not finite; otherwise an id in [0, buffer_count). */
int animorder_select_keyframe(const animorder_runtime* rt, uint32_t clip, double keyframe, const float camera[3],
                              const float centre[3]);

/* The same with a time in seconds from the clip's first keyframe (sampled at its sample rate;
 * times before the clip or NaN give the first keyframe, times after it the last). */
int animorder_select_time(const animorder_runtime* rt, uint32_t clip, double seconds, const float camera[3],
                          const float centre[3]);

/* Pointer to buffer `buffer`'s index_count indices, or NULL when out of range, for a NULL or
 * unopened runtime, or when the bytes were not loaded 4-byte aligned (the pointer would be
 * misaligned). The values are little-endian: read them through this pointer only on
 * little-endian hosts. */
const uint32_t* animorder_buffer(const animorder_runtime* rt, int buffer);

#ifdef __cplusplus
}
#endif

#endif /* ANIMORDER_RUNTIME_H */

#ifdef ANIMORDER_RUNTIME_IMPLEMENTATION
#include <float.h>
#include <limits.h>
#include <math.h>
#include <string.h>

static uint32_t animorder__u32(const unsigned char* p) {
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}
static float animorder__f32(const unsigned char* p) {
    uint32_t u = animorder__u32(p);
    float f;
    memcpy(&f, &u, 4);
    return f;
}

#define ANIMORDER__HEADER 20u
#define ANIMORDER__CLIP 32u
#define ANIMORDER__PI 3.14159265358979323846

/* Overflow-checked 64-bit arithmetic: 0 (and *out untouched) when the result does not fit. */
static int animorder__mul(uint64_t a, uint64_t b, uint64_t* out) {
    if (a != 0 && b > UINT64_MAX / a) return 0;
    *out = a * b;
    return 1;
}
static int animorder__add(uint64_t a, uint64_t b, uint64_t* out) {
    if (b > UINT64_MAX - a) return 0;
    *out = a + b;
    return 1;
}

/* One clip record, read and checked against the bytes. */
typedef struct animorder__clip_info {
    uint32_t keyframes, theta_steps, phi_steps, buffer_base;
    float sample_rate;
    uint64_t cells, cell_bytes, centres, centre_bytes;
} animorder__clip_info;

/* The end of the clip records and index buffers, or 0 when it does not fit in the bytes. */
static uint64_t animorder__buffers_end(uint64_t size, uint32_t clip_count, uint32_t buffer_count,
                                       uint32_t index_count) {
    uint64_t records, buffer_bytes, end;
    if (!animorder__mul(clip_count, ANIMORDER__CLIP, &records) || !animorder__add(ANIMORDER__HEADER, records, &end))
        return 0;
    if (!animorder__mul(buffer_count, index_count, &buffer_bytes) || !animorder__mul(buffer_bytes, 4u, &buffer_bytes) ||
        !animorder__add(end, buffer_bytes, &end))
        return 0;
    return end <= size ? end : 0;
}

/* 0 when clip `clip` is well formed and its table and centres lie in [buffers_end, size);
 * otherwise the open error code. */
static int animorder__read_clip(const unsigned char* p, uint64_t size, uint64_t buffers_end, uint32_t buffer_count,
                                uint32_t clip, animorder__clip_info* info) {
    const unsigned char* q = p + ANIMORDER__HEADER + (size_t)clip * ANIMORDER__CLIP;
    uint64_t end;
    info->keyframes = animorder__u32(q);
    info->theta_steps = animorder__u32(q + 4);
    info->phi_steps = animorder__u32(q + 8);
    info->sample_rate = animorder__f32(q + 12);
    info->buffer_base = animorder__u32(q + 16);
    info->cells = animorder__u32(q + 20);
    info->centres = animorder__u32(q + 24);
    if (info->keyframes == 0 || info->theta_steps < 2 || info->phi_steps == 0) return -3;
    if (!animorder__mul(info->keyframes, info->theta_steps, &info->cell_bytes) ||
        !animorder__mul(info->cell_bytes, info->phi_steps, &info->cell_bytes))
        return -3;
    info->centre_bytes = (uint64_t)info->keyframes * 12u; /* < 2^36: no overflow */
    if (info->cells < buffers_end || !animorder__add(info->cells, info->cell_bytes, &end) || end > size) return -3;
    if (info->centres < buffers_end || !animorder__add(info->centres, info->centre_bytes, &end) || end > size)
        return -3;
    if (info->buffer_base >= buffer_count) return -4;
    if (!(info->sample_rate > 0 && info->sample_rate <= FLT_MAX)) return -4;
    return 0;
}

int animorder_runtime_open(animorder_runtime* rt, const void* data, size_t size) {
    const unsigned char* p = (const unsigned char*)data;
    uint32_t c, buffer_count, index_count, clip_count;
    uint64_t buffers_end, tables = 0;
    int error;
    if (rt == NULL) return -2;
    memset(rt, 0, sizeof *rt);
    if (p == NULL || size < ANIMORDER__HEADER) return -2;
    if (memcmp(p, "AOR1", 4) != 0 || animorder__u32(p + 4) != 1) return -1;
    buffer_count = animorder__u32(p + 8);
    index_count = animorder__u32(p + 12);
    clip_count = animorder__u32(p + 16);
    buffers_end = animorder__buffers_end((uint64_t)size, clip_count, buffer_count, index_count);
    if (buffers_end == 0) return -2;
    /* No buffer would leave the fallback (buffer 0) unbound; a partial triangle, a draw call's
     * count that is not whole triangles. */
    if (buffer_count == 0 || buffer_count > (uint32_t)INT_MAX || index_count % 3 != 0) return -4;
    for (c = 0; c < clip_count; ++c) {
        animorder__clip_info info;
        uint64_t k;
        error = animorder__read_clip(p, size, buffers_end, buffer_count, c, &info);
        if (error != 0) return error;
        /* The tables follow the buffers one after the other: together they fit in what is left.
         * (This also bounds the cell scan below by the size of the bytes.) */
        if (!animorder__add(tables, info.cell_bytes, &tables) || !animorder__add(tables, info.centre_bytes, &tables) ||
            tables > (uint64_t)size - buffers_end)
            return -3;
        for (k = 0; k < info.cell_bytes; ++k)
            if ((uint64_t)info.buffer_base + p[info.cells + k] >= buffer_count) return -4;
    }
    rt->data = p;
    rt->size = size;
    rt->buffer_count = buffer_count;
    rt->index_count = index_count;
    rt->clip_count = clip_count;
    return 0;
}

/* The clip's record, checked again against the runtime's bytes (a runtime is plain data that an
 * application may have copied or changed): 0 when usable. */
static int animorder__clip(const animorder_runtime* rt, uint32_t clip, animorder__clip_info* info) {
    uint64_t buffers_end;
    if (rt == NULL || rt->data == NULL || clip >= rt->clip_count || rt->buffer_count > (uint32_t)INT_MAX) return -1;
    buffers_end = animorder__buffers_end((uint64_t)rt->size, rt->clip_count, rt->buffer_count, rt->index_count);
    if (buffers_end == 0) return -1;
    return animorder__read_clip(rt->data, rt->size, buffers_end, rt->buffer_count, clip, info) == 0 ? 0 : -1;
}

static int animorder__select(const animorder_runtime* rt, const animorder__clip_info* info, double keyframe,
                             const float camera[3], const float centre[3]) {
    uint32_t f, i, j;
    uint64_t cell;
    double d[3], length, theta, phi, k, x;
    float stored[3];
    if (camera == NULL) return -1;
    k = keyframe != keyframe ? 0.0 : floor(keyframe + 0.5); /* NaN → first keyframe */
    f = k <= 0 ? 0u : (k >= (double)(info->keyframes - 1) ? info->keyframes - 1 : (uint32_t)k);
    if (centre == NULL) {
        const unsigned char* c = rt->data + (size_t)(info->centres + (uint64_t)f * 12u);
        stored[0] = animorder__f32(c);
        stored[1] = animorder__f32(c + 4);
        stored[2] = animorder__f32(c + 8);
        centre = stored;
    }
    d[0] = (double)camera[0] - centre[0];
    d[1] = (double)camera[1] - centre[1];
    d[2] = (double)camera[2] - centre[2];
    length = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(length > 0 && length <= DBL_MAX)) return -1; /* at the centre, NaN or infinite */
    theta = acos(fmax(-1.0, fmin(1.0, d[1] / length)));
    phi = atan2(d[0], d[2]);
    if (phi < 0) phi += 2.0 * ANIMORDER__PI;
    x = floor(theta / ANIMORDER__PI * (double)(info->theta_steps - 1) + 0.5);
    i = x <= 0 ? 0u : (x >= (double)(info->theta_steps - 1) ? info->theta_steps - 1 : (uint32_t)x);
    x = floor(phi / (2.0 * ANIMORDER__PI) * (double)info->phi_steps + 0.5);
    j = x <= 0 || x >= (double)info->phi_steps ? 0u : (uint32_t)x; /* φ = 2π is φ = 0 */
    cell = info->cells + ((uint64_t)f * info->theta_steps + i) * info->phi_steps + j;
    x = (double)info->buffer_base + rt->data[(size_t)cell];
    return x < (double)rt->buffer_count ? (int)x : -1;
}

int animorder_select_keyframe(const animorder_runtime* rt, uint32_t clip, double keyframe, const float camera[3],
                              const float centre[3]) {
    animorder__clip_info info;
    if (animorder__clip(rt, clip, &info) != 0) return -1;
    return animorder__select(rt, &info, keyframe, camera, centre);
}

int animorder_select_time(const animorder_runtime* rt, uint32_t clip, double seconds, const float camera[3],
                          const float centre[3]) {
    animorder__clip_info info;
    if (animorder__clip(rt, clip, &info) != 0) return -1;
    return animorder__select(rt, &info, seconds * info.sample_rate, camera, centre);
}

const uint32_t* animorder_buffer(const animorder_runtime* rt, int buffer) {
    uint64_t buffers_end, offset;
    const unsigned char* p;
    if (rt == NULL || rt->data == NULL || buffer < 0 || (uint32_t)buffer >= rt->buffer_count) return NULL;
    buffers_end = animorder__buffers_end((uint64_t)rt->size, rt->clip_count, rt->buffer_count, rt->index_count);
    if (buffers_end == 0) return NULL;
    /* buffer < buffer_count and the buffers fit in the bytes: no overflow from here. */
    offset = ANIMORDER__HEADER + (uint64_t)rt->clip_count * ANIMORDER__CLIP + (uint64_t)buffer * rt->index_count * 4u;
    p = rt->data + (size_t)offset;
    if (((uintptr_t)(const void*)p & 3u) != 0) return NULL;
    return (const uint32_t*)(const void*)p;
}

#endif /* ANIMORDER_RUNTIME_IMPLEMENTATION */
