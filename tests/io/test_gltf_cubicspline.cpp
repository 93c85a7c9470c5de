// CUBICSPLINE animation samplers off the key times, with non-zero tangents: there the Hermite
// curve differs from linear interpolation (at u = 0.5 with zero tangents the two coincide, so a
// loader that interpolated linearly would pass such a test). A triangle hangs on a node whose
// translation (or rotation) is keyed at t = 0 and t = 0.1 s; sampled at 30/s, keyframes 1 and 2
// fall at u = 1/3 and 2/3 of the key interval. Expected positions are worked out by hand from the
// glTF 2.0 spec (Appendix C):
//   p(u) = (2u³−3u²+1)·p0 + (u³−2u²+u)·m0 + (−2u³+3u²)·p1 + (u³−u²)·m1,  m = tangent·(t1−t0),
// with m0 the out-tangent of key 0 and m1 the in-tangent of key 1. The weights:
//   u = 1/3: 20/27, 4/27, 7/27, −2/27        u = 2/3: 7/27, 2/27, 20/27, −4/27
#include "animorder/animated_mesh.h"
#include "animorder/gltf_loader.h"
#include "support/files.h"
#include "support/meshes.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

using namespace animorder;
using nlohmann::json;

namespace {

// The triangle's bind positions: (0,0,0), (1,0,0), (0,1,0).
const std::vector<float> kTriangle = {0, 0, 0, 1, 0, 0, 0, 1, 0};

class GltfCubicSpline : public test::ScratchFolderTest {
protected:
    GltfCubicSpline() : ScratchFolderTest("animorder-cubicspline") {}

