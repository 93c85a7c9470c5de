// A headless OpenGL drawing context for the references (Mesa's llvmpipe over EGL without a
// display here, a GPU driver where there is one): one square framebuffer with a 32-bit float
// depth buffer, a vertex shader that passes clip-space positions through (the very floats the
// CPU rasteriser gets), a fragment shader given by the caller, and DESIGN.md's state (depth test
// LESS against a buffer cleared to 1, back faces culled, fronts counter-clockwise). Each draw
// goes into a freshly cleared framebuffer and counts GL_SAMPLES_PASSED; it can also be timed.
// Kept apart from the library: only tests and benchmarks use it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

namespace animorder {

// colour = 1: the cheapest shader, for counting fragments.
extern const char* const kFlatFragmentShader;
// Deliberately expensive: `uniform int iterations` rounds of transcendental math whose result is
// the colour; no discard, no depth write, `layout(early_fragment_tests) in;` so that a fragment
// failing the depth test is never shaded. Its cost per shaded fragment grows with iterations.
extern const char* const kExpensiveFragmentShader;

struct GlDraw {
    uint64_t samples_passed = 0;  // GL_SAMPLES_PASSED of the draw
    double seconds = 0;           // wall time from the draw call until glFinish returned (timed draws)
    double gpu_seconds = 0;       // GL_TIME_ELAPSED of the draw (timed draws; 0 where unsupported)
};

class GlContext {
public:
    // Opens an OpenGL 4.5 core context (EGL: the surfaceless Mesa platform first, then the
    // device platform, then the default display) and sets up the framebuffer and the program;
    // throws std::runtime_error saying why when that is impossible.
    GlContext(unsigned resolution, const char* fragment_shader = kFlatFragmentShader);
    ~GlContext();
    GlContext(const GlContext&) = delete;
    GlContext& operator=(const GlContext&) = delete;

    std::string renderer() const;  // GL_RENDERER
    unsigned resolution() const;

    // Sets an int uniform of the fragment shader (e.g. "iterations"); throws if it has none.
    void set_uniform(const char* name, int value);

    // The clip-space vertices (4 floats each) every later draw reads, until the next call.
    void set_vertices(const float* clip_xyzw, size_t vertex_count);
    // Stores an index buffer (triangle list) on the GL side; returns its id for draw().
    size_t add_index_buffer(const uint32_t* indices, size_t index_count);
    // Replaces the contents of a stored index buffer.
    void set_index_buffer(size_t id, const uint32_t* indices, size_t index_count);

    // Clears colour and depth, then draws index buffer `id` with an occlusion query; the query
    // ends its own llvmpipe scene (DESIGN.md's binning trap). When `timed`, the clear is finished
    // first and the draw is timed up to glFinish, with a GL_TIME_ELAPSED query beside it.
    GlDraw draw(size_t id, bool timed = false);

    // Back-face culling on (the default) or off (double-sided materials) for later draws.
    void set_culling(bool cull);

    // Pixels whose depth is below 1 in the framebuffer now (after a draw: the visible pixels).
    uint64_t covered_pixels();

private:
    struct State;
    std::unique_ptr<State> state_;
};

}  // namespace animorder
