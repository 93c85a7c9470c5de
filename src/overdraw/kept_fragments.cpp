// A node's fragments kept compactly between k-means iterations (issue 19: memory-lean scoring),
// giving exactly the counts of the per-triangle lists (rasterizer.cpp) for unit orders.
//
// Scoring follows Han & Sander, "Triangle Reordering for Efficient Rendering in Complex Scenes",
// JCGT 2017, §3: the fragments passing a LESS depth test at a node when the mesh is drawn in a
// given order; the orders k-means scores are its patch orders, each patch a contiguous block
// drawn in its Tipsify order. Three reductions, each exact for such orders:
//   1. A fragment with a nearer (or equally near) fragment of its own unit that the unit draws
//      first never passes, and every fragment it could stop is stopped by that one already:
//      dropped (the tie bits are rejoined so equal depths stay groups).
//   2. Between fragments of different units only the units' positions in the order matter: a
//      list whose units are all different becomes a list of unit ids (16 bits each).
//   3. Pixels with equal unit lists are kept once, with a weight.
// The unit lists are stored shortest first, so that scoring (k-means scores every node again at
// each step) walks runs of lists of one length with loops that know their trip counts.
// A pixel left with one fragment passes one under every order (it joins `single`). A unit left
// twice in a list (a farther fragment it draws before the nearer one: common on double-sided
// meshes) stays a unit list, its second entry flagged: that entry ranks just before the unit's
// first in every order. The rare list that still holds a unit three times keeps its triangles
// (their inner order decides).
#include "animorder/kept_fragments.h"
#include "always_inline.h"
#include "fragment_encoding.h"

#include "animorder/invalid_input.h"

#include <algorithm>
#include <cstring>
#include <numeric>
#include <string>
#include <tuple>
#include <type_traits>
#ifdef __SSE2__
#include <emmintrin.h>
#endif
#if (defined(__GNUC__) || defined(__clang__)) && (defined(__x86_64__) || defined(__i386__))
#include <immintrin.h>
#endif

namespace animorder {
namespace {

constexpr uint32_t kMaxWeight = UINT16_MAX;

// A list's first four entries side by side (zeros beyond its end): with its length, the whole of
// nearly every list, so most lookups compare one word. `e` must have four entries readable.
uint64_t key_of(const uint16_t* e, size_t n) {
    uint64_t key;
    std::memcpy(&key, e, sizeof key);
    return n >= 4 ? key : key & ((uint64_t(1) << (16 * n)) - 1);
}

uint64_t hash_list(uint64_t key, const uint16_t* e, size_t n) {
    uint64_t h = (key ^ (uint64_t(n) << 59)) * 0x9e3779b97f4a7c15ULL;
    for (size_t i = 4; i < n; ++i) {
        h ^= e[i];
        h *= 0xff51afd7ed558ccdULL;
    }
    return h ^ (h >> 29);
}

// Drops the fragments of reduction 1 from one pixel's list of n fragments into `out` (tie bits
// recomputed: an entry is tied when its depth equals the previous kept entry's) and returns how many
// are kept; `units` gets their unit list entries (unit | kUnitTieBit when tied, | kUnitRepeatBit
// for the unit's second entry). Sets `repeated` when a unit still appears three times. `out` and
// `units` need n entries: an entry is written at the kept count whether or not it stays (the next
// one overwrites a dropped one).
//
// A fragment is tested against every nearer one, dropped or not: a dropped one is dominated by a
// still nearer fragment of its unit drawn earlier still, which then dominates this one too. The
// repeat flag counts kept entries only. N > 0 is n known at compile time (nearly every
// multi-fragment pixel has 2 to 4): the loops are unrolled, no branch on the data, and the
// entries' units, positions and kept flags live in local arrays; N = 0 takes any n, with those in
// the scratch arrays (each at least n long).
template <uint32_t N>
ANIMORDER_ALWAYS_INLINE uint32_t reduce_list(const uint32_t* f, uint32_t n, const UnitPartition& partition,
                                             uint32_t* out, uint16_t* units, KeepScratch& scratch, bool& repeated) {
    const uint32_t count = N ? N : n;
    const size_t triangles = partition.unit_of_triangle.size();
    uint32_t local_unit[N ? N : 1], local_position[N ? N : 1];
    uint8_t local_kept[N ? N : 1];
    uint32_t* unit = N ? local_unit : scratch.entry_unit.data();
    uint32_t* position = N ? local_position : scratch.entry_position.data();
    uint8_t* kept_entry = N ? local_kept : scratch.entry_kept.data();
    bool outside = false;
    for (uint32_t j = 0; j < count; ++j) outside |= (f[j] & kTriangleMask) >= triangles;
    if (outside)
        for (uint32_t j = 0; j < count; ++j)
            if ((f[j] & kTriangleMask) >= triangles)
                throw InvalidInput("kept fragments: triangle " + std::to_string(f[j] & kTriangleMask) +
                                   ", but the partition has " + std::to_string(triangles));
    for (uint32_t j = 0; j < count; ++j) std::tie(unit[j], position[j]) = partition.unit_position[f[j] & kTriangleMask];
    bool previous_at_kept_depth = true;  // the previous fragment's depth equals the last kept one's
    uint32_t kept = 0;
    repeated = false;
    for (uint32_t j = 0; j < count; ++j) {
        const bool tied = j > 0 && (f[j] & kTieBit) && previous_at_kept_depth;
        bool dominated = false;
        uint32_t same_unit = 0;  // kept nearer entries of this unit, all drawn after it (else dominated)
        for (uint32_t i = 0; i < j; ++i) {
            const bool same = unit[i] == unit[j];
            dominated |= same && position[i] < position[j];
            same_unit += same && kept_entry[i];
        }
        kept_entry[j] = !dominated;
        previous_at_kept_depth = dominated ? tied : true;
        repeated |= !dominated && same_unit > 1;
        out[kept] = (f[j] & kTriangleMask) | (tied ? kTieBit : 0);
        units[kept] = uint16_t(unit[j] | (same_unit ? kUnitRepeatBit : 0) | (tied ? kUnitTieBit : 0));
        kept += !dominated;
    }
    return kept;
}

// The deduplicated unit lists of one node, kept per length (each length's lists in order of first
// appearance): the node stores them shortest first without a sort. Which list a pixel joins
// never depends on the hash: a list's content has one slot, and grow() reinserts each length's
// lists in their order (so a full list is met before its later copy, as when it was first filled).
struct ListTable {
    KeepScratch& s;
    size_t mask = 0;
    uint32_t generation = 0;
    size_t lists = 0, entries = 0;

