#include "output.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <unistd.h>

namespace animorder::tool {

void write_file_atomically(const std::string& path, const std::string& data) {
    namespace fs = std::filesystem;
    const fs::path target(path);
    if (fs::is_directory(target)) throw std::runtime_error(path + ": is a directory, expected a file name");
    const fs::path folder = target.has_parent_path() ? target.parent_path() : fs::path(".");
    if (!fs::is_directory(folder)) throw std::runtime_error(path + ": folder " + folder.string() + " does not exist");

    // The temporary name is unique per process so concurrent runs never share a temp file.
    const fs::path temp = folder / ("." + target.filename().string() + ".tmp" + std::to_string(::getpid()));
    std::FILE* file = std::fopen(temp.c_str(), "wb");
    if (!file) throw std::runtime_error(path + ": cannot create " + temp.string() + ": " + std::strerror(errno));
    const bool written = std::fwrite(data.data(), 1, data.size(), file) == data.size();
    const bool flushed = std::fflush(file) == 0 && ::fsync(::fileno(file)) == 0;
    const bool closed = std::fclose(file) == 0;
    if (!written || !flushed || !closed) {
        const std::string why = std::strerror(errno);
        std::remove(temp.c_str());
        throw std::runtime_error(path + ": write failed: " + why);
    }
    std::error_code error;
    fs::rename(temp, target, error);
    if (error) {
        std::remove(temp.c_str());
        throw std::runtime_error(path + ": cannot replace: " + error.message());
    }
}

}  // namespace animorder::tool
