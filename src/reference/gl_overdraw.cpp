// OpenGL reference: occlusion-query overdraw counts over EGL, as DESIGN.md's notes describe.
//
// The context (gl_context.cpp) passes clip-space positions through, so OpenGL and the CPU
// engine get the very same floats; each order is drawn into a cleared depth buffer with its own
// query, which ends its own llvmpipe scene, and the counts are checked for plausibility (the
// binning trap of DESIGN.md corrupted 2 in 8,000 queries before).
#include "gl_overdraw.h"

#include <stdexcept>
#include <string>

namespace animorder {

GlOverdrawReference::GlOverdrawReference(unsigned resolution)
    : context_(std::make_unique<GlContext>(resolution, kFlatFragmentShader)) {
    scratch_ = context_->add_index_buffer(nullptr, 0);
}

GlOverdrawReference::~GlOverdrawReference() = default;

std::string GlOverdrawReference::renderer() const { return context_->renderer(); }

GlNodeCounts GlOverdrawReference::score(const float* clip_xyzw, size_t vertex_count,
                                        const std::vector<std::vector<uint32_t>>& index_buffers, bool double_sided) {
    GlContext& gl = *context_;
    gl.set_culling(!double_sided);
    gl.set_vertices(clip_xyzw, vertex_count);
    GlNodeCounts counts;
    const uint64_t pixels = uint64_t(gl.resolution()) * gl.resolution();
    for (size_t o = 0; o < index_buffers.size(); ++o) {
        gl.set_index_buffer(scratch_, index_buffers[o].data(), index_buffers[o].size());
        counts.passed.push_back(gl.draw(scratch_).samples_passed);
        if (o == 0) counts.visible = gl.covered_pixels();
    }
    gl.set_culling(true);
    for (uint64_t p : counts.passed)
        if (p < counts.visible || counts.visible > pixels)
            throw std::runtime_error("OpenGL reference: implausible query result (passed " + std::to_string(p) +
                                     ", visible " + std::to_string(counts.visible) + ")");
    return counts;
}

}  // namespace animorder
