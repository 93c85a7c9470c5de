// The summary writer of `animorder batch`: a row per item from its report or error file (or why it
// has no result), written as SUMMARY.json and a Markdown table, SUMMARY.md.
#include "batch_summary.h"

#include "report.h"

#include "animorder/atomic_write.h"
#include "animorder/methods.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <cstring>
#include <exception>
#include <filesystem>
#include <string>
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
        std::string line = p.item.name + ": " + s.why;
        for (char& c : line)
            if (c == '\n' || c == '\r') c = ' ';
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

std::string summary_markdown(const json& summary) {
    std::string md = "# animorder batch summary\n\n";
    md += std::to_string(summary["items"].size()) + " items: " + summary["ok"].dump() + " ok, " +
          summary["failed"].dump() + " failed, " + summary["missing"].dump() + " missing (animorder " +
          summary["version"].get<std::string>() + ").\n\n";
    md +=
        "| item | method | triangles | clips | OVR before | OVR after | ACMR before | ACMR after | index bytes added | "
        "time (s) | status |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const json& r : summary["items"]) {
        std::string status = r["status"].get<std::string>();
        if (!r["error"].is_null()) status += ": " + cell(r["error"], 0);
        md += "| " + cell(r["name"], 0) + " | " + cell(r["method"], 0) + " | " + cell(r["triangles"], 0) + " | " +
              cell(r["clips"], 0) + " | " + cell(r["ovr_before"], 3) + " | " + cell(r["ovr_after"], 3) + " | " +
              cell(r["acmr_before"], 3) + " | " + cell(r["acmr_after"], 3) + " | " + cell(r["index_bytes_added"], 0) +
              " | " + cell(r["time_s"], 1) + " | " + status + " |\n";
    }
    return md;
}

// Builds and writes the summary; returns the exit code it implies. failed_now: per item, the
// error of this run's attempt when it failed (empty otherwise).
int write_summary(const std::vector<PlannedItem>& items, const std::vector<Stamp>& stamps,
                  const std::vector<std::string>& failed_now, const std::string& stem, const std::string& manifest,
                  const BatchOptions& batch) {
    json summary = {
        {"tool", "animorder"}, {"version", ANIMORDER_VERSION}, {"manifest", fs::path(manifest).filename().string()}};
    json rows = json::array();
    size_t ok = 0, failed = 0, missing = 0;
    for (size_t i = 0; i < items.size(); ++i) {
        rows.push_back(summary_row(items[i], stamps[i], failed_now[i], batch.merge));
        const std::string status = rows.back()["status"].get<std::string>();
        (status == "ok" ? ok : status == "failed" ? failed : missing) += 1;
    }
    summary["ok"] = ok;
    summary["failed"] = failed;
    summary["missing"] = missing;
    summary["items"] = rows;
    remove_stale_temporaries({stem + ".json", stem + ".md"});
    OutputSet files;
    files.add(stem + ".json", report_text(summary));
    files.add(stem + ".md", summary_markdown(summary));
    files.commit();
    if (!batch.quiet)
        std::fprintf(stderr, "animorder: batch: summary %s.json / .md: %zu ok, %zu failed, %zu missing\n", stem.c_str(),
                     ok, failed, missing);
    return failed && missing ? kExitFailedAndMissing : failed ? kExitItemsFailed : missing ? kExitItemsMissing : 0;
}

}  // namespace

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
