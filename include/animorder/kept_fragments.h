// animorder — a node's fragments kept compactly for scoring unit orders (kept_fragments.cpp).
//
// k-means scores only orders made of whole units (the λ patches, or planar clusters), each unit
// drawn in its own fixed inner order. Then much of a node's per-pixel fragment lists is
// redundant: a fragment behind a nearer one of its own unit that its unit draws first never
// passes and hides nothing that unit does not hide already, so it is dropped; among different
// units only the units' positions matter, so a pixel's list becomes a list of unit ids; and
// many pixels share a list, kept once with a weight. A KeptNode is that (about a sixth of
// NodeFragments on real characters) and gives exactly NodeFragments' counts for every order that
// keeps the units contiguous. No file I/O here.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

namespace animorder {

// Triangles grouped into units that every scored order keeps contiguous, each unit drawn in a
// fixed inner order: unit_position[t] is t's unit and its place in the concatenation of the units'
// inner orders (side by side: the dropping test reads both at once); unit_of_triangle[t] its unit.
struct UnitPartition {
    std::vector<uint32_t> unit_of_triangle;
    std::vector<std::pair<uint32_t, uint32_t>> unit_position;
    size_t unit_count = 0;
};

// From unit_starts (unit_count + 1 offsets into inner_order) and inner_order (every triangle
// once: MeshPatches' patch_starts and cache_order). Throws InvalidInput when it is not a partition.
UnitPartition make_unit_partition(const uint32_t* unit_starts, size_t unit_count, const uint32_t* inner_order,
                                  size_t triangle_count);

// Unit lists have at most this many units (longer ones are kept per triangle), and unit ids
// below kMaxListedUnits (a mesh with more units keeps every list per triangle; bits 14 and 15 of
// an entry are flags).
constexpr size_t kMaxListLength = 255;
constexpr size_t kMaxListedUnits = 0x4000;

// One node, compact. visible: pixels covered; single: pixels whose every order passes exactly one
// fragment. Unit lists: deduplicated, each with its weight (pixels), entries unit | 0x8000 when
// at the depth of the previous entry, | 0x4000 for a unit's second entry (a farther fragment
// that its unit draws before the nearer one: the two units' inner order is then known); stored
// shortest first (lists of one length in order of first appearance), so that scoring walks runs
// of one length. Triangle lists: the rare pixels where a unit appears three times or more after
// dropping (its inner order then matters), entries triangle | kTieBit, weight one.
struct KeptNode {
    uint64_t visible = 0, single = 0;
    uint32_t unit_lists = 0, unit_entries = 0, triangle_lists = 0, triangle_entries = 0;
    // weights u16[unit_lists] | entries u16[unit_entries] | lengths u8[unit_lists] | padding to 4 |
    // per triangle list: length u32, entries u32[length]
    std::vector<uint8_t> data;
    size_t bytes() const { return data.capacity() + sizeof(*this); }
};

// Working memory of keep_fragments, reused between nodes (its list table too: each slot is
// stamped with the node that filled it, so nothing is cleared node after node).
struct KeepScratch {
    struct Slot {
        uint32_t stamp = 0;  // generation << 8 | the list's length; a slot of another generation is empty
        uint32_t list = 0;   // the list's index among the lists of its length
    };
    std::vector<Slot> slots;
    uint32_t generation = 0;
    // The node's unit lists of one length n: entries (n a list), weights, and keys (the first
    // four entries side by side); used_lengths: the lengths with lists in this node.
    struct Lists {
        std::vector<uint16_t> entries, weights;
        std::vector<uint64_t> keys;
    };
    std::vector<Lists> lists;
    std::vector<uint8_t> used_lengths;
    std::vector<uint32_t> reduced, entry_unit, entry_position;  // a pixel's entries, as reduced
    std::vector<uint8_t> entry_kept;
    std::vector<uint16_t> units;
    std::vector<uint32_t> triangle_lists;
};

// A node's multi-fragment pixels (starts: pixel_count + 1 offsets into fragments, nearest first,
// triangle | kTieBit as in NodeFragments) kept compactly.
KeptNode keep_fragments(uint64_t visible, uint64_t single, const uint32_t* starts, size_t pixel_count,
                        const uint32_t* fragments, const UnitPartition& partition, KeepScratch& scratch);

// Per order, the rank of every unit (u16, order-major within a unit:
// [u · unit_rank_stride(order_count) + o]) from a triangle rank table (make_rank_table): 2 ·
// position + 1 in row u, and 2 · position in row 0x4000 + u (a unit's second entry in a list,
// drawn just before its first). Rows of 2 to 8 orders are padded to 8 lanes and hold rank ^ 0x8000
// (so that score_kept compares them as signed 16-bit lanes). Throws InvalidInput when an order
// splits a unit.
std::vector<uint16_t> make_unit_rank_table(const uint32_t* triangle_ranks, size_t order_count,
                                           const UnitPartition& partition);

// A unit's row in make_unit_rank_table: 2 to 8 orders padded to 8 (one vector for score_kept).
constexpr size_t unit_rank_stride(size_t order_count) { return order_count < 2 || order_count > 8 ? order_count : 8; }

// passed[o] for each order: what score_fragments gives on the node's NodeFragments. 2 to 8 orders
// run an AVX2 copy where the CPU has it (two lists a vector step; the same counts).
void score_kept(uint64_t* passed, const KeptNode& node, const uint16_t* unit_ranks, const uint32_t* triangle_ranks,
                size_t order_count);
// The same in the portable copy only (tests compare the two).
void score_kept_portable(uint64_t* passed, const KeptNode& node, const uint16_t* unit_ranks,
                         const uint32_t* triangle_ranks, size_t order_count);

// Every list of the node as units nearest first (unit | 0x80000000 when at the previous entry's
// depth), with its weight: unit lists as kept, triangle lists mapped through unit_of_triangle
// (triangle_count entries: the partition's; InvalidInput for a triangle beyond).
void for_each_unit_list(const KeptNode& node, const uint32_t* unit_of_triangle, size_t triangle_count,
                        std::vector<uint32_t>& scratch,
                        const std::function<void(const uint32_t* units, uint32_t count, uint32_t weight)>& visit);

}  // namespace animorder
