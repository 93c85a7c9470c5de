// A manifest item as an optimize run (PlannedItem): its options and plan, the files batch names
// for it (OUT.animorder.report.json, OUT.animorder.error.json), and the paths of its files.
#pragma once

#include "batch_manifest.h"
#include "commands.h"
#include "optimize.h"

#include <cstddef>
#include <filesystem>
#include <string>
#include <unordered_map>
#include <vector>

namespace animorder::tool {

struct PlannedItem {
    ManifestItem item;
    OptimizeOptions options;
    OptimizePlan plan;
    std::string report, error;  // OUT.animorder.report.json, OUT.animorder.error.json
};

// An item as errors name it: its CSV line or its number, and its name.
std::string item_label(const ManifestItem& item, size_t index);

// The item's optimize options (its fields first, its options last; batch's own options refused:
// outputs, clips and threads) and plan; an error names the item's line or number and name.
PlannedItem plan_item(const ManifestItem& item, size_t index, const BatchOptions& batch, const ItemParser& parse);

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
