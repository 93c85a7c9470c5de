// Shard selection (--shard I/N or env/N) and the merge of the shards' items into one summary
// (--merge), with the options each refuses.
#include "batch_shard.h"

#include "batch_stamp.h"
#include "batch_summary.h"

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <vector>

namespace animorder::tool {

// --shard I/N or env/N → (I, N). Anything else is refused, an empty text or part included: a
// farm's command whose variable is unset ("$INDEX/4" read as "/4", "$SHARD" as "") would
// otherwise run every item in every process.
std::pair<size_t, size_t> parse_shard(const std::string& text) {
    const std::string given = "--shard '" + text + "'";
    if (text.empty())
        throw std::runtime_error(given + ": is empty (an unset variable in the command?); give I/N or env/N");
    const size_t slash = text.find('/');
    auto number = [&](const std::string& s, const char* what) {
        if (s.empty())
            throw std::runtime_error(given + ": " + what +
                                     " is empty (an unset variable in the command?); give I/N or env/N");
        if (s.size() > 9 || !std::all_of(s.begin(), s.end(), [](char c) { return std::isdigit(uint8_t(c)); }))
            throw std::runtime_error(given + ": " + what + " must be a whole number below 10^9 (I/N, or env/N)");
        return size_t(std::stoul(s));
    };
    if (slash == std::string::npos) throw std::runtime_error(given + ": expected I/N (or env/N)");
    std::string index = text.substr(0, slash);
    const size_t count = number(text.substr(slash + 1), "N");
    if (count == 0) throw std::runtime_error(given + ": N must be at least 1");
    if (index == "env") {
        const char* k8s = std::getenv("JOB_COMPLETION_INDEX");
        const char* slurm = std::getenv("SLURM_ARRAY_TASK_ID");
        const char* variable = k8s && *k8s ? "JOB_COMPLETION_INDEX" : slurm && *slurm ? "SLURM_ARRAY_TASK_ID" : nullptr;
        if (!variable)
            throw std::runtime_error(given + ": neither JOB_COMPLETION_INDEX nor SLURM_ARRAY_TASK_ID is set");
        index = std::getenv(variable);
        const bool digits = !index.empty() && index.size() <= 9 && std::all_of(index.begin(), index.end(), [](char c) {
            return std::isdigit(uint8_t(c)) != 0;
        });
        if (!digits || size_t(std::stoul(index)) >= count)
            throw std::runtime_error(given + ": " + variable + "=" + index + " is not a shard index from 0 to " +
                                     std::to_string(count - 1));
    }
    const size_t i = number(index, "I");
    if (i >= count) throw std::runtime_error(given + ": needs 0 <= I < N (I = " + index + ")");
    return {i, count};
}

void check_merge_options(const BatchOptions& batch) {
    if (batch.merge && batch.shard_given)
        throw std::runtime_error("--merge builds the summary of every shard: drop --shard");
    if (batch.merge && batch.force) throw std::runtime_error("--merge runs no item: drop --force");
    if (batch.merge && batch.dry_run) throw std::runtime_error("--merge runs no item: drop --dry-run");
    if (batch.merge && batch.item_failures_ok)
        throw std::runtime_error(
            "--merge runs no item: drop --item-failures-ok (the merge's exit 3 lists the failures)");
}

int merge_shards(const std::vector<PlannedItem>& items, const std::string& summary, const BatchOptions& batch) {
    return summarise(items, {}, {}, summary, batch);  // each item stamped as its row is made
}

}  // namespace animorder::tool
