// libFuzzer target: any bytes → animorder_runtime_open → every query with arguments derived from
// the bytes and the usual hostile values (out-of-range clips and buffers, NaN and infinite times
// and cameras, a camera at the centre). A select answer outside [-1, buffer_count) or a buffer
// that is not entirely inside the bytes aborts; ASan catches every read past them (the bytes are
// copied into an allocation of exactly their size).
#define ANIMORDER_RUNTIME_IMPLEMENTATION
#include "animorder_runtime.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>

namespace {

void check(bool ok, const char* what) {
    if (!ok) {
        std::fprintf(stderr, "fuzz_runtime: %s\n", what);
        std::abort();
    }
}

uint32_t word(const uint8_t* data, size_t size, size_t at) {
    uint32_t v = 0;
    for (size_t b = 0; b < 4; ++b) v |= uint32_t(at + b < size ? data[at + b] : 0) << (8 * b);
    return v;
}
float f32(uint32_t u) {
    float f;
    std::memcpy(&f, &u, 4);
    return f;
}

volatile uint32_t g_sink;

void exercise(const animorder_runtime& rt, const uint8_t* data, size_t size) {
    const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
    const float fnan = std::numeric_limits<float>::quiet_NaN(), finf = std::numeric_limits<float>::infinity();
    // Cameras: the axes and diagonals at distance 5, zero, NaN, infinite, and two from the bytes.
    float cameras[20][3] = {{5, 0, 0},
                            {-5, 0, 0},
                            {0, 5, 0},
                            {0, -5, 0},
                            {0, 0, 5},
                            {0, 0, -5},
                            {3, 3, 3},
                            {-3, 3, -3},
                            {0, 0, 0},
                            {fnan, 0, 0},
                            {0, finf, 0},
                            {-finf, finf, 1},
                            {1e38f, -1e38f, 1e38f},
                            {1e-38f, 0, 0},
                            {-0.001f, 0, 5},
                            {0, -0.f, -5}};
    for (int d = 0; d < 3; ++d) {
        cameras[16][d] = f32(word(data, size, size - (size >= 12 ? 12 : size) + 4 * size_t(d)));
        cameras[17][d] = size ? float(data[(7 * size_t(d) + 3) % size] % 16) - 8.f : 1.f;
        cameras[18][d] = f32(word(data, size, 20 + 4 * size_t(d)));
        cameras[19][d] = cameras[17][d] * 1e30f;
    }
    const float centre_zero[3] = {0, 0, 0}, centre_nan[3] = {0, fnan, 0};
    const float* centres[3] = {nullptr, centre_zero, centre_nan};
    const uint32_t clip_limit = rt.clip_count < 8 ? rt.clip_count : 8;
    const uint32_t clips[] = {0, 1, 2, 3, 4, 5, 6, 7, rt.clip_count, rt.clip_count + 1, rt.clip_count - 1, UINT32_MAX};
    for (uint32_t clip : clips) {
        if (clip < rt.clip_count && clip >= clip_limit && clip != rt.clip_count - 1) continue;
        const uint32_t keyframes = clip < rt.clip_count ? word(rt.data, rt.size, 20 + 32 * size_t(clip)) : 1;
        const double times[] = {0,
                                0.5,
                                -1,
                                double(keyframes) - 1,
                                double(keyframes),
                                1e300,
                                -1e300,
                                nan,
                                inf,
                                -inf,
                                double(word(data, size, 4)) / 7.0};
        for (const auto& camera : cameras)
            for (const float* centre : centres)
                for (double t : times) {
                    const int a = animorder_select_keyframe(&rt, clip, t, camera, centre);
                    const int b = animorder_select_time(&rt, clip, t, camera, centre);
                    check(a >= -1 && (a < 0 || uint32_t(a) < rt.buffer_count), "select_keyframe out of range");
                    check(b >= -1 && (b < 0 || uint32_t(b) < rt.buffer_count), "select_time out of range");
                    if (clip >= rt.clip_count) check(a == -1 && b == -1, "a clip that does not exist was selected");
                }
        check(animorder_select_keyframe(&rt, clip, 0, nullptr, nullptr) == -1, "NULL camera selected");
    }
    // Buffers: each one returned must lie inside the bytes; read it whole (bounded by the size).
    const int ids[] = {-1, 0, 1, 2, int(rt.buffer_count) - 1, int(rt.buffer_count), INT32_MAX, INT32_MIN};
    for (int id : ids) {
        const uint32_t* p = animorder_buffer(&rt, id);
        if (p == nullptr) continue;
        check(id >= 0 && uint32_t(id) < rt.buffer_count, "a buffer out of range was returned");
        const unsigned char* bytes = reinterpret_cast<const unsigned char*>(p);
        check(bytes >= rt.data && uint64_t(bytes - rt.data) + uint64_t(rt.index_count) * 4 <= rt.size,
              "a buffer past the end of the bytes");
        uint32_t sum = 0;
        for (uint32_t i = 0; i < rt.index_count; ++i) sum += p[i];
        g_sink = sum;
    }
    check(animorder_select_keyframe(nullptr, 0, 0, cameras[0], nullptr) == -1, "NULL runtime selected");
    check(animorder_buffer(nullptr, 0) == nullptr, "NULL runtime gave a buffer");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    // Exactly `size` bytes (malloc is 16-byte aligned), so ASan sees any read past them.
    unsigned char* copy = static_cast<unsigned char*>(std::malloc(size ? size : 1));
    if (size) std::memcpy(copy, data, size);
    animorder_runtime rt;
    const int code = animorder_runtime_open(&rt, copy, size);
    check(code == 0 || code == -1 || code == -2 || code == -3 || code == -4, "open returned an undocumented code");
    if (code != 0)
        check(rt.data == nullptr && rt.clip_count == 0 && rt.buffer_count == 0, "a failed open left a runtime");
    exercise(rt, data, size);  // an opened runtime, or the zeroed one a failed open leaves
    if (code == 0) {
        // The same runtime with its fields changed by the application: still no read past the bytes.
        animorder_runtime changed = rt;
        changed.clip_count ^= word(data, size, 8);
        changed.buffer_count ^= word(data, size, 12) >> 8;
        changed.index_count ^= word(data, size, 16) >> 16;
        changed.size = size - (size ? data[0] % (size < 64 ? size : 64) : 0);
        exercise(changed, data, size);
    }
    std::free(copy);

    // One byte off 4-byte alignment: open and select still work, buffers are refused.
    unsigned char* shifted = static_cast<unsigned char*>(std::malloc(size + 1));
    if (size) std::memcpy(shifted + 1, data, size);
    animorder_runtime rt2;
    check(animorder_runtime_open(&rt2, shifted + 1, size) == code, "open depends on alignment");
    if (code == 0) {
        check(animorder_buffer(&rt2, 0) == nullptr, "a misaligned buffer pointer was returned");
        exercise(rt2, data, size);
    }
    std::free(shifted);
    return 0;
}
