// The bundled character: size, structure, closed outward parts, real and different motion per
// clip, skin that stretches without tearing, determinism.
#include "animorder/animated_mesh.h"
#include "animorder/procedural_character.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

using namespace animorder;

namespace {
const AnimatedMesh& character() {
    static const AnimatedMesh mesh = make_procedural_character();
    return mesh;
}

double mean_displacement(const AnimatedMesh& m, size_t a, size_t b) {
    double sum = 0;
    for (size_t v = 0; v < m.vertex_count; ++v) {
        const float *p = m.keyframe(a) + 3 * v, *q = m.keyframe(b) + 3 * v;
        sum += std::sqrt(double(p[0] - q[0]) * (p[0] - q[0]) + double(p[1] - q[1]) * (p[1] - q[1]) +
                         double(p[2] - q[2]) * (p[2] - q[2]));
    }
    return sum / double(m.vertex_count);
}

// Connected components of the index buffer (union-find over triangle corners): the parts.
std::vector<uint32_t> component_of_vertex(const AnimatedMesh& m) {
    std::vector<uint32_t> parent(m.vertex_count);
    for (uint32_t v = 0; v < parent.size(); ++v) parent[v] = v;
    auto root = [&](uint32_t v) {
        while (parent[v] != v) v = parent[v] = parent[parent[v]];
        return v;
    };
    for (size_t t = 0; t < m.indices.size(); t += 3) {
        parent[root(m.indices[t])] = root(m.indices[t + 1]);
        parent[root(m.indices[t + 1])] = root(m.indices[t + 2]);
    }
    for (uint32_t v = 0; v < parent.size(); ++v) parent[v] = root(v);
    return parent;
}
}  // namespace

TEST(ProceduralCharacter, SizeAndStructure) {
    const AnimatedMesh& m = character();
    EXPECT_GE(m.triangle_count(), 9500u);
    EXPECT_LE(m.triangle_count(), 12000u);
    EXPECT_NO_THROW(validate_animated_mesh(m));
    ASSERT_EQ(m.primitives.size(), 4u);
    EXPECT_EQ(m.primitives[1].name, "shield");
    // Issue 18: 60 hair cards of 5 quads and a 16 × 12 cape, blended and double-sided; the body
    // and the shield single-sided and opaque.
    EXPECT_EQ(m.primitives[2].name, "hair");
    EXPECT_EQ(m.primitives[2].index_count, 3u * 60 * 5 * 2);
    EXPECT_EQ(m.primitives[3].name, "cape");
    EXPECT_EQ(m.primitives[3].index_count, 3u * 16 * 12 * 2);
    for (size_t p = 0; p < 4; ++p) {
        EXPECT_EQ(m.primitives[p].double_sided, p >= 2) << p;
        EXPECT_EQ(m.primitives[p].alpha_mode, p >= 2 ? AlphaMode::Blend : AlphaMode::Opaque) << p;
    }
    ASSERT_EQ(m.clips.size(), 2u);
    EXPECT_EQ(m.clips[0].name, "walk");
    EXPECT_EQ(m.clips[1].name, "wave");
    for (const Clip& c : m.clips) EXPECT_EQ(c.keyframe_count, size_t(std::lround(c.duration_s * 30)) + 1);
    EXPECT_EQ(m.keyframe_count(), 31u + 46u);
    EXPECT_GE(m.joint_count, 12u);
}

// The opaque primitives (body, shield): closed surfaces. The blended hair cards and cape are open
// sheets, drawn double-sided.
AnimatedMesh opaque_part(const AnimatedMesh& full) {
    AnimatedMesh m = full;
    m.indices.resize(full.primitives[1].first_index + full.primitives[1].index_count);
    m.primitives.resize(2);
    return m;
}

TEST(ProceduralCharacter, EveryKeyframeIsClosedAndOutward) {
    const AnimatedMesh m = opaque_part(character());
    std::map<std::pair<uint32_t, uint32_t>, int> edges;
    for (size_t t = 0; t < m.indices.size(); t += 3)
        for (int i = 0; i < 3; ++i) ++edges[{m.indices[t + i], m.indices[t + (i + 1) % 3]}];
    for (const auto& [e, count] : edges) {
        ASSERT_EQ(count, 1);
        ASSERT_TRUE(edges.count({e.second, e.first}));
    }
    for (size_t k = 0; k < m.keyframe_count(); k += 5) {
        const float* p = m.keyframe(k);
        double volume = 0;
        for (size_t t = 0; t < m.indices.size(); t += 3) {
            const float *a = p + 3 * m.indices[t], *b = p + 3 * m.indices[t + 1], *c = p + 3 * m.indices[t + 2];
            volume += (double(a[0]) * (double(b[1]) * c[2] - double(b[2]) * c[1]) -
                       double(a[1]) * (double(b[0]) * c[2] - double(b[2]) * c[0]) +
                       double(a[2]) * (double(b[0]) * c[1] - double(b[1]) * c[0])) /
                      6.0;
        }
        EXPECT_GT(volume, 0.05) << "keyframe " << k;  // a body of tens of litres, outward
        EXPECT_LT(volume, 0.2) << "keyframe " << k;
    }
}

