// The rasteriser on hand-worked scenes (coverage, fill rule, culling, clipping, depth order),
// and its multi-order scoring against a brute-force z-buffer that draws each order separately.
#include "animorder/animated_mesh.h"
#include "animorder/camera.h"
#include "animorder/invalid_input.h"
#include "animorder/overdraw.h"
#include "animorder/procedural_character.h"
#include "animorder/procedural_shapes.h"
#include "animorder/rasterizer.h"
#include "animorder/viewpoints.h"
#include "support/meshes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <numeric>
#include <random>
#include <tuple>
#include <vector>

using namespace animorder;

namespace {

using Copy = NodeRasterizer::Copy;

// The copies of the per-node code this CPU runs, narrowest (portable) first.
std::vector<Copy> copies_here() {
    std::vector<Copy> copies;
    for (const Copy c : {Copy::Portable, Copy::Avx2, Copy::Avx512})
        if (c <= NodeRasterizer::widest_copy()) copies.push_back(c);
    return copies;
}

// A scene in clip space with w = 1 (orthographic): x, y, z are NDC.
struct Scene {
    std::vector<float> clip;
    std::vector<uint32_t> ib;
    unsigned resolution;

    explicit Scene(unsigned res) : resolution(res) {}
    uint32_t vertex(float x, float y, float z) {
        clip.insert(clip.end(), {x, y, z, 1.0f});
        return uint32_t(clip.size() / 4 - 1);
    }
    // Window-space rectangle [x0,x1]×[y0,y1] (pixels, y up) at NDC depth z, as two triangles.
    void rect(float x0, float y0, float x1, float y1, float z, bool counter_clockwise = true) {
        auto ndc = [&](float p) { return 2.0f * p / float(resolution) - 1.0f; };
        const uint32_t a = vertex(ndc(x0), ndc(y0), z), b = vertex(ndc(x1), ndc(y0), z),
                       c = vertex(ndc(x1), ndc(y1), z), d = vertex(ndc(x0), ndc(y1), z);
        if (counter_clockwise)
            ib.insert(ib.end(), {a, b, c, a, c, d});
        else
            ib.insert(ib.end(), {a, c, b, a, d, c});
    }
    size_t triangles() const { return ib.size() / 3; }
    NodeRasterizer rasterize() const {
        NodeRasterizer r;
        r.rasterize(clip.data(), clip.size() / 4, ib.data(), ib.size(), resolution);
        return r;
    }
};

// Orders given as lists of rectangles (each rectangle = 2 consecutive triangles).
std::vector<uint64_t> score_rect_orders(const Scene& s, const std::vector<std::vector<uint32_t>>& rect_orders) {
    std::vector<std::vector<uint32_t>> orders;
    for (const auto& rects : rect_orders) {
        std::vector<uint32_t> order;
        for (uint32_t r : rects) order.insert(order.end(), {2 * r, 2 * r + 1});
        orders.push_back(order);
    }
    std::vector<const uint32_t*> pointers;
    for (const auto& o : orders) pointers.push_back(o.data());
    const std::vector<uint32_t> ranks = make_rank_table(pointers, s.triangles());
    std::vector<uint64_t> passed(orders.size());
    s.rasterize().score(passed.data(), ranks.data(), orders.size());
    return passed;
}

}  // namespace

TEST(Rasterizer, PixelAlignedQuadCoversExactlyItsPixelsOnce) {
    for (unsigned n : {1u, 7u, 64u, 256u}) {
        Scene s(n);
        s.rect(0, 0, float(n), float(n), 0.0f);
        const NodeRasterizer r = s.rasterize();
        EXPECT_EQ(r.visible_pixels(), uint64_t(n) * n) << n;
        EXPECT_EQ(r.fragments(), uint64_t(n) * n) << n << ": the shared diagonal is covered once";
    }
    Scene s(16);
    s.rect(2, 3, 6, 7, 0.0f);
    EXPECT_EQ(s.rasterize().visible_pixels(), 16u);
    EXPECT_EQ(s.rasterize().fragments(), 16u);
}

TEST(Rasterizer, TopLeftRuleOnPixelCentres) {
    // Edges through pixel centres: x ∈ [2.5, 6.5] covers centre columns 2.5..5.5 (the left edge
    // owns its centres, the right edge does not); y (up) ∈ [3.5, 7.5] covers centre rows 4.5..7.5
    // (after flipping y, 7.5 is the top edge, which owns its centres; 3.5 is the bottom).
    const unsigned n = 16;
    Scene s(n);
    s.rect(2.5f, 3.5f, 6.5f, 7.5f, 0.0f);
    const NodeRasterizer r = s.rasterize();
    const std::vector<uint32_t> ranks{0, 1};
    const std::vector<uint32_t> image = r.passed_per_pixel(ranks.data(), 1, 0);
    for (unsigned row = 0; row < n; ++row)
        for (unsigned col = 0; col < n; ++col) {
            const unsigned gl_row = n - 1 - row;
            const bool expected = col >= 2 && col <= 5 && gl_row >= 4 && gl_row <= 7;
            EXPECT_EQ(image[row * n + col], expected ? 1u : 0u) << "row " << row << " col " << col;
        }
}

TEST(Rasterizer, AdjacentQuadsShareTheirEdgeWithoutGapOrDoubleCount) {
    // Four quads tiling [0,10]² at a fractional split (3.3, 6.5): every pixel exactly once.
    Scene s(10);
    s.rect(0, 0, 3.3f, 6.5f, 0);
    s.rect(3.3f, 0, 10, 6.5f, 0);
    s.rect(0, 6.5f, 3.3f, 10, 0);
    s.rect(3.3f, 6.5f, 10, 10, 0);
    const NodeRasterizer r = s.rasterize();
    EXPECT_EQ(r.visible_pixels(), 100u);
    EXPECT_EQ(r.fragments(), 100u);
}

TEST(Rasterizer, BackFacesAreCulled) {
    Scene s(16);
    s.rect(0, 0, 16, 16, 0.0f, /*counter_clockwise=*/false);
    EXPECT_EQ(s.rasterize().visible_pixels(), 0u);
    EXPECT_EQ(s.rasterize().fragments(), 0u);
}

TEST(Rasterizer, OverdrawDependsOnOrderAsHandCounted) {
    // Rect 0 (near, z = −0.6) covers columns 0–3, rect 1 (far, z = 0.2) columns 2–5, rows 0–3.
    Scene s(8);
    s.rect(0, 0, 4, 4, -0.6f);
    s.rect(2, 0, 6, 4, 0.2f);
    EXPECT_EQ(s.rasterize().visible_pixels(), 24u);
    // Near first: 16 + the 8 far-only pixels = 24. Far first: 16 + 16 = 32.
    EXPECT_EQ(score_rect_orders(s, {{0, 1}, {1, 0}}), (std::vector<uint64_t>{24, 32}));
}

TEST(Rasterizer, EqualDepthPassesOnlyTheFirstDrawn) {
    Scene s(8);
    s.rect(0, 0, 4, 4, 0.1f);
    s.rect(0, 0, 4, 4, 0.1f);
    EXPECT_EQ(score_rect_orders(s, {{0, 1}, {1, 0}}), (std::vector<uint64_t>{16, 16}));
}

TEST(Rasterizer, ThreeLayersBackToFrontShadeEveryLayer) {
    Scene s(4);
    s.rect(0, 0, 4, 4, 0.5f);
    s.rect(0, 0, 4, 4, 0.0f);
    s.rect(0, 0, 4, 4, -0.5f);
    // Back to front (0,1,2): 48. Front to back (2,1,0): 16. Middle first (1,0,2): 16 + 0 + 16.
    EXPECT_EQ(score_rect_orders(s, {{0, 1, 2}, {2, 1, 0}, {1, 0, 2}}), (std::vector<uint64_t>{48, 16, 32}));
}

TEST(Rasterizer, NearPlaneClipsAwayThePartInFront) {
    // A full-height quad whose NDC z runs from −2 (x = −1) to 0.5 (x = +1): z < −1 lies in front
    // of the near plane. z = −1 at NDC x = −0.2, window x = 4.0 at 10 pixels: columns 4–9 remain.
    Scene s(10);
    const uint32_t a = s.vertex(-1, -1, -2), b = s.vertex(1, -1, 0.5f), c = s.vertex(1, 1, 0.5f),
                   d = s.vertex(-1, 1, -2);
    s.ib = {a, b, c, a, c, d};
    EXPECT_EQ(s.rasterize().visible_pixels(), 60u);
    // The same beyond the far plane: z from 0.5 to 2 crosses z = 1 at NDC x = −1/3, window 3.33:
    // centre columns 0.5, 1.5, 2.5 remain.
    Scene f(10);
    const uint32_t e = f.vertex(-1, -1, 0.5f), g = f.vertex(1, -1, 2), h = f.vertex(1, 1, 2), i = f.vertex(-1, 1, 0.5f);
    f.ib = {e, g, h, e, h, i};
    EXPECT_EQ(f.rasterize().visible_pixels(), 30u);
}

