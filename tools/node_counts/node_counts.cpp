// node_counts INPUT.glb SIDECAR [--nodes-per-clip N] [--resolution R] [--seed S]
//
// For the viewer's browser test (viewer/test/browser.mjs): per (clip, keyframe, view) node of the
// protocol (DESIGN.md: framing, node camera of include/animorder/camera.h), the fragments that pass
// the depth test and the visible pixels, from the overdraw engine that `animorder evaluate` uses
// (score_nodes), for the input file's own index order ("original") and for the buffer the C runtime
// (include/animorder_runtime.h) picks at that node from the sidecar ("optimised"); and the node's
// camera (view-projection matrix, centre) so a page can draw exactly the same. Prints JSON.
// Nodes: N keyframes per clip spread over the clip, each with a direction from
// random_sphere_directions (the evaluation's kind of viewpoint; seed S).
#define ANIMORDER_RUNTIME_IMPLEMENTATION
#include "animorder_runtime.h"

#include "animorder/camera.h"
#include "animorder/load.h"
#include "animorder/overdraw.h"
#include "animorder/viewpoints.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <iterator>
#include <map>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

using namespace animorder;

namespace {

// The face permutation of `buffer` (a full index buffer over the same triangles as `indices`).
std::vector<uint32_t> face_order(const std::vector<uint32_t>& indices, const uint32_t* buffer) {
    auto key = [](uint32_t a, uint32_t b, uint32_t c) {  // a triangle whatever corner comes first
        if (b < a && b < c) return std::array<uint32_t, 3>{b, c, a};
        if (c < a && c < b) return std::array<uint32_t, 3>{c, a, b};
        return std::array<uint32_t, 3>{a, b, c};
    };
    std::map<std::array<uint32_t, 3>, std::vector<uint32_t>> where;
    for (size_t t = 0; t < indices.size() / 3; ++t)
        where[key(indices[3 * t], indices[3 * t + 1], indices[3 * t + 2])].push_back(uint32_t(t));
    std::vector<uint32_t> order(indices.size() / 3);
    for (size_t i = 0; i < order.size(); ++i) {
        auto it = where.find(key(buffer[3 * i], buffer[3 * i + 1], buffer[3 * i + 2]));
        if (it == where.end() || it->second.empty())
            throw std::runtime_error("the sidecar's buffer is not a permutation of the input's triangles");
        order[i] = it->second.back();
        it->second.pop_back();
    }
    return order;
}

}  // namespace

int main(int argc, char** argv) try {
    if (argc < 3) {
        std::fprintf(stderr, "usage: node_counts INPUT.glb SIDECAR [--nodes-per-clip N] [--resolution R] [--seed S]\n");
        return 1;
    }
    size_t per_clip = 12;
    unsigned resolution = 256;
    uint64_t seed = 7;
    for (int a = 3; a + 1 < argc; a += 2) {
        const std::string name = argv[a];
        const unsigned long long value = std::strtoull(argv[a + 1], nullptr, 10);
        if (name == "--nodes-per-clip")
            per_clip = value;
        else if (name == "--resolution")
            resolution = unsigned(value);
        else if (name == "--seed")
            seed = value;
        else
            throw std::runtime_error("unknown option " + name);
    }
    const AnimatedMesh mesh = load_character(argv[1]);
    std::ifstream in(argv[2], std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    animorder_runtime rt;
    if (animorder_runtime_open(&rt, bytes.data(), bytes.size()) != 0)
        throw std::runtime_error("the sidecar does not open");
    if (rt.index_count != mesh.indices.size() || rt.clip_count != mesh.clips.size())
        throw std::runtime_error("the sidecar does not belong to this input");

    // Orders: 0 the input's own, 1 + b buffer b of the sidecar.
    const size_t triangles = mesh.triangle_count();
    std::vector<std::vector<uint32_t>> orders;
    orders.emplace_back(triangles);
    std::iota(orders[0].begin(), orders[0].end(), 0u);
    for (uint32_t b = 0; b < rt.buffer_count; ++b)
        orders.push_back(face_order(mesh.indices, animorder_buffer(&rt, int(b))));
    std::vector<const uint32_t*> pointers;
    for (const auto& o : orders) pointers.push_back(o.data());
    const std::vector<uint32_t> ranks = make_rank_table(pointers, triangles);

    const Framing all = frame_animated_mesh(mesh);
    const std::vector<float> directions = random_sphere_directions(per_clip * mesh.clips.size(), seed);
    nlohmann::json out;
    out["resolution"] = resolution;
    out["nodes"] = nlohmann::json::array();
    size_t d = 0;
    for (size_t c = 0; c < mesh.clips.size(); ++c) {
        const Clip& clip = mesh.clips[c];
        std::vector<uint32_t> keyframes(clip.keyframe_count);
        std::iota(keyframes.begin(), keyframes.end(), uint32_t(clip.first_keyframe));
        const Framing framing = frame_subset(all, keyframes);
        for (size_t k = 0; k < per_clip; ++k, ++d) {
            const uint32_t f = uint32_t(k * (clip.keyframe_count - 1) / std::max<size_t>(1, per_clip - 1));
            OverdrawNode node;
            node.keyframe = uint32_t(clip.first_keyframe + f);
            for (int i = 0; i < 3; ++i) node.direction[i] = directions[3 * d + i];
            const float* centre = &all.centres[3 * node.keyframe];
            const float camera[3] = {centre[0] + 3 * framing.radius * node.direction[0],
                                     centre[1] + 3 * framing.radius * node.direction[1],
                                     centre[2] + 3 * framing.radius * node.direction[2]};
            const int buffer = animorder_select_keyframe(&rt, uint32_t(c), double(f), camera, nullptr);
            if (buffer < 0) throw std::runtime_error("the runtime gives no buffer for a node");
            uint64_t visible = 0;
            std::vector<uint64_t> passed(orders.size());
            ScoreSettings settings;
            settings.resolution = resolution;
            settings.threads = 1;
            score_nodes(&visible, passed.data(), mesh.keyframe_positions.data(), mesh.vertex_count, framing,
                        mesh.indices.data(), mesh.indices.size(), &node, 1, ranks.data(), orders.size(), settings);
            const Mat4d vp = node_view_projection(node.direction, framing.radius);
            out["nodes"].push_back({{"clip", c},
                                    {"keyframe", f},
                                    {"direction", {node.direction[0], node.direction[1], node.direction[2]}},
                                    {"radius", framing.radius},
                                    {"centre", {centre[0], centre[1], centre[2]}},
                                    {"view_projection", std::vector<double>(vp.begin(), vp.end())},
                                    {"buffer", buffer},
                                    {"visible", visible},
                                    {"original_passed", passed[0]},
                                    {"optimised_passed", passed[1 + size_t(buffer)]}});
        }
    }
    std::cout << out.dump() << "\n";
    return 0;
} catch (const std::exception& e) {
    std::fprintf(stderr, "node_counts: error: %s\n", e.what());
    return 1;
}