    explicit ListTable(KeepScratch& scratch) : s(scratch) {
        if (s.lists.size() < kMaxListLength + 1) s.lists.resize(kMaxListLength + 1);
        for (const uint8_t n : s.used_lengths) {
            s.lists[n].entries.clear();
            s.lists[n].weights.clear();
            s.lists[n].keys.clear();
        }
        s.used_lengths.clear();
        // The previous node's table (nodes of a run are alike): no regrowth node after node, and
        // no clearing either: a new generation empties every slot.
        if (s.slots.size() < 1024 || ++s.generation >= (1u << 24)) {
            s.slots.assign(std::max<size_t>(1024, s.slots.size()), KeepScratch::Slot{});
            s.generation = 1;
        }
        generation = s.generation;
        mask = s.slots.size() - 1;
    }
    void insert(size_t n, uint32_t list) {
        const KeepScratch::Lists& of = s.lists[n];
        size_t i = hash_list(of.keys[list], &of.entries[list * n], n) & mask;
        while ((s.slots[i].stamp >> 8) == generation) i = (i + 1) & mask;
        s.slots[i] = {generation << 8 | uint32_t(n), list};
    }
    void grow() {
        s.slots.assign(s.slots.size() * 2, KeepScratch::Slot{});
        mask = s.slots.size() - 1;
        for (const uint8_t n : s.used_lengths)
            for (uint32_t list = 0; list < s.lists[n].weights.size(); ++list) insert(n, list);
    }
    const KeepScratch::Slot* slot_of(uint64_t hash) const { return &s.slots[hash & mask]; }
    // One more pixel with this list (2 ≤ n ≤ kMaxListLength; key and hash its key_of and
    // hash_list). A full weight starts a second copy (later pixels count there).
    void add(const uint16_t* e, size_t n, uint64_t key, uint64_t hash) {
        const uint32_t stamp = generation << 8 | uint32_t(n);
        KeepScratch::Lists& of = s.lists[n];
        size_t i = hash & mask;
        for (;; i = (i + 1) & mask) {
            const KeepScratch::Slot& slot = s.slots[i];
            if ((slot.stamp >> 8) != generation) break;  // empty
            if (slot.stamp != stamp) continue;
            const uint32_t list = slot.list;
            if (of.keys[list] != key) continue;
            if (n > 4 && std::memcmp(&of.entries[list * n + 4], e + 4, (n - 4) * sizeof(uint16_t)) != 0) continue;
            if (of.weights[list] < kMaxWeight) {
                ++of.weights[list];
                return;
            }
            break;  // this slot now names the new copy
        }
        if (of.weights.empty()) s.used_lengths.push_back(uint8_t(n));
        const uint32_t list = uint32_t(of.weights.size());
        of.entries.insert(of.entries.end(), e, e + n);
        of.weights.push_back(1);
        of.keys.push_back(key);
        s.slots[i] = {stamp, list};
        ++lists;
        entries += n;
        if (2 * lists > s.slots.size()) grow();
    }
};

struct Layout {
    size_t weights, entries, lengths, triangles, total;
};

Layout layout_of(const KeptNode& n) {
    Layout l;
    l.weights = 0;
    l.entries = l.weights + 2 * size_t(n.unit_lists);
    l.lengths = l.entries + 2 * size_t(n.unit_entries);
    l.triangles = (l.lengths + n.unit_lists + 3) & ~size_t(3);
    l.total = l.triangles + 4 * (size_t(n.triangle_lists) + n.triangle_entries);
    return l;
}

template <typename T>
const T* at(const KeptNode& n, size_t offset) {
    return reinterpret_cast<const T*>(n.data.data() + offset);
}

// One order. Scalar replay_list for a list with ties: an entry passes iff its rank beats the
// running minimum and nothing of its own tie group passed before it.
uint32_t replay_units_1(const uint16_t* f, uint32_t n, const uint16_t* unit_ranks) {
    uint32_t running = UINT16_MAX, before = UINT16_MAX, passes = 0;
    for (uint32_t j = 0; j < n; ++j) {
        const uint32_t r = unit_ranks[f[j] & ~uint32_t(kUnitTieBit)];
        if (j == 0 || !(f[j] & kUnitTieBit)) before = running;
        passes += uint32_t(r < running) & uint32_t(running == before);
        running = std::min(running, r);
    }
    return passes;
}

// Calls run(length, first list, end) for each run of lists of one length (keep_fragments stores
// the lists by length), `length` a compile-time constant for 2 to 5 and 0 (any) beyond.
template <typename Run>
ANIMORDER_ALWAYS_INLINE void for_each_length_run(const KeptNode& node, const uint8_t* lengths, Run&& run) {
    for (uint32_t list = 0; list < node.unit_lists;) {
        const uint32_t n = lengths[list];
        uint32_t end = list + 1;
        while (end < node.unit_lists && lengths[end] == n) ++end;
        switch (n) {
            case 2: run(std::integral_constant<uint32_t, 2>{}, list, end, n); break;
            case 3: run(std::integral_constant<uint32_t, 3>{}, list, end, n); break;
            case 4: run(std::integral_constant<uint32_t, 4>{}, list, end, n); break;
            case 5: run(std::integral_constant<uint32_t, 5>{}, list, end, n); break;
            default: run(std::integral_constant<uint32_t, 0>{}, list, end, n); break;
        }
        list = end;
    }
}

// One order, run by run: a list without ties takes its entries without a branch.
void score_unit_lists_1(uint64_t* passed, const KeptNode& node, const uint16_t* unit_ranks) {
    const Layout l = layout_of(node);
    const uint16_t* weights = at<uint16_t>(node, l.weights);
    const uint16_t* e = at<uint16_t>(node, l.entries);
    uint64_t count = 0;
    for_each_length_run(node, at<uint8_t>(node, l.lengths), [&](auto fixed, uint32_t first, uint32_t end, uint32_t n) {
        constexpr uint32_t N = decltype(fixed)::value;
        for (uint32_t list = first; list < end; ++list, e += n) {
            uint32_t ties = 0;
            for (uint32_t j = 1; j < (N ? N : n); ++j) ties |= e[j];
            uint32_t passes;
            if (__builtin_expect(ties & kUnitTieBit, 0)) {
                passes = replay_units_1(e, n, unit_ranks);
            } else {
                uint32_t running = unit_ranks[e[0]];
                passes = 1;
                for (uint32_t j = 1; j < (N ? N : n); ++j) {
                    const uint32_t r = unit_ranks[e[j]];
                    passes += r < running;
                    running = std::min(running, r);
                }
            }
            count += uint64_t(weights[list]) * passes;
        }
    });
    passed[0] += count;
}

typedef int16_t I16x8 __attribute__((vector_size(16)));
typedef uint16_t U16x8 __attribute__((vector_size(16)));
typedef uint32_t U32x4 __attribute__((vector_size(16)));

// The lane-wise minimum: one instruction on x86 (SSE2's pminsw), which the compiler does not find
// in the portable form.
ANIMORDER_ALWAYS_INLINE I16x8 lane_min(I16x8 a, I16x8 b) {
#ifdef __SSE2__
    return I16x8(_mm_min_epi16(__m128i(a), __m128i(b)));
#else
    return a < b ? a : b;
#endif
}

// 2 to 8 orders side by side, one vector lane each (rows of 8 ranks ^ 0x8000: signed compares
// order them as the ranks), list by list. The replay is replay_list's: an entry passes iff its
// rank beats the running minimum and nothing of its own tie group passed before it. A list
// without ties among its first four entries (most of them) takes those in four steps without a
// branch (a shorter list repeats its last entry, which can neither pass nor lower the minimum),
// then any more one by one.
template <size_t K>
void score_unit_lists_k(uint64_t* passed, const KeptNode& node, const uint16_t* unit_ranks) {
    static_assert(K >= 2 && K <= 8 && unit_rank_stride(K) == 8, "one lane per order");
    const Layout l = layout_of(node);
    const uint16_t* weights = at<uint16_t>(node, l.weights);
    const uint16_t* e = at<uint16_t>(node, l.entries);
    const uint8_t* lengths = at<uint8_t>(node, l.lengths);
    const auto row = [unit_ranks](uint32_t u) {
        I16x8 r;
        std::memcpy(&r, unit_ranks + size_t(u & ~uint32_t(kUnitTieBit)) * 8, sizeof r);
        return r;
    };
    U32x4 low = {}, high = {};
    // low, high += passes × weight, lane by lane (16 × 16 → 32 bits): on x86 the two 16-bit halves
    // of each product (SSE2 has no 32-bit multiply; its emulation costs twice as much), else
    // widened and multiplied.
    const auto add = [&](I16x8 passes, uint32_t weight) {
#ifdef __SSE2__
        const __m128i p = __m128i(passes), w = _mm_set1_epi16(int16_t(uint16_t(weight)));
        const __m128i product_low = _mm_mullo_epi16(p, w), product_high = _mm_mulhi_epu16(p, w);
        low += U32x4(_mm_unpacklo_epi16(product_low, product_high));
        if constexpr (K > 4) high += U32x4(_mm_unpackhi_epi16(product_low, product_high));
#else
        const U32x4 w = U32x4{} + weight;
        const U16x8 p = U16x8(passes);
        low += U32x4(__builtin_shufflevector(p, U16x8{}, 0, 8, 1, 9, 2, 10, 3, 11)) * w;
        if constexpr (K > 4) high += U32x4(__builtin_shufflevector(p, U16x8{}, 4, 12, 5, 13, 6, 14, 7, 15)) * w;
#endif
    };
    // Any list, ties or not: replay_list's rule entry by entry.
    const auto general = [&](const uint16_t* f, uint32_t n) {
        I16x8 running = I16x8{} + INT16_MAX, passes = {}, before = running;
        for (uint32_t j = 0; j < n; ++j) {
            const I16x8 r = row(f[j]);
            if (j == 0 || !(f[j] & kUnitTieBit)) before = running;
            const I16x8 below = r < running;
            passes -= below & (running == before);
            running = lane_min(running, r);
        }
        return passes;
    };
    // A run of lists of one length n (sorted so by keep_fragments): a list without ties takes its
    // entries in n steps without a branch; N > 0 is n known at compile time.
    const auto run = [&](auto fixed, uint32_t first, uint32_t end, uint32_t n) {
        constexpr uint32_t N = decltype(fixed)::value;
        for (uint32_t list = first; list < end; ++list, e += n) {
            uint32_t ties = 0;
            for (uint32_t j = 1; j < (N ? N : n); ++j) ties |= e[j];
            if (__builtin_expect(ties & kUnitTieBit, 0)) {
                add(general(e, n), weights[list]);
                continue;
            }
            I16x8 running = I16x8{} + INT16_MAX, passes = {};
            for (uint32_t j = 0; j < (N ? N : n); ++j) {
                const I16x8 r = row(e[j]);
                const I16x8 below = r < running;
                passes -= below;
                running = lane_min(running, r);
            }
            add(passes, weights[list]);
        }
    };
    for_each_length_run(node, lengths, run);
    for (size_t o = 0; o < K; ++o) passed[o] += o < 4 ? low[o] : high[o - 4];
}

#if (defined(__GNUC__) || defined(__clang__)) && (defined(__x86_64__) || defined(__i386__))
#define ANIMORDER_KEPT_AVX2 1
// score_unit_lists_k in AVX2: two lists of a run side by side (the first in the low 128-bit half,
// the second in the high one), so each vector step serves both; a list with ties, or the last of
// an odd run, goes alone (the high half zero, weighed 0). The same comparisons, minimums and
// 16 × 16 → 32-bit products lane by lane, so the same counts; the halves' sums are added at the
// end. (Plain functions, not lambdas: a lambda does not inherit the target attribute.)
#define ANIMORDER_KEPT_AVX2_INLINE __attribute__((target("avx2"), always_inline)) inline

struct Avx2Sums {
    __m256i low, high;  // per order: lanes 0-3 (orders 0-3) of each half, and 4-7 (orders 4-7)
};

ANIMORDER_KEPT_AVX2_INLINE __m128i avx2_row(const uint16_t* unit_ranks, uint32_t u) {
    return _mm_loadu_si128(reinterpret_cast<const __m128i*>(unit_ranks + size_t(u & ~uint32_t(kUnitTieBit)) * 8));
}

template <size_t K>
ANIMORDER_KEPT_AVX2_INLINE void avx2_add(Avx2Sums& sums, __m256i passes, uint32_t first_weight,
                                         uint32_t second_weight) {
    const __m256i w = _mm256_set_m128i(_mm_set1_epi16(int16_t(uint16_t(second_weight))),
                                       _mm_set1_epi16(int16_t(uint16_t(first_weight))));
    const __m256i product_low = _mm256_mullo_epi16(passes, w), product_high = _mm256_mulhi_epu16(passes, w);
    sums.low = _mm256_add_epi32(sums.low, _mm256_unpacklo_epi16(product_low, product_high));
    if constexpr (K > 4) sums.high = _mm256_add_epi32(sums.high, _mm256_unpackhi_epi16(product_low, product_high));
}

// One list, ties or not: replay_list's rule entry by entry (score_unit_lists_k's `general`), in
// the low half.
ANIMORDER_KEPT_AVX2_INLINE __m256i avx2_alone(const uint16_t* unit_ranks, const uint16_t* f, uint32_t n) {
    __m128i running = _mm_set1_epi16(INT16_MAX), passes = _mm_setzero_si128(), before = running;
    for (uint32_t j = 0; j < n; ++j) {
        const __m128i r = avx2_row(unit_ranks, f[j]);
        if (j == 0 || !(f[j] & kUnitTieBit)) before = running;
        const __m128i below = _mm_cmpgt_epi16(running, r);
        passes = _mm_sub_epi16(passes, _mm_and_si128(below, _mm_cmpeq_epi16(running, before)));
        running = _mm_min_epi16(running, r);
    }
    return _mm256_inserti128_si256(_mm256_setzero_si256(), passes, 0);
}

// A run of lists of one length (N > 0: known at compile time; 0: n).
template <size_t K, uint32_t N>
ANIMORDER_KEPT_AVX2_INLINE void avx2_run(Avx2Sums& sums, const uint16_t* unit_ranks, const uint16_t* weights,
                                         const uint16_t*& e, uint32_t first, uint32_t end, uint32_t n) {
    const uint32_t count = N ? N : n;
    uint32_t list = first;
    for (; list + 1 < end; list += 2, e += 2 * count) {
        const uint16_t* second = e + count;
        uint32_t ties = 0;
        for (uint32_t j = 1; j < count; ++j) ties |= e[j] | second[j];
        if (__builtin_expect(ties & kUnitTieBit, 0)) {
            avx2_add<K>(sums, avx2_alone(unit_ranks, e, count), weights[list], 0);
            avx2_add<K>(sums, avx2_alone(unit_ranks, second, count), weights[list + 1], 0);
            continue;
        }
        __m256i running = _mm256_set1_epi16(INT16_MAX), passes = _mm256_setzero_si256();
        for (uint32_t j = 0; j < count; ++j) {
            const __m256i r = _mm256_inserti128_si256(_mm256_castsi128_si256(avx2_row(unit_ranks, e[j])),
                                                      avx2_row(unit_ranks, second[j]), 1);
            passes = _mm256_sub_epi16(passes, _mm256_cmpgt_epi16(running, r));
            running = _mm256_min_epi16(running, r);
        }
        avx2_add<K>(sums, passes, weights[list], weights[list + 1]);
    }
    if (list < end) {
        avx2_add<K>(sums, avx2_alone(unit_ranks, e, count), weights[list], 0);
        e += count;
    }
}

template <size_t K>
__attribute__((target("avx2"))) void score_unit_lists_k_avx2(uint64_t* passed, const KeptNode& node,
                                                             const uint16_t* unit_ranks) {
    static_assert(K >= 2 && K <= 8 && unit_rank_stride(K) == 8, "one lane per order");
    const Layout l = layout_of(node);
    const uint16_t* weights = at<uint16_t>(node, l.weights);
    const uint16_t* e = at<uint16_t>(node, l.entries);
    const uint8_t* lengths = at<uint8_t>(node, l.lengths);
    Avx2Sums sums{_mm256_setzero_si256(), _mm256_setzero_si256()};
    for (uint32_t list = 0; list < node.unit_lists;) {  // runs of one length, as for_each_length_run
        const uint32_t n = lengths[list];
        uint32_t end = list + 1;
        while (end < node.unit_lists && lengths[end] == n) ++end;
        switch (n) {
            case 2: avx2_run<K, 2>(sums, unit_ranks, weights, e, list, end, n); break;
            case 3: avx2_run<K, 3>(sums, unit_ranks, weights, e, list, end, n); break;
            case 4: avx2_run<K, 4>(sums, unit_ranks, weights, e, list, end, n); break;
            case 5: avx2_run<K, 5>(sums, unit_ranks, weights, e, list, end, n); break;
            default: avx2_run<K, 0>(sums, unit_ranks, weights, e, list, end, n); break;
        }
        list = end;
    }
    alignas(32) uint32_t low[8], high[8];
    _mm256_store_si256(reinterpret_cast<__m256i*>(low), sums.low);
    _mm256_store_si256(reinterpret_cast<__m256i*>(high), sums.high);
    for (size_t o = 0; o < K; ++o) passed[o] += o < 4 ? uint64_t(low[o]) + low[4 + o] : uint64_t(high[o - 4]) + high[o];
}
#endif

void score_unit_lists_any(uint64_t* passed, const KeptNode& node, const uint16_t* unit_ranks, size_t order_count,
                          bool portable) {
#ifdef ANIMORDER_KEPT_AVX2
    static const bool avx2 = __builtin_cpu_supports("avx2");
    if (avx2 && !portable) switch (order_count) {
            case 2: return score_unit_lists_k_avx2<2>(passed, node, unit_ranks);
            case 3: return score_unit_lists_k_avx2<3>(passed, node, unit_ranks);
            case 4: return score_unit_lists_k_avx2<4>(passed, node, unit_ranks);
            case 5: return score_unit_lists_k_avx2<5>(passed, node, unit_ranks);
            case 6: return score_unit_lists_k_avx2<6>(passed, node, unit_ranks);
            case 7: return score_unit_lists_k_avx2<7>(passed, node, unit_ranks);
            case 8: return score_unit_lists_k_avx2<8>(passed, node, unit_ranks);
            default: break;
        }
#endif
    switch (order_count) {
        case 1: return score_unit_lists_1(passed, node, unit_ranks);
        case 2: return score_unit_lists_k<2>(passed, node, unit_ranks);
        case 3: return score_unit_lists_k<3>(passed, node, unit_ranks);
        case 4: return score_unit_lists_k<4>(passed, node, unit_ranks);
        case 5: return score_unit_lists_k<5>(passed, node, unit_ranks);
        case 6: return score_unit_lists_k<6>(passed, node, unit_ranks);
        case 7: return score_unit_lists_k<7>(passed, node, unit_ranks);
        case 8: return score_unit_lists_k<8>(passed, node, unit_ranks);
        default: break;
    }
    const Layout l = layout_of(node);
    const uint16_t* weights = at<uint16_t>(node, l.weights);
    const uint16_t* e = at<uint16_t>(node, l.entries);
    const uint8_t* lengths = at<uint8_t>(node, l.lengths);
    std::vector<uint16_t> scratch(2 * order_count);
    for (uint32_t list = 0; list < node.unit_lists; ++list) {
        replay_list(e, lengths[list], kUnitTieBit, unit_ranks, order_count, scratch.data(),
                    scratch.data() + order_count, [&](size_t o) { passed[o] += weights[list]; });
        e += lengths[list];
    }
}

}  // namespace

UnitPartition make_unit_partition(const uint32_t* unit_starts, size_t unit_count, const uint32_t* inner_order,
                                  size_t triangle_count) {
    if (unit_count == 0 ? triangle_count != 0 : unit_starts[0] != 0 || unit_starts[unit_count] != triangle_count)
        throw InvalidInput("unit partition: the units do not cover the " + std::to_string(triangle_count) +
                           " triangles");
    UnitPartition p;
    p.unit_count = unit_count;
    p.unit_of_triangle.assign(triangle_count, UINT32_MAX);
    p.unit_position.assign(triangle_count, {0, 0});
    for (size_t u = 0; u < unit_count; ++u) {
        if (unit_starts[u + 1] < unit_starts[u]) throw InvalidInput("unit partition: unit starts go backwards");
        for (uint32_t j = unit_starts[u]; j < unit_starts[u + 1]; ++j) {
            const uint32_t t = inner_order[j];
            if (t >= triangle_count || p.unit_of_triangle[t] != UINT32_MAX)
                throw InvalidInput("unit partition: triangle " + std::to_string(t) +
                                   " is out of range or listed twice");
            p.unit_of_triangle[t] = uint32_t(u);
            p.unit_position[t] = {uint32_t(u), j};
        }
    }
    return p;
}

KeptNode keep_fragments(uint64_t visible, uint64_t single, const uint32_t* starts, size_t pixel_count,
                        const uint32_t* fragments, const UnitPartition& partition, KeepScratch& s) {
    KeptNode node;
    node.visible = visible;
    node.single = single;
    const bool unit_lists = partition.unit_count <= kMaxListedUnits;
    ListTable table(s);
    s.triangle_lists.clear();
    bool repeated = false;
    // A unit list waits one pixel before it is looked up, its slot fetched meanwhile (the table is
    // larger than the nearest cache); lookups still run in pixel order. Two halves of s.units
    // take turns: the pending list's and the current pixel's.
    uint16_t* pending = nullptr;
    uint32_t pending_n = 0;
    uint64_t pending_key = 0, pending_hash = 0;
    // The units of the fragments kPrefetchAhead entries on are fetched meanwhile when the triangle
    // -> (unit, place) table is larger than kPrefetchTriangles entries (256 KB: half the nearest
    // cache a core has to itself on common CPUs; the lists follow no order in it). Below, the
    // table stays cached and prefetching only adds work (measured: Ganfaul's 13,802 triangles).
    constexpr size_t kPrefetchAhead = 24, kPrefetchTriangles = size_t(1) << 15;
    const size_t triangle_count = partition.unit_position.size();
    const size_t to_prefetch =  // the node's fragments, or none
        pixel_count && triangle_count > kPrefetchTriangles ? starts[pixel_count] - starts[0] : 0;
    size_t prefetched = 0;
    for (size_t p = 0; p < pixel_count; ++p) {
        const uint32_t n = starts[p + 1] - starts[p];
        for (const size_t until = std::min(size_t(starts[p + 1] - starts[0]) + kPrefetchAhead, to_prefetch);
             prefetched < until; ++prefetched) {
            const uint32_t t = fragments[starts[0] + prefetched] & kTriangleMask;
            if (t < triangle_count) __builtin_prefetch(&partition.unit_position[t]);
        }
        if (s.reduced.size() < n) {
            s.reduced.resize(n);
            s.entry_unit.resize(n);
            s.entry_position.resize(n);
            s.entry_kept.resize(n);
        }
        if (s.units.size() < 2 * std::max<size_t>(n, 4)) {
            std::vector<uint16_t> units(2 * std::max<size_t>(n, 4));
            if (pending) std::copy(pending, pending + pending_n, units.begin());
            s.units.swap(units);
            if (pending) pending = s.units.data();
        }
        uint16_t* units = s.units.data() + (pending == s.units.data() ? s.units.size() / 2 : 0);
        const uint32_t* f = fragments + starts[p];
        uint32_t* reduced = s.reduced.data();
        const uint32_t kept = n == 2   ? reduce_list<2>(f, n, partition, reduced, units, s, repeated)
                              : n == 3 ? reduce_list<3>(f, n, partition, reduced, units, s, repeated)
                              : n == 4 ? reduce_list<4>(f, n, partition, reduced, units, s, repeated)
                                       : reduce_list<0>(f, n, partition, reduced, units, s, repeated);
        if (kept < 2) {
            ++node.single;  // only the nearest is left: it passes under every order, nothing else does
            continue;
        }
        if (!unit_lists || repeated || kept > kMaxListLength) {
            s.triangle_lists.push_back(kept);
            s.triangle_lists.insert(s.triangle_lists.end(), s.reduced.begin(), s.reduced.begin() + kept);
            ++node.triangle_lists;
            node.triangle_entries += kept;
            continue;
        }
        if (pending) table.add(pending, pending_n, pending_key, pending_hash);
        pending = units;
        pending_n = kept;
        pending_key = key_of(units, kept);
        pending_hash = hash_list(pending_key, units, kept);
        __builtin_prefetch(table.slot_of(pending_hash));
    }
    if (pending) table.add(pending, pending_n, pending_key, pending_hash);
    node.unit_lists = uint32_t(table.lists);
    node.unit_entries = uint32_t(table.entries);
    const Layout l = layout_of(node);
    node.data = std::vector<uint8_t>(l.total, 0);  // exactly its size: bytes() is deterministic
    // The unit lists shortest first (scoring then meets runs of one length, so its loops know
    // their trip counts), each length's in order of first appearance.
    std::sort(s.used_lengths.begin(), s.used_lengths.end());
    uint8_t* weights = node.data.data() + l.weights;
    uint8_t* entries = node.data.data() + l.entries;
    uint8_t* lengths = node.data.data() + l.lengths;
    for (const uint8_t n : s.used_lengths) {
        const KeepScratch::Lists& of = s.lists[n];
        std::memcpy(weights, of.weights.data(), of.weights.size() * sizeof(uint16_t));
        std::memcpy(entries, of.entries.data(), of.entries.size() * sizeof(uint16_t));
        std::memset(lengths, n, of.weights.size());
        weights += of.weights.size() * sizeof(uint16_t);
        entries += of.entries.size() * sizeof(uint16_t);
        lengths += of.weights.size();
    }
    if (!s.triangle_lists.empty())
        std::memcpy(node.data.data() + l.triangles, s.triangle_lists.data(),
                    s.triangle_lists.size() * sizeof(uint32_t));
    return node;
}

std::vector<uint16_t> make_unit_rank_table(const uint32_t* triangle_ranks, size_t order_count,
                                           const UnitPartition& partition) {
    const size_t units = partition.unit_count, triangles = partition.unit_of_triangle.size();
    if (units > kMaxListedUnits) return {};  // every list is kept per triangle
    const size_t stride = unit_rank_stride(order_count);
    std::vector<uint16_t> table((kUnitRepeatBit + units) * stride, 0);
    std::vector<uint32_t> low(units), high(units), size(units), by_position(units);
    for (size_t o = 0; o < order_count; ++o) {
        std::fill(low.begin(), low.end(), UINT32_MAX);
        std::fill(high.begin(), high.end(), 0);
        std::fill(size.begin(), size.end(), 0);
        for (size_t t = 0; t < triangles; ++t) {
            const uint32_t u = partition.unit_of_triangle[t], r = triangle_ranks[t * order_count + o];
            low[u] = std::min(low[u], r);
            high[u] = std::max(high[u], r);
            ++size[u];
        }
        for (size_t u = 0; u < units; ++u)
            if (size[u] > 0 && high[u] - low[u] + 1 != size[u])
                throw InvalidInput("order " + std::to_string(o) + " splits unit " + std::to_string(u) +
                                   ": kept fragments score unit orders only");
        std::iota(by_position.begin(), by_position.end(), 0u);
        std::sort(by_position.begin(), by_position.end(), [&](uint32_t a, uint32_t b) { return low[a] < low[b]; });
        const uint16_t bias = stride == 8 ? 0x8000 : 0;  // see unit_rank_stride: signed lanes
        for (size_t i = 0; i < units; ++i) {
            table[size_t(by_position[i]) * stride + o] = uint16_t((2 * i + 1) ^ bias);
            table[(kUnitRepeatBit + size_t(by_position[i])) * stride + o] = uint16_t((2 * i) ^ bias);
        }
    }
    return table;
}

namespace {

void score_kept_copy(uint64_t* passed, const KeptNode& node, const uint16_t* unit_ranks, const uint32_t* triangle_ranks,
                     size_t order_count, bool portable) {
    for (size_t o = 0; o < order_count; ++o) passed[o] = node.single;
    if (node.unit_lists) score_unit_lists_any(passed, node, unit_ranks, order_count, portable);
    if (node.triangle_lists == 0) return;
    const uint32_t* t = at<uint32_t>(node, layout_of(node).triangles);
    std::vector<uint32_t> scratch(2 * order_count);
    for (uint32_t list = 0; list < node.triangle_lists; ++list) {
        const uint32_t n = *t++;
        replay_list(t, n, kTieBit, triangle_ranks, order_count, scratch.data(), scratch.data() + order_count,
                    [&](size_t o) { ++passed[o]; });
        t += n;
    }
}

}  // namespace

void score_kept(uint64_t* passed, const KeptNode& node, const uint16_t* unit_ranks, const uint32_t* triangle_ranks,
                size_t order_count) {
    score_kept_copy(passed, node, unit_ranks, triangle_ranks, order_count, false);
}

void score_kept_portable(uint64_t* passed, const KeptNode& node, const uint16_t* unit_ranks,
                         const uint32_t* triangle_ranks, size_t order_count) {
    score_kept_copy(passed, node, unit_ranks, triangle_ranks, order_count, true);
}

void for_each_unit_list(const KeptNode& node, const uint32_t* unit_of_triangle, size_t triangle_count,
                        std::vector<uint32_t>& scratch,
                        const std::function<void(const uint32_t* units, uint32_t count, uint32_t weight)>& visit) {
    const Layout l = layout_of(node);
    const uint16_t* weights = at<uint16_t>(node, l.weights);
    const uint16_t* e = at<uint16_t>(node, l.entries);
    const uint8_t* lengths = at<uint8_t>(node, l.lengths);
    for (uint32_t list = 0; list < node.unit_lists; ++list) {
        scratch.clear();
        for (uint32_t j = 0; j < lengths[list]; ++j)
            scratch.push_back(uint32_t(e[j] & kUnitMask) | (e[j] & kUnitTieBit ? kTieBit : 0));
        visit(scratch.data(), lengths[list], weights[list]);
        e += lengths[list];
    }
    const uint32_t* t = at<uint32_t>(node, l.triangles);
    for (uint32_t list = 0; list < node.triangle_lists; ++list) {
        const uint32_t n = *t++;
        scratch.clear();
        for (uint32_t j = 0; j < n; ++j) {
            const uint32_t triangle = t[j] & kTriangleMask;
            if (triangle >= triangle_count)
                throw InvalidInput("kept fragments: triangle " + std::to_string(triangle) + ", but there are " +
                                   std::to_string(triangle_count));
            scratch.push_back(unit_of_triangle[triangle] | (t[j] & kTieBit));
        }
        visit(scratch.data(), n, 1);
        t += n;
    }
}

}  // namespace animorder
