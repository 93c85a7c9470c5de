// Outputs that appear all together or not at all: temporaries beside their targets, flushed to
// disk, renamed into place only when every file of the run is written, and removed when the run
// is interrupted (SIGINT, SIGTERM, SIGHUP) or fails.
#include "animorder/atomic_write.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>
#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <memory>
#include <random>
#include <mutex>
#include <unordered_map>
#include <unordered_set>
#include <vector>

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

// What a temporary adds to its target's name: "." before; ".tmp" or ".old", a process id, "-" and
// 16 random hex digits after.
constexpr size_t kTemporaryExtra = 1 + 4 + 10 + 1 + 16;

// A name for a temporary of `target` ("tmp") or a backup of it ("old"): its process id, so a later
// run knows whether the process that made it is gone (remove_stale_temporaries), and 64 random
// bits, so that nobody can plant a file or a link under it in advance (a container's PID is 1).
std::string temporary_name(const fs::path& target, const char* kind) {
    static std::mutex mutex;
    static std::random_device device;
    uint64_t bits = 0;
    {
        const std::lock_guard<std::mutex> lock(mutex);
        bits = (uint64_t(device()) << 32) ^ uint64_t(device());
    }
    char suffix[18];
    std::snprintf(suffix, sizeof suffix, "-%016llx", static_cast<unsigned long long>(bits));
    const fs::path folder = target.has_parent_path() ? target.parent_path() : fs::path(".");
    return (folder / ("." + target.filename().string() + "." + kind + std::to_string(::getpid()) + suffix)).string();
}

// A new file of its own under a fresh temporary name of `target`: created exclusively (never
// one that exists, never through a link: a name taken by then is another's, and another random
// name is tried), so nothing planted in the folder can redirect the write. Returns the open
// descriptor and sets `name`; -1 with errno set when no file can be created.
int create_temporary(const fs::path& target, std::string& name) {
    for (int attempt = 0; attempt < 64; ++attempt) {
        name = temporary_name(target, "tmp");
        const int fd = ::open(name.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
        if (fd >= 0 || errno != EEXIST) return fd;
    }
    return -1;  // errno is EEXIST: 64 random names all taken
}

// Renames `from` to `to` unless `to` exists (then false with `error` set to EEXIST): a backup
// never replaces a file that appeared under its name. Falls back to a plain rename where the file
// system cannot refuse to replace.
bool rename_without_replacing(const std::string& from, const std::string& to, std::error_code& error) {
    error.clear();
    if (::renameat2(AT_FDCWD, from.c_str(), AT_FDCWD, to.c_str(), RENAME_NOREPLACE) == 0) return true;
    if (errno == EINVAL || errno == ENOSYS || errno == EPERM) {  // EPERM: a sandbox that forbids the call
        if (::rename(from.c_str(), to.c_str()) == 0) return true;
    }
    error = std::error_code(errno, std::generic_category());
    return false;
}

// A temporary lives from its first write to the commit (seconds; its backup only during the
// commit), so one whose inode has not changed for an hour (ctime: writes and renames set it) is
// left over, whatever its process id now names: another process that took the id, as a
// container's PID 1 on a volume shared between machines does, or one on another machine.
bool untouched_for_an_hour(const fs::path& path, std::time_t now) {
    struct stat st {};
    return ::lstat(path.c_str(), &st) == 0 && now - st.st_ctime > 3600;
}

}  // namespace

bool process_may_run(long pid) {
    if (pid <= 0) return true;
    if (::kill(pid_t(pid), 0) != 0 && errno == ESRCH) return false;
    std::FILE* stat = std::fopen(("/proc/" + std::to_string(pid) + "/stat").c_str(), "r");
    if (!stat) return true;
    char line[512];
    const size_t n = std::fread(line, 1, sizeof line - 1, stat);
    std::fclose(stat);
    const std::string text(line, n);
    const size_t name_end = text.rfind(')');  // "pid (name) state ...": the name may hold anything
    return !(name_end != std::string::npos && name_end + 2 < text.size() && text[name_end + 2] == 'Z');
}

