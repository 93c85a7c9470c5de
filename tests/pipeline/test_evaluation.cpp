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

#include <array>
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

namespace {

// Closed axis-aligned cubes centred on the origin, each face two triangles wound counter-clockwise
// seen from outside (checked: the normal points away from the centre), 12 triangles a cube in
// the order of `halves`.
AnimatedMesh nested_cubes(const std::vector<float>& halves) {
    AnimatedMesh mesh;
    for (const float h : halves) {
        const uint32_t base = uint32_t(mesh.vertex_count);
        for (uint32_t v = 0; v < 8; ++v)  // bit 0: +x, bit 1: +y, bit 2: +z
            mesh.keyframe_positions.insert(mesh.keyframe_positions.end(),
                                           {v & 1 ? h : -h, v & 2 ? h : -h, v & 4 ? h : -h});
        mesh.vertex_count += 8;
        for (uint32_t axis = 0; axis < 3; ++axis)
            for (uint32_t side = 0; side < 2; ++side) {
                // The face's corners in a cycle: the two other axes' bits 00, 10, 11, 01.
                const uint32_t u = 1u << ((axis + 1) % 3), w = 1u << ((axis + 2) % 3), a = side ? 1u << axis : 0;
                std::array<uint32_t, 4> q = {base + a, base + (a | u), base + (a | u | w), base + (a | w)};
                const float* p = mesh.keyframe_positions.data();
                auto corner = [&](uint32_t i, int d) { return double(p[3 * q[i] + d]); };
                double normal_out = 0;  // (q1 − q0) × (q2 − q0) · (face centre): > 0 when counter-clockwise outside
                for (int d = 0; d < 3; ++d) {
                    const int e = (d + 1) % 3, f = (d + 2) % 3;
                    const double n = (corner(1, e) - corner(0, e)) * (corner(2, f) - corner(0, f)) -
                                     (corner(1, f) - corner(0, f)) * (corner(2, e) - corner(0, e));
                    normal_out += n * (corner(0, d) + corner(2, d));
                }
                if (normal_out < 0) std::swap(q[1], q[3]);
                mesh.indices.insert(mesh.indices.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
            }
    }
    return mesh;
}

// The triangles of cubes `cubes` (12 each), in that order: one order drawing whole cubes.
std::vector<uint32_t> cube_order(std::initializer_list<uint32_t> cubes) {
    std::vector<uint32_t> order;
    for (const uint32_t c : cubes)
        for (uint32_t t = 0; t < 12; ++t) order.push_back(12 * c + t);
    return order;
}

}  // namespace

// evaluate_blend adds up, over its nodes, blend error a hand count gives. Three nested blended
// cubes (half sizes 4, 2, 1: cubes 0, 1, 2) around an opaque one (half size 0.5: cube 3), all
// single-sided, at a resolution of one pixel. The pixel's centre is the image centre, the ray from
// the eye through the framing centre (the origin: every keyframe is a uniform scale of the cubes);
// it enters each cube once, through a front face, so from every one of the random views each
// blended cube gives that pixel exactly one fragment, nearest first cube 0, 1, 2, all in front of
// the opaque cube (which hides none of them and is no layer). So at every node: covered = 1
// pixel, pairs = 3 ((0,1), (0,2), (1,2)), and an order drawing whole cubes mis-sorts the pairs
// whose nearer cube comes first:
//   3 2 1 0 (back to front)  0 of 3     0 1 2 3 (front to back)  3 of 3
//   1 2 0 3                  1 of 3 ((1,2) only: (0,1) and (0,2) are drawn farther first)
//   0 2 1 3                  2 of 3 ((0,1) and (0,2); (1,2) is drawn 2 first, fine)
// Clip 0 has 2 keyframes, clip 1 three; 5 views: 10 and 15 nodes, 25 in all; the rates are
// Σ mis-sorted / Σ pairs and Σ pixels with a mis-sorted pair / Σ covered.
// The bound sorts the blended triangles by their centroids' distance to the eye: for the three
// triangles the ray meets (the same triangle of the same face of each cube, the cubes being
// scales of one another: centroid s·c), |e − s·c|² = D² − 2D·s·(d·c) + s²|c|² with eye e = D·d,
// D = 3R ≥ 3√3·4 (R: the largest cube's corner, over the keyframes of the clip), |c|² = 11/9 and
// d·c ≥ a/3 ≥ 1/(3√3) (a = d·n of the face the ray enters, the largest component of d; the
// centroid's other two coordinates are ±1/3). Cube s1 is nearer than cube s2 < s1 when
// (11/9)(s1 + s2) < 2D(d·c), which holds as 11/9 · 6 = 7.3 < 2 · 3√3·4 / (3√3) = 8: the bound
// draws the three back to front at every node, 0 mis-sorted.
TEST(BlendEvaluation, NestedCubesAddUpToTheHandCountedPairs) {
    AnimatedMesh mesh = nested_cubes({4.0f, 2.0f, 1.0f, 0.5f});
    Primitive blended, opaque;
    blended.name = "shells";
    blended.alpha_mode = AlphaMode::Blend;
    blended.index_count = 3 * 36;
    blended.vertex_count = 24;
    opaque.name = "core";
    opaque.first_index = 3 * 36;
    opaque.index_count = 3 * 12;
    opaque.vertex_base = 24;
    opaque.vertex_count = 8;
    mesh.primitives = {blended, opaque};
    // Five keyframes, each a uniform scale of the first (the framing centre stays the origin).
    const std::vector<float> base = mesh.keyframe_positions;
    for (const float scale : {1.25f, 0.8f, 1.5f, 0.9f})
        for (const float x : base) mesh.keyframe_positions.push_back(scale * x);
    Clip walk, wave;
    walk.name = "walk";
    walk.keyframe_count = 2;
    wave.name = "wave";
    wave.first_keyframe = 2;
    wave.keyframe_count = 3;
    mesh.clips = {walk, wave};
    ASSERT_NO_THROW(validate_animated_mesh(mesh));

    EvaluationSettings settings;
    settings.views = 5;
    settings.resolution = 1;
    const std::vector<std::vector<uint32_t>> orders = {cube_order({3, 2, 1, 0}), cube_order({0, 1, 2, 3}),
                                                       cube_order({1, 2, 0, 3}), cube_order({0, 2, 1, 3})};
    std::vector<MethodBuffers> methods;
    for (const auto& o : orders) methods.push_back(fixed(o));
    const std::vector<BlendEvaluation> r = evaluate_blend(mesh, methods, settings);
    ASSERT_EQ(r.size(), orders.size() + 1);  // + the bound

    const uint64_t missorted_per_node[] = {0, 3, 1, 2, 0};  // the four orders, then the bound
    const uint64_t clip_nodes[] = {10, 15};
    for (size_t o = 0; o < r.size(); ++o) {
        SCOPED_TRACE(o);
        const uint64_t m = missorted_per_node[o], pixel = m > 0 ? 1 : 0;
        const BlendSummary& all = r[o].overall;
        EXPECT_EQ(all.nodes, 25u);
        EXPECT_EQ(all.covered, 25u);
        EXPECT_EQ(all.pairs, 75u);
        EXPECT_EQ(all.missorted_pairs, 25 * m);
        EXPECT_EQ(all.missorted_pixels, 25 * pixel);
        EXPECT_DOUBLE_EQ(all.missorted_pair_fraction, double(m) / 3.0);  // 0, 1, 1/3, 2/3, 0
        EXPECT_DOUBLE_EQ(all.missorted_pixel_fraction, double(pixel));   // 0, 1, 1, 1, 0
        ASSERT_EQ(r[o].per_clip.size(), 2u);
        for (size_t c = 0; c < 2; ++c) {
            const BlendSummary& clip = r[o].per_clip[c];
            EXPECT_EQ(clip.nodes, clip_nodes[c]) << "clip " << c;
            EXPECT_EQ(clip.covered, clip_nodes[c]) << "clip " << c;
            EXPECT_EQ(clip.pairs, 3 * clip_nodes[c]) << "clip " << c;
            EXPECT_EQ(clip.missorted_pairs, m * clip_nodes[c]) << "clip " << c;
            EXPECT_EQ(clip.missorted_pixels, pixel * clip_nodes[c]) << "clip " << c;
            EXPECT_DOUBLE_EQ(clip.missorted_pair_fraction, double(m) / 3.0) << "clip " << c;
        }
    }
}
