// The AVX2 copy of the rasteriser's per-node code (rasterize_node.h), in its own file so that
// it is compiled, and its helpers inlined, for its own instructions alone.
#include "rasterize_node.h"

namespace animorder {
namespace raster {

#ifdef ANIMORDER_RASTER_AVX2
__attribute__((target("avx2"))) void rasterize_node_avx2(NodeRasterizer::State& s, const VertexSource& source,
                                                         size_t vertex_count, const uint32_t* indices,
                                                         size_t index_count, unsigned resolution, const uint8_t* modes,
                                                         const uint32_t* candidates, size_t candidate_count) {
    rasterize_node<NodeRasterizer::Copy::Avx2>(s, source, vertex_count, indices, index_count, resolution, modes,
                                               candidates, candidate_count);
}
#endif

}  // namespace raster
}  // namespace animorder
