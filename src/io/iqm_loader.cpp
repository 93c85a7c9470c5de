// Inter-Quake Model (IQM v2) characters with their skeletal animations (assimp 5.2 reads only the
// mesh).
//
// Format: Lee Salzman's iqm.h / iqm.txt. The file holds vertex arrays (POSITION as 3 floats,
// BLENDINDEXES and BLENDWEIGHTS as 4 bytes), triangles as 3 uint32, joints with a base pose
// (translate, rotate quaternion, scale), and animations as frames of quantised pose channels:
// channel c of pose j is offset[c] + (mask bit c ? stored ushort · scale[c] : 0), for the 10
// channels translate xyz, rotate xyzw, scale xyz. Skinning follows the reference viewer: joint
// matrix = animated global · inverse(base global), weights in bytes normalised by their sum.
// IQM triangles face front clockwise (the reference viewer culls with glFrontFace(GL_CW)), so
// corners 1 and 2 are swapped for DESIGN.md's counter-clockwise fronts. Each animation is sampled
// at its own frame rate and resampled at sample_rate by linear interpolation of the positions.
#include "animorder/iqm_loader.h"

#include "animorder/animated_mesh.h"
#include "animorder/invalid_input.h"
#include "animorder/load.h"
#include "animorder/skinning.h"

#include "checked_size.h"
#include "transform.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>

namespace animorder {
namespace {

using io::Mat;

class Bytes {
public:
    Bytes(const std::string& path, std::vector<unsigned char> data) : path_(path), d_(std::move(data)) {}
    LoadError fail(const std::string& why) const { return LoadError(path_ + ": " + why); }
    void need(size_t offset, size_t count, size_t size, const char* what) const {
        if (offset > d_.size() || count > (d_.size() - offset) / std::max<size_t>(size, 1))
            throw fail(std::string("file is truncated (") + what + " past its end)");
    }
    uint32_t u32(size_t at) const {
        uint32_t v;
        std::memcpy(&v, d_.data() + at, 4);
        return v;
    }
    float f32(size_t at) const {
        float v;
        std::memcpy(&v, d_.data() + at, 4);
        return v;
    }
    uint16_t u16(size_t at) const {
        uint16_t v;
        std::memcpy(&v, d_.data() + at, 2);
        return v;
    }
    uint8_t u8(size_t at) const { return d_[at]; }
    size_t size() const { return d_.size(); }
    std::string text(size_t ofs_text, size_t num_text, uint32_t at) const {
        if (at >= num_text) return "";
        const char* p = reinterpret_cast<const char*>(d_.data() + ofs_text + at);
        return std::string(p, strnlen(p, num_text - at));
    }

private:
    std::string path_;
    std::vector<unsigned char> d_;
};

Mat pose_matrix(const double t[3], const double q_in[4], const double s[3]) {
    const double n = std::sqrt(q_in[0] * q_in[0] + q_in[1] * q_in[1] + q_in[2] * q_in[2] + q_in[3] * q_in[3]);
    const io::Quat q = {q_in[0] / n, q_in[1] / n, q_in[2] / n, q_in[3] / n};
    return io::trs({t[0], t[1], t[2]}, q, {s[0], s[1], s[2]});
}

}  // namespace

AnimatedMesh load_iqm(const std::string& path, const LoadOptions& options) {
    if (!(options.sample_rate > 0 && options.sample_rate <= 1000))
        throw LoadError(path + ": sample rate must be in (0, 1000]");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw LoadError(path + ": cannot open file");
    const Bytes b(path,
                  std::vector<unsigned char>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()));
    if (b.size() < 124) throw b.fail("file is truncated (no IQM header)");
    static const char kMagic[16] = "INTERQUAKEMODEL";
    std::vector<unsigned char> magic(16);
    for (size_t i = 0; i < 16; ++i) magic[i] = b.u8(i);
    if (std::memcmp(magic.data(), kMagic, 16) != 0 || b.u32(16) != 2) throw b.fail("not an IQM version 2 file");
    const size_t num_text = b.u32(28), ofs_text = b.u32(32), num_arrays = b.u32(44), num_vertexes = b.u32(48),
                 ofs_arrays = b.u32(52), num_triangles = b.u32(56), ofs_triangles = b.u32(60), num_joints = b.u32(68),
                 ofs_joints = b.u32(72), num_poses = b.u32(76), ofs_poses = b.u32(80), num_anims = b.u32(84),
                 ofs_anims = b.u32(88), num_frames = b.u32(92), num_channels = b.u32(96), ofs_frames = b.u32(100);
    b.need(ofs_text, num_text, 1, "text");
    b.need(ofs_arrays, num_arrays, 20, "vertex arrays");
    b.need(ofs_triangles, num_triangles, 12, "triangles");
    b.need(ofs_joints, num_joints, 48, "joints");
    b.need(ofs_poses, num_poses, 88, "poses");
    b.need(ofs_anims, num_anims, 20, "animations");
    b.need(ofs_frames, io::mul_or_throw(path + ": frames", num_frames, num_channels), 2, "frames");
    if (num_vertexes == 0 || num_triangles == 0) throw b.fail("no triangle mesh in the file");

