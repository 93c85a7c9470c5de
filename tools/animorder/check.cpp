// `animorder check FILE`: are the ANIMORDER_animated_triangle_orders orders of a glTF file usable
// (check_orders_extension: every reference and size, every order a permutation of the
// primitive's current triangles with their winding, `indices` equal to the fallback, tables
// covering every clip)? A JSON report on stdout; exit 0 when usable, else 1 with the first
// problem on stderr (a file that is no readable glTF too: "readable" false, the error in "errors").
#include "commands.h"

#include "animorder/gltf_extension.h"
#include "animorder/load.h"
#include "animorder/viewpoints.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace animorder::tool {
namespace {

// Each clip's stored centres against the mesh as the file poses it now (DESIGN.md's framing,
// as optimize wrote them): a tool that moved the whole scene (glTF-Transform's `center` adds a
// parent node) leaves the orders valid but every table lookup computes its view direction from
// the wrong point. Off by more than 1% of the view radius is an error (quantised positions move
// them far less). A file that cannot be posed here, or only at a cost far above its size (shared
// accessors), is reported unchecked, not as an error.
nlohmann::json check_centres(const std::string& file, OrdersExtensionCheck& r) {
    if (r.posed_elements > r.work_budget)
        return {{"checked", false},
                {"why", "posing the mesh would read " + std::to_string(r.posed_elements) +
                            " vertices and indices, more than the file's size allows (" +
                            std::to_string(r.work_budget) + "): its nodes or primitives share accessors"}};
    AnimatedMesh mesh;
    try {
        mesh = load_character(file);
    } catch (const std::exception& e) {
        return {{"checked", false}, {"why", e.what()}};
    }
    const Framing framing = frame_animated_mesh(mesh);
    double largest = 0;
    size_t compared = 0;
    for (const ExtensionClip& c : r.clips) {
        double worst = 0;
        const auto clip = std::find_if(mesh.clips.begin(), mesh.clips.end(), [&](const Clip& m) {
            return m.name == c.name && (c.animation < 0 || m.source_animation == c.animation);
        });
        if (clip == mesh.clips.end() || clip->keyframe_count != c.keyframes || c.centers.size() != 3 * c.keyframes)
            continue;
        for (size_t k = 0; k < c.keyframes; ++k) {
            const float* now = &framing.centres[3 * (clip->first_keyframe + k)];
            const float* stored = &c.centers[3 * k];
            const double d =
                std::hypot(double(now[0]) - stored[0], double(now[1]) - stored[1], double(now[2]) - stored[2]);
            worst = std::max(worst, d);
            ++compared;
        }
        largest = std::max(largest, worst);
        const double off = worst / std::max(double(framing.radius), 1e-30);
        if (off > 0.01) {
            char text[64];
            std::snprintf(text, sizeof text, "%.1f%%", 100 * off);
            r.errors.push_back("clip '" + printable(c.name) + "': its centers are " + text +
                               " of the view radius away from the mesh's frame centres (the scene moved since "
                               "the orders were made?): every lookup would use the wrong view direction");
        }
    }
    return {{"checked", true}, {"keyframes", compared}, {"largest_offset", largest}, {"view_radius", framing.radius}};
}

}  // namespace

int run_check(const CheckOptions& options) {
    OrdersExtensionCheck r;
    bool readable = true;
    try {
        r = check_orders_extension(options.file);
    } catch (const LoadError& e) {  // no glTF to check: the report says so too, for scripts reading it
        readable = false;
        std::string message = e.what();
        const std::string prefix = options.file + ": ";
        if (message.rfind(prefix, 0) == 0) message.erase(0, prefix.size());
        r.errors.push_back(message);
    }
    nlohmann::json j;
    j["file"] = options.file;
    j["extension"] = kOrdersExtensionName;
    j["readable"] = readable;
    j["present"] = r.present;
    j["ok"] = nullptr;  // once every check is done
    if (r.present) {
        j["method"] = r.method;
        j["buffer_count"] = r.buffer_count;
        j["fallback"] = r.fallback;
        j["clips"] = nlohmann::json::array();
        for (const ExtensionClip& c : r.clips)
            j["clips"].push_back({{"name", c.name},
                                  {"animation", c.animation >= 0 ? nlohmann::json(c.animation) : nlohmann::json()},
                                  {"keyframes", c.keyframes},
                                  {"sample_rate", c.sample_rate},
                                  {"buffer_base", c.buffer_base},
                                  {"table_cells", c.cells.size()}});
        j["primitives"] = nlohmann::json::array();
        for (const ExtensionPrimitive& p : r.primitives) {
            size_t good = 0;
            for (bool b : p.order_is_permutation) good += b;
            j["primitives"].push_back({{"mesh", p.mesh},
                                       {"primitive", p.primitive},
                                       {"triangles", p.indices.size() / 3},
                                       {"index_type", p.component_type == 5123 ? "UNSIGNED_SHORT" : "UNSIGNED_INT"},
                                       {"orders", p.order_count},
                                       {"orders_valid", good},
                                       {"indices_equal_fallback", p.indices_equal_fallback}});
        }
    }
    if (r.present) {
        j["primitives_without_orders"] = nlohmann::json::array();
        for (const OrdersExtensionCheck::Unordered& u : r.without_orders)
            j["primitives_without_orders"].push_back(
                {{"mesh", u.mesh}, {"primitive", u.primitive}, {"triangles", u.triangles}});
    }
    if (r.present && r.errors.empty()) j["centers"] = check_centres(options.file, r);
    j["ok"] = r.errors.empty();
    j["errors"] = r.errors;
    std::printf("%s\n", j.dump(2).c_str());
    if (r.present && !r.without_orders.empty() && !options.quiet) {
        size_t triangles = 0;
        for (const OrdersExtensionCheck::Unordered& u : r.without_orders) triangles += u.triangles;
        std::fprintf(stderr,
                     "animorder: note: %s: %zu triangle primitive(s) (%zu triangles) carry no orders and draw in "
                     "their file order (primitives_without_orders)\n",
                     options.file.c_str(), r.without_orders.size(), triangles);
    }
    if (r.errors.empty()) return 0;
    if (options.quiet) return 1;
    std::fprintf(
        stderr, "animorder: error: %s: %s%s\n", options.file.c_str(), r.errors.front().c_str(),
        r.errors.size() > 1 ? (" (and " + std::to_string(r.errors.size() - 1) + " more problems)").c_str() : "");
    return 1;
}

}  // namespace animorder::tool
