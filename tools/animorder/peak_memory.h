// The tool's measure of a method's memory: the process's peak resident set while it runs.
#pragma once

#include <cstdint>
#include <optional>

namespace animorder::tool {

// Fixes glibc's mmap threshold at 1 MiB for the whole process. glibc otherwise raises it to the
// largest block freed (up to 32 MiB), after which large short-lived buffers (a cluster's graph of
// several MB, built and freed per cluster and per iteration) come from the heap and leave it
// fragmented (a tenth more resident memory for `measured` at λ = 3 on a small mesh; `single` holds
// the same either way). Elsewhere than glibc, nothing.
void fix_allocator_threshold();

// Peak resident bytes of this process from now on: free heap memory handed back to the system
// first (malloc_trim), then Linux's high-water mark (VmHWM) reset to the current resident size
// (/proc/self/clear_refs, "5"). peak() reads the mark: the most this process held since the
// reset, including what it already held (the loaded mesh, earlier methods' results). Where the
// kernel offers no reset or no mark (not Linux, a restricted /proc), peak() is nullopt: a method's
// peak is then not known, rather than the whole process's passed off as it.
class PeakResident {
public:
    PeakResident();
    std::optional<uint64_t> peak() const;

private:
    bool reset_ = false;
};

}  // namespace animorder::tool
