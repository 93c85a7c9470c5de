// The tool's measure of a method's memory: the process's peak resident set while it runs.
#pragma once

#include <cstdint>
#include <optional>

namespace animorder::tool {

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
