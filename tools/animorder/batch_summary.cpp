// The summary writer of `animorder batch`: a row per item from its report or error file (or why it
// has no result), written as SUMMARY.json and a Markdown table, SUMMARY.md.
#include "batch_summary.h"

#include "report.h"

#include "animorder/atomic_write.h"
#include "animorder/gltf_extension.h"  // printable
#include "animorder/methods.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace animorder::tool {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

// Why an item has no up-to-date result, for the merge's summary (with what to do about it when
// the merge itself is the cause).
std::string why_missing(const Staleness& s) {
    if (s.kind == Staleness::kOtherBuild) return s.why + " (run the merge with the build that ran the items)";
    if (s.kind == Staleness::kOtherEvaluation) return s.why + " (give the merge the same)";
    return s.why;
}

// `failed_now`: the error of this run's attempt, when the item failed in it (its earlier report,
// still matching, does not make it ok). `merge`: a report whose figures no run gives is also told
// on stderr, one line (the item then counts as missing, as if it had no report).
json summary_row(const PlannedItem& p, const Stamp& stamp, const std::string& failed_now, bool merge) {
    json row = {{"name", p.item.name},
                {"input", p.item.input_as_written.empty() ? "(bundled)" : p.item.input_as_written},
                {"output", p.item.output_as_written},
                {"method", method_name(p.shared->plan.method)}};
    json report;
    const Staleness s = failed_now.empty() ? staleness(p, stamp, &report) : Staleness{Staleness::kChanged, ""};
    if (s.kind == Staleness::kCurrent) {
        const json& b = report["batch"];
        for (const char* key : {"triangles", "clips", "buffers", "acmr_before", "acmr_after", "ovr_before", "ovr_after",
                                "index_bytes_added", "time_s"})
            row[key] = b.contains(key) ? b[key] : json(nullptr);
        row["status"] = "ok";
        row["error"] = nullptr;
        return row;
    }
    if (merge && s.kind == Staleness::kEditedReport) {
        // One line on a terminal: every control byte of a name (a line end, ESC) written as \xNN.
        const std::string line = printable(p.item.name + ": " + s.why);
        std::fprintf(stderr, "animorder: batch: %s; counted as missing\n", line.c_str());
    }
    const json failure = read_json_file(p.error);
    const bool failed = !failed_now.empty() || string_at(failure, "stamp") == stamp.digest;
    for (const char* key : {"triangles", "clips", "buffers", "acmr_before", "acmr_after", "ovr_before", "ovr_after",
                            "index_bytes_added", "time_s"})
        row[key] = nullptr;
    row["status"] = failed ? "failed" : "missing";
    row["error"] = !failed_now.empty() ? failed_now : failed ? string_at(failure, "error") : why_missing(s);
    return row;
}

std::string cell(const json& v, int digits) {
    if (v.is_null()) return "—";
    if (v.is_number_float()) {
        char text[32];
        std::snprintf(text, sizeof text, "%.*f", digits, v.get<double>());
        return text;
    }
    if (v.is_string()) {  // as text: Markdown's punctuation escaped, a line end as a space
        std::string s;
        for (const char c : v.get<std::string>()) {
            if (c == '\n' || c == '\r') {
                s += ' ';
                continue;
            }
            if (std::strchr("\\`*_[]<>|~", c) && c != '\0') s += '\\';
            s += c;
        }
        return s;
    }
    return v.dump();
}

// The Markdown summary's title, counts and table header.
std::string markdown_head(size_t items, size_t ok, size_t failed, size_t missing) {
    std::string md = "# animorder batch summary\n\n";
    md += std::to_string(items) + " items: " + std::to_string(ok) + " ok, " + std::to_string(failed) + " failed, " +
          std::to_string(missing) + " missing (animorder " + ANIMORDER_VERSION + ").\n\n";
    md +=
        "| item | method | triangles | clips | OVR before | OVR after | ACMR before | ACMR after | index bytes added | "
        "time (s) | status |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
    return md;
}