TEST(Rasterizer, GeometryOutsideTheViewportIsClippedNotWrapped) {
    Scene s(8);
    const uint32_t a = s.vertex(-50, -50, 0), b = s.vertex(50, -50, 0), c = s.vertex(0, 50, 0);
    s.ib = {a, b, c};
    EXPECT_EQ(s.rasterize().visible_pixels(), 64u);
}

TEST(Rasterizer, SphereFillsTheInscribedDisc) {
    // Framing and camera: the bounding sphere of radius R exactly fits the viewport, so a fine
    // sphere's silhouette covers π(N/2)² pixels (a little less: the mesh is inscribed).
    const AnimatedMesh sphere = make_uv_sphere(40000);
    const Framing framing =
        frame_keyframes(sphere.keyframe(0), 1, sphere.vertex_count, sphere.indices.data(), sphere.indices.size());
    const std::vector<float> dirs = icosphere_directions(1);
    for (size_t v = 0; v < 42; v += 7) {
        std::vector<float> clip(sphere.vertex_count * 4);
        transform_to_clip(clip.data(), sphere.keyframe(0), sphere.vertex_count, framing.centres.data(),
                          node_view_projection(&dirs[3 * v], framing.radius));
        NodeRasterizer r;
        r.rasterize(clip.data(), sphere.vertex_count, sphere.indices.data(), sphere.indices.size(), 256);
        const double disc = M_PI * 128.0 * 128.0;
        EXPECT_NEAR(double(r.visible_pixels()), disc, 0.01 * disc) << "view " << v;
        // A convex closed mesh: every front-facing fragment is visible, nothing overlaps.
        EXPECT_EQ(r.fragments(), r.visible_pixels()) << "view " << v;
    }
}

namespace {
// Independent reference: draws the fragments of each order with a real z-buffer, one triangle
// after another, from the rasteriser's raw fragments.
uint64_t brute_force_passed(const NodeRasterizer& r, const std::vector<uint32_t>& order) {
    std::map<uint32_t, std::vector<std::pair<uint32_t, float>>> by_triangle;  // triangle → (pixel, depth)
    r.visit_fragments([&](uint32_t p, uint32_t t, float z) { by_triangle[t].emplace_back(p, z); });
    std::vector<float> depth(size_t(r.resolution()) * r.resolution(), 1.0f);
    uint64_t passed = 0;
    for (uint32_t t : order)
        for (const auto& [p, z] : by_triangle[t])
            if (z < depth[p]) {
                depth[p] = z;
                ++passed;
            }
    return passed;
}
}  // namespace

// Every copy the CPU runs (portable, AVX2, AVX-512), 1 to 9 orders at once (the wide copies have
// one vector lane per order up to 8, then the generic replay), against a z-buffer drawing each order; on the bundled
// character and on a copy with every seventh triangle drawn twice (equal depths: ties).
TEST(Rasterizer, ScoringManyOrdersEqualsDrawingEachOrderWithAZBuffer) {
    AnimatedMesh doubled = make_procedural_character();
    const size_t original = doubled.indices.size();
    for (size_t t = 0; 3 * t < original; t += 7)
        for (int c = 0; c < 3; ++c) doubled.indices.push_back(doubled.indices[3 * t + c]);
    doubled.primitives.back().index_count += doubled.indices.size() - original;
    bool long_lists = false, ties = false;  // the data has what the replay branches on
    for (const AnimatedMesh& mesh : {make_procedural_character(), doubled}) {
        const Framing framing = frame_animated_mesh(mesh);
        const size_t n = mesh.triangle_count();
        std::vector<std::vector<uint32_t>> orders(9, std::vector<uint32_t>(n));
        std::mt19937 rng(1);
        for (size_t i = 0; i < n; ++i) orders[0][i] = uint32_t(i);
        for (size_t i = 0; i < n; ++i) orders[1][i] = uint32_t(n - 1 - i);
        for (size_t o = 2; o < orders.size(); ++o) {
            orders[o] = orders[0];
            for (size_t i = n; i > 1; --i) std::swap(orders[o][i - 1], orders[o][rng() % i]);
        }
        std::vector<std::vector<uint32_t>> ranks(orders.size() + 1);  // ranks[c]: the first c orders
        for (size_t c = 1; c <= orders.size(); ++c) {
            std::vector<const uint32_t*> pointers;
            for (size_t o = 0; o < c; ++o) pointers.push_back(orders[o].data());
            ranks[c] = make_rank_table(pointers, n);
        }

        const std::vector<float> dirs = icosphere_directions(1);
        for (size_t v : {0u, 5u, 17u, 33u}) {
            for (uint32_t k : {0u, uint32_t(mesh.keyframe_count() - 1)}) {
                std::vector<float> clip(mesh.vertex_count * 4);
                transform_to_clip(clip.data(), mesh.keyframe(k), mesh.vertex_count, &framing.centres[3 * k],
                                  node_view_projection(&dirs[3 * v], framing.radius));
                std::vector<uint64_t> want(orders.size());
                for (const Copy copy : copies_here()) {
                    NodeRasterizer r;
                    r.set_copy(copy);
                    r.rasterize(clip.data(), mesh.vertex_count, mesh.indices.data(), mesh.indices.size(), 128);
                    if (copy == Copy::Portable) {
                        for (size_t o = 0; o < orders.size(); ++o) want[o] = brute_force_passed(r, orders[o]);
                        const NodeRasterizer::FragmentLists l = r.fragment_lists();
                        for (size_t m = 0; m < l.pixels; ++m) {
                            long_lists |= l.starts[m + 1] - l.starts[m] > 4;
                            for (uint32_t f = l.starts[m]; f < l.starts[m + 1]; ++f)
                                ties |= (l.fragments[f] >> 31) != 0;
                        }
                    }
                    for (size_t c = 1; c <= orders.size(); ++c) {
                        std::vector<uint64_t> passed(c);
                        r.score(passed.data(), ranks[c].data(), c);
                        for (size_t o = 0; o < c; ++o) {
                            EXPECT_EQ(passed[o], want[o])
                                << "view " << v << " keyframe " << k << " order " << o << " of " << c << ", "
                                << NodeRasterizer::copy_name(copy) << " copy";
                            EXPECT_GE(passed[o], r.visible_pixels());
                            EXPECT_LE(passed[o], r.fragments());
                        }
                    }
                    EXPECT_GT(r.fragments(), r.visible_pixels());  // the character does overlap itself
                }
            }
        }
    }
    EXPECT_TRUE(long_lists) << "no pixel with more than 4 fragments";
    EXPECT_TRUE(ties) << "no fragments at equal depths";
}

// score_fragments on made-up lists of 2 to 12 fragments with equal depths anywhere in them
// (also only past the fourth fragment, where the wide copies' short-list path ends), 1 to 9
// orders, against drawing each order into one z-buffer entry per pixel.
TEST(Rasterizer, ScoringListsWithTiesAnywhereEqualsAZBuffer) {
    std::mt19937 rng(5);
    const uint32_t triangles = 40;
    NodeFragments node;
    node.starts.push_back(0);
    std::vector<std::vector<float>> depths;  // per pixel, each fragment's depth
    for (int px = 0; px < 400; ++px) {
        std::vector<uint32_t> t(triangles);
        std::iota(t.begin(), t.end(), 0u);
        std::shuffle(t.begin(), t.end(), rng);
        const uint32_t n = 2 + uint32_t(rng() % 11);
        const uint32_t tie_from = px % 3 == 0 ? 4 : 1;  // a third of the pixels: ties only from the fifth on
        std::vector<float> z;
        for (uint32_t j = 0; j < n; ++j) {
            const bool tie = j >= tie_from && rng() % 3 == 0;
            z.push_back(tie ? z.back() : float(j + 1));
            node.fragments.push_back(t[j] | (tie ? 0x80000000u : 0u));
        }
        node.starts.push_back(uint32_t(node.fragments.size()));
        depths.push_back(z);
    }
    node.single = 7;
    node.visible = node.single + depths.size();
    std::vector<std::vector<uint32_t>> orders;
    for (size_t c = 1; c <= 9; ++c) {
        std::vector<uint32_t> order(triangles);
        std::iota(order.begin(), order.end(), 0u);
        std::shuffle(order.begin(), order.end(), rng);
        orders.push_back(order);
        std::vector<const uint32_t*> pointers;
        for (const auto& o : orders) pointers.push_back(o.data());
        const std::vector<uint32_t> ranks = make_rank_table(pointers, triangles);
        std::vector<uint64_t> passed(c);
        score_fragments(passed.data(), node, ranks.data(), c);
        for (size_t o = 0; o < c; ++o) {
            uint64_t want = node.single;
            for (size_t m = 0; m < depths.size(); ++m) {
                float buffer = 1e9f;
                for (const uint32_t triangle : orders[o])
                    for (uint32_t f = node.starts[m]; f < node.starts[m + 1]; ++f)
                        if ((node.fragments[f] & 0x7fffffffu) == triangle && depths[m][f - node.starts[m]] < buffer) {
                            buffer = depths[m][f - node.starts[m]];
                            ++want;
                        }
            }
            EXPECT_EQ(passed[o], want) << "order " << o << " of " << c;
        }
    }
}

