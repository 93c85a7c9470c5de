// optimize's work as a library call, shared by `animorder optimize` (one item) and `animorder
// batch` (many): plan the outputs (no file touched), then load, run the method and add every
// output of the item to an OutputSet, returning the JSON report (the caller adds it, so a batch
// can extend it before the set is committed).
#pragma once

#include "commands.h"

#include "animorder/animated_mesh.h"
#include "animorder/atomic_write.h"
#include "animorder/methods.h"
#include "animorder/vertex_cache.h"

#include <nlohmann/json.hpp>

#include <functional>
#include <string>
#include <vector>

namespace animorder::tool {

struct OptimizePlan {
    Method method = kDefaultMethod;
    MethodSettings settings;
    std::string gltf, sidecar, sidecar_json;  // empty when not written
    std::vector<std::string> outputs;         // every file the run writes (the report included)
    std::vector<std::string> inputs;          // every file it reads, as far as known before loading
    std::vector<std::string> input_folders;   // folders every file of which it reads (clip folders)
};

// Validates the options (method, settings, output names) and names the outputs; touches no file.
OptimizePlan plan_optimize(const OptimizeOptions& options);

// The plan's outputs named anew from the options' output and report (plan_optimize's own last
// step but the inputs), so that runs that differ only in those (a batch's items with one input
// and the same options) share the rest of one plan.
void name_outputs(const OptimizeOptions& options, OptimizePlan& plan);

// The settings as the report writes them: with_threads adds how the run went, which never
// changes an output (the threads used, --fragment-memory and --max-memory).
nlohmann::ordered_json optimize_settings_json(const OptimizeOptions& options, const OptimizePlan& plan,
                                              bool with_threads = true);

struct OptimizeProduct {
    AnimatedMesh mesh;
    std::vector<std::string> files_read;  // every file loading read (side files included: an OBJ's .mtl)
    MethodResult run;
    VertexCacheStats before;
    nlohmann::ordered_json report;
};

// Loads the input, runs the method and adds the glTF / sidecar files of `plan` to `files`
// (not the report, and without committing). Throws for any error, and before the method runs
// when an output would replace a file that loading read (a side file plan_optimize cannot know).
// `loaded`, when set, is called with the files loading read, before the method runs.
OptimizeProduct produce_optimize(const OptimizeOptions& options, const OptimizePlan& plan, OutputSet& files,
                                 const std::function<void(const std::vector<std::string>& files_read)>& loaded = {});

}  // namespace animorder::tool
