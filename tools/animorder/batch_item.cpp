// Planning a manifest item as an optimize run: its arguments built and checked (batch names the
// outputs, clips and threads itself), parsed by optimize's parser, and its files named.
#include "batch_item.h"

#include "animorder/atomic_write.h"
#include "animorder/load.h"

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace animorder::tool {
namespace {

namespace fs = std::filesystem;

// An option that names an output, which batch names itself: -o, -r, --output, --report, also
// glued to its value (-oOUT) or after flags in one word (-qrOUT).
bool names_an_output(const std::string& o) {
    if (o.rfind("--output", 0) == 0 || o.rfind("--report", 0) == 0) return true;
    if (o.size() < 2 || o[0] != '-' || o[1] == '-') return false;
    const size_t first = o.find_first_not_of("qh", 1);  // optimize's short flags that take no value
    return first != std::string::npos && (o[first] == 'o' || o[first] == 'r');
}

}  // namespace

std::string stem_of(const std::string& output) {
    const std::string ext = file_extension(output);
    return ext == ".glb" || ext == ".gltf" ? output.substr(0, output.size() - ext.size()) : output;
}

PlannedItem plan_item(const ManifestItem& item, size_t index, const BatchOptions& batch, const ItemParser& parse) {
    PlannedItem p;
    p.item = item;
    const std::string label = (item.line ? "line " + std::to_string(item.line) : "item " + std::to_string(index + 1)) +
                              " (" + item.name + ")";
    // The item's own fields first, its options last (so an option missing its value says so).
    std::vector<std::string> args = {"-o", item.output};
    if (!item.input.empty()) args.push_back(item.input);
    for (const std::string& c : item.clips) args.insert(args.end(), {"--clip", c});
    if (!item.method.empty()) args.insert(args.end(), {"--method", item.method});
    for (const std::string& o : item.options) {
        if (names_an_output(o))
            throw std::runtime_error(label + ": option " + o + ": batch names the outputs (use the item's \"output\")");
        if (o == "--clip" || o.rfind("--clip=", 0) == 0)
            throw std::runtime_error(label + ": option " + o +
                                     ": use the item's \"clips\" (resolved against the manifest's folder)");
        if (o == "--threads" || o.rfind("--threads=", 0) == 0)
            throw std::runtime_error(label + ": option " + o +
                                     ": threads are the batch's (animorder batch --threads N)");
        args.push_back(o);
    }
    try {
        p.options = parse(args);
        if (p.options.common.input != item.input)
            throw std::runtime_error("the options name a file (" + p.options.common.input +
                                     "): give it as the item's \"input\" (resolved against the manifest's folder)");
        p.options.common.clip_files_absolute = true;
        if (batch.quiet) p.options.common.quiet = true;
        p.options.methods.settings.clustering.threads = batch.threads;
        p.options.report_path = stem_of(item.output) + ".animorder.report.json";
        p.plan = plan_optimize(p.options);
    } catch (const std::exception& e) {
        throw std::runtime_error(label + ": " + e.what());
    }
    p.report = p.options.report_path;
    p.error = stem_of(item.output) + ".animorder.error.json";
    return p;
}

// An output's path as the manifest writes it (the item's output stem as written).
std::string output_as_written(const PlannedItem& p, const std::string& out) {
    const std::string stem = stem_of(p.item.output);
    return out.rfind(stem, 0) == 0 ? stem_of(p.item.output_as_written) + out.substr(stem.size()) : out;
}

fs::path folder_of(const std::string& path) {
    const fs::path p(path);
    return p.has_parent_path() ? p.parent_path() : fs::path(".");
}

// What a run killed part-way left of an item (atomic_write.h's remove_stale_temporaries), removed
// when the item is redone or found up to date.
void remove_stale_temporaries(const std::vector<std::string>& outputs) {
    for (const std::string& out : outputs) animorder::remove_stale_temporaries(out);
}

}  // namespace animorder::tool