TEST(Rasterizer, RejectsBadInput) {
    NodeRasterizer r;
    const std::vector<float> clip(12, 0.0f);
    const std::vector<uint32_t> ib{0, 1, 3};
    EXPECT_THROW(r.rasterize(clip.data(), 3, ib.data(), 3, 16), InvalidInput);
    const std::vector<uint32_t> ok{0, 1, 2};
    EXPECT_THROW(r.rasterize(clip.data(), 3, ok.data(), 3, 0), InvalidInput);
}

// Double-sided triangles (glTF doubleSided materials): the back face is drawn, not culled.
TEST(Rasterizer, DoubleSidedQuadSeenFromBehindIsCounted) {
    Scene s(16);
    s.rect(2, 2, 10, 10, 0.0f, /*counter_clockwise=*/false);  // a back face: 8 × 8 pixels
    EXPECT_EQ(s.rasterize().visible_pixels(), 0u) << "culled when single-sided";
    const std::vector<uint8_t> both(s.triangles(), 1);
    NodeRasterizer r;
    r.rasterize(s.clip.data(), s.clip.size() / 4, s.ib.data(), s.ib.size(), s.resolution, both.data());
    EXPECT_EQ(r.visible_pixels(), 64u);
    EXPECT_EQ(r.fragments(), 64u) << "no double count on the shared diagonal";
}

TEST(Rasterizer, DoubleSidedBackFaceOccludesLikeAFrontFace) {
    // Near: a back-facing double-sided rectangle over [4,12]²; far: a front face over [0,16]².
    Scene s(16);
    s.rect(4, 4, 12, 12, -0.5f, false);
    s.rect(0, 0, 16, 16, 0.5f, true);
    const std::vector<uint8_t> flags = {1, 1, 0, 0};
    NodeRasterizer r;
    r.rasterize(s.clip.data(), s.clip.size() / 4, s.ib.data(), s.ib.size(), s.resolution, flags.data());
    EXPECT_EQ(r.visible_pixels(), 256u);
    const std::vector<uint32_t> near_first = {0, 1, 2, 3}, far_first = {2, 3, 0, 1};
    const std::vector<uint32_t> ranks = make_rank_table({near_first.data(), far_first.data()}, 4);
    uint64_t passed[2];
    r.score(passed, ranks.data(), 2);
    EXPECT_EQ(passed[0], 256u);        // near first: the far quad is hidden where the near one lies
    EXPECT_EQ(passed[1], 256u + 64u);  // far first: the 64 near fragments pass again
}

TEST(Rasterizer, DoubleSidedBackFacesCoverTheSamePixelsAsTheirFrontFaces) {
    // The fill rule is a property of the edges on screen: a triangle and its mirror winding
    // (drawn double-sided) must give the same fragments, with the same depths.
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> coordinate(-1.1f, 1.1f), depth(-0.9f, 0.9f);
    Scene front(37), back(37);
    for (int t = 0; t < 200; ++t) {
        float v[3][3];
        for (auto& p : v) p[0] = coordinate(rng), p[1] = coordinate(rng), p[2] = depth(rng);
        const uint32_t a = front.vertex(v[0][0], v[0][1], v[0][2]), b = front.vertex(v[1][0], v[1][1], v[1][2]),
                       c = front.vertex(v[2][0], v[2][1], v[2][2]);
        back.vertex(v[0][0], v[0][1], v[0][2]), back.vertex(v[1][0], v[1][1], v[1][2]),
            back.vertex(v[2][0], v[2][1], v[2][2]);
        front.ib.insert(front.ib.end(), {a, b, c});
        back.ib.insert(back.ib.end(), {a, c, b});
    }
    const std::vector<uint8_t> both(front.triangles(), 1);
    auto fragments_of = [&](const Scene& s) {
        NodeRasterizer r;
        r.rasterize(s.clip.data(), s.clip.size() / 4, s.ib.data(), s.ib.size(), s.resolution, both.data());
        std::vector<std::tuple<uint32_t, uint32_t, float>> out;
        r.visit_fragments([&](uint32_t p, uint32_t t, float z) { out.emplace_back(p, t, z); });
        std::sort(out.begin(), out.end());
        return out;
    };
    const auto a = fragments_of(front), b = fragments_of(back);
    EXPECT_GT(a.size(), 1000u);
    EXPECT_EQ(a, b);
    // Single-sided, each triangle shows in exactly one of the two scenes.
    EXPECT_EQ(front.rasterize().fragments() + back.rasterize().fragments(), a.size());
}

// Blend error (DESIGN.md): hand-worked transparent passes.
namespace {
BlendCounts blend_counts(const Scene& s, const std::vector<uint8_t>& blended, const std::vector<uint32_t>& order,
                         const std::vector<uint8_t>* double_sided = nullptr) {
    NodeRasterizer r;
    r.rasterize(s.clip.data(), s.clip.size() / 4, s.ib.data(), s.ib.size(), s.resolution,
                double_sided ? double_sided->data() : nullptr);
    const std::vector<uint32_t> ranks = make_rank_table({order.data()}, s.triangles());
    BlendCounts c;
    score_blend(&c, r.export_blend_fragments(blended.data()), ranks.data(), 1);
    return c;
}
}  // namespace

TEST(BlendError, TwoParallelBlendedQuadsSeenFromBothSides) {
    // Quads A (NDC z = −0.5) and B (z = +0.5) over the same 8 × 8 pixels, double-sided, blended.
    // From the front A is nearer: drawing A first mis-sorts all 64 pixels, B first none. Seen from
    // behind (z negated, as a camera on the other side sees them) the right buffer flips.
    for (const float side : {1.0f, -1.0f}) {
        Scene s(16);
        s.rect(4, 4, 12, 12, -0.5f * side);  // A: triangles 0, 1
        s.rect(4, 4, 12, 12, 0.5f * side);   // B: triangles 2, 3
        const std::vector<uint8_t> blended(4, 1), both(4, 1);
        const BlendCounts a_first = blend_counts(s, blended, {0, 1, 2, 3}, &both);
        const BlendCounts b_first = blend_counts(s, blended, {2, 3, 0, 1}, &both);
        EXPECT_EQ(a_first.covered, 64u);
        EXPECT_EQ(a_first.pairs, 64u);
        EXPECT_EQ(a_first.missorted_pairs, side > 0 ? 64u : 0u);
        EXPECT_EQ(a_first.missorted_pixels, side > 0 ? 64u : 0u);
        EXPECT_EQ(b_first.missorted_pairs, side > 0 ? 0u : 64u);
        EXPECT_EQ(b_first.missorted_pixels, side > 0 ? 0u : 64u);
    }
}

TEST(BlendError, HiddenBlendedFragmentsDoNotCount) {
    // An opaque quad at z = 0 over [0,16]²; a blended shell in front (z = −0.5, over [2,6]×[2,6])
    // and behind it (z = −0.2 and z = +0.5 over [8,12]²: one layer hidden by the opaque quad).
    Scene s(16);
    s.rect(0, 0, 16, 16, 0.0f);   // opaque: 0, 1
    s.rect(2, 2, 6, 6, -0.5f);    // blended, in front: 2, 3
    s.rect(8, 8, 12, 12, -0.2f);  // blended, in front: 4, 5
    s.rect(8, 8, 12, 12, 0.5f);   // blended, hidden: 6, 7
    s.rect(2, 2, 6, 6, -0.1f);    // blended, in front, behind 2/3: 8, 9
    const std::vector<uint8_t> blended = {0, 0, 1, 1, 1, 1, 1, 1, 1, 1};
    const BlendCounts c = blend_counts(s, blended, {0, 1, 2, 3, 4, 5, 6, 7, 8, 9});
    EXPECT_EQ(c.covered, 16u + 16u);    // both 4 × 4 squares; the hidden layer adds nothing
    EXPECT_EQ(c.pairs, 16u);            // only [2,6]² has two counted layers
    EXPECT_EQ(c.missorted_pairs, 16u);  // 2/3 (nearer) drawn before 8/9
    EXPECT_EQ(c.missorted_pixels, 16u);
    const BlendCounts back_to_front = blend_counts(s, blended, {0, 1, 8, 9, 6, 7, 4, 5, 2, 3});
    EXPECT_EQ(back_to_front.missorted_pairs, 0u);
    // A blended fragment at exactly the opaque depth fails LESS: moved onto the opaque plane, the
    // [8,12]² layer stops counting.
    Scene t(16);
    t.rect(0, 0, 16, 16, 0.0f);
    t.rect(8, 8, 12, 12, 0.0f);
    EXPECT_EQ(blend_counts(t, {0, 0, 1, 1}, {2, 3, 0, 1}).covered, 0u);
}