    std::vector<float> positions;
    std::vector<uint16_t> joints;
    std::vector<float> weights;
    for (size_t a = 0; a < num_arrays; ++a) {
        const size_t at = ofs_arrays + 20 * a;
        const uint32_t type = b.u32(at), format = b.u32(at + 8), size = b.u32(at + 12), offset = b.u32(at + 16);
        if (type == 0) {  // POSITION
            if (format != 7 || size != 3) throw b.fail("positions must be 3 floats");
            if (!positions.empty()) throw b.fail("two POSITION vertex arrays");
            b.need(offset, num_vertexes * 3, 4, "positions");
            for (size_t i = 0; i < num_vertexes * 3; ++i) positions.push_back(b.f32(offset + 4 * i));
        } else if (type == 4 || type == 5) {  // BLENDINDEXES, BLENDWEIGHTS
            if (format != 1 || size != 4) throw b.fail("blend indices and weights must be 4 unsigned bytes");
            if (type == 4 ? !joints.empty() : !weights.empty()) throw b.fail("two blend index or weight vertex arrays");
            b.need(offset, num_vertexes * 4, 1, "blend data");
            for (size_t i = 0; i < num_vertexes * 4; ++i)
                if (type == 4)
                    joints.push_back(b.u8(offset + i));
                else
                    weights.push_back(float(b.u8(offset + i)) / 255.0f);
        }
    }
    if (positions.empty()) throw b.fail("no POSITION vertex array");
    for (float p : positions)
        if (!std::isfinite(p)) throw b.fail("a position is NaN or infinite");

    AnimatedMesh mesh;
    mesh.name = path;
    mesh.vertex_count = num_vertexes;
    for (size_t t = 0; t < num_triangles; ++t) {
        const uint32_t v0 = b.u32(ofs_triangles + 12 * t), v1 = b.u32(ofs_triangles + 12 * t + 4),
                       v2 = b.u32(ofs_triangles + 12 * t + 8);
        if (v0 >= num_vertexes || v1 >= num_vertexes || v2 >= num_vertexes)
            throw b.fail("triangle " + std::to_string(t) + " names a vertex past " + std::to_string(num_vertexes));
        mesh.indices.insert(mesh.indices.end(), {v0, v2, v1});  // clockwise → counter-clockwise
    }
    Primitive prim;
    prim.name = "iqm";  // no materials in the format: single-sided, opaque (the defaults)
    prim.index_count = mesh.indices.size();
    prim.vertex_count = num_vertexes;
    mesh.primitives.push_back(prim);
    mesh.joint_count = num_joints;

    // Base pose: globals and their inverses.
    std::vector<int> parent(num_joints);
    std::vector<Mat> base_global(num_joints), inverse_base(num_joints);
    for (size_t j = 0; j < num_joints; ++j) {
        const size_t at = ofs_joints + 48 * j;
        parent[j] = int32_t(b.u32(at + 4));
        if (parent[j] >= 0 && size_t(parent[j]) >= j)
            throw b.fail("joint " + std::to_string(j) + " has a parent that does not come before it");
        double t[3], q[4], s[3];
        for (int c = 0; c < 3; ++c) t[c] = b.f32(at + 8 + 4 * size_t(c));
        for (int c = 0; c < 4; ++c) q[c] = b.f32(at + 20 + 4 * size_t(c));
        for (int c = 0; c < 3; ++c) s[c] = b.f32(at + 36 + 4 * size_t(c));
        const Mat local = pose_matrix(t, q, s);
        base_global[j] = parent[j] >= 0 ? io::mul(base_global[size_t(parent[j])], local) : local;
        inverse_base[j] = io::invert_affine(base_global[j]);
    }
    const bool skinned = num_joints > 0 && joints.size() == num_vertexes * 4 && weights.size() == num_vertexes * 4;
    if (skinned)
        for (uint16_t j : joints)
            if (j >= num_joints)
                throw b.fail("a vertex names joint " + std::to_string(j) + ", there are " + std::to_string(num_joints));

    // A frame holds one value per set mask bit of every pose: fewer channels in the header would
    // read each frame's last poses from the next frame.
    if (num_frames > 0) {
        size_t keyed = 0;
        for (size_t j = 0; j < num_poses; ++j)
            keyed += size_t(__builtin_popcount(b.u32(ofs_poses + 88 * j + 4) & 0x3FFu));
        if (keyed != num_channels)
            throw b.fail("its poses animate " + std::to_string(keyed) + " channels a frame, its header says " +
                         std::to_string(num_channels));
    }

