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
 * -1 bad magic or version, -2 truncated, -3 a clip's table or centres out of bounds. */
int animorder_runtime_open(animorder_runtime* rt, const void* data, size_t size);

/* The buffer id for a clip at a keyframe (clip-local, rounded and clamped) seen from `camera`
 * (model space). `centre` is the frame's bounding-sphere centre in model space; NULL uses the one
 * stored for the keyframe. Returns -1 for a bad clip or a camera at the centre. */
int animorder_select_keyframe(const animorder_runtime* rt, uint32_t clip, double keyframe, const float camera[3],
                              const float centre[3]);

/* The same with a time in seconds from the clip's first keyframe (sampled at its sample rate). */
int animorder_select_time(const animorder_runtime* rt, uint32_t clip, double seconds, const float camera[3],
                          const float centre[3]);

/* Pointer to buffer `buffer`'s index_count indices (unaligned-safe only on little-endian hosts
 * where the sidecar was loaded 4-byte aligned), or NULL when out of range. */
const uint32_t* animorder_buffer(const animorder_runtime* rt, int buffer);

#ifdef __cplusplus
}
#endif

#endif /* ANIMORDER_RUNTIME_H */

#ifdef ANIMORDER_RUNTIME_IMPLEMENTATION
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

int animorder_runtime_open(animorder_runtime* rt, const void* data, size_t size) {
    const unsigned char* p = (const unsigned char*)data;
    uint32_t c;
    uint64_t buffers_end;
    if (size < ANIMORDER__HEADER) return -2;
    if (memcmp(p, "AOR1", 4) != 0 || animorder__u32(p + 4) != 1) return -1;
    rt->data = p;
    rt->size = size;
    rt->buffer_count = animorder__u32(p + 8);
    rt->index_count = animorder__u32(p + 12);
    rt->clip_count = animorder__u32(p + 16);
    buffers_end = ANIMORDER__HEADER + (uint64_t)rt->clip_count * ANIMORDER__CLIP +
                  (uint64_t)rt->buffer_count * rt->index_count * 4u;
    if (buffers_end > size) return -2;
    for (c = 0; c < rt->clip_count; ++c) {
        const unsigned char* q = p + ANIMORDER__HEADER + (size_t)c * ANIMORDER__CLIP;
        uint64_t keyframes = animorder__u32(q), theta = animorder__u32(q + 4), phi = animorder__u32(q + 8);
        uint64_t cells = animorder__u32(q + 20), centres = animorder__u32(q + 24);
        if (keyframes == 0 || theta < 2 || phi == 0) return -3;
        if (cells < buffers_end || cells + keyframes * theta * phi > size) return -3;
        if (centres < buffers_end || centres + keyframes * 12u > size) return -3;
        if (animorder__u32(q + 16) > rt->buffer_count) return -3;
    }
    return 0;
}

int animorder_select_keyframe(const animorder_runtime* rt, uint32_t clip, double keyframe, const float camera[3],
                              const float centre[3]) {
    const unsigned char* q;
    uint32_t keyframes, theta_steps, phi_steps, f, i, j;
    double d[3], length, theta, phi, k;
    float stored[3];
    if (clip >= rt->clip_count) return -1;
    q = rt->data + ANIMORDER__HEADER + (size_t)clip * ANIMORDER__CLIP;
    keyframes = animorder__u32(q);
    theta_steps = animorder__u32(q + 4);
    phi_steps = animorder__u32(q + 8);
    k = keyframe != keyframe ? 0.0 : floor(keyframe + 0.5); /* NaN → first keyframe */
    f = k <= 0 ? 0u : (k >= (double)(keyframes - 1) ? keyframes - 1 : (uint32_t)k);
    if (centre == NULL) {
        const unsigned char* c = rt->data + animorder__u32(q + 24) + (size_t)f * 12u;
        stored[0] = animorder__f32(c);
        stored[1] = animorder__f32(c + 4);
        stored[2] = animorder__f32(c + 8);
        centre = stored;
    }
    d[0] = (double)camera[0] - centre[0];
    d[1] = (double)camera[1] - centre[1];
    d[2] = (double)camera[2] - centre[2];
    length = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (!(length > 0)) return -1;
    theta = acos(fmax(-1.0, fmin(1.0, d[1] / length)));
    phi = atan2(d[0], d[2]);
    if (phi < 0) phi += 2.0 * 3.14159265358979323846;
    i = (uint32_t)floor(theta / 3.14159265358979323846 * (double)(theta_steps - 1) + 0.5);
    j = (uint32_t)floor(phi / (2.0 * 3.14159265358979323846) * (double)phi_steps + 0.5) % phi_steps;
    return (int)(animorder__u32(q + 16) +
                 rt->data[animorder__u32(q + 20) + ((size_t)f * theta_steps + i) * phi_steps + j]);
}

int animorder_select_time(const animorder_runtime* rt, uint32_t clip, double seconds, const float camera[3],
                          const float centre[3]) {
    if (clip >= rt->clip_count) return -1;
    return animorder_select_keyframe(rt, clip,
                                     seconds * animorder__f32(rt->data + ANIMORDER__HEADER + (size_t)clip * ANIMORDER__CLIP + 12),
                                     camera, centre);
}

const uint32_t* animorder_buffer(const animorder_runtime* rt, int buffer) {
    if (buffer < 0 || (uint32_t)buffer >= rt->buffer_count) return NULL;
    return (const uint32_t*)(const void*)(rt->data + ANIMORDER__HEADER + (size_t)rt->clip_count * ANIMORDER__CLIP +
                                          (size_t)buffer * rt->index_count * 4u);
}

#endif /* ANIMORDER_RUNTIME_IMPLEMENTATION */
