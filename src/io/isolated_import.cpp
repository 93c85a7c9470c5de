// A loader run in a forked child (isolated_import.h). The child's mesh comes back through a
// memfd in a small native-endian format: magic, kind ('M' mesh or 'E' error message), fields,
// end magic. The parent trusts none of it: every count is checked against the bytes left before
// anything is allocated, the keyframes against the loading budget, and the mesh is validated.
#include "isolated_import.h"

#include "checked_size.h"

#include "animorder/animated_mesh.h"
#include "animorder/invalid_input.h"
#include "animorder/load.h"

#include <sys/mman.h>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <new>

namespace animorder::io {
namespace {

constexpr char kMagic[8] = {'A', 'O', 'C', 'H', 'I', 'L', 'D', '1'};
constexpr char kEnd[8] = {'A', 'O', 'C', 'H', 'I', 'L', 'D', '.'};
constexpr int kCannotWriteBack = 97;  // the child's exit code when the memfd write fails

// The page the parent and the child share: [0] the file the child reads (ChildContext::reading),
// [1] the processor time in ms its current parse may take (begin_parsing; 0 between parses).
// Set in the child only: begin_parsing and end_parsing do nothing elsewhere.
volatile uint64_t* child_page = nullptr;

struct Fd {
    int fd = -1;
    explicit Fd(int f) : fd(f) {}
    Fd(const Fd&) = delete;
    Fd& operator=(const Fd&) = delete;
    ~Fd() {
        if (fd >= 0) ::close(fd);
    }
};

struct Mapping {
    void* data = MAP_FAILED;
    size_t size = 0;
    Mapping(void* d, size_t s) : data(d), size(s) {}
    Mapping(const Mapping&) = delete;
    Mapping& operator=(const Mapping&) = delete;
    ~Mapping() {
        if (data != MAP_FAILED) ::munmap(data, size);
    }
};

std::string errno_text() { return std::strerror(errno); }

// One printable line of at most `limit` characters.
std::string one_line(const std::string& text, size_t limit) {
    std::string out;
    for (char ch : text) {
        if (out.size() >= limit) {
            out += "...";
            break;
        }
        const unsigned char u = static_cast<unsigned char>(ch);
        out += (u < 0x20 || u == 0x7f) ? ' ' : ch;
    }
    while (!out.empty() && out.back() == ' ') out.pop_back();
    return out;
}

std::string signal_name(int sig) {
    switch (sig) {
        case SIGSEGV: return "SIGSEGV";
        case SIGBUS: return "SIGBUS";
        case SIGABRT: return "SIGABRT";
        case SIGFPE: return "SIGFPE";
        case SIGILL: return "SIGILL";
        case SIGKILL: return "SIGKILL";
        case SIGTRAP: return "SIGTRAP";
        case SIGTERM: return "SIGTERM";
        case SIGSYS: return "SIGSYS";
        default: return "signal";
    }
}

// --- Child side ---------------------------------------------------------------------------------

struct WriteFailed {};

class Writer {
public:
    explicit Writer(int fd) : fd_(fd) {}
    void bytes(const void* p, size_t n) {
        constexpr size_t kChunk = size_t(1) << 16;
        if (buf_.size() + n > kChunk) flush();
        if (n >= kChunk)
            write_all(static_cast<const char*>(p), n);
        else
            buf_.append(static_cast<const char*>(p), n);
    }
    void u64(uint64_t v) { bytes(&v, sizeof v); }
    void i64(int64_t v) { bytes(&v, sizeof v); }
    void f64(double v) { bytes(&v, sizeof v); }
    void str(const std::string& s) {
        u64(s.size());
        bytes(s.data(), s.size());
    }
    template <class T>
    void array(const std::vector<T>& v) {
        u64(v.size());
        bytes(v.data(), v.size() * sizeof(T));
    }
    void flush() {
        write_all(buf_.data(), buf_.size());
        buf_.clear();
    }

private:
    void write_all(const char* p, size_t n) {
        while (n > 0) {
            const ssize_t w = ::write(fd_, p, n);
            if (w < 0 && errno == EINTR) continue;
            if (w <= 0) throw WriteFailed{};
            p += w, n -= size_t(w);
        }
    }
    int fd_;
    std::string buf_;
};

void write_mesh(Writer& w, const AnimatedMesh& m, const std::vector<std::string>& opened) {
    w.bytes(kMagic, sizeof kMagic);
    w.bytes("M", 1);
    w.str(m.name);
    w.u64(m.vertex_count);
    w.array(m.indices);
    w.u64(m.primitives.size());
    for (const Primitive& p : m.primitives) {
        w.str(p.name);
        w.u64(p.first_index);
        w.u64(p.index_count);
        w.i64(p.source_mesh);
        w.i64(p.source_primitive);
        w.u64(p.vertex_base);
        w.u64(p.vertex_count);
        w.u64(uint64_t(p.double_sided) | uint64_t(p.alpha_mode) << 1 | uint64_t(p.mirrored) << 3);
    }
    w.u64(m.clips.size());
    for (const Clip& c : m.clips) {
        w.str(c.name);
        w.f64(c.duration_s);
        w.f64(c.sample_rate);
        w.u64(c.first_keyframe);
        w.u64(c.keyframe_count);
        w.str(c.retargeted);
    }
    w.array(m.keyframe_positions);
    w.u64(m.joint_count);
    w.u64(m.morph_target_count);
    w.u64(opened.size());
    for (const std::string& file : opened) w.str(file);
    w.bytes(kEnd, sizeof kEnd);
    w.flush();
}

void write_error(Writer& w, const std::string& message) {
    w.bytes(kMagic, sizeof kMagic);
    w.bytes("E", 1);
    w.str(message);
    w.bytes(kEnd, sizeof kEnd);
    w.flush();
}

[[noreturn]] void run_child(pid_t parent, int data_fd, int log_fd, volatile uint64_t* page, const std::string& path,
                            const std::function<AnimatedMesh(const ChildContext&)>& load) {
    // Killed with the parent (a parent killed before this line is gone already: its child then
    // belongs to another process); no core file from a parser that crashes or runs out of time.
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);
    if (::getppid() != parent) ::_exit(kCannotWriteBack);
    const rlimit no_core{0, 0};
    ::setrlimit(RLIMIT_CORE, &no_core);
    // begin_parsing's limit stops the child by SIGXCPU's default action, whatever the parent
    // ignored or blocked (both are inherited).
    ::signal(SIGXCPU, SIG_DFL);
    sigset_t xcpu;
    ::sigemptyset(&xcpu);
    ::sigaddset(&xcpu, SIGXCPU);
    ::sigprocmask(SIG_UNBLOCK, &xcpu, nullptr);
    child_page = page;
    volatile uint64_t* reading_index = page;
    // Nothing the child (assimp, a sanitizer) prints reaches the user; the parent reads the log.
    ::dup2(log_fd, STDOUT_FILENO);
    ::dup2(log_fd, STDERR_FILENO);
    int code = 0;
    try {
        Writer w(data_fd);
        try {
            std::vector<std::string> opened;
            const AnimatedMesh mesh = load({[reading_index](size_t i) { *reading_index = i; }, opened});
            write_mesh(w, mesh, opened);
        } catch (const WriteFailed&) {
            throw;
        } catch (const std::bad_alloc&) {
            ::ftruncate(data_fd, 0), ::lseek(data_fd, 0, SEEK_SET);
            write_error(w, path + ": out of memory while reading it");
        } catch (const std::exception& e) {
            ::ftruncate(data_fd, 0), ::lseek(data_fd, 0, SEEK_SET);
            write_error(w, e.what());
        }
    } catch (...) {
        code = kCannotWriteBack;
    }
    // _exit: no atexit handlers, static destructors or stdio flushes of the parent's state.
    ::_exit(code);
}

// --- Parent side --------------------------------------------------------------------------------

class Reader {
public:
    Reader(const char* data, size_t size, const std::string& file) : p_(data), left_(size), file_(file) {}
    void bytes(void* out, size_t n) {
        need(n);
        if (n) std::memcpy(out, p_, n);
        p_ += n, left_ -= n;
    }
    uint64_t u64() {
        uint64_t v;
        bytes(&v, sizeof v);
        return v;
    }
    int64_t i64() {
        int64_t v;
        bytes(&v, sizeof v);
        return v;
    }
    double f64() {
        double v;
        bytes(&v, sizeof v);
        return v;
    }
    int small_int() {
        const int64_t v = i64();
        if (v < INT_MIN || v > INT_MAX) bad("an index out of range");
        return int(v);
    }
    // A count of elements of `element` bytes each, which must all be in the bytes left.
    size_t count(size_t element) { return count(element, u64()); }
    size_t count(size_t element, uint64_t n) {
        size_t total = 0;
        if (n > SIZE_MAX || !checked_mul(size_t(n), element, total) || total > left_)
            bad("a count larger than its data");
        return size_t(n);
    }
    std::string str() {
        std::string s(count(1), '\0');
        bytes(s.data(), s.size());
        return s;
    }
    template <class T>
    void array(std::vector<T>& v) {
        array(v, u64());
    }
    // n elements whose count was already read.
    template <class T>
    void array(std::vector<T>& v, uint64_t n) {
        size_t total = 0;
        if (n > SIZE_MAX || !checked_mul(size_t(n), sizeof(T), total) || total > left_)
            bad("a count larger than its data");
        v.resize(size_t(n));
        bytes(v.data(), total);
    }
    void expect(const char (&tag)[8]) {
        char got[8];
        bytes(got, sizeof got);
        if (std::memcmp(got, tag, sizeof got) != 0) bad("a damaged frame");
    }
    bool at_end() const { return left_ == 0; }
    [[noreturn]] void bad(const std::string& what) const {
        throw LoadError(file_ + ": the isolated reader passed back " + what);
    }

private:
    void need(size_t n) const {
        if (n > left_) bad("a truncated mesh");
    }
    const char* p_;
    size_t left_;
    const std::string& file_;
};

AnimatedMesh read_mesh(Reader& r, const std::string& path, const LoadOptions& options,
                       std::vector<std::string>& opened) {
    AnimatedMesh m;
    m.name = r.str();
    m.vertex_count = r.u64();
    r.array(m.indices);
    // Each primitive takes at least 7 · 8 bytes, each clip 4 · 8: counts are bounded by the data.
    m.primitives.resize(r.count(7 * 8));
    for (Primitive& p : m.primitives) {
        p.name = r.str();
        p.first_index = r.u64();
        p.index_count = r.u64();
        p.source_mesh = r.small_int();
        p.source_primitive = r.small_int();
        p.vertex_base = r.u64();
        p.vertex_count = r.u64();
        const uint64_t material = r.u64();
        if ((material & 7) > 5 || material > 15) throw LoadError(path + ": the importer's material flags are corrupt");
        p.double_sided = (material & 1) != 0;
        p.alpha_mode = AlphaMode((material >> 1) & 3);
        p.mirrored = (material & 8) != 0;
    }
    m.clips.resize(r.count(5 * 8));
    for (Clip& c : m.clips) {
        c.name = r.str();
        c.duration_s = r.f64();
        c.sample_rate = r.f64();
        c.first_keyframe = r.u64();
        c.keyframe_count = r.u64();
        c.retargeted = r.str();
    }
    // The budget before the largest allocation: keyframes × vertices × 3 floats.
    const uint64_t floats = r.u64();
    if (m.vertex_count == 0 || floats % 3 != 0 || floats / 3 % m.vertex_count != 0)
        r.bad("keyframes that do not match the vertex count");
    check_keyframe_budget(path, size_t(floats / 3 / m.vertex_count), m.vertex_count, options);
    r.array(m.keyframe_positions, floats);
    m.joint_count = r.u64();
    m.morph_target_count = r.u64();
    opened.resize(r.count(8));  // each at least its length
    for (std::string& file : opened) file = r.str();
    r.expect(kEnd);
    if (!r.at_end()) r.bad("bytes after the mesh");
    try {
        validate_animated_mesh(m);
    } catch (const InvalidInput& e) {
        r.bad(std::string("an invalid mesh: ") + e.what());
    }
    return m;
}

// The last meaningful line the child wrote: a sanitizer's SUMMARY line when there is one, else
// the last non-blank line.
std::string last_words(int log_fd) {
    struct stat st {};
    if (::fstat(log_fd, &st) != 0 || st.st_size <= 0) return "";
    const size_t size = size_t(st.st_size), tail = std::min<size_t>(size, 64 * 1024);
    std::string text(tail, '\0');
    const ssize_t got = ::pread(log_fd, text.data(), tail, off_t(size - tail));
    if (got <= 0) return "";
    text.resize(size_t(got));
    std::string last, summary;
    size_t begin = 0;
    while (begin < text.size()) {
        size_t end = text.find('\n', begin);
        if (end == std::string::npos) end = text.size();
        const std::string line = one_line(text.substr(begin, end - begin), 300);
        if (line.find_first_not_of(' ') != std::string::npos) last = line;
        if (line.find("SUMMARY:") != std::string::npos) summary = line;
        begin = end + 1;
    }
    const std::string& chosen = summary.empty() ? last : summary;
    const size_t first = chosen.find_first_not_of(' ');
    return first == std::string::npos ? "" : chosen.substr(first);
}

}  // namespace