    // Positions at one frame (or the bind pose when frame < 0).
    auto frame_positions = [&](long frame) {
        std::vector<float> out(positions);
        if (!skinned || frame < 0 || num_poses != num_joints) return out;
        std::vector<Mat> global(num_joints);
        std::vector<Mat4> skin(num_joints);
        size_t channel = size_t(frame) * num_channels;
        for (size_t j = 0; j < num_poses; ++j) {
            const size_t at = ofs_poses + 88 * j;
            const uint32_t mask = b.u32(at + 4);
            double value[10];
            for (int c = 0; c < 10; ++c) {
                value[c] = b.f32(at + 8 + 4 * size_t(c));
                if (mask & (1u << c)) {
                    if (channel >= num_frames * num_channels) throw b.fail("frame data runs out");
                    value[c] += double(b.u16(ofs_frames + 2 * channel++)) * b.f32(at + 48 + 4 * size_t(c));
                }
            }
            const Mat local = pose_matrix(value, value + 3, value + 7);
            global[j] = parent[j] >= 0 ? io::mul(global[size_t(parent[j])], local) : local;
            const Mat m = io::mul(global[j], inverse_base[j]);
            for (int k = 0; k < 16; ++k) skin[j][size_t(k)] = float(m[size_t(k)]);
        }
        try {
            skin_positions(out.data(), positions.data(), num_vertexes, joints.data(), weights.data(), 4, skin.data(),
                           num_joints);
        } catch (const InvalidInput& e) {
            throw b.fail(e.what());
        }
        return out;
    };

    // Every animation's frames and keyframe count first: the total is checked against the loading
    // budget before any frame is skinned or any clip sampled.
    struct Animation {
        uint32_t first, count;
        double rate;
    };
    std::vector<Animation> anims;
    size_t total_keyframes = 0;
    for (size_t a = 0; a < num_anims; ++a) {
        const size_t at = ofs_anims + 20 * a;
        const uint32_t first = b.u32(at + 4), count = b.u32(at + 8);
        const double rate = b.f32(at + 12) > 0 ? b.f32(at + 12) : 24.0;
        if (count == 0 || size_t(first) + count > num_frames)
            throw b.fail("animation " + std::to_string(a) + " names missing frames");
        if (!std::isfinite(rate)) throw b.fail("animation " + std::to_string(a) + " has an infinite frame rate");
        Clip clip;
        clip.name = b.text(ofs_text, num_text, b.u32(at));
        if (clip.name.empty()) clip.name = "animation" + std::to_string(a);
        clip.duration_s = double(count - 1) / rate;
        clip.sample_rate = options.sample_rate;
        clip.first_keyframe = total_keyframes;
        clip.keyframe_count = io::clip_keyframes(path, clip.name, clip.duration_s, options.sample_rate);
        total_keyframes += clip.keyframe_count;
        mesh.clips.push_back(clip);
        anims.push_back({first, count, rate});
    }
    io::check_keyframe_budget(path, total_keyframes, num_vertexes, options);
    mesh.keyframe_positions.reserve(total_keyframes * positions.size());  // no regrowth

    // Each keyframe interpolates the two frames around it; only those frames are skinned, each once
    // (keyframes move forward, so the pair slides along), whatever the file's frame count.
    for (size_t a = 0; a < anims.size(); ++a) {
        const auto [first, count, rate] = anims[a];
        std::vector<float> p0, p1;  // the positions of frames k0 and k1
        size_t k0 = SIZE_MAX, k1 = SIZE_MAX;
        for (size_t k = 0; k < mesh.clips[a].keyframe_count; ++k) {
            const double at_frame = std::min(double(k) / options.sample_rate * rate, double(count - 1));
            const size_t f0 = size_t(at_frame), f1 = std::min<size_t>(f0 + 1, count - 1);
            const float u = float(at_frame - double(f0));
            if (f0 != k0) {
                if (f0 == k1)
                    p0.swap(p1), std::swap(k0, k1);
                else
                    p0 = frame_positions(long(first + f0)), k0 = f0;
            }
            if (f1 != k1) {
                if (f1 == k0)
                    p1 = p0;
                else
                    p1 = frame_positions(long(first + f1));
                k1 = f1;
            }
            for (size_t i = 0; i < positions.size(); ++i)
                mesh.keyframe_positions.push_back(p0[i] + u * (p1[i] - p0[i]));
        }
    }
    if (mesh.clips.empty()) {
        mesh.keyframe_positions = frame_positions(-1);
        mesh.clips.push_back({"static", 0.0, options.sample_rate, 0, 1});
    }
    try {
        validate_animated_mesh(mesh);
    } catch (const InvalidInput& e) {
        throw b.fail(e.what());
    }
    return mesh;
}

}  // namespace animorder
