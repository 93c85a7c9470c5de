// `animorder batch MANIFEST`: a library of characters through optimize, as a farm runs it.
//
// Each item of the manifest is one optimize run (the same library call as `animorder optimize`,
// optimize.h) whose files — glTF, sidecar, sidecar description and the item report
// OUT.animorder.report.json — appear together or not at all (OutputSet). The item report holds
// the item's stamp: a SHA-256 (nettle) of the tool version, the item's resolved options, its paths
// as the manifest writes them and the bytes of every file it reads as known before loading (a
// file that many items share read once in a run), plus the side files the importer opened (an
// OBJ's .mtl), each with its digest. Items that differ only in their outputs share one parse and
// plan (batch_item's SharedPlan), so that a library of many is planned at the cost of few. An
// item whose report carries the stamp it would have now, figures that a run can give, its side
// files unchanged and every output present, is up to date and skipped (`--dry-run` says which
// items would run and why: the report keeps the stamp's parts); so a run killed at any moment
// and started again redoes only the items it had not finished, and a changed option or input
// re-runs only the items it affects. Every file an item writes lies in the manifest's folder
// (--allow-outside lets them out). A failing item leaves OUT.animorder.error.json (its stamp and the error) and
// the batch goes on. `--shard I/N` runs items i with i % N == I (and reads their files only);
// the summary (SUMMARY.json and SUMMARY.md) is always merged from the items' files in manifest
// order, so it is the same whichever process ran which item.
//
// Its parts: batch_manifest (the manifest), batch_item (an item as an optimize run), batch_stamp
// (stamps and staleness), batch_shard (--shard and --merge) and batch_summary (the summary).
#include "batch_item.h"
#include "batch_manifest.h"
#include "batch_shard.h"
#include "batch_stamp.h"
#include "batch_summary.h"
#include "commands.h"
#include "input.h"
#include "optimize.h"
#include "report.h"

#include "animorder/atomic_write.h"
#include "animorder/evaluation.h"
#include "animorder/load.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <numeric>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

