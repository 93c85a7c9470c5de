// Linear blend skinning against hand-computed positions.
#include "animorder/invalid_input.h"
#include "animorder/skinning.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

using namespace animorder;

namespace {
Mat4 identity() { return {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}; }
Mat4 translate(float x, float y, float z) {
    Mat4 m = identity();
    m[12] = x, m[13] = y, m[14] = z;
    return m;
}
Mat4 rotate_z_90() { return {0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}; }  // x → y, y → −x
}  // namespace

TEST(Skinning, IdentityKeepsBindPositions) {
    const std::vector<float> bind{1, 2, 3, -4, 5, 6};
    const std::vector<uint16_t> joints{0, 0};
    const std::vector<float> weights{1, 1};
    const Mat4 m = identity();
    std::vector<float> out(6);
    skin_positions(out.data(), bind.data(), 2, joints.data(), weights.data(), 1, &m, 1);
    EXPECT_EQ(out, bind);
}

TEST(Skinning, SingleTranslatingJointMovesEveryVertex) {
    const std::vector<float> bind{0, 0, 0, 1, -2, 0.5f, -3, 4, 10};
    const std::vector<uint16_t> joints{0, 0, 0};
    const std::vector<float> weights{1, 1, 1};
    const Mat4 m = translate(1, 2, 3);
    std::vector<float> out(9);
    skin_positions(out.data(), bind.data(), 3, joints.data(), weights.data(), 1, &m, 1);
    EXPECT_EQ(out, (std::vector<float>{1, 2, 3, 2, 0, 3.5f, -2, 6, 13}));
}

TEST(Skinning, BlendsTwoJointsByWeight) {
    // Vertex (1, 0, 0): joint 0 translates by (1, 2, 3) → (2, 2, 3); joint 1 rotates 90° about
    // Z → (0, 1, 0). Weights 0.25 / 0.75 → (0.5, 1.25, 0.75).
    const std::vector<float> bind{1, 0, 0};
    const std::vector<uint16_t> joints{0, 1};
    const std::vector<float> weights{0.25f, 0.75f};
    const Mat4 matrices[2] = {translate(1, 2, 3), rotate_z_90()};
    std::vector<float> out(3);
    skin_positions(out.data(), bind.data(), 1, joints.data(), weights.data(), 2, matrices, 2);
    EXPECT_FLOAT_EQ(out[0], 0.5f);
    EXPECT_FLOAT_EQ(out[1], 1.25f);
    EXPECT_FLOAT_EQ(out[2], 0.75f);
}

TEST(Skinning, NormalisesWeightsAndKeepsUnweightedVertices) {
    const std::vector<float> bind{1, 0, 0, 7, 8, 9};
    const std::vector<uint16_t> joints{0, 1, 0, 1};
    const std::vector<float> weights{1.0f, 1.0f, 0.0f, 0.0f};  // sums 2 and 0
    const Mat4 matrices[2] = {translate(2, 0, 0), translate(0, 4, 0)};
    std::vector<float> out(6);
    skin_positions(out.data(), bind.data(), 2, joints.data(), weights.data(), 2, matrices, 2);
    EXPECT_FLOAT_EQ(out[0], 2.0f);  // (3,0,0) and (1,4,0) averaged
    EXPECT_FLOAT_EQ(out[1], 2.0f);
    EXPECT_EQ(std::vector<float>(out.begin() + 3, out.end()), (std::vector<float>{7, 8, 9}));
}

TEST(Skinning, RejectsBadJointsAndWeights) {
    const std::vector<float> bind{1, 0, 0};
    const Mat4 m = identity();
    std::vector<float> out(3);
    const std::vector<uint16_t> bad_joint{3};
    const std::vector<float> one{1};
    EXPECT_THROW(skin_positions(out.data(), bind.data(), 1, bad_joint.data(), one.data(), 1, &m, 1), InvalidInput);
    const std::vector<uint16_t> ok{0};
    const std::vector<float> nan{std::nanf("")};
    EXPECT_THROW(skin_positions(out.data(), bind.data(), 1, ok.data(), nan.data(), 1, &m, 1), InvalidInput);
    const std::vector<float> infinite{INFINITY};
    EXPECT_THROW(skin_positions(out.data(), bind.data(), 1, ok.data(), infinite.data(), 1, &m, 1), InvalidInput);
    try {
        skin_positions(out.data(), bind.data(), 1, bad_joint.data(), one.data(), 1, &m, 1);
    } catch (const InvalidInput& e) {
        EXPECT_NE(std::string(e.what()).find("joint 3"), std::string::npos) << e.what();
    }
}

TEST(Skinning, IgnoresTheJointOfAZeroWeightSlot) {
    // glTF pads unused influences with any joint and weight 0; only slots that count are checked.
    const std::vector<float> bind{1, 0, 0};
    const std::vector<uint16_t> joints{0, 9};
    const std::vector<float> weights{1, 0};
    const Mat4 m = translate(0, 0, 5);
    std::vector<float> out(3);
    skin_positions(out.data(), bind.data(), 1, joints.data(), weights.data(), 2, &m, 1);
    EXPECT_EQ(out, (std::vector<float>{1, 0, 5}));
}
