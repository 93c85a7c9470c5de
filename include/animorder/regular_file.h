// animorder — reading files that may be hostile (regular_file.cpp): only regular files, checked
// on the file as opened, never blocking. The loaders read through it, and so does the tool where it
// reads a file whole (a batch manifest, a stamp's bytes).
//
// A FIFO or a device named by a file (a glTF buffer URI of /dev/zero, an OBJ's mtllib) would never
// end, and merely opening some devices has effects (a terminal, a tape): so a path is stat'ed
// first and opened only when it is a regular file, then opened without blocking and without
// becoming a controlling terminal, and checked again with fstat on the descriptor (it may have
// been swapped meanwhile).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace animorder {

// A descriptor open for reading on a regular file, closed with the object.
class RegularFile {
public:
    // Opens `path` when it is a regular file; otherwise ok() is false and why() says what it is.
    explicit RegularFile(const std::string& path);
    ~RegularFile();
    RegularFile(const RegularFile&) = delete;
    RegularFile& operator=(const RegularFile&) = delete;

    bool ok() const { return fd_ >= 0; }
    const char* why() const { return why_; }
    uint64_t size() const { return size_; }

    // Reads up to `count` bytes at the current offset (EINTR retried); returns how many.
    size_t read(void* into, size_t count);

private:
    int fd_ = -1;
    uint64_t size_ = 0;
    const char* why_ = "";
};

}  // namespace animorder
