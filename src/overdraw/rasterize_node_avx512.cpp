// The AVX-512 (at 256-bit width) copy of the rasteriser's per-node code (rasterize_node.h), in its own file so that
// it is compiled, and its helpers inlined, for its own instructions alone.
#include "rasterize_node.h"

namespace animorder {
namespace raster {

#ifdef ANIMORDER_RASTER_AVX2
// The AVX2 copy's source compiled with AVX-512 allowed; GCC keeps its loops at 256-bit vectors
// (its default width for these targets), so no 512-bit clock penalty where a CPU has one.
__attribute__((target("avx2,avx512f,avx512vl,avx512bw,avx512dq"))) void rasterize_node_avx512(
    NodeRasterizer::State& s, const VertexSource& source, size_t vertex_count, const uint32_t* indices,
    size_t index_count, unsigned resolution, const uint8_t* modes, const uint32_t* candidates, size_t candidate_count) {
    rasterize_node<NodeRasterizer::Copy::Avx512>(s, source, vertex_count, indices, index_count, resolution, modes,
                                                 candidates, candidate_count);
}
#endif

}  // namespace raster
}  // namespace animorder