// Four blended quads seen head-on at 8 × 8, each pixel's layers known, and the mis-sorted pairs
// of four orders added up by hand (the materials figures of `evaluate` rest on these sums).
// Window space, pixels, y up (rows of the image: row 0 at the top, so y in [4, 8] is rows 0-3):
//   A  z = −0.5 (nearest)  x in [0, 4], y in [0, 8]   triangles 0, 1
//   D  z = −0.5 (A's depth) x in [0, 2], y in [4, 8]   triangles 6, 7
//   B  z =  0              x in [2, 6], y in [0, 8]   triangles 2, 3
//   C  z = +0.5 (farthest) x in [0, 8], y in [4, 8]   triangles 4, 5
// Regions of 2 columns × 4 rows = 8 pixels each, layers nearest first:
//   columns   bottom (y < 4)   top (y > 4)
//   0-1       A                A=D, C   pairs (A,C), (D,C); A and D tie: no pair
//   2-3       A, B             A, B, C  pairs (A,B); (A,B), (A,C), (B,C)
//   4-5       B                B, C     pairs (B,C)
//   6-7       -                C
// covered: 7 regions × 8 = 56 pixels; with two layers or more: 4 regions, 32 pixels;
// pairs: 8 · (2 + 1 + 3 + 1) = 56.
// A pair is mis-sorted when its nearer quad is drawn first:
//   C B A D (back to front): none.                                   0 pairs, 0 pixels
//   A D B C (front to back): every pair.                            56 pairs, 32 pixels
//   B A C D: (A,B) fine, (A,C) mis, (D,C) fine, (B,C) mis:
//            top 0-1: 1, bottom 2-3: 0, top 2-3: 2, top 4-5: 1  →  8 · 4 = 32 pairs, 24 pixels
//   C D A B: only (A,B) mis: bottom 2-3: 1, top 2-3: 1            → 16 pairs, 16 pixels
TEST(BlendError, FourQuadsHeadOnHandCountedForFourOrders) {
    Scene s(8);
    s.rect(0, 0, 4, 8, -0.5f);  // A: 0, 1
    s.rect(2, 0, 6, 8, 0.0f);   // B: 2, 3
    s.rect(0, 4, 8, 8, 0.5f);   // C: 4, 5
    s.rect(0, 4, 2, 8, -0.5f);  // D: 6, 7
    const std::vector<uint8_t> blended(8, 1);
    enum : uint32_t { A = 0, B = 1, C = 2, D = 3 };
    const std::vector<std::vector<uint32_t>> quad_orders = {{C, B, A, D}, {A, D, B, C}, {B, A, C, D}, {C, D, A, B}};
    std::vector<std::vector<uint32_t>> orders;
    for (const auto& quads : quad_orders) {
        std::vector<uint32_t> order;
        for (uint32_t q : quads) order.insert(order.end(), {2 * q, 2 * q + 1});
        orders.push_back(order);
    }
    std::vector<const uint32_t*> pointers;
    for (const auto& o : orders) pointers.push_back(o.data());
    const std::vector<uint32_t> ranks = make_rank_table(pointers, s.triangles());

    NodeRasterizer r = s.rasterize();
    const BlendFragments fragments = r.export_blend_fragments(blended.data());
    EXPECT_EQ(fragments.covered, 56u);
    EXPECT_EQ(fragments.pixels.size(), 32u);
    EXPECT_EQ(fragments.fragments.size(), 8u * (3 + 2 + 3 + 2));  // the layers of the four regions

    std::vector<BlendCounts> counts(orders.size());
    score_blend(counts.data(), fragments, ranks.data(), orders.size());
    const uint64_t pairs[] = {0, 56, 32, 16}, pixels[] = {0, 32, 24, 16};
    for (size_t o = 0; o < orders.size(); ++o) {
        SCOPED_TRACE(o);
        EXPECT_EQ(counts[o].covered, 56u);
        EXPECT_EQ(counts[o].pairs, 56u);
        EXPECT_EQ(counts[o].missorted_pairs, pairs[o]);
        EXPECT_EQ(counts[o].missorted_pixels, pixels[o]);
        // The same, one order at a time.
        BlendCounts alone;
        const std::vector<uint32_t> one = make_rank_table({orders[o].data()}, s.triangles());
        score_blend(&alone, fragments, one.data(), 1);
        EXPECT_EQ(alone.missorted_pairs, pairs[o]);
        EXPECT_EQ(alone.missorted_pixels, pixels[o]);
    }

    // The heatmap of B A C D, pixel by pixel (row 0 at the top).
    const std::vector<uint32_t> image = missorted_per_pixel(fragments, 8, ranks.data(), orders.size(), 2);
    ASSERT_EQ(image.size(), 64u);
    for (unsigned row = 0; row < 8; ++row)
        for (unsigned column = 0; column < 8; ++column) {
            const uint32_t top[] = {1, 1, 2, 2, 1, 1, 0, 0};
            EXPECT_EQ(image[row * 8 + column], row < 4 ? top[column] : 0u) << "row " << row << ", column " << column;
        }
    // Back to front: a blank heatmap; front to back: one per pair.
    const std::vector<uint32_t> blank = missorted_per_pixel(fragments, 8, ranks.data(), orders.size(), 0);
    EXPECT_EQ(std::accumulate(blank.begin(), blank.end(), 0u), 0u);
    const std::vector<uint32_t> all = missorted_per_pixel(fragments, 8, ranks.data(), orders.size(), 1);
    EXPECT_EQ(std::accumulate(all.begin(), all.end(), 0u), 56u);
}

TEST(BlendError, MatchesABruteForceTransparentPass) {
    // A second implementation from the raw fragments: per pixel, the opaque minimum depth, the
    // blended fragments strictly nearer, and every pair at different depths checked against the
    // order's ranks.
    std::mt19937 rng(23);
    std::uniform_real_distribution<float> coordinate(-1.0f, 1.0f), depth(-0.9f, 0.9f);
    Scene s(24);
    for (int t = 0; t < 120; ++t) {
        const uint32_t a = s.vertex(coordinate(rng), coordinate(rng), depth(rng));
        const uint32_t b = s.vertex(coordinate(rng), coordinate(rng), depth(rng));
        const uint32_t c = s.vertex(coordinate(rng), coordinate(rng), depth(rng));
        s.ib.insert(s.ib.end(), {a, b, c});
    }
    std::vector<uint8_t> blended(s.triangles()), both(s.triangles(), kDrawBothFaces);
    for (size_t t = 0; t < blended.size(); ++t) blended[t] = t % 3 != 0;
    std::vector<uint32_t> order(s.triangles());
    std::iota(order.begin(), order.end(), 0u);
    std::shuffle(order.begin(), order.end(), rng);
    NodeRasterizer r;
    r.rasterize(s.clip.data(), s.clip.size() / 4, s.ib.data(), s.ib.size(), s.resolution, both.data());
    const std::vector<uint32_t> ranks = make_rank_table({order.data()}, s.triangles());
    BlendCounts fast;
    score_blend(&fast, r.export_blend_fragments(blended.data()), ranks.data(), 1);

    std::map<uint32_t, float> opaque;
    std::map<uint32_t, std::vector<std::pair<float, uint32_t>>> layers;
    r.visit_fragments([&](uint32_t p, uint32_t t, float z) {
        if (!blended[t]) opaque[p] = opaque.count(p) ? std::min(opaque[p], z) : z;
    });
    r.visit_fragments([&](uint32_t p, uint32_t t, float z) {
        if (blended[t] && (!opaque.count(p) || z < opaque[p])) layers[p].emplace_back(z, t);
    });
    BlendCounts slow;
    for (const auto& [p, list] : layers) {
        ++slow.covered;
        uint64_t missorted = 0;
        for (size_t i = 0; i < list.size(); ++i)
            for (size_t j = 0; j < list.size(); ++j)
                if (list[i].first < list[j].first) {
                    ++slow.pairs;
                    missorted += ranks[list[i].second] < ranks[list[j].second];
                }
        slow.missorted_pairs += missorted;
        slow.missorted_pixels += missorted > 0;
    }
    EXPECT_GT(slow.pairs, 200u);
    EXPECT_GT(slow.missorted_pairs, 0u);
    EXPECT_EQ(fast.covered, slow.covered);
    EXPECT_EQ(fast.pairs, slow.pairs);
    EXPECT_EQ(fast.missorted_pairs, slow.missorted_pairs);
    EXPECT_EQ(fast.missorted_pixels, slow.missorted_pixels);
}