namespace animorder::tool {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;
using Clock = std::chrono::steady_clock;

// Wall times out (--no-timings): every key of seconds set to null, wherever it is, the thread
// count they ran with (settings.threads), which changes nothing else, and the peak resident
// bytes (a measure of the machine's run, like the times).
void drop_timings(json& value) {
    if (value.is_array())
        for (json& v : value) drop_timings(v);
    if (!value.is_object()) return;
    for (auto it = value.begin(); it != value.end(); ++it) {
        const std::string& k = it.key();
        if (k == "time_s" || k == "timings_s" || k == "stages_s" || k == "threads" || k == "peak_rss_bytes" ||
            k.rfind("seconds", 0) == 0)
            it.value() = nullptr;
        else
            drop_timings(it.value());
    }
}

json number_or_null(double v, bool have) { return have ? json(v) : json(nullptr); }

// Every output of the batch by its place (Places: its folder resolved, then its name; a commit
// renames a new file into place, so an output keeps its place but not its inode), for checking
// the files an item's loading read (an importer's side files are known only then).
struct OutputsByPlace {
    std::unordered_map<std::string, std::string> outputs;
    Places places;
};

// Runs one item into one OutputSet (the report, with its stamp, last): all files or none.
void run_item(const PlannedItem& p, const Stamp& stamp, const BatchOptions& batch, OutputsByPlace& all_outputs) {
    const Clock::time_point start = Clock::now();
    std::vector<std::string> files_of_item = p.outputs;
    files_of_item.push_back(p.error);
    remove_stale_temporaries(files_of_item);
    const OptimizeOptions options = p.run_options();
    const OptimizePlan plan = p.run_plan();
    OutputSet files;
    json written = json::array();  // each output but the report: its name and digest
    files.observe([&](const std::string& path, const std::string& data) {
        if (path == p.report) return;
        written.push_back({{"file", fs::path(path).filename().string()}, {"sha256", data_digest(path, data)}});
    });
    json side;  // digests as loaded: an edit while the method runs makes the item stale
    OptimizeProduct product = produce_optimize(options, plan, files, [&](const std::vector<std::string>& read) {
        for (const std::string& file : read) {
            std::error_code error;  // the file as named, and where a link there leads
            auto output = all_outputs.outputs.find(all_outputs.places.of(file).string());
            if (output == all_outputs.outputs.end())
                output = all_outputs.outputs.find(fs::weakly_canonical(fs::absolute(file, error), error).string());
            if (output != all_outputs.outputs.end())
                throw OutputError(output->second + ": is an input of this run (loading " + options.common.input +
                                  " reads it): refusing to overwrite the input; name another output");
        }
        side = side_files(p, read);
    });
    const AnimatedMesh& mesh = product.mesh;
    const MethodResult& run = product.run;

    bool have_ovr = false;
    double ovr_before = 0, ovr_after = 0;
    if (batch.eval_views > 0 && mesh.keyframe_count() > 0) {
        MethodBuffers input_order;
        input_order.orders.emplace_back(mesh.triangle_count());
        std::iota(input_order.orders[0].begin(), input_order.orders[0].end(), 0u);
        EvaluationSettings evaluation;
        evaluation.views = batch.eval_views;
        evaluation.resolution = batch.eval_resolution;
        evaluation.threads = batch.threads;
        evaluation.progress = progress_printer(options.common, "evaluating OVR before and after");
        const std::vector<OrderEvaluation> ovr = evaluate_methods(mesh, {input_order, run.buffers}, evaluation);
        ovr_before = ovr[0].overall.ovr_mean;
        ovr_after = ovr[1].overall.ovr_mean;
        have_ovr = true;
    }
    const size_t buffers = run.buffers.orders.size();
    json& report = product.report;
    // Paths as the manifest writes them (relative to its folder), so that the report is the same
    // bytes whatever folder the batch starts in and however the manifest's path is spelled.
    if (p.item.input_given && report["input"] == options.common.input) report["input"] = p.item.input_as_written;
    for (auto& [kind, path] : report["outputs"].items())  // OUT.glb, OUT.animorder.bin, ...: all from the stem
        if (path.is_string()) path = output_as_written(p, path.get<std::string>());
    report["batch"] = {{"stamp", stamp.digest},
                       {"stamp_parts", stamp_parts_json(stamp.parts)},
                       {"item", p.item.name},
                       {"status", "ok"},
                       {"triangles", mesh.triangle_count()},
                       {"clips", mesh.clips.size()},
                       {"keyframes", mesh.keyframe_count()},
                       {"buffers", buffers},
                       {"acmr_before", product.before.acmr},
                       {"acmr_after", run.acmr_mean},
                       {"ovr_before", number_or_null(ovr_before, have_ovr)},
                       {"ovr_after", number_or_null(ovr_after, have_ovr)},
                       {"eval_views", batch.eval_views},
                       {"eval_resolution", batch.eval_resolution},
                       {"index_bytes_added", uint64_t(buffers > 0 ? buffers - 1 : 0) * mesh.indices.size() * 4},
                       {"side_files", side},
                       {"outputs", written},
                       {"tool", tool_digest()},
                       {"time_s", std::chrono::duration<double>(Clock::now() - start).count()}};
    if (batch.no_timings) drop_timings(report);
    // An input edited while the item ran (between its stamp and its load): the outputs may come
    // from other bytes than the stamp's, so none is kept and the next run redoes the item.
    if (stamp_of(p, batch).digest != stamp.digest)
        throw std::runtime_error("an input changed while the item ran; run the batch again to redo it");
    files.add(p.report, report_text(report));
    files.commit();
    std::error_code error;
    fs::remove(p.error, error);  // an earlier failure of this item is over
}

// An item's error with its paths as the manifest writes them (the loaders name them as resolved
// against the manifest's folder, or made absolute), so that the summary is the same bytes whatever
// folder the batch starts in.
std::string as_written(const ManifestItem& item, std::string message) {
    std::vector<std::pair<std::string, std::string>> paths = {{item.input, item.input_as_written},
                                                              {item.output, item.output_as_written}};
    for (size_t c = 0; c < item.clips.size() && c < item.clips_as_written.size(); ++c)
        paths.emplace_back(item.clips[c], item.clips_as_written[c]);
    std::sort(paths.begin(), paths.end(), [](const auto& a, const auto& b) { return a.first.size() > b.first.size(); });
    for (const auto& [resolved, written] : paths) {
        if (resolved.empty() || resolved == written) continue;
        for (size_t at = message.find(resolved); at != std::string::npos;
             at = message.find(resolved, at + written.size()))
            message.replace(at, resolved.size(), written);
    }
    return message;
}

// --dry-run: which of the shard's items a run would redo, and why, as JSON on stdout; nothing is
// written or removed. The items' rows are printed one at a time (a library's plan as one JSON
// value took more memory than all its items).
int print_plan(const std::vector<PlannedItem>& items, std::pair<size_t, size_t> shard, bool sharded,
               const BatchOptions& batch) {
    std::vector<std::pair<size_t, std::string>> why;  // per item of the shard: its index, why it runs ("": skip)
    size_t run = 0, skip = 0;
    for (size_t i = 0; i < items.size(); ++i) {
        if (i % shard.second != shard.first) continue;
        const PlannedItem& p = items[i];
        Staleness s = staleness(p, stamp_of(p, batch));
        if (batch.force) s = {Staleness::kChanged, "--force"};
        const bool current = s.kind == Staleness::kCurrent;
        (current ? skip : run) += 1;
        why.emplace_back(i, current ? std::string() : std::move(s.why));
    }
    json plan = {{"manifest", fs::path(batch.manifest).filename().string()},
                 {"shard", sharded ? json::array({shard.first, shard.second}) : json(nullptr)},
                 {"run", run},
                 {"skip", skip},
                 {"items", json::array()}};
    const auto [head, tail] = report_text_around_list(plan, why.empty());
    std::fputs(head.c_str(), stdout);
    for (size_t r = 0; r < why.size(); ++r) {
        const PlannedItem& p = items[why[r].first];
        const bool current = why[r].second.empty();
        const json row = {{"item", why[r].first + 1},
                          {"name", p.item.name},
                          {"output", p.item.output_as_written},
                          {"action", current ? "skip" : "run"},
                          {"why", current ? "up to date" : why[r].second}};
        std::fputs(list_element_text(row, r == 0).c_str(), stdout);
    }
    std::fputs(tail.c_str(), stdout);
    return 0;
}

}  // namespace

