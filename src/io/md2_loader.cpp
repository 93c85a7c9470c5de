// Quake II MD2 vertex-keyframe models, every frame (assimp 5.2 reads only the first).
//
// Format (id Software's md2.h): a 68-byte header ("IDP2", version 8, counts and offsets), then
// triangles as 3 vertex + 3 texture-coordinate indices, and frames as scale, translate, a
// 16-character name and per vertex 3 bytes (position = byte · scale + translate) plus a normal
// index. Frames whose names differ only in trailing digits ("run1" … "run6") form one clip, split
// where the number starts again or a Quake II variant begins ("pain101" … "pain104", "pain201"
// …: clips pain1 and pain2).
// MD2 has no timing; the Quake II convention plays 10 frames per second, so a clip of n frames
// lasts (n − 1)/10 s and is resampled at the sample rate by linear interpolation between frames.
// Triangles index the file's own vertex array (texture coordinates are separate in MD2), so
// vertex identity is the file's; MD2 stores front faces clockwise, so corners 1 and 2 are
// swapped to give DESIGN.md's counter-clockwise fronts.
#include "animorder/md2_loader.h"

#include "animorder/animated_mesh.h"
#include "animorder/invalid_input.h"
#include "animorder/load.h"

#include "checked_size.h"

#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <utility>

