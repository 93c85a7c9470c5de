// The summary of a batch (SUMMARY.json and SUMMARY.md), merged from the items' files in manifest
// order, and the exit codes of `animorder batch`.
#pragma once

#include "batch_item.h"
#include "batch_stamp.h"
#include "commands.h"

#include <nlohmann/json_fwd.hpp>

#include <string>
#include <utility>
#include <vector>

namespace animorder::tool {

// Exit codes beyond 0 (all done) and 1 (an error before any work).
constexpr int kExitItemsFailed = 3;       // at least one item failed (each has its error line)
constexpr int kExitItemsMissing = 4;      // merge: some items have no up-to-date result yet
constexpr int kExitFailedAndMissing = 5;  // merge: both (a farm learns of unfinished shards either way)
constexpr int kExitNoSummary = 6;         // the items ran (or were merged) but the summary could not be written

// Builds and writes the summary under `stem` (.json and .md) and returns the exit code it implies;
// kExitNoSummary when it cannot be written. stamps: per item, or none (the merge: each item
// stamped as its row is made); failed_now: per item, the error of this run's attempt when it
// failed (empty otherwise), or none.
int summarise(const std::vector<PlannedItem>& items, const std::vector<Stamp>& stamps,
              const std::vector<std::string>& failed_now, const std::string& stem, const BatchOptions& batch);

// A value as report_text writes it as an element of the list that is the last key of a document
// (indented by that depth, after a comma unless it is the first), and that document's text cut
// where the elements go (its last key an empty list; `empty`: no element comes): so that a
// library's long lists (the summary's rows, a dry run's plan) are written a row at a time, never
// held as one JSON value.
std::string list_element_text(const nlohmann::ordered_json& value, bool first);
std::pair<std::string, std::string> report_text_around_list(const nlohmann::ordered_json& outline, bool empty);

}  // namespace animorder::tool