int run_batch(const BatchOptions& batch, const ItemParser& parse_item) {
    std::vector<ManifestItem> manifest = read_manifest(batch.manifest);
    std::pair<size_t, size_t> shard = {0, 1};
    if (batch.shard_given || !batch.shard.empty()) shard = parse_shard(batch.shard);
    check_merge_options(batch);

    // Every item planned and every output of every item checked before any work: folders exist
    // and are writable, no output is any item's input or the manifest, no file is named twice.
    std::vector<PlannedItem> items;
    items.reserve(manifest.size());
    PlanCache shared_plans;
    for (size_t i = 0; i < manifest.size(); ++i)
        items.push_back(plan_item(std::move(manifest[i]), i, batch, parse_item, &shared_plans));
    std::vector<ManifestItem>().swap(manifest);  // each item's fields are its PlannedItem's now
    shared_plans = PlanCache();
    Places places;
    if (!batch.allow_outside) check_outputs_inside(items, batch.manifest, places);
    std::string summary = batch.summary;
    if (file_extension(summary) == ".json" || file_extension(summary) == ".md")  // --summary S.json: S
        summary.erase(summary.size() - file_extension(summary).size());
    if (summary.empty()) {
        const fs::path m(batch.manifest);
        summary = (m.parent_path() / m.stem()).string() + ".summary";
    }
    check_output_stem(summary);
    const bool sharded = shard.second > 1 || batch.shard_given || !batch.shard.empty();
    OutputsByPlace outputs_by_place{{}, std::move(places)};
    {  // the lists of every path go once checked (a library's are large)
        // Only what this process writes is checked for writing (a shard its own items' files, the
        // merge the summary, a whole run everything); the files of the job's other processes are
        // checked against every input and every other output only.
        std::vector<const std::string*> written, others;  // the items' own strings, not copies
        std::vector<std::string> inputs = {batch.manifest}, folders;
        std::unordered_set<const SharedPlan*> planned;
        const std::string summary_files[] = {summary + ".json", summary + ".md"};
        for (const std::string& file : summary_files) (batch.merge || !sharded ? written : others).push_back(&file);
        for (size_t i = 0; i < items.size(); ++i) {
            const PlannedItem& p = items[i];
            std::vector<const std::string*>& files = !batch.merge && i % shard.second == shard.first ? written : others;
            for (const std::string& out : p.outputs) files.push_back(&out);
            files.push_back(&p.error);
            if (!planned.insert(p.shared.get()).second) continue;  // a shared plan's inputs are listed
            inputs.insert(inputs.end(), p.shared->plan.inputs.begin(), p.shared->plan.inputs.end());
            folders.insert(folders.end(), p.shared->plan.input_folders.begin(), p.shared->plan.input_folders.end());
        }
        const size_t written_here = written.size();
        std::vector<const std::string*> outputs = std::move(written);
        outputs.insert(outputs.end(), others.begin(), others.end());
        std::vector<const std::string*>().swap(others);
        // A dry run writes nothing, not even the probes that check a folder takes a new file.
        check_output_paths(
            outputs.size(), [&](size_t i) -> const std::string& { return *outputs[i]; }, inputs, folders,
            batch.dry_run ? 0 : written_here);
        if (!batch.merge && !batch.dry_run)
            for (const std::string* output : outputs)
                outputs_by_place.outputs.emplace(outputs_by_place.places.of(*output).string(), *output);
    }

    if (batch.merge) return merge_shards(items, summary, batch);  // it stamps every item

    if (batch.dry_run) return print_plan(items, shard, sharded, batch);

    // A shard stamps its own items only, each when its turn comes (so that an input edited while
    // earlier items run is read as it is then).
    std::vector<Stamp> stamps(items.size());
    std::vector<std::string> failed_now(items.size());

    size_t done = 0, skipped = 0, failed = 0, mine = 0;
    for (size_t i = 0; i < items.size(); ++i) mine += i % shard.second == shard.first;
    size_t position = 0;
    for (size_t i = 0; i < items.size(); ++i) {
        if (i % shard.second != shard.first) continue;
        const PlannedItem& p = items[i];
        std::string label = "batch [" + std::to_string(++position) + "/" + std::to_string(mine) + "] " + p.item.name;
        for (char& c : label)  // progress and failure lines stay one line each
            if (c == '\n' || c == '\r') c = ' ';
        stamps[i] = stamp_of(p, batch);
        if (!batch.force && current_report(p, stamps[i]).is_object()) {
            ++skipped;
            std::vector<std::string> files_of_item = p.outputs;
            files_of_item.push_back(p.error);
            remove_stale_temporaries(files_of_item);
            std::error_code error;
            fs::remove(p.error, error);  // an earlier failure of this item is over: its result is current
            note(p.shared->options.common, label + ": up to date, skipped");
            continue;
        }
        note(p.shared->options.common, label + ": running");
        try {
            run_item(p, stamps[i], batch, outputs_by_place);
            ++done;
            note(p.shared->options.common, label + ": done");
        } catch (const std::exception& e) {
            ++failed;
            std::string message = as_written(p.item, e.what());
            for (char& c : message)
                if (c == '\n' || c == '\r') c = ' ';
            std::fprintf(stderr, "animorder: %s: failed: %s\n", label.c_str(), message.c_str());
            failed_now[i] = message;
            try {
                write_file_atomically(p.error, report_text(json{{"stamp", stamps[i].digest},
                                                                {"stamp_parts", stamp_parts_json(stamps[i].parts)},
                                                                {"tool", tool_digest()},
                                                                {"item", p.item.name},
                                                                {"status", "failed"},
                                                                {"error", message}}));
            } catch (const std::exception& again) {
                std::fprintf(stderr, "animorder: %s: cannot record the failure: %s\n", label.c_str(), again.what());
            }
        }
    }
    std::printf("batch%s: %zu items: %zu done, %zu up to date, %zu failed\n",
                sharded ? (" shard " + std::to_string(shard.first) + "/" + std::to_string(shard.second)).c_str() : "",
                mine, done, skipped, failed);
    const bool failures_count = failed && !batch.item_failures_ok;
    if (sharded) return failures_count ? kExitItemsFailed : 0;  // the summary is the merge step's
    const int code = summarise(items, stamps, failed_now, summary, batch);
    return code == kExitItemsFailed && !failures_count ? 0 : code;
}

}  // namespace animorder::tool
