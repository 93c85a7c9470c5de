// Private to src/: how many threads a task arena gets for a `threads` setting.
#pragma once

#include <tbb/info.h>
#include <tbb/task_arena.h>

#include <algorithm>

namespace animorder {

// 0: every core the caller's arena has; otherwise the number asked, but at most the cores TBB
// runs: it never gives an arena more (the results do not depend on the count), and asking for
// more makes it print a warning on stderr, which --quiet must keep silent.
inline int worker_threads(unsigned threads) {
    if (threads == 0) return tbb::this_task_arena::max_concurrency();
    return std::min(int(std::min(threads, 1u << 20)), tbb::info::default_concurrency());
}

}  // namespace animorder
