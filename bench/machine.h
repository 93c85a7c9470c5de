// The machine a benchmark ran on, for the first line of its output: absolute times move from one
// processor to another (this project's machines are not always of one kind), ratios measured in
// one run much less, so every report that docs/RESULTS.md quotes names its processor. The model
// name alone does not tell them apart (a hypervisor shows "AMD EPYC" for processors with and
// without AVX-512), so the family and model numbers and the widest vector instructions follow it.
#pragma once

#include <fstream>
#include <string>
#include <thread>

namespace animorder::bench {

// "MODEL (family F, model M; VECTORS), N hardware threads": MODEL is /proc/cpuinfo's first
// "model name" (what the hypervisor shows), or "unknown processor" where there is none; VECTORS
// is AVX-512, AVX2 or neither (on x86), the copies of the rasteriser the CPU can run.
inline std::string machine_description() {
    std::string model = "unknown processor", family, number;
    std::ifstream cpuinfo("/proc/cpuinfo");
    auto value = [](const std::string& line) {
        const size_t colon = line.find(':');
        const size_t first = colon == std::string::npos ? std::string::npos : line.find_first_not_of(" \t", colon + 1);
        return first == std::string::npos ? std::string()
                                          : line.substr(first, line.find_last_not_of(" \t\r") + 1 - first);
    };
    for (std::string line; std::getline(cpuinfo, line) && !line.empty();) {  // the first processor's block
        if (line.rfind("model name", 0) == 0 && !value(line).empty()) model = value(line);
        if (line.rfind("cpu family", 0) == 0) family = value(line);
        if (line.rfind("model\t", 0) == 0 || line.rfind("model :", 0) == 0) number = value(line);
    }
    std::string details;
    if (!family.empty() && !number.empty()) details = "family " + family + ", model " + number;
#if (defined(__GNUC__) || defined(__clang__)) && (defined(__x86_64__) || defined(__i386__))
    const char* vectors = __builtin_cpu_supports("avx512f") ? "AVX-512"
                          : __builtin_cpu_supports("avx2")  ? "AVX2"
                                                            : "SSE2";
    details += (details.empty() ? "" : "; ") + std::string(vectors);
#endif
    if (!details.empty()) model += " (" + details + ")";
    return model + ", " + std::to_string(std::thread::hardware_concurrency()) + " hardware threads";
}

}  // namespace animorder::bench
