#include "report.h"

namespace animorder::tool {

nlohmann::ordered_json report_header(const AnimatedMesh& mesh, const std::string& input_name) {
    nlohmann::ordered_json report;
    report["tool"] = "animorder";
    report["version"] = ANIMORDER_VERSION;
    report["input"] = input_name;
    report["triangles"] = mesh.triangle_count();
    report["vertices"] = mesh.vertex_count;
    return report;
}

nlohmann::ordered_json cache_stats_json(const VertexCacheStats& stats) {
    return {{"acmr", stats.acmr}, {"atvr", stats.atvr}, {"misses", stats.misses}};
}

std::string report_text(const nlohmann::ordered_json& report) { return report.dump(2) + "\n"; }

}  // namespace animorder::tool
