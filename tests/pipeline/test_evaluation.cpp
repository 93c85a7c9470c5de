// The evaluation harness: every way a method picks its buffer (fixed, per keyframe, per node for
// the oracle) checked against the engine scoring the same buffers directly, and the oracle against
// a scene where front-to-back is provably overdraw-free.
#include "animorder/animated_mesh.h"
#include "animorder/evaluation.h"
#include "animorder/invalid_input.h"
#include "animorder/mesh_patches.h"
#include "animorder/methods.h"
#include "animorder/overdraw.h"
#include "animorder/procedural_character.h"
#include "animorder/procedural_shapes.h"
#include "animorder/viewpoints.h"
#include "support/meshes.h"

#include <gtest/gtest.h>

#include <numeric>

using namespace animorder;

namespace {

// Two unit-radius spheres side by side on the x axis (centres ±2): from a view near the axis the
// nearer one hides part of the farther one; their triangles' centroids are never closer than 2
// apart in depth where they overlap on screen, so a front-to-back triangle order shades nothing
// twice (a convex closed sphere's front faces never overlap one another).
AnimatedMesh two_spheres() {
    const AnimatedMesh sphere = make_uv_sphere(1500);
    AnimatedMesh mesh;
    mesh.vertex_count = 2 * sphere.vertex_count;
    for (int s = 0; s < 2; ++s) {
        const float* p = sphere.keyframe(0);
        for (size_t v = 0; v < sphere.vertex_count; ++v) {
            mesh.keyframe_positions.push_back(p[3 * v] + (s == 0 ? -2.0f : 2.0f));
            mesh.keyframe_positions.push_back(p[3 * v + 1]);
            mesh.keyframe_positions.push_back(p[3 * v + 2]);
        }
        for (uint32_t i : sphere.indices) mesh.indices.push_back(i + uint32_t(s * sphere.vertex_count));
    }
    Primitive primitive;
    primitive.name = "spheres";
    primitive.index_count = mesh.indices.size();
    primitive.vertex_count = mesh.vertex_count;
    mesh.primitives = {primitive};
    Clip clip;
    clip.name = "static";
    clip.keyframe_count = 1;
    mesh.clips = {clip};
    return mesh;
}

MethodBuffers fixed(std::vector<uint32_t> order) {
    MethodBuffers m;
    m.orders.push_back(std::move(order));
    return m;
}

std::vector<uint32_t> iota_order(size_t n) {
    std::vector<uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    return order;
}

// The engine directly: mean and pooled OVR of one order over one clip's evaluation nodes.
OverdrawSummary direct(const AnimatedMesh& mesh, size_t clip, const std::vector<uint32_t>& order,
                       const EvaluationSettings& settings) {
    const Framing all = frame_animated_mesh(mesh);
    std::vector<uint32_t> keyframes;
    for (size_t f = 0; f < mesh.clips[clip].keyframe_count; ++f)
        keyframes.push_back(uint32_t(mesh.clips[clip].first_keyframe + f));
    const Framing framing = frame_subset(all, keyframes);
    const std::vector<float> directions = random_sphere_directions(settings.views, settings.seed);
    std::vector<OverdrawNode> nodes;
    for (uint32_t k : keyframes)
        for (size_t v = 0; v < settings.views; ++v) {
            OverdrawNode node;
            node.keyframe = k;
            std::copy(&directions[3 * v], &directions[3 * v] + 3, node.direction);
            nodes.push_back(node);
        }
    const std::vector<uint32_t> ranks = make_rank_table({order.data()}, mesh.triangle_count());
    std::vector<uint64_t> visible(nodes.size()), passed(nodes.size());
    ScoreSettings score;
    score.resolution = settings.resolution;
    const std::vector<uint8_t> modes = opaque_pass_modes(mesh);  // the character's hair and cape blend
    score.triangle_modes = modes.empty() ? nullptr : modes.data();
    score_nodes(visible.data(), passed.data(), mesh.keyframe_positions.data(), mesh.vertex_count, framing,
                mesh.indices.data(), mesh.indices.size(), nodes.data(), nodes.size(), ranks.data(), 1, score);
    OverdrawSummary s;
    double ratios = 0, p = 0, v = 0;
    for (size_t n = 0; n < nodes.size(); ++n) {
        ratios += double(passed[n]) / double(visible[n]);
        p += double(passed[n]);
        v += double(visible[n]);
    }
    s.nodes = nodes.size();
    s.ovr_mean = ratios / double(nodes.size());
    s.ovr_pooled = p / v;
    return s;
}

}  // namespace

TEST(Evaluation, FrontToBackPatchOrderHandWorked) {
    const float centroids[] = {0, 0, 5, 0, 0, 1, 0, 0, -3, 0, 0, 1};  // patch 3 ties patch 1
    const float eye[3] = {0, 0, 10};
    EXPECT_EQ(front_to_back_patch_order(centroids, 4, eye), (std::vector<uint32_t>{0, 1, 3, 2}));
}