// A row of the Markdown table.
std::string markdown_row(const json& r) {
    std::string status = r["status"].get<std::string>();
    if (!r["error"].is_null()) status += ": " + cell(r["error"], 0);
    return "| " + cell(r["name"], 0) + " | " + cell(r["method"], 0) + " | " + cell(r["triangles"], 0) + " | " +
           cell(r["clips"], 0) + " | " + cell(r["ovr_before"], 3) + " | " + cell(r["ovr_after"], 3) + " | " +
           cell(r["acmr_before"], 3) + " | " + cell(r["acmr_after"], 3) + " | " + cell(r["index_bytes_added"], 0) +
           " | " + cell(r["time_s"], 1) + " | " + status + " |\n";
}

// Builds and writes the summary; returns the exit code it implies. stamps: per item, or none (the
// merge: each item is stamped as its row is made); failed_now: per item, the error of this run's
// attempt when it failed (empty otherwise), or none. The rows are written into the two texts one
// at a time (a library's summary as one JSON value took several times the memory of its text).
int write_summary(const std::vector<PlannedItem>& items, const std::vector<Stamp>& stamps,
                  const std::vector<std::string>& failed_now, const std::string& stem, const std::string& manifest,
                  const BatchOptions& batch) {
    std::string json_rows, md_rows;
    size_t ok = 0, failed = 0, missing = 0;
    for (size_t i = 0; i < items.size(); ++i) {
        const json row = summary_row(items[i], stamps.empty() ? stamp_of(items[i], batch) : stamps[i],
                                     failed_now.empty() ? std::string() : failed_now[i], batch.merge);
        const std::string status = row["status"].get<std::string>();
        (status == "ok" ? ok : status == "failed" ? failed : missing) += 1;
        json_rows += list_element_text(row, i == 0);
        md_rows += markdown_row(row);
    }
    const json summary = {{"tool", "animorder"},
                          {"version", ANIMORDER_VERSION},
                          {"manifest", fs::path(manifest).filename().string()},
                          {"ok", ok},
                          {"failed", failed},
                          {"missing", missing},
                          {"items", json::array()}};
    const auto [head, tail] = report_text_around_list(summary, items.empty());
    remove_stale_temporaries({stem + ".json", stem + ".md"});
    OutputSet files;
    files.add(stem + ".json", head + json_rows + tail);
    std::string().swap(json_rows);
    files.add(stem + ".md", markdown_head(items.size(), ok, failed, missing) + md_rows);
    files.commit();
    if (!batch.quiet)
        std::fprintf(stderr, "animorder: batch: summary %s.json / .md: %zu ok, %zu failed, %zu missing\n", stem.c_str(),
                     ok, failed, missing);
    return failed && missing ? kExitFailedAndMissing : failed ? kExitItemsFailed : missing ? kExitItemsMissing : 0;
}

}  // namespace

std::string list_element_text(const json& value, bool first) {
    std::string text = report_text(value);
    text.pop_back();  // its line end
    std::string indented = first ? "\n    " : ",\n    ";
    for (const char c : text) indented += c == '\n' ? std::string("\n    ") : std::string(1, c);
    return indented;
}

std::pair<std::string, std::string> report_text_around_list(const json& outline, bool empty) {
    const std::string text = report_text(outline);
    const size_t list = text.rfind("[]");
    return {text.substr(0, list + 1), (empty ? "" : "\n  ") + text.substr(list + 1)};
}

// write_summary, whose failure (a full disk, say) comes after the items' work: its own exit code,
// not 1 (an error before any work), so that a farm does not take it for a bad manifest.
int summarise(const std::vector<PlannedItem>& items, const std::vector<Stamp>& stamps,
              const std::vector<std::string>& failed_now, const std::string& stem, const BatchOptions& batch) {
    try {
        return write_summary(items, stamps, failed_now, stem, batch.manifest, batch);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "animorder: batch: the items' files are written, but not the summary: %s\n", e.what());
        return kExitNoSummary;
    }
}

}  // namespace animorder::tool
