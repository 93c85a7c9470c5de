// Private to src/overdraw (and the layers above): how a pixel's fragment list is encoded and replayed.
//
// NodeFragments::fragments (rasterizer.h) packs one fragment into a uint32_t: the low 31 bits are
// the triangle index; the top bit is set when the fragment's depth equals the previous fragment's
// of the same pixel (fragments run nearest first), so the two are one depth group of which only
// the one drawn first can pass. rasterize_node.h writes it; fragment_scoring.cpp, kept_fragments.cpp and
// nehab06.cpp read it. KeptNode's unit lists use the same scheme in 16 bits (kUnitTieBit).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>

namespace animorder {

constexpr uint32_t kTieBit = 0x80000000u;
constexpr uint32_t kTriangleMask = 0x7fffffffu;
constexpr uint16_t kUnitTieBit = 0x8000u;
// A unit list entry with this bit is its unit's second entry in the list: a farther fragment of
// the unit that the unit draws before its nearer one (kept_fragments.cpp). Its rank row is
// kUnitRepeatBit rows past the unit's own (make_unit_rank_table), one step earlier in the order.
constexpr uint16_t kUnitRepeatBit = 0x4000u;
constexpr uint16_t kUnitMask = 0x3fffu;

// Replays one pixel's list nearest first for every order, keeping the lowest rank seen so far
// (`running`) and the lowest before the current group of equal depths (`before`). An entry passes
// LESS iff its rank beats every entry at smaller or equal depth; of a group of equal depths only
// the first drawn can pass, hence at most one emit(o) per group. ranks[id · order_count + o].
template <typename Entry, typename Rank, typename Emit>
void replay_list(const Entry* entries, uint32_t count, Entry tie_bit, const Rank* ranks, size_t order_count,
                 Rank* running, Rank* before, Emit&& emit) {
    std::fill(running, running + order_count, std::numeric_limits<Rank>::max());
    for (uint32_t j = 0; j < count; ++j) {
        const Entry f = entries[j];
        const Rank* r = ranks + size_t(f & Entry(~tie_bit)) * order_count;
        const bool same_group = (f & tie_bit) != 0;
        for (size_t o = 0; o < order_count; ++o) {
            if (!same_group) before[o] = running[o];
            if (r[o] < running[o]) {
                if (running[o] == before[o]) emit(o);
                running[o] = r[o];
            }
        }
    }
}

// The same for a list without equal depths (nearly all), branch-free and vectorised across the K
// orders: an entry passes under order o iff its rank is below the running minimum.
template <size_t K, typename Entry, typename Rank>
void replay_untied_list(const Entry* entries, uint32_t count, const Rank* ranks, uint32_t (&passes)[K]) {
    Rank running[K];
    for (size_t o = 0; o < K; ++o) running[o] = std::numeric_limits<Rank>::max();
    for (uint32_t j = 0; j < count; ++j) {
        const Rank* r = ranks + size_t(entries[j]) * K;
        for (size_t o = 0; o < K; ++o) {
            passes[o] += r[o] < running[o];
            running[o] = std::min(running[o], r[o]);
        }
    }
}

}  // namespace animorder
