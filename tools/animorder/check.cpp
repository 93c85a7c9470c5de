// `animorder check FILE`: are the ANIMORDER_animated_triangle_orders orders of a glTF file usable
// (check_orders_extension: every reference and size, every order a permutation of the
// primitive's current triangles with their winding, `indices` equal to the fallback, tables
// covering every clip)? A JSON report on stdout; exit 0 when usable, else 1 with the first
// problem on stderr (a file that is no readable glTF too: "readable" false, the error in "errors").
#include "commands.h"

#include "animorder/gltf_extension.h"
#include "animorder/load.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <stdexcept>

namespace animorder::tool {

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
    j["ok"] = r.errors.empty();
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
