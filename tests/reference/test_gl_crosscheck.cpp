// The CPU rasteriser against real OpenGL (Mesa llvmpipe over EGL here; a GPU driver elsewhere):
// the same clip-space vertices, the same orders, occlusion-query counts against ours.
#include "gl_overdraw.h"

#include "animorder/animated_mesh.h"
#include "animorder/camera.h"
#include "animorder/gltf_loader.h"
#include "animorder/overdraw.h"
#include "animorder/procedural_character.h"
#include "animorder/procedural_shapes.h"
#include "animorder/rasterizer.h"
#include "animorder/tipsify.h"
#include "animorder/triangle_order.h"
#include "animorder/viewpoints.h"

#include "support/require.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <random>

using namespace animorder;

namespace {

// No context: skipped with the reason, or failed where ANIMORDER_REQUIRE requires gl (CI has Mesa).
std::unique_ptr<GlOverdrawReference> open_reference(unsigned resolution, std::string& why) {
    try {
        return std::make_unique<GlOverdrawReference>(resolution);
    } catch (const std::exception& e) {
        why = std::string("no OpenGL context: ") + e.what();
        return nullptr;
    }
}

// Our counts against OpenGL's, measured on Mesa llvmpipe (deterministic: the same on every run):
// 313 of the 320 counts (4 meshes x 20 views x visible + 3 orders) exactly equal, the other 7
// within 0.0114% (observed 2026-11, llvmpipe LLVM 15.0.6, 256 bits). The tolerance allows
// less than twice that; a GPU driver may round differently, so the exact count is checked only
// on llvmpipe.
constexpr double kTolerance = 0.0002;
constexpr size_t kProceduralExactOnLlvmpipe = 234;  // of 240 (walk, wave, torus knot); Ganfaul adds 79 of 80

// Without culling (torus knot and the character's walk, 20 views x 4 counts each): measured on
// llvmpipe as above.
constexpr size_t kDoubleSidedExactOnLlvmpipe = 149;  // of 160; worst 0.0083% (2026-11, LLVM 15.0.6)

// The exact counts above and kTolerance hold on llvmpipe, the reference these rules follow.
bool is_llvmpipe(const GlOverdrawReference& gl) { return gl.renderer().find("llvmpipe") != std::string::npos; }

// A hardware driver rounds depths differently from llvmpipe, and near-coincident surfaces (the
// double-sided cards and cape) then resolve a few ties the other way. Measured on an NVIDIA H100
// 80GB HBM3 (driver 580.159.04, EGL device platform, 2026-11-27): the procedural meshes 225 of 240
// counts exactly equal, worst 0.0137%; double-sided 96 of 160, worst 0.0296%. The tolerance for
// any renderer but llvmpipe allows about twice the worst.
constexpr double kDriverTolerance = 0.0006;

double tolerance_for(const GlOverdrawReference& gl) { return is_llvmpipe(gl) ? kTolerance : kDriverTolerance; }

std::string shared_data(const std::string& relative) { return animorder::test::shared_data_path(relative).string(); }

// The bundled character's opaque primitives (body, shield) with their own vertices: the character
// these counts were measured on before it gained blended hair and a cape (issue 18), whose
// vertices come after.
AnimatedMesh opaque_character() {
    const AnimatedMesh full = make_procedural_character();
    AnimatedMesh m = full;
    m.primitives.resize(2);
    m.indices.resize(m.primitives[1].first_index + m.primitives[1].index_count);
    m.vertex_count = *std::max_element(m.indices.begin(), m.indices.end()) + 1;
    m.keyframe_positions.clear();
    for (size_t k = 0; k < full.keyframe_count(); ++k)
        m.keyframe_positions.insert(m.keyframe_positions.end(), full.keyframe(k),
                                    full.keyframe(k) + 3 * m.vertex_count);
    return m;
}

struct Totals {
    size_t comparisons = 0, exact = 0;
    double worst = 0;
};

void compare_mesh(GlOverdrawReference& gl, const AnimatedMesh& mesh, size_t keyframe, unsigned resolution,
                  Totals& totals, bool double_sided = false) {
    const double tolerance = tolerance_for(gl);
    SCOPED_TRACE(mesh.name + " keyframe " + std::to_string(keyframe));
    const Framing framing = frame_animated_mesh(mesh);
    const size_t n = mesh.triangle_count();
    std::vector<uint32_t> tipsified(n), random(n);
    tipsify(tipsified.data(), mesh.indices.data(), mesh.indices.size(), mesh.vertex_count);
    for (size_t i = 0; i < n; ++i) random[i] = uint32_t(i);
    std::mt19937 rng(5);
    for (size_t i = n; i > 1; --i) std::swap(random[i - 1], random[rng() % i]);

    const std::vector<float> views = random_sphere_directions(20, 99);
    std::vector<float> clip(mesh.vertex_count * 4);
    NodeRasterizer ours;
    for (size_t v = 0; v < 20; ++v) {
        const float* dir = &views[3 * v];
        transform_to_clip(clip.data(), mesh.keyframe(keyframe), mesh.vertex_count, &framing.centres[3 * keyframe],
                          node_view_projection(dir, framing.radius));
        // Front to back at this view: triangles by eye distance of their centroid.
        const float eye[3] = {3 * framing.radius * dir[0], 3 * framing.radius * dir[1], 3 * framing.radius * dir[2]};
        std::vector<double> distance(n);
        const float* p = mesh.keyframe(keyframe);
        const float* c = &framing.centres[3 * keyframe];
        for (size_t t = 0; t < n; ++t) {
            double d2 = 0;
            for (int d = 0; d < 3; ++d) {
                const double centroid = (double(p[3 * mesh.indices[3 * t] + d]) + p[3 * mesh.indices[3 * t + 1] + d] +
                                         p[3 * mesh.indices[3 * t + 2] + d]) /
                                            3.0 -
                                        c[d];
                d2 += (centroid - eye[d]) * (centroid - eye[d]);
            }
            distance[t] = d2;
        }
        std::vector<uint32_t> front(n);
        for (size_t i = 0; i < n; ++i) front[i] = uint32_t(i);
        std::stable_sort(front.begin(), front.end(), [&](uint32_t a, uint32_t b) { return distance[a] < distance[b]; });

        const std::vector<std::vector<uint32_t>*> orders = {&tipsified, &random, &front};
        std::vector<std::vector<uint32_t>> index_buffers;
        std::vector<const uint32_t*> pointers;
        for (auto* o : orders) {
            index_buffers.emplace_back(mesh.indices.size());
            apply_triangle_order(index_buffers.back().data(), mesh.indices.data(), o->data(), n);
            pointers.push_back(o->data());
        }
        const std::vector<uint32_t> ranks = make_rank_table(pointers, n);
        const std::vector<uint8_t> both(double_sided ? n : 0, 1);
        ours.rasterize(clip.data(), mesh.vertex_count, mesh.indices.data(), mesh.indices.size(), resolution,
                       double_sided ? both.data() : nullptr);
        std::vector<uint64_t> passed(3);
        ours.score(passed.data(), ranks.data(), 3);
        const GlNodeCounts reference = gl.score(clip.data(), mesh.vertex_count, index_buffers, double_sided);

        auto check = [&](uint64_t a, uint64_t b, const char* what) {
            const double relative = b ? std::fabs(double(a) - double(b)) / double(b) : double(a != b);
            totals.worst = std::max(totals.worst, relative);
            totals.exact += a == b;
            ++totals.comparisons;
            EXPECT_LE(relative, tolerance) << what << " view " << v << ": ours " << a << ", OpenGL " << b;
        };
        check(ours.visible_pixels(), reference.visible, "visible");
        for (size_t o = 0; o < 3; ++o)
            check(passed[o], reference.passed[o], o == 0 ? "tipsify" : o == 1 ? "random" : "front-to-back");
    }
}

}  // namespace

