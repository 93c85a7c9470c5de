// The OpenGL reference for the overdraw engine: the same node drawn by a real OpenGL (Mesa's
// llvmpipe over EGL without a display here, a GPU driver where there is one), counting the
// fragments that pass the depth test with occlusion queries (GL_SAMPLES_PASSED), as Han &
// Sander 2017 measured, in a GlContext (gl_context.h) with the flat fragment shader. Kept apart
// from the library: only tests and benchmarks use it.
#pragma once

#include "gl_context.h"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace animorder {

struct GlNodeCounts {
    uint64_t visible = 0;          // pixels whose depth < 1 after drawing
    std::vector<uint64_t> passed;  // per order: GL_SAMPLES_PASSED
};

class GlOverdrawReference {
public:
    // Opens a headless OpenGL 4.5 core context (EGL, surfaceless Mesa platform first, then the
    // device platform); throws std::runtime_error saying why when that is impossible.
    explicit GlOverdrawReference(unsigned resolution);
    ~GlOverdrawReference();
    GlOverdrawReference(const GlOverdrawReference&) = delete;
    GlOverdrawReference& operator=(const GlOverdrawReference&) = delete;

    std::string renderer() const;

    // Draws the clip-space vertices (4 floats each, the array transform_to_clip gives the CPU
    // rasteriser) once per index buffer, each into a cleared depth buffer with its own query.
    // double_sided: every triangle drawn without back-face culling (a double-sided material).
    GlNodeCounts score(const float* clip_xyzw, size_t vertex_count,
                       const std::vector<std::vector<uint32_t>>& index_buffers, bool double_sided = false);

private:
    std::unique_ptr<GlContext> context_;
    size_t scratch_ = 0;  // the index buffer each order is copied into
};

}  // namespace animorder
