// The portable (SSE2 on x86-64) copy of the rasteriser's per-node code (rasterize_node.h), in its own file so that
// it is compiled, and its helpers inlined, for its own instructions alone.
#include "rasterize_node.h"

namespace animorder {
namespace raster {
void rasterize_node_portable(NodeRasterizer::State& s, const VertexSource& source, size_t vertex_count,
                             const uint32_t* indices, size_t index_count, unsigned resolution, const uint8_t* modes,
                             const uint32_t* candidates, size_t candidate_count) {
    rasterize_node<NodeRasterizer::Copy::Portable>(s, source, vertex_count, indices, index_count, resolution, modes,
                                                   candidates, candidate_count);
}

}  // namespace raster
}  // namespace animorder