void remove_stale_temporaries(const std::string& target, std::time_t now) {
    const fs::path path(target);
    const fs::path folder = path.has_parent_path() ? path.parent_path() : fs::path(".");
    const std::string prefix = "." + path.filename().string() + ".";
    std::error_code error;
    for (auto it = fs::directory_iterator(folder, error); !error && it != fs::directory_iterator();
         it.increment(error)) {
        const std::string name = it->path().filename().string();
        if (name.size() <= prefix.size() + 3 || name.compare(0, prefix.size(), prefix) != 0) continue;
        // ".NAME.tmpPID-RANDOM" (and ".NAME.tmpPID", as earlier versions named them).
        const std::string kind = name.substr(prefix.size(), 3), rest = name.substr(prefix.size() + 3);
        const size_t dash = rest.find('-');
        const std::string pid = rest.substr(0, dash), random = dash == std::string::npos ? "" : rest.substr(dash + 1);
        if ((kind != "tmp" && kind != "old") || pid.empty() || pid.size() > 9 ||
            !std::all_of(pid.begin(), pid.end(), [](char c) { return c >= '0' && c <= '9'; }) ||
            (dash != std::string::npos &&
             (random.size() != 16 || !std::all_of(random.begin(), random.end(), [](char c) {
                 return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'f');
             }))))
            continue;
        if (process_may_run(std::stol(pid)) && !untouched_for_an_hour(it->path(), now)) continue;
        std::error_code ignored;
        if (kind == "old" && !fs::exists(path, ignored)) continue;
        fs::remove(it->path(), ignored);
    }
}

namespace {

// The temporaries of the unfinished OutputSets, for the signal handler: a slot names one (and
// the process that made it) while its file exists and is not being put in place. Each slot's name
// is written into its own buffer, reused, while the slot names nothing.
constexpr size_t kTrackedTemporaries = 256;
struct TrackedTemporary {
    std::atomic<const char*> name{nullptr};
    std::atomic<pid_t> owner{0};
};
TrackedTemporary tracked_temporaries[kTrackedTemporaries];

// SIGINT, SIGTERM, SIGHUP: this process's temporaries removed (unlink is async-signal-safe; a
// forked child, such as isolated_import's, removes only its own), then the signal's default
// action, so the run still ends as killed. A container's first process (PID 1) is not killed by
// a default action: it then exits with the status a shell gives a killed process (128 + signal).
void remove_temporaries_and_reraise(int sig) {
    const pid_t self = ::getpid();
    for (TrackedTemporary& slot : tracked_temporaries)
        if (slot.owner.load() == self)
            if (const char* name = slot.name.load()) ::unlink(name);
    ::signal(sig, SIG_DFL);
    sigset_t just_this;  // blocked while its handler runs: unblocked, it acts before raise returns
    sigemptyset(&just_this);
    sigaddset(&just_this, sig);
    ::sigprocmask(SIG_UNBLOCK, &just_this, nullptr);
    ::raise(sig);
    ::_exit(128 + sig);
}

// Commits under way in this process, and a signal that came meanwhile: a commit moves targets
// aside and renames temporaries into place, and stopped half-way it would leave targets missing
// or temporaries behind, so the signal waits until the commit has finished or rolled back (renames
// only: at once).
std::atomic<int> commits_running{0};
std::atomic<int> deferred_signal{0};

void on_signal(int sig) {
    if (commits_running.load() > 0) {
        deferred_signal.store(sig);
        return;
    }
    remove_temporaries_and_reraise(sig);
}

// For the length of one commit: then a deferred signal acts (the temporaries not put in place are
// still tracked, so it removes them).
struct SignalsWaitForTheCommit {
    SignalsWaitForTheCommit() { commits_running.fetch_add(1); }
    ~SignalsWaitForTheCommit() {
        if (commits_running.fetch_sub(1) == 1)
            if (const int sig = deferred_signal.exchange(0)) remove_temporaries_and_reraise(sig);
    }
};

}  // namespace

// For the signals whose action is the default one (one that is ignored, as under nohup, or that
// the program handles itself is left as it is); once.
void install_signal_cleanup() {
    static std::once_flag once;
    std::call_once(once, [] {
        for (const int sig : {SIGINT, SIGTERM, SIGHUP}) {
            struct sigaction previous {};
            if (::sigaction(sig, nullptr, &previous) != 0 || (previous.sa_flags & SA_SIGINFO) ||
                previous.sa_handler != SIG_DFL)
                continue;
            struct sigaction action {};
            action.sa_handler = on_signal;
            sigemptyset(&action.sa_mask);
            ::sigaction(sig, &action, nullptr);
        }
    });
}