void begin_parsing(uint64_t bytes, const LoadOptions& options) {
    const double seconds = options.parse_seconds * (1.0 + double(bytes) / double(1 << 20));
    if (!child_page || !(seconds > 0)) return;
    rusage usage{};
    rlimit limit{};
    if (::getrusage(RUSAGE_SELF, &usage) != 0 || ::getrlimit(RLIMIT_CPU, &limit) != 0) return;
    const double used = double(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
                        1e-6 * double(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
    const double until = std::ceil(used + seconds);  // the limit is whole seconds of the process's time
    if (limit.rlim_max != RLIM_INFINITY && until >= double(limit.rlim_max)) return;
    limit.rlim_cur = until < 1e12 ? rlim_t(until) : RLIM_INFINITY;
    child_page[1] = uint64_t(seconds * 1000.0);
    ::setrlimit(RLIMIT_CPU, &limit);
}

void end_parsing() {
    rlimit limit{};
    if (!child_page || ::getrlimit(RLIMIT_CPU, &limit) != 0) return;
    limit.rlim_cur = limit.rlim_max;
    ::setrlimit(RLIMIT_CPU, &limit);
    child_page[1] = 0;
}

AnimatedMesh load_isolated(const std::vector<std::string>& files, const LoadOptions& options,
                           const std::function<AnimatedMesh(const ChildContext& child)>& load) {
    if (files.empty()) throw LoadError("(no file): nothing to read");
    const std::string& path = files[0];
    const Fd data(::memfd_create("animorder-child-mesh", MFD_CLOEXEC));
    const Fd log(::memfd_create("animorder-child-log", MFD_CLOEXEC));
    if (data.fd < 0 || log.fd < 0)
        throw LoadError(path + ": cannot create the isolated reader's buffer: " + errno_text());
    const Mapping shared(
        ::mmap(nullptr, 2 * sizeof(uint64_t), PROT_READ | PROT_WRITE, MAP_SHARED | MAP_ANONYMOUS, -1, 0),
        2 * sizeof(uint64_t));
    if (shared.data == MAP_FAILED) throw LoadError(path + ": cannot map the isolated reader's page: " + errno_text());
    volatile uint64_t* page = static_cast<volatile uint64_t*>(shared.data);
    page[0] = page[1] = 0;

    const pid_t parent = ::getpid();
    const pid_t child = ::fork();
    if (child < 0) throw LoadError(path + ": cannot start the isolated reader: " + errno_text());
    if (child == 0) run_child(parent, data.fd, log.fd, page, path, load);

    int status = 0;
    pid_t waited;
    do waited = ::waitpid(child, &status, 0);
    while (waited < 0 && errno == EINTR);
    if (waited < 0) throw LoadError(path + ": lost the isolated reader: " + errno_text());

    const uint64_t index = page[0], parse_ms = page[1];
    const std::string& blamed = index < files.size() ? files[size_t(index)] : path;
    if (WIFSIGNALED(status) && parse_ms > 0 && WTERMSIG(status) == SIGXCPU) {  // begin_parsing's limit
        char seconds[32];
        std::snprintf(seconds, sizeof seconds, "%.0f", double(parse_ms) / 1000.0);
        throw LoadError(blamed + ": assimp did not finish reading it in " + seconds +
                        " s of processor time (a damaged file it loops on?)");
    }
    if (WIFSIGNALED(status) ||
        (WIFEXITED(status) && WEXITSTATUS(status) != 0 && WEXITSTATUS(status) != kCannotWriteBack)) {
        std::string why = WIFSIGNALED(status)
                              ? "signal " + std::to_string(WTERMSIG(status)) + ": " + signal_name(WTERMSIG(status))
                              : "exit code " + std::to_string(WEXITSTATUS(status));
        const std::string said = last_words(log.fd);
        throw LoadError(blamed + ": assimp crashed reading it (" + why + ")" +
                        (said.empty() ? "" : "; it said: " + said));
    }
    if (!WIFEXITED(status)) throw LoadError(path + ": the isolated reader stopped abnormally");
    if (WEXITSTATUS(status) == kCannotWriteBack)
        throw LoadError(path + ": the isolated reader could not pass the mesh back (out of memory?)");

    struct stat st {};
    if (::fstat(data.fd, &st) != 0 || st.st_size <= 0)
        throw LoadError(path + ": the isolated reader passed nothing back");
    const size_t size = size_t(st.st_size);
    const Mapping bytes(::mmap(nullptr, size, PROT_READ, MAP_PRIVATE, data.fd, 0), size);
    if (bytes.data == MAP_FAILED) throw LoadError(path + ": cannot read the isolated reader's mesh: " + errno_text());
    Reader r(static_cast<const char*>(bytes.data), size, path);
    r.expect(kMagic);
    char kind = 0;
    r.bytes(&kind, 1);
    if (kind == 'E') {
        const std::string message = one_line(r.str(), 2000);
        r.expect(kEnd);
        // Errors start with a file name; a message that does not (garbled) gets the character's.
        for (const std::string& f : files)
            if (message.rfind(f + ":", 0) == 0) throw LoadError(message);
        throw LoadError(path + ": " + message);
    }
    if (kind != 'M') r.bad("an unknown answer");
    std::vector<std::string> opened;
    AnimatedMesh mesh = read_mesh(r, path, options, opened);
    if (options.files_read) add_files_read(*options.files_read, opened);
    return mesh;
}

}  // namespace animorder::io
