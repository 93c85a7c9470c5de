// PeakResident (peak_memory.h): Linux's VmHWM, reset through /proc/self/clear_refs (proc(5)).
#include "peak_memory.h"

#include <malloc.h>

#include <fstream>
#include <sstream>
#include <string>

namespace animorder::tool {

void fix_allocator_threshold() {
#ifdef M_MMAP_THRESHOLD
    mallopt(M_MMAP_THRESHOLD, 1 << 20);
#endif
}

PeakResident::PeakResident() {
    malloc_trim(0);
    std::ofstream clear("/proc/self/clear_refs");
    clear << "5";
    clear.flush();
    reset_ = bool(clear);
}

std::optional<uint64_t> PeakResident::peak() const {
    if (!reset_) return std::nullopt;
    std::ifstream status("/proc/self/status");
    std::string line;
    while (std::getline(status, line)) {
        if (line.rfind("VmHWM:", 0) != 0) continue;
        std::istringstream fields(line.substr(6));
        uint64_t kib = 0;
        std::string unit;
        if (fields >> kib >> unit && unit == "kB" && kib < (uint64_t(1) << 50)) return kib * 1024;
        return std::nullopt;
    }
    return std::nullopt;
}

}  // namespace animorder::tool