TEST(Evaluation, FixedOrdersMatchTheEngineScoredDirectly) {
    const AnimatedMesh mesh = make_procedural_character();
    EvaluationSettings settings;
    settings.views = 6;
    settings.resolution = 96;
    const StaticMethodResult sander = run_static_method(mesh, StaticMethod::StaticSander07, {});
    const std::vector<uint32_t> identity = iota_order(mesh.triangle_count());
    const auto results = evaluate_methods(mesh, {fixed(identity), fixed(sander.order)}, settings);
    ASSERT_EQ(results.size(), 2u);
    for (size_t c = 0; c < mesh.clips.size(); ++c) {
        const OverdrawSummary a = direct(mesh, c, identity, settings), b = direct(mesh, c, sander.order, settings);
        EXPECT_EQ(results[0].per_clip[c].nodes, a.nodes);
        EXPECT_DOUBLE_EQ(results[0].per_clip[c].ovr_mean, a.ovr_mean);
        EXPECT_DOUBLE_EQ(results[0].per_clip[c].ovr_pooled, a.ovr_pooled);
        EXPECT_DOUBLE_EQ(results[1].per_clip[c].ovr_mean, b.ovr_mean);
        EXPECT_LT(b.ovr_mean, a.ovr_mean);  // the sort does remove overdraw
    }
}

TEST(Evaluation, PerKeyframeBuffersAreTheKeyframesOwn) {
    // Two one-keyframe clips: a method drawing buffer 1 at keyframe 0 and buffer 0 at keyframe 1
    // scores, clip by clip, exactly what those fixed buffers score there.
    const AnimatedMesh character = make_procedural_character();
    AnimatedMesh mesh = character;
    mesh.keyframe_positions.assign(character.keyframe(10), character.keyframe(10) + 3 * character.vertex_count);
    mesh.keyframe_positions.insert(mesh.keyframe_positions.end(), character.keyframe(60),
                                   character.keyframe(60) + 3 * character.vertex_count);
    mesh.clips.resize(2);
    mesh.clips[0] = {"a", 0, 30, 0, 1};
    mesh.clips[1] = {"b", 0, 30, 1, 1};
    StaticMethodSettings at0, at1;
    at1.keyframe = 1;
    const std::vector<uint32_t> b0 = run_static_method(mesh, StaticMethod::StaticSander07, at0).order;
    const std::vector<uint32_t> b1 = run_static_method(mesh, StaticMethod::StaticSander07, at1).order;
    ASSERT_NE(b0, b1);
    MethodBuffers per_keyframe;
    per_keyframe.orders = {b0, b1};
    per_keyframe.keyframe_buffer = {1, 0};
    EvaluationSettings settings;
    settings.views = 8;
    settings.resolution = 96;
    const auto r = evaluate_methods(mesh, {per_keyframe, fixed(b0), fixed(b1)}, settings);
    EXPECT_DOUBLE_EQ(r[0].per_clip[0].ovr_mean, r[2].per_clip[0].ovr_mean);
    EXPECT_DOUBLE_EQ(r[0].per_clip[1].ovr_mean, r[1].per_clip[1].ovr_mean);
    EXPECT_NE(r[0].overall.ovr_mean, r[1].overall.ovr_mean);

    per_keyframe.keyframe_buffer = {0};  // one entry for two keyframes
    EXPECT_THROW(evaluate_methods(mesh, {per_keyframe}, settings), InvalidInput);
    per_keyframe.keyframe_buffer = {0, 2};  // no buffer 2
    EXPECT_THROW(evaluate_methods(mesh, {per_keyframe}, settings), InvalidInput);
}

TEST(Evaluation, OracleShadesEveryPixelOnceWhereFrontToBackIsExact) {
    const AnimatedMesh mesh = two_spheres();
    const size_t half = mesh.triangle_count() / 2;
    // The far sphere first from views along +x: the +x sphere (second half) drawn first.
    std::vector<uint32_t> plus_x_first = iota_order(mesh.triangle_count());
    std::rotate(plus_x_first.begin(), plus_x_first.begin() + ptrdiff_t(half), plus_x_first.end());
    MethodBuffers oracle;
    oracle.front_to_back = std::make_shared<MeshPatches>(build_mesh_patches(mesh, 3.0));  // single triangles
    EvaluationSettings settings;
    settings.views = 80;
    settings.resolution = 128;
    const auto r =
        evaluate_methods(mesh, {oracle, fixed(iota_order(mesh.triangle_count())), fixed(plus_x_first)}, settings);
    EXPECT_DOUBLE_EQ(r[0].overall.ovr_mean, 1.0);
    EXPECT_DOUBLE_EQ(r[0].overall.ovr_pooled, 1.0);
    EXPECT_GT(r[1].overall.ovr_mean, 1.001);  // each fixed order is back to front from half the views
    EXPECT_GT(r[2].overall.ovr_mean, 1.001);

    // Coarser patches are a weaker bound, never below 1.
    oracle.front_to_back = std::make_shared<MeshPatches>(build_mesh_patches(mesh, 0.85));
    const auto coarse = evaluate_methods(mesh, {oracle}, settings);
    EXPECT_GE(coarse[0].overall.ovr_mean, 1.0);
}

TEST(Evaluation, SameNumbersWithOneOrTwoThreads) {
    const AnimatedMesh mesh = make_procedural_character();
    MethodBuffers oracle;
    oracle.front_to_back = std::make_shared<MeshPatches>(build_mesh_patches(mesh, 0.85));
    EvaluationSettings one;
    one.views = 4;
    one.resolution = 64;
    one.threads = 1;
    EvaluationSettings two = one;
    two.threads = 2;
    const std::vector<MethodBuffers> methods = {oracle, fixed(iota_order(mesh.triangle_count()))};
    const auto a = evaluate_methods(mesh, methods, one), b = evaluate_methods(mesh, methods, two);
    for (size_t m = 0; m < methods.size(); ++m) {
        EXPECT_EQ(a[m].overall.ovr_mean, b[m].overall.ovr_mean);
        EXPECT_EQ(a[m].overall.ovr_pooled, b[m].overall.ovr_pooled);
    }
}
