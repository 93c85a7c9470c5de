// Scoring from one rasterisation (the method at the top of rasterizer.cpp): a node's kept
// fragments, grouped by pixel and nearest first, replayed under any number of triangle orders at
// once (the hot loop of k-means), with its portable and AVX2 copies; the fragments exported for
// keeping (kept_fragments.h) and scored again from there.
#include "animorder/rasterizer.h"

#include "animorder/invalid_input.h"
#include "animorder/kept_fragments.h"

#include "fragment_encoding.h"
#include "raster_state.h"

#include <algorithm>
#include <cstring>
#include <vector>

namespace animorder {

namespace {

// The hot loop of k-means: all multi-fragment pixels of a node for K orders at once. Pixels
// without equal depths (nearly all) take a branch-free path the compiler vectorises across the K
// orders: a fragment passes under order o iff its rank is below the running minimum.
template <size_t K>
void replay_all(uint64_t* passed, const uint32_t* starts, size_t pixels, const uint32_t* fragments,
                const uint32_t* ranks) {
    uint64_t count[K] = {};
    uint32_t scratch[2 * K] = {};
    for (size_t m = 0; m < pixels; ++m) {
        const uint32_t* f = fragments + starts[m];
        const uint32_t n = starts[m + 1] - starts[m];
        uint32_t ties = 0;
        for (uint32_t j = 0; j < n; ++j) ties |= f[j];
        if (ties & kTieBit) {
            replay_list(f, n, kTieBit, ranks, K, scratch, scratch + K, [&](size_t o) { ++count[o]; });
            continue;
        }
        uint32_t passes[K] = {};
        replay_untied_list(f, n, ranks, passes);
        for (size_t o = 0; o < K; ++o) count[o] += passes[o];
    }
    for (size_t o = 0; o < K; ++o) passed[o] += count[o];
}

#ifdef ANIMORDER_RASTER_AVX2
// replay_all in the wide copies: the K orders are K lanes of one 8-lane vector (a masked load reads a
// fragment's K ranks; ranks are below 2^31, so signed compares order them). A list of at most 4
// fragments without equal depths (nearly all) takes 4 steps without a branch, a shorter one
// repeating its last fragment (which can neither pass nor lower the minimum); longer untied lists
// go on one by one; lists with equal depths take replay_list. Integer counts: the same as replay_all.
// One fragment of an untied list: passes under the orders whose running minimum its rank beats.
__attribute__((target("avx2"))) ANIMORDER_ALWAYS_INLINE void replay_step_avx2(const uint32_t* rank_row, __m256i live,
                                                                              __m256i& running, __m256i& passes) {
    const __m256i r = _mm256_maskload_epi32(reinterpret_cast<const int*>(rank_row), live);
    passes = _mm256_sub_epi32(passes, _mm256_cmpgt_epi32(running, r));
    running = _mm256_min_epi32(running, r);
}

template <size_t K>
__attribute__((target("avx2"))) void replay_all_avx2(uint64_t* passed, const uint32_t* starts, size_t pixels,
                                                     const uint32_t* fragments, const uint32_t* ranks) {
    static_assert(K >= 1 && K <= 8, "one lane per order");
    const __m256i live = _mm256_cmpgt_epi32(_mm256_set1_epi32(int32_t(K)), _mm256_set_epi32(7, 6, 5, 4, 3, 2, 1, 0));
    __m256i total = _mm256_setzero_si256();  // per order, fragments passed (a node has fewer than 2^32)
    const __m256i first = _mm256_and_si256(live, _mm256_set1_epi32(1));  // a list's nearest fragment passes
    uint64_t tied[K] = {};
    uint32_t scratch[2 * K] = {};
    for (size_t m = 0; m < pixels; ++m) {
        const uint32_t* f = fragments + starts[m];
        const uint32_t n = starts[m + 1] - starts[m];
        const uint32_t f1 = f[1], f2 = f[n > 2 ? 2 : 1], f3 = f[n > 3 ? 3 : n - 1];
        uint32_t ties = f1 | f2 | f3;
        for (uint32_t j = 4; j < n; ++j) ties |= f[j];
        if (ties & kTieBit) {
            replay_list(f, n, kTieBit, ranks, K, scratch, scratch + K, [&](size_t o) { ++tied[o]; });
            continue;
        }
        __m256i running = _mm256_maskload_epi32(reinterpret_cast<const int*>(ranks + size_t(f[0]) * K), live);
        __m256i passes = first;
        replay_step_avx2(ranks + size_t(f1) * K, live, running, passes);
        replay_step_avx2(ranks + size_t(f2) * K, live, running, passes);
        replay_step_avx2(ranks + size_t(f3) * K, live, running, passes);
        for (uint32_t j = 4; j < n; ++j) replay_step_avx2(ranks + size_t(f[j]) * K, live, running, passes);
        total = _mm256_add_epi32(total, passes);
    }
    alignas(32) uint32_t lanes[8];
    _mm256_store_si256(reinterpret_cast<__m256i*>(lanes), total);
    for (size_t o = 0; o < K; ++o) passed[o] += lanes[o] + tied[o];
}
#endif

void replay_all_any(uint64_t* passed, const uint32_t* starts, size_t pixels, const uint32_t* fragments,
                    const uint32_t* ranks, size_t order_count, bool simd) {
#ifdef ANIMORDER_RASTER_AVX2
    if (simd && NodeRasterizer::widest_copy() != NodeRasterizer::Copy::Portable) switch (order_count) {
            case 1: return replay_all_avx2<1>(passed, starts, pixels, fragments, ranks);
            case 2: return replay_all_avx2<2>(passed, starts, pixels, fragments, ranks);
            case 3: return replay_all_avx2<3>(passed, starts, pixels, fragments, ranks);
            case 4: return replay_all_avx2<4>(passed, starts, pixels, fragments, ranks);
            case 5: return replay_all_avx2<5>(passed, starts, pixels, fragments, ranks);
            case 6: return replay_all_avx2<6>(passed, starts, pixels, fragments, ranks);
            case 7: return replay_all_avx2<7>(passed, starts, pixels, fragments, ranks);
            case 8: return replay_all_avx2<8>(passed, starts, pixels, fragments, ranks);
            default: break;
        }
#else
    (void)simd;
#endif
    switch (order_count) {
        case 1: return replay_all<1>(passed, starts, pixels, fragments, ranks);
        case 2: return replay_all<2>(passed, starts, pixels, fragments, ranks);
        case 3: return replay_all<3>(passed, starts, pixels, fragments, ranks);
        case 4: return replay_all<4>(passed, starts, pixels, fragments, ranks);
        case 5: return replay_all<5>(passed, starts, pixels, fragments, ranks);
        case 6: return replay_all<6>(passed, starts, pixels, fragments, ranks);
        case 7: return replay_all<7>(passed, starts, pixels, fragments, ranks);
        case 8: return replay_all<8>(passed, starts, pixels, fragments, ranks);
        default: break;
    }
    std::vector<uint32_t> scratch(2 * order_count);
    for (size_t m = 0; m < pixels; ++m)
        replay_list(fragments + starts[m], starts[m + 1] - starts[m], kTieBit, ranks, order_count, scratch.data(),
                    scratch.data() + order_count, [&](size_t o) { ++passed[o]; });
}

}  // namespace

NodeFragments NodeRasterizer::export_fragments() const {
    const State& s = *state_;
    NodeFragments out;
    out.visible = s.visible;
    out.single = s.single;
    out.starts.assign(s.multi_start.begin(), s.multi_start.begin() + s.multi_count + 1);
    const uint32_t first = out.starts.empty() ? 0 : out.starts.front();
    for (uint32_t& start : out.starts) start -= first;
    out.fragments.assign(s.multi_fragment.begin() + first, s.multi_fragment.begin() + first + out.starts.back());
    return out;
}

NodeRasterizer::FragmentLists NodeRasterizer::fragment_lists() const {
    const State& s = *state_;
    return {s.visible, s.single, s.multi_start.data(), s.multi_count, s.multi_fragment.data()};
}

void score_fragments(uint64_t* passed, const NodeFragments& node, const uint32_t* ranks, size_t order_count) {
    for (size_t o = 0; o < order_count; ++o) passed[o] = node.single;  // a lone fragment always passes
    if (node.starts.size() > 1)
        replay_all_any(passed, node.starts.data(), node.starts.size() - 1, node.fragments.data(), ranks, order_count,
                       true);
}

void NodeRasterizer::score(uint64_t* passed, const uint32_t* ranks, size_t order_count) const {
    const State& s = *state_;
    for (size_t o = 0; o < order_count; ++o) passed[o] = s.single;  // a lone fragment always passes
    replay_all_any(passed, s.multi_start.data(), s.multi_count, s.multi_fragment.data(), ranks, order_count,
                   s.copy != Copy::Portable);
}

std::vector<uint32_t> NodeRasterizer::passed_per_pixel(const uint32_t* ranks, size_t order_count,
                                                       size_t order_index) const {
    const State& s = *state_;
    if (order_index >= order_count) throw InvalidInput("order index out of range");
    std::vector<uint32_t> image(size_t(s.resolution) * s.resolution, 0);
    for (size_t i = 0; i < s.single; ++i) image[s.single_pixels[i]] = 1;
    std::vector<uint32_t> scratch(2 * order_count);
    for (size_t m = 0; m < s.multi_count; ++m) {
        const uint32_t begin = s.multi_start[m];
        uint32_t& pixel = image[s.multi_pixel[m]];
        replay_list(s.multi_fragment.data() + begin, s.multi_start[m + 1] - begin, kTieBit, ranks, order_count,
                    scratch.data(), scratch.data() + order_count, [&](size_t o) { pixel += o == order_index; });
    }
    return image;
}

}  // namespace animorder
