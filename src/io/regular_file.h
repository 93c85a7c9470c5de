// Reading files that may be hostile: only regular files, checked on the file as opened, never
// blocking. Private to src/io.
//
// A FIFO or a device named by a file (a glTF buffer URI of /dev/zero, an OBJ's mtllib) would never
// end, and merely opening some devices has effects (a terminal, a tape): so a path is stat'ed
// first and opened only when it is a regular file, then opened without blocking and without
// becoming a controlling terminal, and checked again with fstat on the descriptor (it may have
// been swapped meanwhile).
#pragma once

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <string>

namespace animorder::io {

// A descriptor open for reading on a regular file, closed with the object.
class RegularFile {
public:
    // Opens `path` when it is a regular file; otherwise ok() is false and why() says what it is.
    explicit RegularFile(const std::string& path) {
        struct stat st {};
        if (::stat(path.c_str(), &st) != 0) {
            why_ = errno == ENOENT ? "missing" : "unreadable";
            return;
        }
        if (!S_ISREG(st.st_mode)) {
            why_ = S_ISDIR(st.st_mode) ? "a folder" : "not a regular file";
            return;
        }
        fd_ = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
        if (fd_ < 0) {
            why_ = "unreadable";
            return;
        }
        if (::fstat(fd_, &st) != 0 || !S_ISREG(st.st_mode)) {  // swapped since the stat
            why_ = "not a regular file";
            ::close(fd_);
            fd_ = -1;
            return;
        }
        size_ = uint64_t(st.st_size);
    }
    ~RegularFile() {
        if (fd_ >= 0) ::close(fd_);
    }
    RegularFile(const RegularFile&) = delete;
    RegularFile& operator=(const RegularFile&) = delete;

    bool ok() const { return fd_ >= 0; }
    const char* why() const { return why_; }
    uint64_t size() const { return size_; }

    // Reads up to `count` bytes at the current offset (EINTR retried); returns how many.
    size_t read(void* into, size_t count) {
        size_t got = 0;
        while (got < count) {
            const ssize_t n = ::read(fd_, static_cast<char*>(into) + got, count - got);
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) break;
            got += size_t(n);
        }
        return got;
    }

private:
    int fd_ = -1;
    uint64_t size_ = 0;
    const char* why_ = "";
};

}  // namespace animorder::io
