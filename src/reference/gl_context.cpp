// The headless OpenGL context shared by the OpenGL references (DESIGN.md, notes on the OpenGL
// reference): eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA), an OpenGL 4.5 core
// context made current with no surface, drawing into a framebuffer object with a 32-bit float
// depth buffer (the CPU engine compares float depths too). llvmpipe bins draws into scenes and
// may corrupt a query whose begin/end straddles a flush, so every draw's query is followed by
// glFlush (or glFinish when timed): one query per scene.
#include "gl_context.h"

#define EGL_EGLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/glcorearb.h>

#include <chrono>
#include <stdexcept>
#include <string>
#include <vector>

namespace animorder {

const char* const kFlatFragmentShader =
    "#version 450 core\n"
    "layout(early_fragment_tests) in;\n"
    "out vec4 colour;\n"
    "void main() { colour = vec4(1.0); }\n";

const char* const kExpensiveFragmentShader =
    "#version 450 core\n"
    "layout(early_fragment_tests) in;\n"
    "uniform int iterations;\n"
    "out vec4 colour;\n"
    "void main() {\n"
    "    float a = gl_FragCoord.x * 0.013, b = gl_FragCoord.y * 0.017, c = gl_FragCoord.z;\n"
    "    for (int i = 0; i < iterations; ++i) {\n"
    "        a = sin(a * 1.31 + b) + 0.5 * cos(c * 2.17 - a);\n"
    "        b = exp2(-abs(a)) + log2(1.0 + b * b) * 0.25;\n"
    "        c = sqrt(abs(a * b) + 0.1) + atan(c, 1.0 + b * b);\n"
    "    }\n"
    "    colour = vec4(fract(a), fract(b), fract(c), 1.0);\n"
    "}\n";

struct GlContext::State {
    EGLDisplay display = EGL_NO_DISPLAY;
    EGLContext context = EGL_NO_CONTEXT;
    GLuint framebuffer = 0, colour = 0, depth = 0, program = 0, vao = 0, vbo = 0, samples = 0, elapsed = 0;
    std::vector<GLuint> index_buffers;
    std::vector<size_t> index_counts;
    unsigned resolution = 0;
};

namespace {

EGLDisplay open_display() {
    auto get_platform_display =
        reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (get_platform_display) {
        EGLDisplay d = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
        if (d != EGL_NO_DISPLAY && eglInitialize(d, nullptr, nullptr)) return d;
        auto query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
        EGLDeviceEXT devices[8];
        EGLint count = 0;
        if (query_devices && query_devices(8, devices, &count) && count > 0) {
            d = get_platform_display(EGL_PLATFORM_DEVICE_EXT, devices[0], nullptr);
            if (d != EGL_NO_DISPLAY && eglInitialize(d, nullptr, nullptr)) return d;
        }
    }
    EGLDisplay d = eglGetDisplay(EGL_DEFAULT_DISPLAY);
    if (d != EGL_NO_DISPLAY && eglInitialize(d, nullptr, nullptr)) return d;
    throw std::runtime_error("OpenGL reference: no EGL display could be opened (EGL error " +
                             std::to_string(eglGetError()) + ")");
}

GLuint compile(GLenum type, const char* source) {
    const GLuint shader = glCreateShader(type);
    glShaderSource(shader, 1, &source, nullptr);
    glCompileShader(shader);
    GLint ok = 0;
    glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[1024];
        glGetShaderInfoLog(shader, sizeof log, nullptr, log);
        glDeleteShader(shader);
        throw std::runtime_error(std::string("OpenGL reference: shader does not compile: ") + log);
    }
    return shader;
}

}  // namespace

GlContext::GlContext(unsigned resolution, const char* fragment_shader) : state_(std::make_unique<State>()) {
    State& s = *state_;
    if (resolution == 0) throw std::runtime_error("OpenGL reference: the resolution must be at least one pixel");
    s.resolution = resolution;
    s.display = open_display();
    const EGLint config_attributes[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT,
                                        EGL_NONE};
    EGLConfig config;
    EGLint configs = 0;
    if (!eglChooseConfig(s.display, config_attributes, &config, 1, &configs) || configs < 1)
        throw std::runtime_error("OpenGL reference: no EGL config for desktop OpenGL");
    if (!eglBindAPI(EGL_OPENGL_API)) throw std::runtime_error("OpenGL reference: eglBindAPI(EGL_OPENGL_API) failed");
    const EGLint context_attributes[] = {
        EGL_CONTEXT_MAJOR_VERSION,           4,       EGL_CONTEXT_MINOR_VERSION, 5, EGL_CONTEXT_OPENGL_PROFILE_MASK,
        EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    s.context = eglCreateContext(s.display, config, EGL_NO_CONTEXT, context_attributes);
    if (s.context == EGL_NO_CONTEXT) throw std::runtime_error("OpenGL reference: no OpenGL 4.5 core context");
    if (!eglMakeCurrent(s.display, EGL_NO_SURFACE, EGL_NO_SURFACE, s.context))
        throw std::runtime_error("OpenGL reference: cannot make the context current without a surface");

    glGenFramebuffers(1, &s.framebuffer);
    glBindFramebuffer(GL_FRAMEBUFFER, s.framebuffer);
    glGenRenderbuffers(1, &s.colour);
    glBindRenderbuffer(GL_RENDERBUFFER, s.colour);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, GLsizei(resolution), GLsizei(resolution));
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, s.colour);
    glGenRenderbuffers(1, &s.depth);
    glBindRenderbuffer(GL_RENDERBUFFER, s.depth);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, GLsizei(resolution), GLsizei(resolution));
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, s.depth);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        throw std::runtime_error("OpenGL reference: incomplete framebuffer");

    const GLuint vs =
        compile(GL_VERTEX_SHADER,
                "#version 450 core\nlayout(location = 0) in vec4 clip;\nvoid main() { gl_Position = clip; }\n");
    const GLuint fs = compile(GL_FRAGMENT_SHADER, fragment_shader);
    s.program = glCreateProgram();
    glAttachShader(s.program, vs);
    glAttachShader(s.program, fs);
    glLinkProgram(s.program);
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint linked = 0;
    glGetProgramiv(s.program, GL_LINK_STATUS, &linked);
    if (!linked) throw std::runtime_error("OpenGL reference: the program does not link");
    glUseProgram(s.program);

    glGenVertexArrays(1, &s.vao);
    glBindVertexArray(s.vao);
    glGenBuffers(1, &s.vbo);
    glBindBuffer(GL_ARRAY_BUFFER, s.vbo);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 4, GL_FLOAT, GL_FALSE, 0, nullptr);
    glGenQueries(1, &s.samples);
    glGenQueries(1, &s.elapsed);
    glViewport(0, 0, GLsizei(resolution), GLsizei(resolution));
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDepthMask(GL_TRUE);
    glClearDepth(1.0);
    glClearColor(0, 0, 0, 0);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glFrontFace(GL_CCW);
    glDisable(GL_MULTISAMPLE);
    if (glGetError() != GL_NO_ERROR) throw std::runtime_error("OpenGL reference: setup failed");
}

