// The machine a benchmark ran on, for the first line of its output: absolute times move from one
// processor to another (this project's machines are not always of one kind), ratios measured in
// one run much less, so every report that docs/RESULTS.md quotes names its processor.
#pragma once

#include <fstream>
#include <string>
#include <thread>

namespace animorder::bench {

// "MODEL, N hardware threads": MODEL is /proc/cpuinfo's first "model name" (what the hypervisor
// shows), or "unknown processor" where there is none.
inline std::string machine_description() {
    std::string model = "unknown processor";
    std::ifstream cpuinfo("/proc/cpuinfo");
    for (std::string line; std::getline(cpuinfo, line);) {
        if (line.rfind("model name", 0) != 0) continue;
        const size_t colon = line.find(':');
        const size_t first = colon == std::string::npos ? std::string::npos : line.find_first_not_of(" \t", colon + 1);
        if (first != std::string::npos) model = line.substr(first, line.find_last_not_of(" \t\r") + 1 - first);
        break;
    }
    return model + ", " + std::to_string(std::thread::hardware_concurrency()) + " hardware threads";
}

}  // namespace animorder::bench
