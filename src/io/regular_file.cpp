// Files that may be hostile, read as regular files only (regular_file.h).
#include "animorder/regular_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>

namespace animorder {

RegularFile::RegularFile(const std::string& path) {
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

RegularFile::~RegularFile() {
    if (fd_ >= 0) ::close(fd_);
}

size_t RegularFile::read(void* into, size_t count) {
    size_t got = 0;
    while (got < count) {
        const ssize_t n = ::read(fd_, static_cast<char*>(into) + got, count - got);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;
        got += size_t(n);
    }
    return got;
}

}  // namespace animorder