TEST(ProceduralCharacter, EveryPartIsOutwardInEveryKeyframe) {
    // Per part, not just in total: one part wound inward would hide inside a positive sum.
    const AnimatedMesh m = opaque_part(character());
    const std::vector<uint32_t> component = component_of_vertex(m);
    for (size_t k = 0; k < m.keyframe_count(); ++k) {
        const float* p = m.keyframe(k);
        std::map<uint32_t, double> volume;
        for (size_t t = 0; t < m.indices.size(); t += 3) {
            const float *a = p + 3 * m.indices[t], *b = p + 3 * m.indices[t + 1], *c = p + 3 * m.indices[t + 2];
            volume[component[m.indices[t]]] += (double(a[0]) * (double(b[1]) * c[2] - double(b[2]) * c[1]) -
                                                double(a[1]) * (double(b[0]) * c[2] - double(b[2]) * c[0]) +
                                                double(a[2]) * (double(b[0]) * c[1] - double(b[1]) * c[0])) /
                                               6.0;
        }
        ASSERT_GE(volume.size(), 7u);  // torso, head, two arms, two legs, shield at least
        for (const auto& [part, v] : volume) EXPECT_GT(v, 1e-4) << "keyframe " << k << ", part of vertex " << part;
    }
}

TEST(ProceduralCharacter, ClipsMoveAndDifferFromEachOther) {
    const AnimatedMesh& m = character();
    const Clip &walk = m.clips[0], &wave = m.clips[1];
    // Within a clip: a quarter stride apart, vertices move centimetres on average.
    EXPECT_GT(mean_displacement(m, walk.first_keyframe, walk.first_keyframe + 7), 0.02);
    EXPECT_GT(mean_displacement(m, wave.first_keyframe, wave.first_keyframe + 20), 0.02);
    // Between clips' middle keyframes: different poses.
    EXPECT_GT(mean_displacement(m, walk.first_keyframe + 15, wave.first_keyframe + 23), 0.05);
}

TEST(ProceduralCharacter, SkinStretchesWithoutTearing) {
    const AnimatedMesh& m = character();
    for (size_t k = 1; k < m.keyframe_count(); k += 4) {
        std::vector<double> ratios;
        double worst = 1;
        for (size_t t = 0; t < m.indices.size(); t += 3)
            for (int i = 0; i < 3; ++i) {
                const uint32_t a = m.indices[t + i], b = m.indices[t + (i + 1) % 3];
                auto length = [&](size_t f) {
                    const float *p = m.keyframe(f) + 3 * a, *q = m.keyframe(f) + 3 * b;
                    return std::sqrt(double(p[0] - q[0]) * (p[0] - q[0]) + double(p[1] - q[1]) * (p[1] - q[1]) +
                                     double(p[2] - q[2]) * (p[2] - q[2]));
                };
                const double r = length(k) / length(0);
                ratios.push_back(r);
                worst = std::max(worst, std::max(r, 1 / r));
            }
        std::nth_element(ratios.begin(), ratios.begin() + ratios.size() / 2, ratios.end());
        EXPECT_NEAR(ratios[ratios.size() / 2], 1.0, 0.02) << "keyframe " << k;
        EXPECT_LT(worst, 4.0) << "keyframe " << k;  // bends stretch the skin; nothing tears apart
    }
}

TEST(ProceduralCharacter, DeterministicAndBuiltToHumanScale) {
    const AnimatedMesh again = make_procedural_character();
    EXPECT_EQ(again.indices, character().indices);
    EXPECT_EQ(again.keyframe_positions, character().keyframe_positions);
    float lo = INFINITY, hi = -INFINITY;
    for (size_t v = 0; v < character().vertex_count; ++v) {
        lo = std::min(lo, character().keyframe(0)[3 * v + 1]);
        hi = std::max(hi, character().keyframe(0)[3 * v + 1]);
    }
    EXPECT_GT(hi - lo, 1.6f);
    EXPECT_LT(hi - lo, 2.0f);
}