namespace {

constexpr size_t kNoSlot = SIZE_MAX;

// The slot that names `temp` for the handler (kNoSlot when every slot is taken: that one
// temporary is then not removed on a signal).
size_t track_temporary(const std::string& temp) {
    install_signal_cleanup();
    static std::mutex mutex;
    static std::unique_ptr<char[]> buffers[kTrackedTemporaries];
    static size_t capacity[kTrackedTemporaries] = {};
    const std::lock_guard<std::mutex> lock(mutex);
    for (size_t i = 0; i < kTrackedTemporaries; ++i) {
        if (tracked_temporaries[i].name.load() != nullptr) continue;
        if (capacity[i] < temp.size() + 1) {
            capacity[i] = std::max<size_t>(temp.size() + 1, 256);
            buffers[i] = std::make_unique<char[]>(capacity[i]);
        }
        std::memcpy(buffers[i].get(), temp.c_str(), temp.size() + 1);
        tracked_temporaries[i].owner.store(::getpid());
        tracked_temporaries[i].name.store(buffers[i].get());
        return i;
    }
    return kNoSlot;
}

// The handler no longer removes that temporary (put in place, or removed); slot becomes kNoSlot.
void untrack_temporary(size_t& slot) {
    if (slot < kTrackedTemporaries) tracked_temporaries[slot].name.store(nullptr);
    slot = kNoSlot;
}

// Whether a file can be created in `folder` and removed again: access() answers yes to root
// everywhere, /proc and /sys included, where creating fails; so the temporary's own name is
// created (never one that exists) and removed.
std::string creation_error(const fs::path& target) {
    std::string probe;
    const int fd = create_temporary(target, probe);
    if (fd < 0) return std::strerror(errno);
    ::close(fd);
    ::unlink(probe.c_str());
    return {};
}

// `probe`: also create and remove the temporary (OutputSet::add, which creates it next, does not).
void check_writable_target(const std::string& path, bool probe = true) {
    const fs::path target(path);
    std::error_code error;
    if (path.empty()) throw OutputError("an output path is empty");
    if (fs::is_directory(target, error)) throw OutputError(path + ": is a directory, expected a file name");
    const fs::path folder = target.has_parent_path() ? target.parent_path() : fs::path(".");
    if (!fs::is_directory(folder, error)) {
        if (error == std::errc::filename_too_long)
            throw OutputError(path + ": the path is too long for this system (" + error.message() + ")");
        throw OutputError(path + ": folder " + folder.string() +
                          (fs::exists(folder, error) ? " is not a folder" : " does not exist"));
    }
    if (::access(folder.c_str(), W_OK | X_OK) != 0)
        throw OutputError(path + ": folder " + folder.string() + " is not writable");
    const long name_max = ::pathconf(folder.c_str(), _PC_NAME_MAX);
    const size_t limit = name_max > 0 ? size_t(name_max) : 255;
    if (target.filename().string().size() + kTemporaryExtra > limit)
        throw OutputError(path + ": the file name is too long (at most " + std::to_string(limit - kTemporaryExtra) +
                          " bytes here, so that its temporary fits)");
    // A commit renames over the target: a device (-r /dev/full), a FIFO or a link would be replaced
    // by a plain file, for every other user of it too.
    struct stat existing {};
    const bool exists = ::lstat(path.c_str(), &existing) == 0;
    if (exists && !S_ISREG(existing.st_mode))
        throw OutputError(path + ": is " +
                          (S_ISLNK(existing.st_mode)    ? "a symbolic link (name the file it leads to)"
                           : S_ISFIFO(existing.st_mode) ? "a FIFO"
                           : S_ISCHR(existing.st_mode) || S_ISBLK(existing.st_mode) ? "a device"
                                                                                    : "not a regular file") +
                          ": refusing to replace it with a file; name another output");
    const std::string why = probe ? creation_error(target) : std::string();
    if (!why.empty()) throw OutputError(path + ": folder " + folder.string() + " is not writable (" + why + ")");
    // In a sticky folder (/tmp) only the file's owner, the folder's owner or root may replace a
    // file: known now rather than when the outputs are put in place, after the work.
    struct stat folder_stat {};
    const uid_t user = ::geteuid();
    if (exists && user != 0 && existing.st_uid != user && ::stat(folder.c_str(), &folder_stat) == 0 &&
        (folder_stat.st_mode & S_ISVTX) && folder_stat.st_uid != user)
        throw OutputError(path + ": belongs to another user in a sticky folder (" + folder.string() +
                          "), so it cannot be replaced; name another output");
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

namespace {

// file_identity for many paths in few folders (a library's batch checks thousands of outputs
// against thousands of inputs): a file that does not exist yet is its folder resolved, once per
// folder, then its name, as resolved() would give it.
class Identities {
public:
    std::string of(const std::string& path) {
        struct stat st {};
        if (::stat(path.c_str(), &st) == 0)
            return "inode " + std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino);
        const fs::path p(path);
        const fs::path name = p.filename();
        if (name.empty() || name == "." || name == "..") return file_identity(path);
        const std::string folder = p.has_parent_path() ? p.parent_path().string() : std::string(".");
        auto known = folders_.find(folder);
        if (known == folders_.end()) known = folders_.emplace(folder, resolved(folder)).first;
        return "path " + (known->second / name).string();
    }

private:
    std::unordered_map<std::string, fs::path> folders_;
};

}  // namespace

void check_output_paths(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs,
                        const std::vector<std::string>& input_folders, size_t written_here) {
    check_output_paths(
        outputs.size(), [&](size_t i) -> const std::string& { return outputs[i]; }, inputs, input_folders,
        written_here);
}

void check_output_paths(size_t count, const std::function<const std::string&(size_t)>& output,
                        const std::vector<std::string>& inputs, const std::vector<std::string>& input_folders,
                        size_t written_here) {
    // Each path resolved once, each folder once (a library's batch checks thousands against
    // thousands, many of them one shared input).
    Identities identities;
    std::unordered_set<std::string> input_files, inputs_seen;
    for (const std::string& input : inputs)
        if (!input.empty() && inputs_seen.insert(input).second) input_files.insert(identities.of(input));
    std::unordered_map<std::string, std::string> folders;  // identity → the folder as named
    for (const std::string& folder : input_folders)
        if (!folder.empty()) folders.emplace(file_identity(folder), folder);
    std::unordered_map<std::string, std::string> output_folders;  // folder as named → its identity
    // The outputs by their identities' hashes (a library's outputs are many: their identities are
    // not kept, but worked out again for the outputs whose hashes match).
    std::unordered_multimap<size_t, size_t> output_files;
    for (size_t i = 0; i < count; ++i) {
        const std::string& path = output(i);
        if (i < written_here) check_writable_target(path);
        const std::string identity = identities.of(path);
        if (input_files.count(identity))
            throw OutputError(path + ": is an input of this run: refusing to overwrite the input; name another output");
        if (!folders.empty()) {
            const fs::path target(path);
            const std::string named = target.has_parent_path() ? target.parent_path().string() : std::string(".");
            auto known = output_folders.find(named);
            if (known == output_folders.end()) known = output_folders.emplace(named, file_identity(named)).first;
            const auto folder = folders.find(known->second);
            if (folder != folders.end())
                throw OutputError(path + ": lies in " + folder->second +
                                  ", a folder every file of which this run reads (a clip folder): a later run would "
                                  "read the output as an input; name an output outside it");
        }
        const size_t hash = std::hash<std::string>{}(identity);
        const auto [same_hash, end] = output_files.equal_range(hash);
        for (auto other = same_hash; other != end; ++other)
            if (identities.of(output(other->second)) == identity)
                throw OutputError(path + ": named twice as an output (" + output(other->second) + ")");
        output_files.emplace(hash, i);
    }
}

OutputSet::~OutputSet() {
    for (Pending& p : pending_) {
        if (!committed_) std::remove(p.temp.c_str());
        untrack_temporary(p.slot);
    }
}

void OutputSet::add(const std::string& path, const std::string& data) {
    if (committed_) throw OutputError(path + ": the output set is already committed");
    check_writable_target(path, false);  // creating the temporary below is the probe
    for (const Pending& p : pending_)
        if (same_file(p.target, path)) throw OutputError(path + ": named twice as an output (" + p.target + ")");
    std::string temp;
    const int fd = create_temporary(path, temp);
    if (fd < 0) throw OutputError(path + ": cannot create a temporary beside it: " + std::strerror(errno));
    pending_.push_back({path, temp, track_temporary(temp)});
    size_t written = 0;
    errno = 0;
    while (written < data.size()) {
        const ssize_t n = ::write(fd, data.data() + written, std::min<size_t>(data.size() - written, size_t(1) << 30));
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;
        written += size_t(n);
    }
    const int write_error = written == data.size() ? 0 : errno ? errno : EIO;
    const bool synced = write_error == 0 && ::fsync(fd) == 0;
    const int sync_error = synced ? 0 : errno;
    const bool closed = ::close(fd) == 0;
    if (write_error || !synced || !closed)
        throw OutputError(path + ": write failed: " + std::strerror(write_error ? write_error : sync_error ? sync_error : errno));
    if (observer_) observer_(path, data);
}

void OutputSet::commit() {
    // A signal now waits for the end of the commit (or of its roll-back); each temporary is
    // tracked until it is in place.
    const SignalsWaitForTheCommit wait;
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
        std::string backup = temporary_name(p.target, "old");
        for (int attempt = 0; !rename_without_replacing(p.target, backup, error) && error == std::errc::file_exists &&
                              attempt < 64;
             ++attempt)
            backup = temporary_name(p.target, "old");
        if (error == std::errc::no_such_file_or_directory) continue;  // gone meanwhile: nothing to keep
        if (error) roll_back(p.target + ": cannot replace: " + error.message());
        backups.emplace_back(p.target, backup);
    }
    for (; placed < pending_.size(); ++placed) {
        fs::rename(pending_[placed].temp, pending_[placed].target, error);
        if (error) roll_back(pending_[placed].target + ": cannot replace: " + error.message());
        untrack_temporary(pending_[placed].slot);
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
