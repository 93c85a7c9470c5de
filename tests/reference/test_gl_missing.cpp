// Built instead of test_gl_crosscheck and test_render_time when CMake found no OpenGL/EGL: the
// missing OpenGL checks show as a skip in the CTest summary, and as a failure where
// ANIMORDER_REQUIRE requires gl (CI).
#include "support/require.h"

#include <gtest/gtest.h>

TEST(GlReference, OpenGLWasFoundAtConfigureTime) {
    ANIMORDER_REQUIRE_OR_SKIP(
        "gl", false,
        "OpenGL/EGL was not found at configure time: the OpenGL cross-check and the rendering-time "
        "check were not built (install libegl-dev and libopengl-dev, then reconfigure)");
}
