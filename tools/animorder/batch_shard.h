// Sharding a batch (--shard I/N, or env/N from a job array's index) and --merge, which builds the
// summary of every shard's items from their files.
#pragma once

#include "batch_item.h"
#include "commands.h"

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace animorder::tool {

// --shard I/N or env/N (JOB_COMPLETION_INDEX or SLURM_ARRAY_TASK_ID) → (I, N): shard I runs the
// items i with i % N == I.
std::pair<size_t, size_t> parse_shard(const std::string& text);

// The options --merge refuses: it builds the summary of every shard and runs no item.
void check_merge_options(const BatchOptions& batch);

// --merge: every item stamped and the summary written from the items' files; returns the exit
// code the summary implies.
int merge_shards(const std::vector<PlannedItem>& items, const std::string& summary, const BatchOptions& batch);

}  // namespace animorder::tool
