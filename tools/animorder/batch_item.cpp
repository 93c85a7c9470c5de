// Planning a manifest item as an optimize run: its arguments built and checked (batch names the
// outputs, clips and threads itself), parsed by optimize's parser, and its files named.
#include "batch_item.h"

#include "animorder/atomic_write.h"
#include "animorder/load.h"

#include <filesystem>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>
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

std::string item_label(const ManifestItem& item, size_t index) {
    return (item.line ? "line " + std::to_string(item.line) : "item " + std::to_string(index + 1)) + " (" + item.name +
           ")";
}

PlannedItem plan_item(ManifestItem item, size_t index, const BatchOptions& batch, const ItemParser& parse,
                      PlanCache* shared) {
    PlannedItem p;
    const std::string label = item_label(item, index);
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
    // The item's input, then the arguments but the output, as the key of a shared plan (no
    // argument holds a NUL): the input on its own, so that an item whose options name the file
    // another item gives as its input gets a plan of its own (and its refusal). An output that
    // reads as an option is parsed on its own.
    std::string key = item.input + '\0' + '\0';
    const bool shareable = shared && !item.output.empty() && item.output[0] != '-';
    if (shareable)
        for (size_t a = 2; a < args.size(); ++a) key += args[a] + '\0';
    p.report = stem_of(item.output) + ".animorder.report.json";
    p.error = stem_of(item.output) + ".animorder.error.json";
    try {
        const auto known = shareable ? shared->find(key) : PlanCache::iterator();
        if (shareable && known != shared->end()) {
            p.shared = known->second;
        } else {
            auto plan = std::make_shared<SharedPlan>();
            OptimizeOptions& options = plan->options;
            options = parse(args);
            if (options.common.input != item.input)
                throw std::runtime_error("the options name a file (" + options.common.input +
                                         "): give it as the item's \"input\" (resolved against the manifest's folder)");
            options.common.clip_files_absolute = true;
            if (batch.quiet) options.common.quiet = true;
            options.methods.settings.clustering.threads = batch.threads;
            options.report_path = p.report;
            plan->plan = plan_optimize(options);
            options.output.clear(), options.report_path.clear();
            plan->plan.gltf.clear(), plan->plan.sidecar.clear(), plan->plan.sidecar_json.clear();
            plan->plan.outputs.clear();
            p.shared = plan;
            if (shareable) shared->emplace(key, p.shared);
        }
        // Its outputs, as plan_optimize names them from -o and -r (and the input's kind).
        OptimizeOptions named;
        named.common.input = item.input;
        named.output = item.output;
        named.report_path = p.report;
        OptimizePlan outputs;
        name_outputs(named, outputs);
        p.outputs = std::move(outputs.outputs);
    } catch (const std::exception& e) {
        throw std::runtime_error(label + ": " + e.what());
    }
    p.item = std::move(item);
    return p;
}

OptimizeOptions PlannedItem::run_options() const {
    OptimizeOptions options = shared->options;
    options.output = item.output;
    options.report_path = report;
    return options;
}

OptimizePlan PlannedItem::run_plan() const {
    OptimizePlan plan = shared->plan;
    name_outputs(run_options(), plan);
    return plan;
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

fs::path Places::folder(const fs::path& folder) {
    const auto known = folders_.find(folder.string());
    if (known != folders_.end()) return known->second;
    std::error_code error;
    fs::path where = fs::weakly_canonical(fs::absolute(folder, error), error);
    if (error) where = fs::absolute(folder, error).lexically_normal();
    return folders_.emplace(folder.string(), where).first->second;
}

fs::path Places::of(const std::string& path) { return folder(folder_of(path)) / fs::path(path).filename(); }

namespace {

// Whether `place` is `folder` or lies under it (both resolved: no "..", no links).
bool lies_in(const fs::path& place, const fs::path& folder) {
    auto p = place.begin();
    for (const fs::path& part : folder) {
        if (part.empty()) continue;  // a trailing separator
        if (p == place.end() || *p != part) return false;
        ++p;
    }
    return true;
}

}  // namespace

void check_outputs_inside(const std::vector<PlannedItem>& items, const std::string& manifest, Places& places) {
    const fs::path home = places.folder(folder_of(manifest));
    for (size_t i = 0; i < items.size(); ++i) {
        const PlannedItem& p = items[i];
        std::vector<std::string> files = p.outputs;
        files.push_back(p.error);
        for (const std::string& file : files) {
            const fs::path place = places.of(file);
            if (lies_in(place, home)) continue;
            throw std::runtime_error(item_label(p.item, i) + ": the output " + output_as_written(p, file) +
                                     " lies outside the manifest's folder (" + place.string() + ", not under " +
                                     home.string() + "): batch writes outside it only with --allow-outside");
        }
    }
}

// What a run killed part-way left of an item (atomic_write.h's remove_stale_temporaries), removed
// when the item is redone or found up to date.
void remove_stale_temporaries(const std::vector<std::string>& outputs) {
    for (const std::string& out : outputs) animorder::remove_stale_temporaries(out);
}

}  // namespace animorder::tool