TEST(GlCrosscheck, PixelAlignedQuadCountsExactlyNTimesN) {
    for (unsigned n : {1u, 7u, 64u, 256u}) {
        std::string why;
        auto gl = open_reference(n, why);
        ANIMORDER_REQUIRE_OR_SKIP("gl", gl != nullptr, why);
        const float clip[16] = {-1, -1, 0, 1, 1, -1, 0, 1, 1, 1, 0, 1, -1, 1, 0, 1};
        const std::vector<std::vector<uint32_t>> ib = {{0, 1, 2, 0, 2, 3}};
        const GlNodeCounts counts = gl->score(clip, 4, ib);
        EXPECT_EQ(counts.visible, uint64_t(n) * n);
        EXPECT_EQ(counts.passed[0], uint64_t(n) * n) << "no double count on the shared edge";
        NodeRasterizer ours;
        ours.rasterize(clip, 4, ib[0].data(), 6, n);
        EXPECT_EQ(ours.visible_pixels(), counts.visible);
        EXPECT_EQ(ours.fragments(), counts.passed[0]);
    }
}

TEST(GlCrosscheck, ThreeMeshesTwentyViewsThreeOrdersMatchOpenGL) {
    const unsigned resolution = 256;
    std::string why;
    auto gl = open_reference(resolution, why);
    ANIMORDER_REQUIRE_OR_SKIP("gl", gl != nullptr, why);
    std::printf("OpenGL renderer: %s\n", gl->renderer().c_str());
    Totals totals;
    const AnimatedMesh character = opaque_character();
    compare_mesh(*gl, character, 10, resolution, totals);                                      // walk
    compare_mesh(*gl, character, character.clips[1].first_keyframe + 20, resolution, totals);  // wave
    compare_mesh(*gl, make_torus_knot(10000), 0, resolution, totals);
    const size_t procedural_exact = totals.exact;
    std::printf("procedural meshes: %zu counts compared, %zu exactly equal, worst relative difference %.6f%%\n",
                totals.comparisons, totals.exact, 100 * totals.worst);
    const std::string ganfaul = shared_data("mixamo-ganfaul/Ganfaul.gltf");
    const bool have_ganfaul = std::filesystem::exists(ganfaul);
    if (have_ganfaul) {
        const AnimatedMesh mesh = load_gltf(ganfaul);
        compare_mesh(*gl, mesh, mesh.clips[0].first_keyframe + mesh.clips[0].keyframe_count / 2, resolution, totals);
    }
    std::printf("cross-check: %zu counts compared, %zu exactly equal, worst relative difference %.6f%%\n",
                totals.comparisons, totals.exact, 100 * totals.worst);
    EXPECT_EQ(totals.comparisons, have_ganfaul ? 320u : 240u);  // 20 views x 4 counts per mesh
    EXPECT_LE(totals.worst, tolerance_for(*gl));
    if (is_llvmpipe(*gl)) {
        EXPECT_EQ(procedural_exact, kProceduralExactOnLlvmpipe) << "of the 240 counts of the three procedural meshes";
        if (have_ganfaul) {
            EXPECT_EQ(totals.exact, 313u) << "DESIGN.md: llvmpipe agrees on 313 of 320 counts";
        }
    } else {
        std::printf("not llvmpipe (%s): the exact-match counts are not checked\n", gl->renderer().c_str());
    }
    ANIMORDER_REQUIRE_DATA(ganfaul);
}

