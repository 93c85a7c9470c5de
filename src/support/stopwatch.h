// Private to the library (src/support): wall-clock seconds for the timings that results report
// (ClusteringResult, Nehab06Result). Timings never change an output.
#pragma once

#include <chrono>

namespace animorder {

using Clock = std::chrono::steady_clock;

inline double seconds_since(Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace animorder
