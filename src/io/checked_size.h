// Overflow-checked size arithmetic for every size, count and offset read from a file (they are
// hostile: a count near 2^64 must fail, not wrap), and the loading memory budget.
#pragma once

#include "animorder/load.h"

#include <cmath>
#include <cstddef>
#include <string>

namespace animorder::io {

// out = a · b / a + b; false (out unspecified) when the result does not fit in size_t.
inline bool checked_mul(size_t a, size_t b, size_t& out) { return !__builtin_mul_overflow(a, b, &out); }
inline bool checked_add(size_t a, size_t b, size_t& out) { return !__builtin_add_overflow(a, b, &out); }

// a · b · c, or throws LoadError("<what>: <a> x <b> x <c> overflows") — for sizes that must
// fit before anything is allocated or read.
inline size_t mul_or_throw(const std::string& what, size_t a, size_t b, size_t c = 1) {
    size_t ab = 0, abc = 0;
    if (!checked_mul(a, b, ab) || !checked_mul(ab, c, abc))
        throw LoadError(what + ": " + std::to_string(a) + " x " + std::to_string(b) + " x " + std::to_string(c) +
                        " does not fit in memory arithmetic");
    return abc;
}

// Throws LoadError, before any allocation, when keyframes × vertices × 12 bytes of positions
// exceed options.max_keyframe_bytes (or overflow); `what` names the count in the message (a
// file's own frames, checked before they are resampled, are not its keyframes).
inline void check_keyframe_budget(const std::string& path, size_t keyframes, size_t vertices,
                                  const LoadOptions& options, const char* what = "keyframes") {
    size_t kv = 0, bytes = 0;
    if (!checked_mul(keyframes, vertices, kv) || !checked_mul(kv, 12, bytes) || bytes > options.max_keyframe_bytes)
        throw LoadError(path + ": the animation needs " + std::to_string(keyframes) + " " + what + " x " +
                        std::to_string(vertices) + " vertices x 12 bytes, more than the loading budget of " +
                        std::to_string(options.max_keyframe_bytes) + " bytes (raise it with --max-memory)");
}

// The most keyframes one clip may have (about 55 minutes at 30 per second).
constexpr size_t kMaxClipKeyframes = 100000;

// Keyframes of a clip of duration_s sampled at sample_rate, both ends included
// (round(duration · rate) + 1), or throws LoadError("<path>: clip '<name>' is absurdly long")
// past kMaxClipKeyframes; a NaN, infinite or negative duration is an error too (never converted).
inline size_t clip_keyframes(const std::string& path, const std::string& name, double duration_s, double sample_rate) {
    const double intervals = duration_s * sample_rate;
    if (!(intervals >= 0)) throw LoadError(path + ": clip '" + name + "' has an invalid duration");
    if (intervals > double(kMaxClipKeyframes)) throw LoadError(path + ": clip '" + name + "' is absurdly long");
    const size_t count = size_t(std::llround(intervals)) + 1;
    if (count > kMaxClipKeyframes) throw LoadError(path + ": clip '" + name + "' is absurdly long");
    return count;
}

}  // namespace animorder::io