namespace {

// A second, deliberately plain rasteriser of unclipped triangles, written from DESIGN.md's rules
// without any of the engine's shortcuts (batching, boxes, one-pixel path, branch-free spans): every
// pixel centre of the viewport is tested against three int64 edge functions of the snapped corners.
// Its fragments in drawing order: triangle by triangle, rows top to bottom, columns left to right.
struct RefVertex {
    int64_t X, Y;
    float x, y, z;
};

RefVertex reference_project(const float* v, unsigned resolution) {
    const float half = 0.5f * float(resolution);
    const float inv_w = 1.0f / v[3];
    const float x = v[0] * inv_w * half + half, y = v[1] * inv_w * half + half;
    auto round_half_away = [](float f) { return int64_t(f >= 0.0f ? f + 0.5f : f - 0.5f); };
    RefVertex r;
    r.z = v[2] * inv_w * 0.5f + 0.5f;
    r.X = round_half_away((x - 0.5f) * 256.0f);
    r.Y = int64_t(resolution - 1) * 256 - round_half_away((y - 0.5f) * 256.0f);
    r.x = x - 0.5f;
    r.y = float(resolution) - y - 0.5f;
    return r;
}

std::vector<std::tuple<uint32_t, uint32_t, float>> reference_fragments(const std::vector<float>& clip,
                                                                       const std::vector<uint32_t>& ib,
                                                                       const std::vector<uint8_t>& modes,
                                                                       unsigned resolution) {
    std::vector<std::tuple<uint32_t, uint32_t, float>> out;
    for (size_t t = 0; t < ib.size() / 3; ++t) {
        if (modes[t] & kSkipTriangle) continue;
        RefVertex v[3];
        for (int i = 0; i < 3; ++i) v[i] = reference_project(&clip[4 * ib[3 * t + i]], resolution);
        const int64_t area = (v[1].X - v[0].X) * (v[2].Y - v[0].Y) - (v[2].X - v[0].X) * (v[1].Y - v[0].Y);
        if (area == 0 || (area > 0 && !(modes[t] & kDrawBothFaces))) continue;
        // Positive orientation: corners 0, 2, 1 for a front face (negative area), else 0, 1, 2.
        const RefVertex c[3] = {v[0], area < 0 ? v[2] : v[1], area < 0 ? v[1] : v[2]};
        const double ax = c[1].x - c[0].x, ay = c[1].y - c[0].y, az = c[1].z - c[0].z;
        const double bx = c[2].x - c[0].x, by = c[2].y - c[0].y, bz = c[2].z - c[0].z;
        const double det = ax * by - ay * bx;
        const double dzdx = (az * by - ay * bz) / det, dzdy = (ax * bz - az * bx) / det;
        const double z_origin = c[0].z - dzdx * c[0].x - dzdy * c[0].y;
        for (int64_t py = 0; py < int64_t(resolution); ++py)
            for (int64_t px = 0; px < int64_t(resolution); ++px) {
                bool inside = true;
                for (int i = 0; i < 3; ++i) {
                    const RefVertex &a = c[i], &b = c[(i + 1) % 3];
                    const int64_t dx = b.X - a.X, dy = b.Y - a.Y;
                    const int64_t e = dx * (py * 256 - a.Y) - dy * (px * 256 - a.X);
                    const bool top_left = (dy == 0 && dx > 0) || dy < 0;
                    inside = inside && (e > 0 || (e == 0 && top_left));
                }
                if (!inside || det == 0.0) continue;
                const float depth = float((z_origin + dzdy * double(py)) + dzdx * double(px));
                if (depth >= 0.0f && depth < 1.0f) out.emplace_back(uint32_t(py * resolution + px), uint32_t(t), depth);
            }
    }
    return out;
}

std::vector<std::tuple<uint32_t, uint32_t, float>> engine_fragments(const NodeRasterizer& r) {
    std::vector<std::tuple<uint32_t, uint32_t, float>> out;
    r.visit_fragments([&](uint32_t p, uint32_t t, float z) { out.emplace_back(p, t, z); });
    return out;
}

// The same fragments in the same order, depths bit for bit.
void expect_same_fragments(const std::vector<std::tuple<uint32_t, uint32_t, float>>& got,
                           const std::vector<std::tuple<uint32_t, uint32_t, float>>& expected,
                           const std::string& what) {
    ASSERT_EQ(got.size(), expected.size()) << what;
    for (size_t f = 0; f < got.size(); ++f) {
        ASSERT_EQ(std::get<0>(got[f]), std::get<0>(expected[f])) << "fragment " << f << ", " << what;
        ASSERT_EQ(std::get<1>(got[f]), std::get<1>(expected[f])) << "fragment " << f << ", " << what;
        ASSERT_EQ(std::memcmp(&std::get<2>(got[f]), &std::get<2>(expected[f]), 4), 0)
            << "fragment " << f << ", " << what;
    }
}

// Every copy of the per-node code the CPU runs (portable, AVX2, AVX-512) draws exactly the
// expected fragments.
void expect_every_copy_draws(const std::vector<float>& clip, const std::vector<uint32_t>& ib,
                             const std::vector<uint8_t>& modes, unsigned resolution,
                             const std::vector<std::tuple<uint32_t, uint32_t, float>>& expected,
                             const std::string& what) {
    for (const Copy copy : copies_here()) {
        NodeRasterizer r;
        r.set_copy(copy);
        r.rasterize(clip.data(), clip.size() / 4, ib.data(), ib.size(), resolution, modes.data());
        expect_same_fragments(engine_fragments(r), expected, what + NodeRasterizer::copy_name(copy) + " copy");
    }
}

}  // namespace

// Every fragment (pixel, triangle, depth bits) and its order, against the plain reference, on
// triangles meant to hit the engine's special cases: random ones of all sizes, tiny ones inside
// one pixel box, slivers, corners on pixel centres (fill rule), double-sided back faces, skipped
// ones, and more triangles than one batch of the pre-pass. Every copy of the per-node code (the
// portable one and, where the CPU has them, the AVX2 and AVX-512 ones) are checked.
TEST(Rasterizer, FragmentsEqualAPlainPerPixelReference) {
    std::mt19937 rng(19);
    std::uniform_real_distribution<float> any(-1.0f, 1.0f), depth(-0.9f, 0.9f), small(-0.02f, 0.02f);
    for (unsigned resolution : {7u, 16u, 33u}) {
        std::vector<float> clip;
        std::vector<uint32_t> ib;
        std::vector<uint8_t> modes;
        auto add = [&](const float(&p)[3][3], uint8_t mode) {
            for (const auto& v : p) {
                ib.push_back(uint32_t(clip.size() / 4));
                const float w = 0.5f + 1.5f * (float(rng() % 1000) / 1000.0f);  // perspective: w varies
                clip.insert(clip.end(), {v[0] * w, v[1] * w, v[2] * w, w});
            }
            modes.push_back(mode);
        };
        // On pixel centres exactly: NDC of centre i is (2i + 1) / resolution − 1.
        auto centre = [&](int i) { return (2.0f * float(i) + 1.0f) / float(resolution) - 1.0f; };
        for (int i = 0; i < 700; ++i) {
            const uint8_t mode = uint8_t(rng() % 2 ? kDrawBothFaces : 0) | uint8_t(rng() % 17 == 0 ? kSkipTriangle : 0);
            float p[3][3];
            switch (i % 5) {
                case 0:  // anywhere, any size
                    for (auto& v : p) v[0] = any(rng), v[1] = any(rng), v[2] = depth(rng);
                    break;
                case 1: {  // tiny, around a random point
                    const float x = any(rng), y = any(rng);
                    for (auto& v : p) v[0] = x + small(rng), v[1] = y + small(rng), v[2] = depth(rng);
                    break;
                }
                case 2: {  // sliver: nearly collinear
                    const float x = any(rng), y = any(rng), dx = any(rng), dy = any(rng);
                    for (int k = 0; k < 3; ++k)
                        p[k][0] = x + dx * float(k) * 0.5f + small(rng) * 0.01f, p[k][1] = y + dy * float(k) * 0.5f,
                        p[k][2] = depth(rng);
                    break;
                }
                default:  // corners on pixel centres: edges through centres
                    for (auto& v : p)
                        v[0] = centre(int(rng() % resolution)), v[1] = centre(int(rng() % resolution)),
                        v[2] = depth(rng);
                    break;
            }
            add(p, mode);
        }
        const auto expected = reference_fragments(clip, ib, modes, resolution);
        expect_every_copy_draws(clip, ib, modes, resolution, expected,
                                "resolution " + std::to_string(resolution) + " ");
        EXPECT_GT(expected.size(), 200u);  // the scene draws something
    }
}