// Double-sided materials: the same meshes drawn without back-face culling by both (every back
// face becomes a fragment source), and the same counts with culling as the test above.
TEST(GlCrosscheck, DoubleSidedMeshesMatchOpenGLWithoutCulling) {
    const unsigned resolution = 256;
    std::string why;
    auto gl = open_reference(resolution, why);
    ANIMORDER_REQUIRE_OR_SKIP("gl", gl != nullptr, why);
    Totals culled, both;
    const AnimatedMesh knot = make_torus_knot(10000);
    AnimatedMesh character = make_procedural_character();
    compare_mesh(*gl, knot, 0, resolution, culled, false);
    compare_mesh(*gl, knot, 0, resolution, both, true);
    compare_mesh(*gl, character, 10, resolution, both, true);
    std::printf("double-sided cross-check: %zu counts compared, %zu exactly equal, worst relative difference %.6f%%\n",
                both.comparisons, both.exact, 100 * both.worst);
    EXPECT_EQ(both.comparisons, 160u);
    EXPECT_LE(both.worst, tolerance_for(*gl));
    EXPECT_LE(culled.worst, tolerance_for(*gl));
    if (is_llvmpipe(*gl)) {
        EXPECT_EQ(both.exact, kDoubleSidedExactOnLlvmpipe) << "of the 160 double-sided counts";
    }
}
