// The content stamps of batch items (SHA-256 of the tool, options, paths and input bytes, in
// parts) and why an item's result is not up to date, as its report and error files tell.
#pragma once

#include "batch_item.h"
#include "commands.h"

#include <nlohmann/json_fwd.hpp>

#include <string>
#include <utility>
#include <vector>

namespace animorder::tool {

// The stamp of an item: everything its outputs depend on (not --threads, which changes nothing),
// in parts, each a digest: the tool (version and executable), the settings, the manifest's
// spellings of its paths, the batch's evaluation, and the bytes of every file it reads as far as
// known before loading (OptimizePlan::inputs: the character, a glTF's external buffers and images,
// clip files, the files of clip folders). The report keeps the parts too ("stamp_parts"), so that
// an item that is not up to date can say which of them changed.
struct StampParts {
    std::string settings, paths, eval;
    std::vector<std::pair<std::string, std::string>> inputs;  // (file as named, digest)
};

// An item's stamp as taken now: its parts (which name what changed, when it did) and the digest.
struct Stamp {
    StampParts parts;
    std::string digest;
};

// Why an item's result is not up to date, as far as its files tell ("" when it is: its report
// carries the stamp the item has now, the summary's figures as written, every output present as
// it was written, and every side file it lists with its digest). `kind` tells the merge which
// hint to add; kEditedReport: the report carries the stamp, but a figure no run gives (the merge
// says so on stderr).
struct Staleness {
    enum Kind { kCurrent, kNoResult, kOtherBuild, kOtherEvaluation, kChanged, kEditedReport } kind = kCurrent;
    std::string why;
};

// The tool: its version and the bytes of its executable (its digest, taken once).
const std::string& tool_digest();

// The item's stamp as its files are now.
Stamp stamp_of(const PlannedItem& p, const BatchOptions& batch);

// The parts as a report keeps them ("stamp_parts"): each input with its name and digest.
nlohmann::ordered_json stamp_parts_json(const StampParts& parts);

// The digest of a file named `path` holding `data`, from the bytes in memory (as a stamp hashes
// a file of that name and those bytes).
std::string data_digest(const std::string& path, const std::string& data);

// The files loading read beyond the stamp's (an OBJ's .mtl), each with its path from the
// report's folder and its digest, for the report's "side_files".
nlohmann::ordered_json side_files(const PlannedItem& p, const std::vector<std::string>& files_read);

// A report or an error file as JSON; null when it is missing or unreadable.
nlohmann::ordered_json read_json_file(const std::string& path);

// object[key] when it is a string, else "" (a report edited by hand is stale, never an error).
std::string string_at(const nlohmann::ordered_json& object, const char* key);

// Why the item's result is not up to date (kCurrent when it is), with the failure its last run
// left, if any; report_out, when given, receives the item's report when it is up to date.
Staleness staleness(const PlannedItem& p, const Stamp& stamp, nlohmann::ordered_json* report_out = nullptr);

// The item's report when it is up to date, else null.
nlohmann::ordered_json current_report(const PlannedItem& p, const Stamp& stamp);

}  // namespace animorder::tool
