// A manifest item as an optimize run (PlannedItem): its options and plan, the files batch names
// for it (OUT.animorder.report.json, OUT.animorder.error.json), and the paths of its files.
#pragma once

#include "batch_manifest.h"
#include "commands.h"
#include "optimize.h"

#include <cstddef>
#include <filesystem>
#include <memory>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace animorder::tool {

// The options and plan of an item but its outputs (output, report_path and the plan's output
// names empty), shared by the items whose arguments differ only in their outputs (a library's
// items with one input and the same options): parsed and planned once.
struct SharedPlan {
    OptimizeOptions options;
    OptimizePlan plan;
    mutable std::string settings_digest;  // the stamp's settings part, once taken (batch_stamp)
};

struct PlannedItem {
    ManifestItem item;
    std::shared_ptr<const SharedPlan> shared;
    std::vector<std::string> outputs;  // every file the item's run writes, the report included
    std::string report, error;         // OUT.animorder.report.json, OUT.animorder.error.json

    // The options and the plan whole, with the item's outputs (to run it).
    OptimizeOptions run_options() const;
    OptimizePlan run_plan() const;
};

// An item as errors name it: its CSV line or its number, and its name.
std::string item_label(const ManifestItem& item, size_t index);

// Shared plans by the items' arguments but their outputs: items that differ only in their outputs
// share one parse and one plan (the parser's work, the input's glTF read for its buffers).
using PlanCache = std::unordered_map<std::string, std::shared_ptr<const SharedPlan>>;

// The item's optimize options (its fields first, its options last; batch's own options refused:
// outputs, clips and threads) and plan, from `shared` when an earlier item had the same
// arguments but its output; an error names the item's line or number and name.
PlannedItem plan_item(ManifestItem item, size_t index, const BatchOptions& batch, const ItemParser& parse,
                      PlanCache* shared = nullptr);

// The output without .glb or .gltf: the stem the item's other files are named from.
std::string stem_of(const std::string& output);

// An output's path as the manifest writes it (the item's output stem as written).
std::string output_as_written(const PlannedItem& p, const std::string& out);

// A path's folder ("." for a bare name).
std::filesystem::path folder_of(const std::string& path);

// Where files are, whether or not they exist yet, each folder resolved once (links and ".."; a
// library's many items share a few folders): the folder's weakly_canonical path, then the name.
class Places {
public:
    std::filesystem::path of(const std::string& path);
    std::filesystem::path folder(const std::filesystem::path& folder);

private:
    std::unordered_map<std::string, std::filesystem::path> folders_;
};

// Refuses, in one line naming the item and the path, a file some item writes (its outputs, report
// and error file) that lies outside the manifest's folder once ".." and links to folders are
// resolved: `../../x.glb`, an absolute path elsewhere, or a link out (batch --allow-outside
// writes there).
void check_outputs_inside(const std::vector<PlannedItem>& items, const std::string& manifest, Places& places);

// What a run killed part-way left of an item (atomic_write.h's remove_stale_temporaries), removed
// when the item is redone or found up to date.
void remove_stale_temporaries(const std::vector<std::string>& outputs);

}  // namespace animorder::tool
