// The JSON report: the tool's stable, machine-readable interface (the human text may change).
//
// Schema (later issues extend it, never rename): {"tool", "version", "input", "triangles",
// "vertices", "settings": {...}, "input_order": {"acmr", "atvr"},
// "methods": [{"name", "buffers", "acmr", "atvr", "ovr_mean", "time_s", ...}],
// "timings_s": {"total", ...}}.
#pragma once

#include "animorder/animated_mesh.h"
#include "animorder/methods.h"
#include "animorder/vertex_cache.h"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <optional>
#include <string>

namespace animorder::tool {

nlohmann::ordered_json report_header(const AnimatedMesh& mesh, const std::string& input_name);
nlohmann::ordered_json cache_stats_json(const VertexCacheStats& stats);

// A method's entry of "methods": name, the settings it used (null where it uses none), buffers,
// ACMR/ATVR, OVR (null until evaluate fills it), time, the process's peak resident bytes while the
// method ran (peak_memory.h; null where not known), and what the method reports of itself
// (patches; single/joint: runs, iterations, stages).
nlohmann::ordered_json method_entry(const AnimatedMesh& mesh, const MethodResult& result,
                                    const MethodSettings& settings, std::optional<uint64_t> peak_resident);

// Serialised with two-space indentation and a final newline.
std::string report_text(const nlohmann::ordered_json& report);

}  // namespace animorder::tool
