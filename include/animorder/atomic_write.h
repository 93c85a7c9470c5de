// animorder — writing outputs so that a run's files appear all together or not at all
// (atomic_write.cpp): each file goes to a temporary in its target folder (flushed to disk), and
// only when every file of the run is written are they renamed into place. Nothing the user named
// as an input is ever replaced, and no two outputs of a run may be the same file.
#pragma once

#include <cstdint>
#include <ctime>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace animorder {

// Thrown when an output cannot be written or is refused; what() names the path, in one line.
class OutputError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Throws OutputError unless every output path can be written as a new or replaced file: its folder
// exists and a file can be created in it (tried, not only asked of access()), it is not a folder,
// its name leaves room for its temporary's, an existing file may be replaced (a sticky folder's
// file of another user may not), it is not (after
// resolving links) one of `inputs`, it does not lie in one of `input_folders` (folders every
// file of which the run reads, such as a clip folder: a later run would read the output as an
// input), and no two outputs are the same file. Call it before any long work, so a bad path fails
// at once. Only the first `written_here` outputs are checked for writing: the others are those
// other processes of the same job write (a farm's other shards), checked against the inputs and
// against each other only.
void check_output_paths(const std::vector<std::string>& outputs, const std::vector<std::string>& inputs,
                        const std::vector<std::string>& input_folders = {}, size_t written_here = SIZE_MAX);

// The same for `count` outputs named by output(i) (a batch's, which its items hold: not copied).
void check_output_paths(size_t count, const std::function<const std::string&(size_t)>& output,
                        const std::vector<std::string>& inputs, const std::vector<std::string>& input_folders,
                        size_t written_here);

// A key equal for two paths exactly when they name the same file: its device and inode when it
// exists, else its path with links and "." / ".." resolved.
std::string file_identity(const std::string& path);

// Throws OutputError when `stem`, a name that a run's outputs extend (OUT → OUT.animorder.bin),
// names a folder instead: empty, ending in '/', ending in "." or "..", or an existing folder.
void check_output_stem(const std::string& stem);

// The outputs of one run. add() writes each to a temporary beside its target (a new file under a
// random name, created exclusively and never through a link, so nothing planted in the folder can
// redirect it); commit() renames
// them all into place. If any add() or the commit fails, or the set is destroyed uncommitted,
// every temporary is removed and no target has been touched (a rename that fails mid-commit
// restores the files already replaced from their backups). A SIGINT, SIGTERM or SIGHUP (whose
// action was the default one) removes the temporaries too before the process ends of it; only
// SIGKILL, or a signal during the commit's renames (when removing them would leave targets
// missing), leaves them (`batch` sweeps those of its items).
class OutputSet {
public:
    OutputSet() = default;
    ~OutputSet();
    OutputSet(const OutputSet&) = delete;
    OutputSet& operator=(const OutputSet&) = delete;

    void add(const std::string& path, const std::string& data);
    void commit();
    // Called by each later add() with its path and bytes once they are written (batch records
    // the outputs' digests in the item report that commits with them).
    void observe(std::function<void(const std::string& path, const std::string& data)> observer) {
        observer_ = std::move(observer);
    }

private:
    struct Pending {
        std::string target, temp;
        size_t slot;  // where the signal handler finds temp (atomic_write.cpp)
    };
    std::vector<Pending> pending_;
    bool committed_ = false;
    std::function<void(const std::string&, const std::string&)> observer_;
};

// Whether process `pid` may still be running: it exists (or is not ours to judge) and is not a
// zombie (killed, its parent not yet told: it writes nothing more).
bool process_may_run(long pid);

// What runs killed part-way left beside `target` (SIGKILL, or a signal during a commit): its
// temporaries (".NAME.tmpPID-RANDOM", or ".NAME.tmpPID" from earlier versions) whose process is
// gone are removed, and so are such backups (".NAME.oldPID-RANDOM") while the target exists (a backup whose target is missing may be the only copy
// of the file it replaced: kept). A process id cannot tell a live process on another machine
// sharing the folder, nor one that took the id since: so a temporary whose inode has not changed
// for an hour before `now` is removed whatever its process id (a temporary lives seconds).
void remove_stale_temporaries(const std::string& target, std::time_t now = std::time(nullptr));

// SIGINT, SIGTERM and SIGHUP, where their action is the default one, remove this process's
// temporaries and end it as killed (also as a container's PID 1, whose default actions do
// nothing: it exits with 128 + the signal). The first temporary installs it; a program that may
// run as PID 1 calls it at its start, so that the signals end it before it writes too.
void install_signal_cleanup();

// One file written atomically: an OutputSet of one.
void write_file_atomically(const std::string& path, const std::string& data);

}  // namespace animorder