// The per-box paths of both copies against the plain reference: boxes of 1 × 1, 1 × 2, 2 × 1 and
// 2 × 2 pixels (the wide copies' one-vector path), and boxes 3 to 10 pixels wide (its 4-pixel groups:
// one group, two, three, with masked lanes past the box), mixed in one batch; boxes cut by the
// viewport's edges; both faces; depths at and next to 0 and 1 (some fragments round to depth 1
// and are dropped).
TEST(Rasterizer, SmallAndWideBoxesEqualThePlainReference) {
    std::mt19937 rng(23);
    const unsigned resolution = 24;
    const float sizes[] = {0.3f, 0.7f, 1.2f, 1.8f, 2.6f, 3.4f, 4.5f, 6.2f, 8.7f};
    const float depths[] = {-1.0f, -0.99999994f, -0.9999999f, 0.9999999f, 0.99999994f, 1.0f};
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    std::vector<float> clip;
    std::vector<uint32_t> ib;
    std::vector<uint8_t> modes;
    for (int i = 0; i < 600; ++i) {
        // In pixels (centre of pixel i at i), from just off the left or top edge to just off the right
        // or bottom one; the size picks the box.
        const float x = -1.5f + unit(rng) * (float(resolution) + 1.0f),
                    y = -1.5f + unit(rng) * (float(resolution) + 1.0f);
        const float w = sizes[rng() % 9], h = sizes[rng() % 9], a = unit(rng), b = unit(rng);
        const float px[3] = {x, x + w, x + b * w}, py[3] = {y, y + a * h, y + h};
        const bool flip = rng() % 2;
        for (int k = 0; k < 3; ++k) {
            const int c = flip ? 2 - k : k;
            const float z = rng() % 3 ? depths[rng() % 6] : unit(rng) * 2.0f - 1.0f;
            const float clip_w = i % 4 ? 1.0f : 0.5f + unit(rng);  // some perspective
            ib.push_back(uint32_t(clip.size() / 4));
            const float nx = (2.0f * px[c] + 1.0f) / float(resolution) - 1.0f;
            const float ny = (2.0f * py[c] + 1.0f) / float(resolution) - 1.0f;
            clip.insert(clip.end(), {nx * clip_w, ny * clip_w, z * clip_w, clip_w});
        }
        modes.push_back(rng() % 2 ? kDrawBothFaces : 0);
    }
    const auto expected = reference_fragments(clip, ib, modes, resolution);
    size_t near_zero = 0, near_one = 0;  // drawn fragments at the ends of the depth range
    for (const auto& f : expected) {
        near_zero += std::get<2>(f) < 0.001f;
        near_one += std::get<2>(f) > 0.999f;
    }
    expect_every_copy_draws(clip, ib, modes, resolution, expected, "");
    EXPECT_GT(expected.size(), 1000u) << near_zero << " " << near_one;
    EXPECT_GT(near_zero, 5u);
    EXPECT_GT(near_one, 5u);
}

// The pre-pass's small-box test (a triangle with a box of at most 2 × 2 pixels and corners within
// 4 pixels of each other that covers none of the box's centres is never set up): pixel-sized
// triangles whose corners sit on the subpixel grid, many exactly on pixel centres or on the line
// between two (so edges pass through centres: the fill rule decides), extents just under and at
// the 4-pixel limit, both faces, boxes cut by the viewport's edges, and long triangles reaching
// into a corner of a 512² viewport from far beyond it, against the plain reference in both
// copies. Fails when the test drops a covered triangle (checked: the top-left bias taken as 1 for
// every edge, the second row's centres left out, or the 4-pixel limit lifted so that int32
// products wrap, each fail it).
TEST(Rasterizer, SmallBoxTestDropsOnlyTrianglesThatCoverNothing) {
    std::mt19937 rng(2611);
    const unsigned resolution = 12;
    // Subpixel offsets from a pixel centre: on it, half-way to the next, random, and near 4 pixels.
    const int32_t steps[] = {0, 128, 256, -128, -256, 384, 512, 767, 768, 1023, 1024, -1, 1, 129};
    std::vector<float> clip;
    std::vector<uint32_t> ib;
    std::vector<uint8_t> modes;
    for (int i = 0; i < 4000; ++i) {
        // A base centre anywhere in the viewport or one pixel beyond it (boxes cut by the edges).
        const int32_t bx = int32_t(rng() % (resolution + 2)) - 1, by = int32_t(rng() % (resolution + 2)) - 1;
        for (int k = 0; k < 3; ++k) {
            const int32_t ox = rng() % 3 ? steps[rng() % 14] : int32_t(rng() % 1100) - 50;
            const int32_t oy = rng() % 3 ? steps[rng() % 14] : int32_t(rng() % 1100) - 50;
            // Window position in pixels (centre of pixel i at i + 0.5, y up), exact in float.
            const float x = float(bx) + 0.5f + float(ox) / 256.0f, y = float(by) + 0.5f + float(oy) / 256.0f;
            ib.push_back(uint32_t(clip.size() / 4));
            const float z = float(rng() % 1000) / 1000.0f * 1.8f - 0.9f;
            clip.insert(clip.end(), {2.0f * x / float(resolution) - 1.0f, 2.0f * y / float(resolution) - 1.0f, z, 1.0f});
        }
        modes.push_back(rng() % 3 ? 0 : kDrawBothFaces);
    }
    // Long triangles from far beyond a corner of the viewport (inside the guard band) into it: boxes
    // cut to at most 2 × 2 pixels, but corners hundreds of pixels apart (products beyond int32: such
    // triangles must not take the test).
    const unsigned large = 512;  // its guard band reaches 256 pixels beyond the viewport
    std::vector<float> far_clip;
    std::vector<uint32_t> far_ib;
    std::vector<uint8_t> far_modes;
    std::uniform_real_distribution<float> unit(0.0f, 1.0f);
    for (int i = 0; i < 300; ++i) {
        const float sx = rng() % 2 ? 1.0f : -1.0f, sy = rng() % 2 ? 1.0f : -1.0f;  // which corner
        const float length = 100.0f + 150.0f * unit(rng), a = unit(rng), b = unit(rng);
        // In pixels from the corner pixel's centre, pointing out of the viewport.
        const float near_x = -1.0f + 2.5f * unit(rng), near_y = -1.0f + 2.5f * unit(rng);
        const float px[3] = {near_x, -length, -b * length}, py[3] = {near_y, -a * length, -length};
        for (int k = 0; k < 3; ++k) {
            const float cx = sx > 0 ? px[k] : float(large - 1) - px[k], cy = sy > 0 ? py[k] : float(large - 1) - py[k];
            far_ib.push_back(uint32_t(far_clip.size() / 4));
            far_clip.insert(far_clip.end(), {(2.0f * cx + 1.0f) / float(large) - 1.0f,
                                             (2.0f * cy + 1.0f) / float(large) - 1.0f, 0.5f * unit(rng), 1.0f});
        }
        far_modes.push_back(kDrawBothFaces);
    }
    const auto far_expected = reference_fragments(far_clip, far_ib, far_modes, large);
    EXPECT_GT(far_expected.size(), 50u);
    expect_every_copy_draws(far_clip, far_ib, far_modes, large, far_expected, "far corners, ");

    const auto expected = reference_fragments(clip, ib, modes, resolution);
    // The scene has both kinds of pixel-sized triangle: those that cover a centre and those that do not.
    std::vector<size_t> per_triangle(ib.size() / 3, 0);
    for (const auto& f : expected) ++per_triangle[std::get<1>(f)];
    const size_t empty = size_t(std::count(per_triangle.begin(), per_triangle.end(), 0u));
    EXPECT_GT(empty, 1000u);
    EXPECT_GT(per_triangle.size() - empty, 1000u);
    expect_every_copy_draws(clip, ib, modes, resolution, expected, "");
}

// Clipped triangles (crossing the near plane or the guard band) among unclipped ones: each
// triangle's fragments are the same drawn alone or in the batch, and in triangle order.
TEST(Rasterizer, ClippedTrianglesAmongOthersDrawAsWhenAlone) {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> wide(-5.0f, 5.0f), z(-2.0f, 2.0f);
    std::vector<float> clip;
    std::vector<uint32_t> ib;
    for (int i = 0; i < 300; ++i)
        for (int k = 0; k < 3; ++k) {
            ib.push_back(uint32_t(clip.size() / 4));
            const float w = i % 3 ? 1.0f : 0.2f + 2.0f * float(rng() % 100) / 100.0f;
            clip.insert(clip.end(), {wide(rng) * (i % 3 ? 0.2f : 1.0f), wide(rng) * (i % 3 ? 0.2f : 1.0f), z(rng), w});
        }
    const std::vector<uint8_t> modes(ib.size() / 3, kDrawBothFaces);
    NodeRasterizer all;
    all.rasterize(clip.data(), clip.size() / 4, ib.data(), ib.size(), 24, modes.data());
    std::vector<std::tuple<uint32_t, uint32_t, float>> alone;
    NodeRasterizer one;
    for (size_t t = 0; t < ib.size() / 3; ++t) {
        one.rasterize(clip.data(), clip.size() / 4, &ib[3 * t], 3, 24, modes.data());
        one.visit_fragments([&](uint32_t p, uint32_t, float d) { alone.emplace_back(p, uint32_t(t), d); });
    }
    const auto got = engine_fragments(all);
    ASSERT_EQ(got.size(), alone.size());
    for (size_t f = 0; f < got.size(); ++f) {
        ASSERT_EQ(std::get<0>(got[f]), std::get<0>(alone[f]));
        ASSERT_EQ(std::get<1>(got[f]), std::get<1>(alone[f]));
        ASSERT_EQ(std::memcmp(&std::get<2>(got[f]), &std::get<2>(alone[f]), 4), 0);
    }
    EXPECT_GT(got.size(), 100u);
}

