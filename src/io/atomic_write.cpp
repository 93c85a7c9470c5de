// Outputs that appear all together or not at all: temporaries beside their targets, flushed to
// disk, renamed into place only when every file of the run is written.
#include "animorder/atomic_write.h"

#include <sys/stat.h>
#include <unistd.h>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <unordered_map>
#include <unordered_set>

namespace animorder {
namespace {

namespace fs = std::filesystem;

// The file a path names once links and "." / ".." are resolved (the path itself when it cannot
// be resolved), so two spellings of one file compare equal.
fs::path resolved(const std::string& path) {
    std::error_code error;
    fs::path p = fs::weakly_canonical(fs::absolute(path, error), error);
    return error ? fs::path(path) : p;
}

bool same_file(const std::string& a, const std::string& b) { return file_identity(a) == file_identity(b); }

// What a temporary adds to its target's name: "." before, ".tmp" or ".old" and a process id after.
constexpr size_t kTemporaryExtra = 1 + 4 + 10;

void check_writable_target(const std::string& path) {
    const fs::path target(path);
    std::error_code error;
    if (path.empty()) throw OutputError("an output path is empty");
    if (fs::is_directory(target, error)) throw OutputError(path + ": is a directory, expected a file name");
    const fs::path folder = target.has_parent_path() ? target.parent_path() : fs::path(".");
    if (!fs::is_directory(folder, error))
        throw OutputError(path + ": folder " + folder.string() +
                          (fs::exists(folder, error) ? " is not a folder" : " does not exist"));
    if (::access(folder.c_str(), W_OK | X_OK) != 0)
        throw OutputError(path + ": folder " + folder.string() + " is not writable");
    const long name_max = ::pathconf(folder.c_str(), _PC_NAME_MAX);
    const size_t limit = name_max > 0 ? size_t(name_max) : 255;
    if (target.filename().string().size() + kTemporaryExtra > limit)
        throw OutputError(path + ": the file name is too long (at most " + std::to_string(limit - kTemporaryExtra) +
                          " bytes here, so that its temporary fits)");
}

std::string temporary_name(const fs::path& target, const char* kind) {
    const fs::path folder = target.has_parent_path() ? target.parent_path() : fs::path(".");
    // Unique per process, so concurrent runs never share a temporary.
    return (folder / ("." + target.filename().string() + "." + kind + std::to_string(::getpid()))).string();
}

}  // namespace

std::string file_identity(const std::string& path) {
    struct stat st {};
    if (::stat(path.c_str(), &st) == 0) return "inode " + std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino);
    return "path " + resolved(path).string();
}

void check_output_stem(const std::string& stem) {
    const fs::path path(stem);
    const std::string last = path.filename().string();
    std::error_code error;
    if (stem.empty() || last.empty() || last == "." || last == ".." || fs::is_directory(path, error))
        throw OutputError((stem.empty() ? std::string("an output name") : stem) +
                          ": names a folder; give a file name the outputs extend (e.g. out/hero)");
}

void check_output_paths(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs,
                        const std::vector<std::string>& input_folders) {
    // Each path resolved once (a library's batch checks thousands against thousands).
    std::unordered_set<std::string> input_files;
    for (const std::string& input : inputs)
        if (!input.empty()) input_files.insert(file_identity(input));
    std::unordered_map<std::string, std::string> folders;  // identity → the folder as named
    for (const std::string& folder : input_folders)
        if (!folder.empty()) folders.emplace(file_identity(folder), folder);
    std::unordered_map<std::string, size_t> output_files;
    for (size_t i = 0; i < outputs.size(); ++i) {
        check_writable_target(outputs[i]);
        const std::string identity = file_identity(outputs[i]);
        if (input_files.count(identity))
            throw OutputError(outputs[i] +
                              ": is an input of this run: refusing to overwrite the input; name another output");
        if (!folders.empty()) {
            const fs::path target(outputs[i]);
            const auto folder = folders.find(
                file_identity(target.has_parent_path() ? target.parent_path().string() : std::string(".")));
            if (folder != folders.end())
                throw OutputError(outputs[i] + ": lies in " + folder->second +
                                  ", a folder every file of which this run reads (a clip folder): a later run would "
                                  "read the output as an input; name an output outside it");
        }
        const auto [first, added] = output_files.emplace(identity, i);
        if (!added) throw OutputError(outputs[i] + ": named twice as an output (" + outputs[first->second] + ")");
    }
}

OutputSet::~OutputSet() {
    if (committed_) return;
    for (const Pending& p : pending_) std::remove(p.temp.c_str());
}

void OutputSet::add(const std::string& path, const std::string& data) {
    if (committed_) throw OutputError(path + ": the output set is already committed");
    check_writable_target(path);
    for (const Pending& p : pending_)
        if (same_file(p.target, path)) throw OutputError(path + ": named twice as an output (" + p.target + ")");
    const std::string temp = temporary_name(path, "tmp");
    std::FILE* file = std::fopen(temp.c_str(), "wb");
    if (!file) throw OutputError(path + ": cannot create " + temp + ": " + std::strerror(errno));
    pending_.push_back({path, temp});
    const bool written = std::fwrite(data.data(), 1, data.size(), file) == data.size();
    const bool flushed = std::fflush(file) == 0 && ::fsync(::fileno(file)) == 0;
    const bool closed = std::fclose(file) == 0;
    if (!written || !flushed || !closed) throw OutputError(path + ": write failed: " + std::strerror(errno));
}

void OutputSet::commit() {
    // Existing targets move aside first, so a failure part-way can put every one of them back.
    std::vector<std::pair<std::string, std::string>> backups;  // target, backup
    size_t placed = 0;
    std::error_code error;
    auto roll_back = [&](const std::string& why) {
        for (size_t i = 0; i < placed; ++i) std::remove(pending_[i].target.c_str());
        for (const auto& [target, backup] : backups) {
            std::error_code ignored;
            fs::rename(backup, target, ignored);
        }
        throw OutputError(why);
    };
    for (const Pending& p : pending_) {
        if (!fs::exists(p.target)) continue;
        const std::string backup = temporary_name(p.target, "old");
        fs::rename(p.target, backup, error);
        if (error == std::errc::no_such_file_or_directory) continue;  // gone meanwhile: nothing to keep
        if (error) roll_back(p.target + ": cannot replace: " + error.message());
        backups.emplace_back(p.target, backup);
    }
    for (; placed < pending_.size(); ++placed) {
        fs::rename(pending_[placed].temp, pending_[placed].target, error);
        if (error) roll_back(pending_[placed].target + ": cannot replace: " + error.message());
    }
    committed_ = true;
    for (const auto& backup : backups) std::remove(backup.second.c_str());
}

void write_file_atomically(const std::string& path, const std::string& data) {
    OutputSet set;
    set.add(path, data);
    set.commit();
}

}  // namespace animorder