GlContext::~GlContext() {
    State& s = *state_;
    if (s.display == EGL_NO_DISPLAY) return;
    if (s.context != EGL_NO_CONTEXT) {
        eglMakeCurrent(s.display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(s.display, s.context);
    }
    eglTerminate(s.display);
}

std::string GlContext::renderer() const {
    const GLubyte* name = glGetString(GL_RENDERER);
    return name ? reinterpret_cast<const char*>(name) : "unknown";
}

unsigned GlContext::resolution() const { return state_->resolution; }

void GlContext::set_uniform(const char* name, int value) {
    const GLint location = glGetUniformLocation(state_->program, name);
    if (location < 0) throw std::runtime_error(std::string("OpenGL reference: the shader has no uniform ") + name);
    glUniform1i(location, value);
}

void GlContext::set_vertices(const float* clip_xyzw, size_t vertex_count) {
    glBindBuffer(GL_ARRAY_BUFFER, state_->vbo);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(vertex_count * 4 * sizeof(float)), clip_xyzw, GL_STREAM_DRAW);
}

size_t GlContext::add_index_buffer(const uint32_t* indices, size_t index_count) {
    GLuint buffer = 0;
    glGenBuffers(1, &buffer);
    state_->index_buffers.push_back(buffer);
    state_->index_counts.push_back(0);
    set_index_buffer(state_->index_buffers.size() - 1, indices, index_count);
    return state_->index_buffers.size() - 1;
}

void GlContext::set_index_buffer(size_t id, const uint32_t* indices, size_t index_count) {
    State& s = *state_;
    if (id >= s.index_buffers.size())
        throw std::runtime_error("OpenGL reference: no index buffer " + std::to_string(id));
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, s.index_buffers[id]);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(index_count * sizeof(uint32_t)), indices, GL_STATIC_DRAW);
    s.index_counts[id] = index_count;
}

GlDraw GlContext::draw(size_t id, bool timed) {
    using Clock = std::chrono::steady_clock;
    State& s = *state_;
    if (id >= s.index_buffers.size())
        throw std::runtime_error("OpenGL reference: no index buffer " + std::to_string(id));
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, s.index_buffers[id]);
    glClear(GL_DEPTH_BUFFER_BIT | GL_COLOR_BUFFER_BIT);
    Clock::time_point start;
    if (timed) {
        glFinish();  // the clear is not the draw's work
        start = Clock::now();
        glBeginQuery(GL_TIME_ELAPSED, s.elapsed);
    }
    glBeginQuery(GL_SAMPLES_PASSED, s.samples);
    glDrawElements(GL_TRIANGLES, GLsizei(s.index_counts[id]), GL_UNSIGNED_INT, nullptr);
    glEndQuery(GL_SAMPLES_PASSED);
    GlDraw result;
    if (timed) {
        glEndQuery(GL_TIME_ELAPSED);
        glFinish();
        result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
        GLuint64 nanoseconds = 0;
        glGetQueryObjectui64v(s.elapsed, GL_QUERY_RESULT, &nanoseconds);
        result.gpu_seconds = double(nanoseconds) * 1e-9;
    } else {
        glFlush();  // one query per scene (DESIGN.md: llvmpipe's binning trap)
    }
    GLuint64 passed = 0;
    glGetQueryObjectui64v(s.samples, GL_QUERY_RESULT, &passed);
    result.samples_passed = passed;
    if (glGetError() != GL_NO_ERROR) throw std::runtime_error("OpenGL reference: a draw failed");
    return result;
}

void GlContext::set_culling(bool cull) {
    if (cull)
        glEnable(GL_CULL_FACE);
    else
        glDisable(GL_CULL_FACE);
}

uint64_t GlContext::covered_pixels() {
    const size_t pixels = size_t(state_->resolution) * state_->resolution;
    std::vector<float> depth(pixels);
    glReadPixels(0, 0, GLsizei(state_->resolution), GLsizei(state_->resolution), GL_DEPTH_COMPONENT, GL_FLOAT,
                 depth.data());
    uint64_t covered = 0;
    for (float d : depth) covered += d < 1.0f;
    return covered;
}

}  // namespace animorder
