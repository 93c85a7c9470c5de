// Patches (fast linear clustering): hand-worked cuts on a strip, the λ limits, and the ACMR
// behaviour Sander et al. 2007 §4 describe.
#include "animorder/animated_mesh.h"
#include "animorder/invalid_input.h"
#include "animorder/patches.h"
#include "animorder/procedural_character.h"
#include "animorder/procedural_shapes.h"
#include "animorder/static_sander07.h"
#include "animorder/tipsify.h"
#include "animorder/vertex_cache.h"
#include "support/meshes.h"

#include <gtest/gtest.h>

#include <vector>

using namespace animorder;

namespace {
// Strip of 6 triangles; cold-cache misses per triangle 3,1,1,1,1,1, so the running local ACMR
// with triangle i counted is 3, 4/2, 5/3, 6/4, 7/5, 8/6.
const std::vector<uint32_t> kStrip{0, 1, 2, 2, 1, 3, 2, 3, 4, 4, 3, 5, 4, 5, 6, 6, 5, 7};

std::vector<uint32_t> patches(const std::vector<uint32_t>& ib, size_t vertices, double lambda,
                              const std::vector<uint32_t>& hard = {}) {
    return build_patches(ib.data(), ib.size(), vertices, hard.data(), hard.size(), lambda, 16);
}
}  // namespace

TEST(Patches, StripCutsWhereLocalAcmrFallsBelowLambda) {
    // λ = 1.6: 5/3 = 1.67 keeps t2; 6/4 = 1.5 < 1.6 cuts before t3. The new patch restarts cold:
    // t3 3 misses, t4 4/2 = 2, t5 5/3 = 1.67: no further cut.
    EXPECT_EQ(patches(kStrip, 8, 1.6), (std::vector<uint32_t>{0, 3, 6}));
    // λ = 2.1: 4/2 = 2 < 2.1 cuts before every triangle after the first of each patch.
    EXPECT_EQ(patches(kStrip, 8, 2.1), (std::vector<uint32_t>{0, 1, 2, 3, 4, 5, 6}));
    // λ = 1.3: 8/6 = 1.33 is never below it.
    EXPECT_EQ(patches(kStrip, 8, 1.3), (std::vector<uint32_t>{0, 6}));
}

TEST(Patches, HardBoundariesAlwaysCut) {
    EXPECT_EQ(patches(kStrip, 8, 0.0, {4}), (std::vector<uint32_t>{0, 4, 6}));
    // Soft and hard together: λ 1.6 cuts at 3, the hard boundary at 4, then t4,t5 stay together.
    EXPECT_EQ(patches(kStrip, 8, 1.6, {4}), (std::vector<uint32_t>{0, 3, 4, 6}));
}

TEST(Patches, LambdaLimitsOfTheDefinition) {
    const AnimatedMesh mesh = make_torus_knot(4000);
    std::vector<uint32_t> order(mesh.triangle_count());
    const TipsifyResult t = tipsify(order.data(), mesh.indices.data(), mesh.indices.size(), mesh.vertex_count);
    const std::vector<uint32_t> ib = test::applied(mesh.indices, order);
    const auto hard = [&](double lambda) {
        return build_patches(ib.data(), ib.size(), mesh.vertex_count, t.hard_boundaries.data(),
                             t.hard_boundaries.size(), lambda, 16);
    };
    // λ < 0.5: exactly the hard boundaries.
    std::vector<uint32_t> expected{0};
    expected.insert(expected.end(), t.hard_boundaries.begin(), t.hard_boundaries.end());
    expected.push_back(uint32_t(mesh.triangle_count()));
    EXPECT_EQ(hard(0.0), expected);
    EXPECT_EQ(hard(0.49), expected);
    // λ >= 3: single triangles.
    EXPECT_EQ(hard(3.0).size(), mesh.triangle_count() + 1);
    EXPECT_EQ(hard(7.5).size(), mesh.triangle_count() + 1);
}

TEST(Patches, EmptyInputGivesOneStart) { EXPECT_EQ(patches({}, 0, 0.85), (std::vector<uint32_t>{0})); }

TEST(Patches, RejectsBadBoundariesAndLambda) {
    EXPECT_THROW(patches(kStrip, 8, 0.85, {7}), InvalidInput);
    EXPECT_THROW(patches(kStrip, 8, 0.85, {3, 2}), InvalidInput);
    EXPECT_THROW(patches(kStrip, 8, std::nan("")), InvalidInput);
}

