/* runtime_answers SIDECAR QUERIES ANSWERS — the C runtime's answers (include/animorder_runtime.h) for
 * a list of queries, for the JavaScript runtime's equivalence test (js/test/equivalence.mjs).
 *
 * QUERIES: records of 40 bytes, little-endian: u32 clip, u32 flags (bit 0: value is a keyframe,
 * animorder_select_keyframe; else seconds, animorder_select_time; bit 1: use the centre given),
 * f64 value, f32 camera[3], f32 centre[3]. ANSWERS: one i32 per query, the buffer id or -1.
 * Exit 1 with a one-line message when a file cannot be read or the sidecar does not open. */
#define ANIMORDER_RUNTIME_IMPLEMENTATION
#include "animorder_runtime.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static unsigned char* read_all(const char* path, size_t* size) {
    FILE* f = fopen(path, "rb");
    unsigned char* data = NULL;
    size_t capacity = 0, used = 0, got;
    if (!f) return NULL;
    do {
        if (used == capacity) {
            unsigned char* grown;
            capacity = capacity ? capacity * 2 : 1 << 16;
            grown = (unsigned char*)realloc(data, capacity);
            if (!grown) {
                free(data);
                fclose(f);
                return NULL;
            }
            data = grown;
        }
        got = fread(data + used, 1, capacity - used, f);
        used += got;
    } while (got > 0);
    fclose(f);
    *size = used;
    return data;
}

int main(int argc, char** argv) {
    size_t sidecar_size = 0, query_size = 0, q, count;
    unsigned char *sidecar, *queries;
    animorder_runtime rt;
    FILE* out;
    int error;
    if (argc != 4) {
        fprintf(stderr, "usage: runtime_answers SIDECAR QUERIES ANSWERS\n");
        return 1;
    }
    sidecar = read_all(argv[1], &sidecar_size);
    queries = read_all(argv[2], &query_size);
    if (!sidecar || !queries || query_size % 40 != 0) {
        fprintf(stderr, "runtime_answers: cannot read %s or %s (or not 40-byte records)\n", argv[1], argv[2]);
        return 1;
    }
    error = animorder_runtime_open(&rt, sidecar, sidecar_size);
    if (error != 0) {
        fprintf(stderr, "runtime_answers: %s does not open (%d)\n", argv[1], error);
        return 1;
    }
    out = fopen(argv[3], "wb");
    if (!out) {
        fprintf(stderr, "runtime_answers: cannot write %s\n", argv[3]);
        return 1;
    }
    count = query_size / 40;
    for (q = 0; q < count; ++q) {
        const unsigned char* r = queries + q * 40;
        uint32_t clip, flags;
        double value;
        float camera[3], centre[3];
        int32_t answer;
        unsigned char le[4];
        memcpy(&clip, r, 4); /* the records are little-endian, as this host (x86-64, arm64) */
        memcpy(&flags, r + 4, 4);
        memcpy(&value, r + 8, 8);
        memcpy(camera, r + 16, 12);
        memcpy(centre, r + 28, 12);
        answer = (flags & 1u) ? animorder_select_keyframe(&rt, clip, value, camera, (flags & 2u) ? centre : NULL)
                              : animorder_select_time(&rt, clip, value, camera, (flags & 2u) ? centre : NULL);
        le[0] = (unsigned char)((uint32_t)answer & 255u);
        le[1] = (unsigned char)(((uint32_t)answer >> 8) & 255u);
        le[2] = (unsigned char)(((uint32_t)answer >> 16) & 255u);
        le[3] = (unsigned char)(((uint32_t)answer >> 24) & 255u);
        fwrite(le, 1, 4, out);
    }
    free(sidecar);
    free(queries);
    return fclose(out) == 0 ? 0 : 1;
}
