// OpenGL reference: occlusion-query overdraw counts over EGL, as DESIGN.md's notes describe.
//
// Headless: eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA), an OpenGL 4.5 core context
// made current with no surface, drawing into a framebuffer object with a 32-bit float depth
// buffer (the CPU engine compares float depths too). The vertex shader passes clip-space
// positions through, so both implementations get the very same floats. llvmpipe bins draws into
// scenes and may corrupt a query whose begin/end straddles a flush, so every query is followed
// by glFlush() and the counts are checked for plausibility.
#include "gl_overdraw.h"

#define EGL_EGLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES
#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GL/glcorearb.h>

#include <stdexcept>
#include <string>

namespace animorder {

struct GlOverdrawReference::Context {
    EGLDisplay display = EGL_NO_DISPLAY;
    EGLContext context = EGL_NO_CONTEXT;
    GLuint framebuffer = 0, colour = 0, depth = 0, program = 0, vao = 0, vbo = 0, ibo = 0, query = 0;
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
        throw std::runtime_error(std::string("OpenGL reference: shader does not compile: ") + log);
    }
    return shader;
}

}  // namespace

GlOverdrawReference::GlOverdrawReference(unsigned resolution) : context_(std::make_unique<Context>()) {
    Context& c = *context_;
    c.resolution = resolution;
    c.display = open_display();
    const EGLint config_attributes[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    EGLConfig config;
    EGLint configs = 0;
    if (!eglChooseConfig(c.display, config_attributes, &config, 1, &configs) || configs < 1)
        throw std::runtime_error("OpenGL reference: no EGL config for desktop OpenGL");
    if (!eglBindAPI(EGL_OPENGL_API)) throw std::runtime_error("OpenGL reference: eglBindAPI(EGL_OPENGL_API) failed");
    const EGLint context_attributes[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                                         EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    c.context = eglCreateContext(c.display, config, EGL_NO_CONTEXT, context_attributes);
    if (c.context == EGL_NO_CONTEXT) throw std::runtime_error("OpenGL reference: no OpenGL 4.5 core context");
    if (!eglMakeCurrent(c.display, EGL_NO_SURFACE, EGL_NO_SURFACE, c.context))
        throw std::runtime_error("OpenGL reference: cannot make the context current without a surface");

    glGenFramebuffers(1, &c.framebuffer);
    glBindFramebuffer(GL_FRAMEBUFFER, c.framebuffer);
    glGenRenderbuffers(1, &c.colour);
    glBindRenderbuffer(GL_RENDERBUFFER, c.colour);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, GLsizei(resolution), GLsizei(resolution));
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, c.colour);
    glGenRenderbuffers(1, &c.depth);
    glBindRenderbuffer(GL_RENDERBUFFER, c.depth);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, GLsizei(resolution), GLsizei(resolution));
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, c.depth);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
        throw std::runtime_error("OpenGL reference: incomplete framebuffer");

    const GLuint vs = compile(GL_VERTEX_SHADER,
                              "#version 450 core\nlayout(location = 0) in vec4 clip;\nvoid main() { gl_Position = clip; }\n");
    const GLuint fs = compile(GL_FRAGMENT_SHADER,
                              "#version 450 core\nlayout(early_fragment_tests) in;\nout vec4 colour;\n"
                              "void main() { colour = vec4(1.0); }\n");
    c.program = glCreateProgram();
    glAttachShader(c.program, vs);
    glAttachShader(c.program, fs);
    glLinkProgram(c.program);
    glDeleteShader(vs);
    glDeleteShader(fs);
    glUseProgram(c.program);

    glGenVertexArrays(1, &c.vao);
    glBindVertexArray(c.vao);
    glGenBuffers(1, &c.vbo);
    glGenBuffers(1, &c.ibo);
    glGenQueries(1, &c.query);
    glViewport(0, 0, GLsizei(resolution), GLsizei(resolution));
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glClearDepth(1.0);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glFrontFace(GL_CCW);
    glDisable(GL_MULTISAMPLE);
    if (glGetError() != GL_NO_ERROR) throw std::runtime_error("OpenGL reference: setup failed");
}

GlOverdrawReference::~GlOverdrawReference() {
    Context& c = *context_;
    if (c.display == EGL_NO_DISPLAY) return;
    if (c.context != EGL_NO_CONTEXT) {
        eglMakeCurrent(c.display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(c.display, c.context);
    }
    eglTerminate(c.display);
}

std::string GlOverdrawReference::renderer() const {
    const GLubyte* name = glGetString(GL_RENDERER);
    return name ? reinterpret_cast<const char*>(name) : "unknown";
}

GlNodeCounts GlOverdrawReference::score(const float* clip_xyzw, size_t vertex_count,
                                        const std::vector<std::vector<uint32_t>>& index_buffers) {
    Context& c = *context_;
    glBindBuffer(GL_ARRAY_BUFFER, c.vbo);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(vertex_count * 4 * sizeof(float)), clip_xyzw, GL_STREAM_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 4, GL_FLOAT, GL_FALSE, 0, nullptr);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, c.ibo);

    GlNodeCounts counts;
    const uint64_t pixels = uint64_t(c.resolution) * c.resolution;
    for (size_t o = 0; o < index_buffers.size(); ++o) {
        const auto& ib = index_buffers[o];
        glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(ib.size() * 4), ib.data(), GL_STREAM_DRAW);
        glClear(GL_DEPTH_BUFFER_BIT | GL_COLOR_BUFFER_BIT);
        glBeginQuery(GL_SAMPLES_PASSED, c.query);
        glDrawElements(GL_TRIANGLES, GLsizei(ib.size()), GL_UNSIGNED_INT, nullptr);
        glEndQuery(GL_SAMPLES_PASSED);
        glFlush();  // one query per scene (DESIGN.md: llvmpipe's binning trap)
        GLuint64 passed = 0;
        glGetQueryObjectui64v(c.query, GL_QUERY_RESULT, &passed);
        counts.passed.push_back(passed);
        if (o == 0) {
            std::vector<float> depth(pixels);
            glReadPixels(0, 0, GLsizei(c.resolution), GLsizei(c.resolution), GL_DEPTH_COMPONENT, GL_FLOAT, depth.data());
            for (float d : depth) counts.visible += d < 1.0f;
        }
    }
    if (glGetError() != GL_NO_ERROR) throw std::runtime_error("OpenGL reference: a draw failed");
    for (uint64_t p : counts.passed)
        if (p < counts.visible || counts.visible > pixels)
            throw std::runtime_error("OpenGL reference: implausible query result (passed " + std::to_string(p) +
                                     ", visible " + std::to_string(counts.visible) + ")");
    return counts;
}

}  // namespace animorder