TEST(ExpandPatchOrder, ConcatenatesPatchesInTheGivenOrder) {
    const std::vector<uint32_t> starts{0, 2, 3, 6};
    const std::vector<uint32_t> patch_order{2, 0, 1};
    std::vector<uint32_t> order(6);
    expand_patch_order(order.data(), patch_order.data(), starts.data(), 3);
    EXPECT_EQ(order, (std::vector<uint32_t>{3, 4, 5, 0, 1, 2}));
}

// ACMR of the static-sander07 order as λ grows (Sander et al. 2007 §4, Figure 5; the JCGT
// paper's λ sweep): unchanged below 0.5, growing with λ, near 3 at λ = 3 where only the few
// vertices that consecutive single triangles happen to share are still hits.
namespace {
double sander07_acmr(const AnimatedMesh& mesh, double lambda, size_t* patch_count = nullptr) {
    std::vector<uint32_t> order(mesh.triangle_count());
    const StaticOrderResult r = order_static_sander07(order.data(), mesh.indices.data(), mesh.indices.size(),
                                                      mesh.keyframe(0), mesh.vertex_count, 12, lambda, 16);
    if (patch_count) *patch_count = r.patch_count;
    const std::vector<uint32_t> ib = test::applied(mesh.indices, order);
    return analyze_vertex_cache(ib.data(), ib.size(), mesh.vertex_count, 16).acmr;
}
double tipsify_acmr(const AnimatedMesh& mesh) {
    std::vector<uint32_t> order(mesh.triangle_count());
    tipsify(order.data(), mesh.indices.data(), mesh.indices.size(), mesh.vertex_count, 16);
    const std::vector<uint32_t> ib = test::applied(mesh.indices, order);
    return analyze_vertex_cache(ib.data(), ib.size(), mesh.vertex_count, 16).acmr;
}
}  // namespace

// Fraction of corners a triangle shares with the triangle drawn just before it: those are FIFO
// hits for certain, so 3·(1 − shared) bounds the ACMR from above.
double shared_with_previous(const std::vector<uint32_t>& ib) {
    size_t shared = 0;
    for (size_t t = 3; t < ib.size(); t += 3)
        for (int c = 0; c < 3; ++c)
            shared += ib[t + c] == ib[t - 3] || ib[t + c] == ib[t - 2] || ib[t + c] == ib[t - 1];
    return ib.empty() ? 0.0 : double(shared) / double(ib.size());
}

TEST(Patches, AcmrFollowsLambdaAsThePapersSay) {
    for (const AnimatedMesh& mesh : {make_procedural_character(), make_torus_knot(20000)}) {
        SCOPED_TRACE(mesh.name);
        const double base = tipsify_acmr(mesh);
        // Hard boundaries only: the cache was (nearly always) flushed at a dead-end jump anyway.
        EXPECT_NEAR(sander07_acmr(mesh, 0.0), base, 0.01 * base);
        double previous = 0;
        size_t previous_patches = 0;
        for (double lambda : {0.0, 0.7, 0.85, 1.0, 1.5, 2.0}) {
            size_t patch_count = 0;
            const double acmr = sander07_acmr(mesh, lambda, &patch_count);
            EXPECT_GE(acmr, previous - 0.005) << "lambda " << lambda;
            EXPECT_GT(patch_count, previous_patches) << "lambda " << lambda;
            // λ is a close lower bound on the clustered model's ACMR (for λ above Tipsify's;
            // for tiny patches, neighbours sorted next to each other share some vertices).
            if (lambda > base && lambda <= 1.5) {
                EXPECT_GE(acmr, 0.95 * lambda) << "lambda " << lambda;
            }
            previous = acmr;
            previous_patches = patch_count;
        }
        // λ = 3: single triangles, so the ACMR is 3·(1 − shared) with "shared" the corners still
        // cached from earlier triangles: at least those shared with the triangle just before
        // (an upper bound), and far more misses than Tipsify. On these regular, symmetric meshes
        // neighbours of equal rank are sorted next to each other, so sharing is not negligible.
        std::vector<uint32_t> order(mesh.triangle_count());
        const StaticOrderResult r = order_static_sander07(order.data(), mesh.indices.data(), mesh.indices.size(),
                                                          mesh.keyframe(0), mesh.vertex_count, 12, 3.0, 16);
        EXPECT_EQ(r.patch_count, mesh.triangle_count());
        const std::vector<uint32_t> ib = test::applied(mesh.indices, order);
        const double acmr = analyze_vertex_cache(ib.data(), ib.size(), mesh.vertex_count, 16).acmr;
        const double bound = 3.0 * (1.0 - shared_with_previous(ib));
        EXPECT_LE(acmr, bound + 1e-12);
        EXPECT_GT(acmr, 1.5 * base);
        EXPECT_GT(acmr, previous - 0.5);
    }
}