namespace animorder {
namespace {

constexpr double kMd2FramesPerSecond = 10.0;

int32_t i32(const std::vector<unsigned char>& d, size_t at) {
    int32_t v;
    std::memcpy(&v, d.data() + at, 4);
    return v;
}

// Whether frame number `next` (its name's trailing digits) continues `previous` in one clip: it
// does unless it starts again (not larger), or it is frame 01 of the next variant: Quake II
// numbers the frames of an action's variants "pain101" … "pain104", "pain201" …, each variant a
// clip (while "run099", "run100" continue). A gap ("run2", "run4") continues; so do names
// without digits.
bool follows(const std::string& previous, const std::string& next) {
    if (previous.empty() || next.empty() || previous.size() > 9 || next.size() > 9) return true;
    if (std::stol(next) <= std::stol(previous)) return false;
    const bool next_variant = next.size() >= 3 && next.size() == previous.size() &&
                              next.compare(0, next.size() - 2, previous, 0, previous.size() - 2) != 0 &&
                              next.compare(next.size() - 2, 2, "01") == 0;
    return !next_variant;
}

}  // namespace

AnimatedMesh load_md2(const std::string& path, const LoadOptions& options) {
    if (!(options.sample_rate > 0 && options.sample_rate <= 1000))
        throw LoadError(path + ": sample rate must be in (0, 1000]");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw LoadError(path + ": cannot open file");
    const std::vector<unsigned char> d((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    auto fail = [&](const std::string& why) -> LoadError { return LoadError(path + ": " + why); };
    if (d.size() < 68) throw fail("file is truncated (no MD2 header)");
    if (std::memcmp(d.data(), "IDP2", 4) != 0 || i32(d, 4) != 8) throw fail("not an MD2 version 8 file");
    const int32_t frame_size = i32(d, 16), vertices = i32(d, 24), triangles = i32(d, 32), frames = i32(d, 40);
    const int32_t ofs_tris = i32(d, 52), ofs_frames = i32(d, 56);
    // Every count and offset is hostile: compared in 64 bits (40 + 4 · vertices overflows an int)
    // and every byte range checked against the file before anything is allocated or read.
    if (vertices <= 0 || triangles <= 0 || frames <= 0 || int64_t(frame_size) < 40 + 4 * int64_t(vertices))
        throw fail("header counts are invalid");
    size_t tris_end = 0, frames_end = 0;
    if (ofs_tris < 0 || ofs_frames < 0 || !io::checked_add(size_t(ofs_tris), size_t(triangles) * 12, tris_end) ||
        tris_end > d.size() ||
        !io::checked_add(size_t(ofs_frames), io::mul_or_throw(path + ": frames", size_t(frames), size_t(frame_size)),
                         frames_end) ||
        frames_end > d.size())
        throw fail("file is truncated (triangles or frames past its end)");
    // The file's own frames, then the resampled clips, must fit the loading budget.
    io::check_keyframe_budget(path, size_t(frames), size_t(vertices), options, "frames of the file");

    AnimatedMesh mesh;
    mesh.name = path;
    mesh.vertex_count = size_t(vertices);
    for (int32_t t = 0; t < triangles; ++t) {
        uint16_t v[3];
        std::memcpy(v, d.data() + size_t(ofs_tris) + 12 * size_t(t), 6);
        for (uint16_t x : v)
            if (x >= vertices)
                throw fail("triangle " + std::to_string(t) + " names vertex " + std::to_string(x) + ", there are " +
                           std::to_string(vertices));
        mesh.indices.insert(mesh.indices.end(), {v[0], v[2], v[1]});  // clockwise → counter-clockwise
    }
    Primitive prim;
    prim.name = "md2";  // no materials in the format: single-sided, opaque (the defaults)
    prim.index_count = mesh.indices.size();
    prim.vertex_count = mesh.vertex_count;
    mesh.primitives.push_back(prim);

    // Frame positions and names.
    std::vector<std::vector<float>> frame_positions(size_t(frames), std::vector<float>(size_t(vertices) * 3));
    // Per frame, its name without the trailing digits (the clip it belongs to) and those digits.
    std::vector<std::string> group(static_cast<size_t>(frames)), number(static_cast<size_t>(frames));
    for (int32_t f = 0; f < frames; ++f) {
        const unsigned char* p = d.data() + ofs_frames + size_t(f) * size_t(frame_size);
        float scale[3], translate[3];
        std::memcpy(scale, p, 12);
        std::memcpy(translate, p + 12, 12);
        for (int c = 0; c < 3; ++c)
            if (!std::isfinite(scale[c]) || !std::isfinite(translate[c]))
                throw fail("frame " + std::to_string(f) + " has a NaN or infinite scale or translation");
        std::string name(reinterpret_cast<const char*>(p + 24), strnlen(reinterpret_cast<const char*>(p + 24), 16));
        size_t digits = name.size();
        while (digits > 0 && std::isdigit(static_cast<unsigned char>(name[digits - 1]))) --digits;
        number[size_t(f)] = name.substr(digits);
        name.resize(digits);
        group[size_t(f)] = name.empty() ? "frames" : name;
        for (int32_t v = 0; v < vertices; ++v)
            for (int c = 0; c < 3; ++c)
                frame_positions[size_t(f)][size_t(v) * 3 + size_t(c)] =
                    float(p[40 + 4 * size_t(v) + size_t(c)]) * scale[c] + translate[c];
    }

    // One clip per run of frames with the same group name, resampled from 10 frames per second;
    // every clip's keyframe count is known (and the total checked against the budget) before any
    // is sampled.
    std::vector<std::pair<int32_t, int32_t>> runs;  // [begin, end) frames of each clip
    size_t total_keyframes = 0;
    for (int32_t begin = 0; begin < frames;) {
        int32_t end = begin + 1;
        while (end < frames && group[size_t(end)] == group[size_t(begin)] &&
               follows(number[size_t(end) - 1], number[size_t(end)]))
            ++end;
        Clip clip;
        clip.name = group[size_t(begin)];
        clip.duration_s = double(end - begin - 1) / kMd2FramesPerSecond;
        clip.sample_rate = options.sample_rate;
        clip.keyframe_count = io::clip_keyframes(path, clip.name, clip.duration_s, options.sample_rate);
        clip.first_keyframe = total_keyframes;
        total_keyframes += clip.keyframe_count;
        mesh.clips.push_back(clip);
        runs.emplace_back(begin, end);
        begin = end;
    }
    // A name that several clips share because follows() split its frames (Quake II's variants)
    // takes the variant's digits: pain1, pain2, pain3.
    std::vector<size_t> sharing(runs.size(), 0);
    for (size_t c = 0; c < runs.size(); ++c)
        for (const Clip& other : mesh.clips) sharing[c] += other.name == mesh.clips[c].name;
    for (size_t c = 0; c < runs.size(); ++c) {
        const std::string& digits = number[size_t(runs[c].first)];
        if (sharing[c] > 1 && digits.size() >= 3 && digits.size() <= 9)
            mesh.clips[c].name += digits.substr(0, digits.size() - 2);
    }
    io::check_keyframe_budget(path, total_keyframes, size_t(vertices), options);
    mesh.keyframe_positions.reserve(total_keyframes * size_t(vertices) * 3);
    for (size_t c = 0; c < mesh.clips.size(); ++c) {
        const auto [begin, end] = runs[c];
        for (size_t k = 0; k < mesh.clips[c].keyframe_count; ++k) {
            const double at = std::min(double(k) / options.sample_rate * kMd2FramesPerSecond, double(end - begin - 1));
            const size_t a = size_t(begin) + size_t(at), b = std::min(a + 1, size_t(end - 1));
            const float u = float(at - std::floor(at));
            for (size_t i = 0; i < size_t(vertices) * 3; ++i)
                mesh.keyframe_positions.push_back(frame_positions[a][i] +
                                                  u * (frame_positions[b][i] - frame_positions[a][i]));
        }
    }
    try {
        validate_animated_mesh(mesh);
    } catch (const InvalidInput& e) {
        throw fail(e.what());
    }
    return mesh;
}

}  // namespace animorder
