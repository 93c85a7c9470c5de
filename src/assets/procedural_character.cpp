// The bundled default input: a procedurally built, skinned, animated character.
//
// It stands in for the paper's Mixamo characters wherever no file is given, so it has what makes
// their overdraw interesting: limbs and a shield that occlude the body and each other from many
// views (a cape behind the back, shoulder pads, a shield on the left forearm), joints that bend
// (smooth weights, so the skin stretches instead of tearing), and two
// clips with different motion. Its hair cards and cloth cape are blended and double-sided
// (issue 18): the input on which blend orders are measured. Parts are closed capsules (surfaces of revolution) around the
// bones of a 13-joint skeleton, about 1.8 m tall, Y up, facing +Z, its left on +X. Keyframes are
// skinned with skin_positions at 30 samples per second, as DESIGN.md says for clips.
#include "animorder/procedural_character.h"

#include "animorder/animated_mesh.h"
#include "animorder/skinning.h"

#include "../support/mat4.h"
#include "lathe.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

namespace animorder {
namespace {

using procedural::Ring;
using procedural::Vec3;

enum Joint : uint16_t {
    kHips,
    kChest,
    kHead,
    kLeftUpperArm,
    kLeftForearm,
    kRightUpperArm,
    kRightForearm,
    kLeftThigh,
    kLeftShin,
    kRightThigh,
    kRightShin,
    kLeftFoot,
    kRightFoot,
    kJointCount
};

struct Bone {
    int parent;
    Vec3 position;  // bind pose, world space (the bind pose has no rotation)
};

const std::array<Bone, kJointCount> kSkeleton = {{
    {-1, {0, 0.95, 0}},      // hips
    {kHips, {0, 1.20, 0}},   // chest
    {kChest, {0, 1.50, 0}},  // head (neck base)
    {kChest, {0.22, 1.40, 0}},
    {kLeftUpperArm, {0.30, 1.12, 0}},  // left shoulder, elbow
    {kChest, {-0.22, 1.40, 0}},
    {kRightUpperArm, {-0.30, 1.12, 0}},  // right shoulder, elbow
    {kHips, {0.10, 0.92, 0}},
    {kLeftThigh, {0.11, 0.51, 0}},  // left hip, knee
    {kHips, {-0.10, 0.92, 0}},
    {kRightThigh, {-0.11, 0.51, 0}},  // right hip, knee
    {kLeftShin, {0.12, 0.09, 0}},
    {kRightShin, {-0.12, 0.09, 0}},  // ankles
}};

struct Builder {
    std::vector<double> positions, along;
    std::vector<uint32_t> indices;
    std::vector<uint16_t> joints;  // 2 influences per vertex
    std::vector<float> weights;

    // A capsule from a to b around a chain of two bones meeting at `joint_at` (a fraction of the
    // length); weights blend from `first` to `second` over ±blend around the joint.
    void limb(Vec3 a, Vec3 b, double r0, double r1, uint16_t first, uint16_t second, double joint_at, double blend,
              int cap_rings, int body_rings, int segments, double side_scale = 1.0) {
        const double length = std::sqrt(procedural::dot(b - a, b - a));
        const size_t start = positions.size() / 3;
        procedural::add_lathe(positions, along, indices, a, b - a, -r0,
                              procedural::capsule_rings(length, r0, r1, cap_rings, body_rings), length + r1, segments,
                              side_scale);
        for (size_t v = start; v < positions.size() / 3; ++v) {
            const double s = along[v] / length - joint_at;
            const double t = std::clamp(0.5 + s * length / (2.0 * blend), 0.0, 1.0);
            const double w = t * t * (3 - 2 * t);  // smoothstep
            joints.insert(joints.end(), {first, second});
            weights.insert(weights.end(), {float(1 - w), float(w)});
        }
    }