// The grouped lists scoring walks (visible and single-fragment pixels; per pixel with several
// fragments its triangles nearest first, ties flagged) against a std::sort of the node's raw
// fragments, at a viewport small enough for the count-image grouping and one beyond it (the radix
// passes). Duplicated triangles make exact depth ties.
TEST(Rasterizer, GroupedListsEqualASortOfTheRawFragments) {
    for (unsigned resolution : {40u, 1100u}) {
        std::mt19937 rng(resolution);
        std::uniform_real_distribution<float> any(-1.0f, 1.0f), depth(-0.9f, 0.9f), size(0.0f, 0.3f);
        std::vector<float> clip;
        std::vector<uint32_t> ib;
        for (int i = 0; i < 300; ++i) {
            const float x = any(rng), y = any(rng), r = size(rng) * (resolution > 100 ? 0.15f : 1.0f);
            const uint32_t first = uint32_t(clip.size() / 4);
            for (int k = 0; k < 3; ++k) {
                const float angle = float(k) * 2.0944f + any(rng) * 0.3f;
                clip.insert(clip.end(), {x + r * std::cos(angle), y + r * std::sin(angle), depth(rng), 1.0f});
            }
            ib.insert(ib.end(), {first, first + 1, first + 2});
            if (i % 4 == 0) ib.insert(ib.end(), {first, first + 1, first + 2});  // an exact tie
        }
        const std::vector<uint8_t> modes(ib.size() / 3, kDrawBothFaces);
        NodeRasterizer r;
        r.rasterize(clip.data(), clip.size() / 4, ib.data(), ib.size(), resolution, modes.data());
        std::vector<std::tuple<uint32_t, float, uint32_t>> raw;
        r.visit_fragments([&](uint32_t p, uint32_t t, float z) { raw.emplace_back(p, z, t); });
        std::sort(raw.begin(), raw.end());
        uint64_t visible = 0, single = 0;
        std::vector<uint32_t> starts{0}, fragments;
        for (size_t i = 0; i < raw.size();) {
            size_t end = i;
            while (end < raw.size() && std::get<0>(raw[end]) == std::get<0>(raw[i])) ++end;
            ++visible;
            if (end - i == 1) {
                ++single;
            } else {
                for (size_t j = i; j < end; ++j)
                    fragments.push_back(std::get<2>(raw[j]) |
                                        (j > i && std::get<1>(raw[j]) == std::get<1>(raw[j - 1]) ? 0x80000000u : 0u));
                starts.push_back(uint32_t(fragments.size()));
            }
            i = end;
        }
        const NodeFragments got = r.export_fragments();
        EXPECT_EQ(got.visible, visible) << resolution;
        EXPECT_EQ(got.single, single) << resolution;
        EXPECT_EQ(got.starts, starts) << resolution;
        EXPECT_EQ(got.fragments, fragments) << resolution;
        EXPECT_GT(starts.size(), 100u);
        EXPECT_NE(std::count_if(fragments.begin(), fragments.end(), [](uint32_t f) { return f >> 31; }), 0);
        // At 40², pixels of 2-4, 5-8 and more fragments all occur: each of the count-image
        // grouping's sorts (two sorting networks, insertion) is checked.
        if (resolution != 40) continue;
        size_t by_size[3] = {};
        for (size_t m = 0; m + 1 < starts.size(); ++m) {
            const uint32_t c = starts[m + 1] - starts[m];
            ++by_size[c <= 4 ? 0 : c <= 8 ? 1 : 2];
        }
        EXPECT_GT(by_size[0], 0u) << resolution;
        EXPECT_GT(by_size[1], 0u) << resolution;
        EXPECT_GT(by_size[2], 0u) << resolution;
    }
}

// The wide copies of the per-node code (AVX2, AVX-512) against the portable one, bit for bit: every raw fragment
// (pixel, triangle, depth bits, in order) and the grouped lists, on the bundled character from
// 42 directions at two keyframes (small triangles, the common case) at 64² and 256², with a
// wide near-plane-crossing triangle added (the exact paths).
TEST(Rasterizer, WideCopiesGiveThePortableBits) {
    if (copies_here().size() < 2) GTEST_SKIP() << "this CPU has no AVX2: only the portable copy runs";
    const AnimatedMesh mesh = make_procedural_character();
    const Framing framing = frame_animated_mesh(mesh);
    const std::vector<float> dirs = icosphere_directions(1);
    std::vector<uint32_t> ib = mesh.indices;
    std::vector<float> clip((mesh.vertex_count + 3) * 4);
    const uint32_t extra = uint32_t(mesh.vertex_count);
    ib.insert(ib.end(), {extra, extra + 1, extra + 2});
    std::vector<uint8_t> modes(ib.size() / 3, 0);
    modes.back() = kDrawBothFaces;
    for (size_t i = 0; i < modes.size(); i += 13) modes[i] |= kDrawBothFaces;
    size_t compared = 0;
    for (unsigned resolution : {64u, 256u})
        for (uint32_t k : {0u, uint32_t(mesh.keyframe_count() / 2)})
            for (size_t v = 0; v < dirs.size() / 3; ++v) {
                transform_to_clip(clip.data(), mesh.keyframe(k), mesh.vertex_count, &framing.centres[3 * k],
                                  node_view_projection(&dirs[3 * v], framing.radius));
                const float wide[12] = {-3.0f, -0.5f, -2.0f, 1.0f, 3.0f, 0.2f, 0.5f, 1.0f, 0.1f, 2.5f, 0.9f, 1.0f};
                std::copy(wide, wide + 12, clip.end() - 12);
                NodeRasterizer portable;
                portable.set_copy(Copy::Portable);
                portable.rasterize(clip.data(), mesh.vertex_count + 3, ib.data(), ib.size(), resolution, modes.data());
                const auto a = engine_fragments(portable);
                const NodeFragments ga = portable.export_fragments();
                for (const Copy copy : copies_here()) {
                    if (copy == Copy::Portable) continue;
                    NodeRasterizer wide_copy;
                    wide_copy.set_copy(copy);
                    wide_copy.rasterize(clip.data(), mesh.vertex_count + 3, ib.data(), ib.size(), resolution,
                                        modes.data());
                    const std::string what =
                        std::string(NodeRasterizer::copy_name(copy)) + " copy, view " + std::to_string(v);
                    const auto b = engine_fragments(wide_copy);
                    ASSERT_EQ(a.size(), b.size()) << what;
                    for (size_t f = 0; f < a.size(); ++f) {
                        ASSERT_EQ(std::get<0>(a[f]), std::get<0>(b[f])) << what << " fragment " << f;
                        ASSERT_EQ(std::get<1>(a[f]), std::get<1>(b[f])) << what << " fragment " << f;
                        ASSERT_EQ(std::memcmp(&std::get<2>(a[f]), &std::get<2>(b[f]), 4), 0)
                            << what << " fragment " << f;
                    }
                    const NodeFragments gb = wide_copy.export_fragments();
                    ASSERT_EQ(ga.visible, gb.visible) << what;
                    ASSERT_EQ(ga.single, gb.single) << what;
                    ASSERT_EQ(ga.starts, gb.starts) << what;
                    ASSERT_EQ(ga.fragments, gb.fragments) << what;
                    compared += a.size();
                }
            }
    EXPECT_GT(compared, 100000u);  // the views draw the character
}

