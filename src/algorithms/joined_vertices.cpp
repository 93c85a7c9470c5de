// Vertices at bit-identical positions joined: the vertices sorted by their coordinates' bytes
// (ties by index), each run of equal coordinates mapped to its smallest index.
#include "joined_vertices.h"

#include <algorithm>
#include <cstring>

namespace animorder {

std::vector<uint32_t> first_vertex_at_each_position(const float* positions, size_t vertex_count) {
    std::vector<uint32_t> by_position(vertex_count);
    for (size_t v = 0; v < vertex_count; ++v) by_position[v] = uint32_t(v);
    auto less = [positions](uint32_t a, uint32_t b) {
        const int c = std::memcmp(positions + 3 * size_t(a), positions + 3 * size_t(b), 3 * sizeof(float));
        return c != 0 ? c < 0 : a < b;
    };
    std::sort(by_position.begin(), by_position.end(), less);
    std::vector<uint32_t> canonical(vertex_count);
    for (size_t i = 0; i < vertex_count; ++i) {
        const uint32_t v = by_position[i];
        const bool same = i > 0 && std::memcmp(positions + 3 * size_t(v), positions + 3 * size_t(by_position[i - 1]),
                                               3 * sizeof(float)) == 0;
        canonical[v] = same ? canonical[by_position[i - 1]] : v;
    }
    return canonical;
}

}  // namespace animorder