    // A sheet (open surface) of columns × rows quads: point(u, v) for u, v in [0, 1], counter-
    // clockwise seen from where cross(∂u, ∂v) points; vertex weights from `first` (v = 0) to
    // `second` (v = 1) by weight(v).
    template <typename Point, typename Weight>
    void sheet(int columns, int rows, Point point, uint16_t first, uint16_t second, Weight weight) {
        const uint32_t start = uint32_t(positions.size() / 3);
        for (int r = 0; r <= rows; ++r)
            for (int c = 0; c <= columns; ++c) {
                const double u = double(c) / columns, v = double(r) / rows;
                const Vec3 p = point(u, v);
                positions.insert(positions.end(), {p.x, p.y, p.z});
                along.push_back(0);
                const double w = std::clamp(weight(v), 0.0, 1.0);
                joints.insert(joints.end(), {first, second});
                weights.insert(weights.end(), {float(1 - w), float(w)});
            }
        const uint32_t stride = uint32_t(columns + 1);
        for (int r = 0; r < rows; ++r)
            for (int c = 0; c < columns; ++c) {
                const uint32_t a = start + uint32_t(r) * stride + uint32_t(c), b = a + 1, d = a + stride, e = d + 1;
                indices.insert(indices.end(), {a, b, e, a, e, d});
            }
    }
};

// Column-major 4×4 helpers (glTF layout); the product is multiply_mat4 (src/support/mat4.h).
Mat4 identity() { return {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}; }
Mat4 translation(Vec3 t) {
    Mat4 m = identity();
    m[12] = float(t.x), m[13] = float(t.y), m[14] = float(t.z);
    return m;
}
// Rotation about X, then Y, then Z (R = Rz · Ry · Rx), angles in radians.
Mat4 rotation(Vec3 angles) {
    const double cx = std::cos(angles.x), sx = std::sin(angles.x), cy = std::cos(angles.y), sy = std::sin(angles.y),
                 cz = std::cos(angles.z), sz = std::sin(angles.z);
    const Mat4 rx = {1, 0, 0, 0, 0, float(cx), float(sx), 0, 0, float(-sx), float(cx), 0, 0, 0, 0, 1};
    const Mat4 ry = {float(cy), 0, float(-sy), 0, 0, 1, 0, 0, float(sy), 0, float(cy), 0, 0, 0, 0, 1};
    const Mat4 rz = {float(cz), float(sz), 0, 0, float(-sz), float(cz), 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    return multiply_mat4(rz, multiply_mat4(ry, rx));
}

struct Pose {
    std::array<Vec3, kJointCount> rotation{};  // local Euler angles
    Vec3 root_offset;                          // hips translation from the bind position
};

Pose walk_pose(double t) {  // one stride per second
    const double s = std::sin(2 * M_PI * t), c = std::cos(2 * M_PI * t);
    Pose p;
    p.root_offset = {0, 0.03 * std::fabs(std::sin(2 * M_PI * t)) - 0.015, 0};
    p.rotation[kLeftThigh].x = -0.55 * s;  // negative X rotation swings the leg forward (+Z)
    p.rotation[kRightThigh].x = 0.55 * s;
    p.rotation[kLeftShin].x = 0.35 + 0.45 * std::max(0.0, c);  // knees bend back
    p.rotation[kRightShin].x = 0.35 + 0.45 * std::max(0.0, -c);
    p.rotation[kLeftFoot].x = -0.2 * s;
    p.rotation[kRightFoot].x = 0.2 * s;
    p.rotation[kLeftUpperArm].x = 0.45 * s;  // arms swing opposite to the legs
    p.rotation[kRightUpperArm].x = -0.45 * s;
    p.rotation[kLeftForearm].x = -0.5;  // elbows bent forward
    p.rotation[kRightForearm].x = -0.5;
    p.rotation[kChest].y = 0.12 * s;  // shoulders counter-rotate
    p.rotation[kHead].y = -0.08 * s;
    return p;
}

Pose wave_pose(double t) {  // 1.5 s: right arm up and waving, shield raised, torso turning
    const double raise = std::min(1.0, t / 0.35);
    const double ease = raise * raise * (3 - 2 * raise);
    Pose p;
    p.rotation[kRightUpperArm].z = -2.5 * ease;                                              // up and out to −X
    p.rotation[kRightForearm].z = -0.3 * ease + 0.55 * ease * std::sin(2 * M_PI * 2.0 * t);  // waving
    p.rotation[kLeftUpperArm].x = -1.1 * ease;                                               // shield arm forward
    p.rotation[kLeftForearm].y = 0.9 * ease;                                                 // shield across the chest
    p.rotation[kLeftForearm].x = -0.6 * ease;
    p.rotation[kChest].y = 0.35 * std::sin(2 * M_PI * t / 1.5);
    p.rotation[kChest].z = 0.12 * ease;
    p.rotation[kHead].y = 0.45 * std::sin(2 * M_PI * t / 1.5 + 0.8);
    p.rotation[kHead].x = -0.15 * ease;
    p.rotation[kLeftThigh].x = -0.15 * ease;  // weight shift
    p.rotation[kLeftShin].x = 0.3 * ease;
    return p;
}

std::array<Mat4, kJointCount> skinning_matrices(const Pose& pose) {
    std::array<Mat4, kJointCount> world{}, skin{};
    for (int j = 0; j < kJointCount; ++j) {
        const Bone& bone = kSkeleton[j];
        const Vec3 offset =
            bone.parent < 0 ? bone.position + pose.root_offset : bone.position - kSkeleton[bone.parent].position;
        const Mat4 local = multiply_mat4(translation(offset), rotation(pose.rotation[j]));
        world[j] = bone.parent < 0 ? local : multiply_mat4(world[bone.parent], local);  // parents come first
        skin[j] = multiply_mat4(world[j], translation(bone.position * -1.0));           // · inverse bind
    }
    return skin;
}

}  // namespace

AnimatedMesh make_procedural_character() {
    Builder body;
    const auto& S = kSkeleton;
    // Torso (hips → chest), slightly flattened front to back.
    body.limb({0, 0.80, 0}, {0, 1.42, 0}, 0.16, 0.19, kHips, kChest, 0.5, 0.12, 7, 24, 28, 0.7);
    // Head on a short neck.
    body.limb({0, 1.50, 0}, {0, 1.66, 0}, 0.085, 0.10, kHead, kHead, 0.5, 0.05, 6, 11, 24);
    // Arms: upper arm and forearm in one tube bending at the elbow.
    for (int side = 0; side < 2; ++side) {
        const uint16_t upper = side ? kRightUpperArm : kLeftUpperArm, fore = side ? kRightForearm : kLeftForearm;
        const Vec3 shoulder = S[upper].position, elbow = S[fore].position;
        const Vec3 wrist = elbow + (elbow - shoulder) * 0.95;
        const double at = 1.0 / 1.95;
        body.limb(shoulder, wrist, 0.055, 0.04, upper, fore, at, 0.05, 5, 27, 16);
    }
    // Legs: thigh and shin bending at the knee, then feet.
    for (int side = 0; side < 2; ++side) {
        const uint16_t thigh = side ? kRightThigh : kLeftThigh, shin = side ? kRightShin : kLeftShin,
                       foot = side ? kRightFoot : kLeftFoot;
        const Vec3 hip = S[thigh].position, knee = S[shin].position, ankle = S[foot].position;
        const double upper = std::sqrt(procedural::dot(knee - hip, knee - hip));
        const double total = upper + std::sqrt(procedural::dot(ankle - knee, ankle - knee));
        body.limb(hip, ankle, 0.08, 0.05, thigh, shin, upper / total, 0.06, 5, 31, 16);
        body.limb(ankle + Vec3{0, -0.03, -0.04}, ankle + Vec3{0, -0.04, 0.16}, 0.045, 0.04, foot, foot, 0.5, 0.05, 4, 9,
                  12);
    }
    // A cape hanging from the shoulders to the knees behind the back, and shoulder pads over the
    // arms: layers that hide the back, the legs and the arms from many views.
    body.limb({0, 1.40, -0.16}, {0, 0.55, -0.20}, 0.03, 0.03, kChest, kHips, 0.35, 0.25, 3, 16, 16, 9.0);
    for (int side = 0; side < 2; ++side) {
        const uint16_t upper = side ? kRightUpperArm : kLeftUpperArm;
        const Vec3 shoulder = S[upper].position;
        body.limb(shoulder + Vec3{side ? -0.03 : 0.03, 0.05, 0}, shoulder + Vec3{side ? -0.05 : 0.05, -0.06, 0}, 0.09,
                  0.07, upper, upper, 0.6, 0.05, 4, 4, 14);
    }
    const size_t body_indices = body.indices.size();
    // The shield: a flat disc strapped to the outside of the left forearm.
    {
        const Vec3 elbow = S[kLeftForearm].position, shoulder = S[kLeftUpperArm].position;
        const Vec3 centre = elbow + (elbow - shoulder) * 0.45 + Vec3{0.06, 0, 0};
        std::vector<Ring> rings;
        const int count = 14;
        for (int i = 1; i < count; ++i) {
            const double a = M_PI * i / count;
            rings.push_back({-0.025 * std::cos(a), 0.21 * std::sin(a)});
        }
        const size_t start = body.positions.size() / 3;
        procedural::add_lathe(body.positions, body.along, body.indices, centre, {1, 0, 0}, -0.025, rings, 0.025, 28,
                              1.15);
        for (size_t v = start; v < body.positions.size() / 3; ++v) {
            body.joints.insert(body.joints.end(), {kLeftForearm, kLeftForearm});
            body.weights.insert(body.weights.end(), {1.0f, 0.0f});
        }
    }

    const size_t shield_end = body.indices.size();
    // Hair cards (blended, double-sided, issue 18): three layers of 20 narrow strips around the
    // back and sides of the head, each hanging from the scalp to the shoulders and overlapping
    // its neighbours, skinned to the head. Seen from most views several layers cover a pixel.
    for (int layer = 0; layer < 3; ++layer)
        for (int card = 0; card < 20; ++card) {
            const double angle = M_PI * (-0.8 + 1.6 * (card + 0.5 * (layer % 2)) / 19.0);  // 0: the back (−Z)
            const Vec3 out = {std::sin(angle), 0, -std::cos(angle)}, side = {std::cos(angle), 0, std::sin(angle)};
            const double r_top = 0.085 + 0.012 * layer, r_bottom = 0.125 + 0.02 * layer;
            body.sheet(
                1, 5,
                [&](double u, double v) {
                    const double r = r_top + (r_bottom - r_top) * v;
                    return Vec3{0, 1.73 - 0.31 * v - 0.02 * layer, 0} + out * r + side * (0.05 * (u - 0.5));
                },
                kHead, kHead, [](double) { return 0.0; });
        }
    const size_t hair_end = body.indices.size();
    // A cloth cape (blended, double-sided): a sheet wrapped round the back from the shoulders to
    // the knees, widening as it falls, its top following the chest and its hem the hips.
    body.sheet(
        16, 12,
        [&](double u, double v) {
            const double angle = M_PI * (-0.55 + 1.1 * u), r = 0.23 + 0.12 * v;
            return Vec3{r * std::sin(angle), 1.42 - 0.87 * v, -r * std::cos(angle) - 0.02};
        },
        kChest, kHips, [](double v) { return v * 1.4; });

    AnimatedMesh mesh;
    mesh.name = "procedural-character";
    mesh.vertex_count = body.positions.size() / 3;
    mesh.indices = body.indices;
    mesh.primitives = {{"body", 0, body_indices},
                       {"shield", body_indices, shield_end - body_indices},
                       {"hair", shield_end, hair_end - shield_end},
                       {"cape", hair_end, body.indices.size() - hair_end}};
    for (size_t p = 2; p < 4; ++p) {
        mesh.primitives[p].double_sided = true;
        mesh.primitives[p].alpha_mode = AlphaMode::Blend;
    }
    mesh.joint_count = kJointCount;
    const std::vector<float> bind(body.positions.begin(), body.positions.end());

    struct ClipSpec {
        const char* name;
        double duration;
        Pose (*pose)(double);
    };
    for (const ClipSpec& spec : {ClipSpec{"walk", 1.0, walk_pose}, ClipSpec{"wave", 1.5, wave_pose}}) {
        Clip clip;
        clip.name = spec.name;
        clip.duration_s = spec.duration;
        clip.sample_rate = 30;
        clip.first_keyframe = mesh.keyframe_count();
        clip.keyframe_count = size_t(std::lround(spec.duration * 30)) + 1;
        const size_t first_float = mesh.keyframe_positions.size();
        mesh.keyframe_positions.resize(first_float + clip.keyframe_count * mesh.vertex_count * 3);
        for (size_t f = 0; f < clip.keyframe_count; ++f) {
            const std::array<Mat4, kJointCount> skin = skinning_matrices(spec.pose(double(f) / 30.0));
            skin_positions(mesh.keyframe_positions.data() + first_float + f * mesh.vertex_count * 3, bind.data(),
                           mesh.vertex_count, body.joints.data(), body.weights.data(), 2, skin.data(), kJointCount);
        }
        mesh.clips.push_back(clip);
    }
    return mesh;
}

}  // namespace animorder