// The wide copies' vertex pass (8 vertices at a time) against the portable one's (one at a time),
// bit for bit, on vertices chosen to hit its branches: inside and outside each clip plane and the
// guard band (and exactly on them), w negative, tiny and huge, subpixel coordinates exactly
// half-way between two integers (rounding half away from zero), −0, resolutions whose half is not
// a power of two (the products' rounding shows), and NaN and infinite coordinates (no crash, the
// same fragments); vertex counts of every remainder modulo 8 (the scalar tail). Small triangles
// among them, so that most vertices are drawn. Fails when a record (snapped X, Y, the depth
// plane's x, y, z) differs: fragments then move, change depth or go (checked: rounding ties to
// even, or x · (1/w · half) for (x · 1/w) · half, fail it).
TEST(Rasterizer, WideVertexPassGivesThePortableBits) {
    if (copies_here().size() < 2) GTEST_SKIP() << "this CPU has no AVX2: only the portable copy runs";
    std::mt19937 rng(20261125);
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f), small(-0.02f, 0.02f);
    const float inf = std::numeric_limits<float>::infinity(), nan = std::numeric_limits<float>::quiet_NaN();
    size_t fragments = 0;
    for (const unsigned resolution : {1u, 7u, 64u, 256u}) {
        const float half = 0.5f * float(resolution);
        for (size_t tail = 0; tail < 8; ++tail) {
            std::vector<float> clip;
            const auto add = [&](float x, float y, float z, float w) { clip.insert(clip.end(), {x, y, z, w}); };
            for (int c = 0; c < 150; ++c) {  // clusters of three nearby vertices: one small triangle each
                const float w = c % 17 == 0   ? -1.0f
                                : c % 13 == 0 ? 1e-30f
                                : c % 11 == 0 ? 1e30f
                                              : 0.5f + unit(rng) * 0.4f;
                const float x = unit(rng) * 2.2f, y = unit(rng) * 2.2f, z = unit(rng) * 1.1f;
                for (int k = 0; k < 3; ++k) add((x + small(rng)) * w, (y + small(rng)) * w, (z + small(rng)) * w, w);
            }
            // On the planes: z = ±w, |x| = |y| = 2w (inside), and just beyond.
            for (const float s : {1.0f, -1.0f}) {
                add(0.1f, 0.1f, s, 1.0f), add(0.2f, 0.1f, s, 1.0f), add(0.1f, 0.2f, s, 1.0f);
                add(2.0f * s, 0.0f, 0.5f, 1.0f), add(2.0f * s, 0.3f, 0.5f, 1.0f), add(1.7f * s, 0.1f, 0.5f, 1.0f);
                add(std::nextafter(2.0f * s, 3.0f * s), 0.0f, 0.5f, 1.0f), add(1.9f * s, 0.0f, 0.5f, 1.0f),
                    add(1.9f * s, 0.1f, 0.5f, 1.0f);
            }
            // Subpixel coordinates exactly half-way (x · 256 · half − 128 = k + 0.5), and −0.
            for (int k = -4; k < 4; ++k) {
                const float x = ((float(k) + 0.5f) / 256.0f + 0.5f - half) / half;
                add(x, -x, 0.25f, 1.0f), add(x + 0.01f, -x, 0.25f, 1.0f), add(x, -x + 0.01f, 0.25f, 1.0f);
            }
            add(-0.0f, -0.0f, -0.0f, 1.0f), add(0.05f, -0.0f, -0.0f, 1.0f), add(-0.0f, 0.05f, -0.0f, 1.0f);
            // Not numbers: NaN and infinite coordinates, and infinite w (x · 1/w is then NaN or 0).
            add(nan, 0.0f, 0.0f, 1.0f), add(0.0f, nan, 0.0f, 1.0f), add(0.0f, 0.0f, 0.0f, nan);
            add(inf, 0.0f, 0.0f, inf), add(0.0f, 0.1f, 0.0f, inf), add(0.1f, 0.0f, 0.5f, inf);
            add(0.5f, 0.5f, 0.5f, inf), add(0.6f, 0.5f, 0.5f, 1.0f), add(0.5f, 0.6f, 0.5f, 1.0f);
            while ((clip.size() / 4) % 8 != tail) add(unit(rng), unit(rng), 0.5f * unit(rng), 1.0f);
            const size_t vertices = clip.size() / 4;
            std::vector<uint32_t> ib;
            for (uint32_t v = 0; v + 2 < vertices; v += 3) ib.insert(ib.end(), {v, v + 1, v + 2});
            for (uint32_t v = 0; v + 2 < vertices; ++v) ib.insert(ib.end(), {v + 2, v + 1, v});  // back faces too
            std::vector<uint8_t> modes(ib.size() / 3, 0);
            for (size_t t = 0; t < modes.size(); t += 2) modes[t] = kDrawBothFaces;
            NodeRasterizer portable;
            portable.set_copy(Copy::Portable);
            portable.rasterize(clip.data(), vertices, ib.data(), ib.size(), resolution, modes.data());
            const auto expected = engine_fragments(portable);
            for (const Copy copy : copies_here()) {
                if (copy == Copy::Portable) continue;
                NodeRasterizer wide_copy;
                wide_copy.set_copy(copy);
                wide_copy.rasterize(clip.data(), vertices, ib.data(), ib.size(), resolution, modes.data());
                expect_same_fragments(engine_fragments(wide_copy), expected,
                                      std::string(NodeRasterizer::copy_name(copy)) + " copy, resolution " +
                                          std::to_string(resolution) + ", " + std::to_string(vertices) + " vertices");
            }
            fragments += expected.size();
        }
    }
    EXPECT_GT(fragments, 20000u);
}

// The centred-positions entry (the transform to clip space inside the vertex pass) against
// transform_to_clip and the clip-space entry, bit for bit, in every copy: the bundled character
// from 42 directions at two keyframes, at 64² and 256², with extra vertices that take the exact
// paths (one behind the near plane, one beyond the guard band, one not a number) in triangles
// with the character's vertices, and every vertex count modulo 8 (the vertex pass's scalar tail,
// which transforms one vertex at a time). Fails when a clip coordinate differs (fragments then
// move, change depth or go; checked: m·x + (m·y + m·z) for (m·x + m·y) + m·z in the wide vertex
// pass fails it; the one-vertex transform is clip_row, transform_to_clip's own, which
// Camera.TransformIsThePlainPerVertexProductBitForBit checks against the plain product).
TEST(Rasterizer, CentredVerticesGiveTheClipSpaceBits) {
    const AnimatedMesh mesh = make_procedural_character();
    const Framing framing = frame_animated_mesh(mesh);
    const std::vector<float> dirs = icosphere_directions(1);
    size_t compared = 0, exact_paths = 0;
    for (size_t tail = 0; tail < 8; ++tail)
        for (const uint32_t k : {0u, uint32_t(mesh.keyframe_count() / 2)}) {
            const float* centre = &framing.centres[3 * k];
            std::vector<float> positions(mesh.keyframe(k), mesh.keyframe(k) + 3 * mesh.vertex_count);
            std::vector<uint32_t> ib = mesh.indices;
            const uint32_t first_extra = uint32_t(mesh.vertex_count);
            const float r = framing.radius;
            // Vertices that take the exact paths in some views: 2.8R and 2.9R out along an axis
            // (closer than the near plane, R in front of a camera 3R out, for the views near that
            // axis), 40R out (beyond the guard band, or behind the camera), and NaN.
            const float extra[4][3] = {{centre[0] + 2.8f * r, centre[1], centre[2]},
                                       {centre[0], centre[1] + 40.0f * r, centre[2]},
                                       {centre[0], centre[1], centre[2] - 2.9f * r},
                                       {std::numeric_limits<float>::quiet_NaN(), centre[1], centre[2]}};
            for (const auto& e : extra) positions.insert(positions.end(), e, e + 3);
            for (uint32_t e = 0; e < 4; ++e)  // each with two of the character's vertices, both windings
                for (uint32_t a = 0; a < 6; ++a) {
                    const uint32_t u = a * 97 % first_extra, w = (a * 97 + 1) % first_extra;
                    ib.insert(ib.end(), {first_extra + e, u, w, w, u, first_extra + e});
                }
            while ((positions.size() / 3) % 8 != tail) positions.insert(positions.end(), centre, centre + 3);
            const size_t vertices = positions.size() / 3;
            std::vector<uint8_t> modes(ib.size() / 3, 0);
            for (size_t t = 0; t < modes.size(); t += 5) modes[t] = kDrawBothFaces;
            std::vector<float> clip(4 * vertices);
            CentredKeyframe centred;
            centred.centre(positions.data(), vertices, centre);
            for (size_t v = 0; v < dirs.size() / 3; v += tail + 1)
                for (const unsigned resolution : {64u, 256u}) {
                    const Mat4d vp = node_view_projection(&dirs[3 * v], framing.radius);
                    transform_to_clip(clip.data(), positions.data(), vertices, centre, vp);
                    const NodeRasterizer::CentredVertices source = centred.vertices(vp);
                    for (size_t c = 0; c < 4; ++c) {  // how many extra vertices this view draws exactly
                        const float* q = &clip[4 * (first_extra + c)];
                        exact_paths += !(q[2] >= -q[3] && q[2] <= q[3] && std::fabs(q[0]) <= 2.0f * q[3] &&
                                         std::fabs(q[1]) <= 2.0f * q[3]);
                    }
                    for (const Copy copy : copies_here()) {
                        NodeRasterizer from_clip, from_centred;
                        from_clip.set_copy(copy);
                        from_centred.set_copy(copy);
                        from_clip.rasterize(clip.data(), vertices, ib.data(), ib.size(), resolution, modes.data());
                        from_centred.rasterize_validated(source, vertices, ib.data(), ib.size(), resolution,
                                                         modes.data());
                        const auto expected = engine_fragments(from_clip);
                        expect_same_fragments(engine_fragments(from_centred), expected,
                                              std::string(NodeRasterizer::copy_name(copy)) + " copy, view " +
                                                  std::to_string(v) + ", " + std::to_string(vertices) + " vertices");
                        if (HasFatalFailure()) return;
                        ASSERT_EQ(from_clip.export_fragments().fragments, from_centred.export_fragments().fragments);
                        compared += expected.size();
                    }
                }
        }
    EXPECT_GT(compared, 500000u);  // the views draw the character
    EXPECT_GT(exact_paths, 100u);  // and the extra vertices take the exact paths
}