    // A .gltf with its buffer in a .bin beside it: the triangle on node 0, whose `target`
    // (translation or rotation) is animated by one CUBICSPLINE sampler with keys at 0 and 0.1 s.
    // `keys` holds, per key, in-tangent, value, out-tangent (3 or 4 floats each).
    std::string write(const std::string& target, const std::vector<float>& keys) {
        std::string bin;
        json views = json::array(), accessors = json::array();
        auto add = [&](const void* data, size_t bytes, size_t count, const char* type, int component) {
            while (bin.size() % 4) bin.push_back('\0');
            views.push_back({{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", bytes}});
            bin.append(static_cast<const char*>(data), bytes);
            accessors.push_back(
                {{"bufferView", views.size() - 1}, {"componentType", component}, {"count", count}, {"type", type}});
            return accessors.size() - 1;
        };
        const std::vector<uint16_t> indices = {0, 1, 2};
        const std::vector<float> times = {0.0f, 0.1f};
        const size_t components = target == "rotation" ? 4 : 3;
        const size_t p = add(kTriangle.data(), kTriangle.size() * 4, 3, "VEC3", 5126);
        accessors[p]["min"] = {0, 0, 0};
        accessors[p]["max"] = {1, 1, 0};
        const size_t i = add(indices.data(), indices.size() * 2, 3, "SCALAR", 5123);
        const size_t t = add(times.data(), times.size() * 4, 2, "SCALAR", 5126);
        accessors[t]["min"] = {0.0};
        accessors[t]["max"] = {times[1]};
        const size_t v =
            add(keys.data(), keys.size() * 4, keys.size() / components, components == 4 ? "VEC4" : "VEC3", 5126);
        const json doc = {
            {"asset", {{"version", "2.0"}}},
            {"buffers", json::array({{{"byteLength", bin.size()}, {"uri", "cubic.bin"}}})},
            {"bufferViews", views},
            {"accessors", accessors},
            {"meshes",
             json::array({{{"primitives", json::array({{{"attributes", {{"POSITION", p}}}, {"indices", i}}})}}})},
            {"nodes", json::array({{{"name", "moving"}, {"mesh", 0}}})},
            {"scenes", json::array({{{"nodes", {0}}}})},
            {"scene", 0},
            {"animations",
             json::array(
                 {{{"name", "move"},
                   {"samplers", json::array({{{"input", t}, {"output", v}, {"interpolation", "CUBICSPLINE"}}})},
                   {"channels", json::array({{{"sampler", 0}, {"target", {{"node", 0}, {"path", target}}}}})}}})}};
        std::ofstream(path("cubic.bin"), std::ios::binary) << bin;
        std::ofstream(path("cubic.gltf"), std::ios::binary) << doc.dump();
        return path("cubic.gltf").string();
    }
};

void expect_vertex(const AnimatedMesh& m, size_t keyframe, size_t vertex, double x, double y, double z) {
    test::expect_position(m, keyframe, vertex, x, y, z, 1e-5);
}

}  // namespace

TEST_F(GltfCubicSpline, TranslationFollowsTheHermiteCurveOffCentre) {
    // p0 = (0,0,0), p1 = (1,2,3); out-tangent of key 0 (10,0,−5) and in-tangent of key 1 (−20,10,5)
    // per second, so over the 0.1 s interval m0 = (1,0,−0.5), m1 = (−2,1,0.5). The other two
    // tangents lie outside the interval and must not matter: they are set to junk.
    const std::vector<float> keys = {99,  99, 99, 0, 0, 0, 10, 0,  -5,   // key 0: in, value, out
                                     -20, 10, 5,  1, 2, 3, 77, 77, 77};  // key 1
    const AnimatedMesh m = load_gltf(write("translation", keys));
    ASSERT_EQ(m.clips.size(), 1u);
    ASSERT_EQ(m.clips[0].keyframe_count, 4u);  // 0.1 s at 30/s: 0, 1/30, 2/30, 3/30
    ASSERT_EQ(m.vertex_count, 3u);
    // u = 1/3: x = 4/27·1 + 7/27·1 − 2/27·(−2) = 15/27; y = 7/27·2 − 2/27·1 = 12/27;
    //          z = 4/27·(−0.5) + 7/27·3 − 2/27·0.5 = 18/27.   (Linear would be (1/3, 2/3, 1).)
    const double a[3] = {15.0 / 27, 12.0 / 27, 18.0 / 27};
    // u = 2/3: x = 2/27·1 + 20/27·1 − 4/27·(−2) = 30/27; y = 20/27·2 − 4/27·1 = 36/27;
    //          z = 2/27·(−0.5) + 20/27·3 − 4/27·0.5 = 57/27.  (Linear would be (2/3, 4/3, 2).)
    const double b[3] = {30.0 / 27, 36.0 / 27, 57.0 / 27};
    for (size_t v = 0; v < 3; ++v) {
        const float* bind = &kTriangle[3 * v];
        expect_vertex(m, 0, v, bind[0], bind[1], bind[2]);
        expect_vertex(m, 1, v, bind[0] + a[0], bind[1] + a[1], bind[2] + a[2]);
        expect_vertex(m, 2, v, bind[0] + b[0], bind[1] + b[1], bind[2] + b[2]);
        expect_vertex(m, 3, v, bind[0] + 1, bind[1] + 2, bind[2] + 3);
    }
}

TEST_F(GltfCubicSpline, RotationIsTheNormalisedHermiteQuaternion) {
    // About Z from the identity (0,0,0,1) to 90° (0,0,s,s), s = √½; out-tangent of key 0
    // (0,0,5,0) and in-tangent of key 1 (0,0,0,−5) per second, so m0 = (0,0,0.5,0) and
    // m1 = (0,0,0,−0.5). x and y stay 0; the unnormalised z and w:
    //   u = 1/3: z = 4/27·0.5 + 7/27·s = (2 + 7s)/27,   w = 20/27 + 7/27·s − 2/27·(−0.5) = (21 + 7s)/27
    //   u = 2/3: z = 2/27·0.5 + 20/27·s = (1 + 20s)/27, w = 7/27 + 20/27·s − 4/27·(−0.5) = (9 + 20s)/27
    // Normalised, that is a turn by θ about Z with cos θ = (w² − z²)/(w² + z²) and
    // sin θ = 2zw/(w² + z²): θ ≈ 29.986° and 66.394° (linear slerp would give 30° and 60°).
    const float s = float(std::sqrt(0.5));
    const std::vector<float> keys = {9, 9, 9, 9,  0, 0, 0, 1, 0, 0, 5, 0,   // key 0: in, value, out
                                     0, 0, 0, -5, 0, 0, s, s, 9, 9, 9, 9};  // key 1
    const AnimatedMesh m = load_gltf(write("rotation", keys));
    ASSERT_EQ(m.clips.size(), 1u);
    ASSERT_EQ(m.clips[0].keyframe_count, 4u);
    ASSERT_EQ(m.vertex_count, 3u);
    const double r = std::sqrt(0.5);
    const double z[2] = {(2 + 7 * r) / 27, (1 + 20 * r) / 27}, w[2] = {(21 + 7 * r) / 27, (9 + 20 * r) / 27};
    const double degrees[2] = {29.9857, 66.3943};
    for (size_t k = 1; k <= 2; ++k) {
        const double n = w[k - 1] * w[k - 1] + z[k - 1] * z[k - 1];
        const double c = (w[k - 1] * w[k - 1] - z[k - 1] * z[k - 1]) / n, sn = 2 * z[k - 1] * w[k - 1] / n;
        EXPECT_NEAR(std::atan2(sn, c) * 180 / M_PI, degrees[k - 1], 1e-3);  // the derivation's figure
        expect_vertex(m, k, 0, 0, 0, 0);                                    // the origin stays
        expect_vertex(m, k, 1, c, sn, 0);                                   // (1,0,0) turned by θ
        expect_vertex(m, k, 2, -sn, c, 0);                                  // (0,1,0) turned by θ
    }
    expect_vertex(m, 3, 1, 0, 1, 0);  // 90° at the last key
}
