// animorder view [FILE] — serves the viewer page (viewer/, with js/ and three.js from
// viewer/node_modules) and FILE as /model/NAME (also /model.glb) on 127.0.0.1 only, with the
// external buffers and images a .gltf or .glb names (at the URLs its URIs resolve to from there;
// the same for --original's file under /original/), prints the address and opens it in the
// default browser. Without FILE it first optimises the bundled character (subdivide
// --levels 0, then optimize with the default method) into a new scratch folder of its own (random name,
// mode 0700), and serves the un-optimised file too (/original.glb) so the page can compare the
// original order with the optimised ones.
// The server is deliberately tiny: GET and HEAD, one request per connection, nothing but loopback.
// What a client can and cannot do to it:
// - Connections are served at once by a pool of kWorkers threads; when all are busy, new ones
//   wait in the listen backlog (not refused) until a worker is free. A connection has kReadSeconds
//   to send its request head (at most 8 KiB, http_request.h) and then kResponseSeconds to take
//   the whole response, taking some of it at least every kStallSeconds; no single socket call
//   waits longer than about a second, so a client that stalls (sends half a request, or never
//   reads) holds one worker until its deadline, never the others, nor the end of `--seconds`,
//   nor SIGINT/SIGTERM.
// - `--seconds` and SIGINT/SIGTERM (handlers without SA_RESTART, the workers blocking both) end
//   the server within about a second whatever the clients do: the workers' sockets are shut down,
//   the workers joined, and the scratch folder removed.
// - Files only below the viewer's folders (no "..", no "%", no backslash; real paths checked, see
//   resolve()) and the files the two glTF files name from below their folders (sent as bytes or
//   images, never as a page: serve_with_its_files), and requests whose Host is not this server's
//   loopback address and port are refused
//   (421: a page rebound to 127.0.0.1 by DNS rebinding cannot read the model).
// - Without -q, refused requests are logged with their URL's control bytes and non-ASCII bytes
//   written as \xNN.
#include "commands.h"
#include "http_request.h"

#include "animorder/atomic_write.h"
#include "animorder/load.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <pthread.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/time.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace fs = std::filesystem;

namespace animorder::tool {
namespace {

using Clock = std::chrono::steady_clock;

constexpr size_t kWorkers = 32;                          // connections served at once (a browser opens at most 6)
constexpr int kBacklog = 64;                             // connections that wait while every worker is busy
constexpr int kReadSeconds = 10;                         // to send the request head, from the connection's accept
constexpr int kResponseSeconds = 60;                     // to take the whole response, from the end of the request
constexpr int kStallSeconds = 5;                         // the longest a client may take no byte of the response
constexpr auto kSlice = std::chrono::milliseconds(250);  // the accept loop's longest wait

volatile std::sig_atomic_t interrupted = 0;  // Ctrl-C / SIGTERM: stop serving, remove the scratch folder
void on_signal(int) { interrupted = 1; }

// SIGINT, SIGTERM and SIGHUP (the terminal closed) set `interrupted`; without SA_RESTART, so that
// a wait under way returns at once. (While the bundled character is optimised, before, their
// default actions end the run; the next `view` removes the scratch folder it left.)
void install_signal_handlers() {
    struct sigaction action {};
    action.sa_handler = on_signal;
    sigemptyset(&action.sa_mask);
    action.sa_flags = 0;
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
    sigaction(SIGHUP, &action, nullptr);
}

std::string content_type(const fs::path& path) {
    const std::string e = path.extension().string();
    if (e == ".html") return "text/html; charset=utf-8";
    if (e == ".js" || e == ".mjs") return "text/javascript; charset=utf-8";
    if (e == ".json" || e == ".gltf") return "application/json";
    if (e == ".glb") return "model/gltf-binary";
    if (e == ".bin") return "application/octet-stream";
    if (e == ".css") return "text/css";
    if (e == ".png") return "image/png";
    if (e == ".wasm") return "application/wasm";
    return "application/octet-stream";
}

struct Site {
    fs::path root;      // the folder holding viewer/ and js/
    fs::path model;     // served as /model/NAME (and /model.glb)
    fs::path original;  // served as /original/NAME (and /original.glb; may be empty)
    std::string model_url, original_url;  // /model/NAME, /original/NAME, percent-encoded
    // The two files and their external buffers and images, by the URL path a browser asks for
    // them at (each URI resolved against its file's URL, percent-encoded as canonical_path does).
    std::map<std::string, fs::path> files;
    unsigned port = 0;  // the port listened on (the Host check)
    bool quiet = false;
};

// `text` percent-encoded: every byte but the unreserved ones (RFC 3986) and '/' as %XX.
std::string percent_encode(const std::string& text, bool keep_slash) {
    static const char* hex = "0123456789ABCDEF";
    std::string out;
    for (const unsigned char c : text) {
        if (std::isalnum(c) || c == '-' || c == '.' || c == '_' || c == '~' || (keep_slash && c == '/')) {
            out += char(c);
        } else {
            out += '%';
            out += hex[c >> 4];
            out += hex[c & 15];
        }
    }
    return out;
}

// A URL path in one spelling: percent-decoded (false for a '%' not followed by two hex digits),
// its "." and ".." segments removed (RFC 3986 §5.2.4, ".." at the root staying there), then
// percent-encoded again. Two spellings of one path a browser may send come out equal.
bool canonical_path(const std::string& path, std::string& out) {
    std::string decoded;
    for (size_t i = 0; i < path.size(); ++i) {
        if (path[i] != '%') {
            decoded += path[i];
            continue;
        }
        if (i + 2 >= path.size() || !std::isxdigit(static_cast<unsigned char>(path[i + 1])) ||
            !std::isxdigit(static_cast<unsigned char>(path[i + 2])))
            return false;
        decoded += char(std::stoi(path.substr(i + 1, 2), nullptr, 16));
        i += 2;
    }
    std::vector<std::string> segments;
    size_t begin = decoded.empty() || decoded[0] != '/' ? 0 : 1;
    while (begin <= decoded.size()) {
        size_t end = decoded.find('/', begin);
        if (end == std::string::npos) end = decoded.size();
        const std::string segment = decoded.substr(begin, end - begin);
        const bool last = end == decoded.size();
        if (segment == "..") {
            if (!segments.empty()) segments.pop_back();
            if (last) segments.push_back("");
        } else if (segment == ".") {
            if (last) segments.push_back("");
        } else {
            segments.push_back(segment);
        }
        begin = end + 1;
    }
    out.clear();
    for (const std::string& segment : segments) out += "/" + percent_encode(segment, false);
    return true;
}

// Whether the canonical path `path` is `base` or lies below it.
bool inside(const fs::path& path, const fs::path& base);

// `file` served under `prefix` (/model/ or /original/): its URL, and each of its external
// buffers and images at the URL its URI resolves to from there (the browser's URL, which may
// leave the prefix: "../textures/a.png"). Only files whose real path lies below one of `roots`
// (the folders of the model and the original) are served, and only under a URL no other file
// holds; a URI that is absolute, has a scheme or a backslash is left to the page (it fails
// there). Without `quiet`, says on stderr what it serves and what it leaves out. Returns the
// file's URL.
std::string serve_with_its_files(Site& site, const std::string& prefix, const fs::path& file,
                                 const std::vector<fs::path>& roots, bool quiet) {
    const std::string url = prefix + percent_encode(file.filename().string(), false);
    site.files[url] = file;
    const std::string ext = file_extension(file.string());
    if (ext != ".gltf" && ext != ".glb") return url;
    const auto say = [&](const std::string& text) {
        if (!quiet) std::fprintf(stderr, "view: %s\n", text.c_str());
    };
    for (const ExternalFile& f : gltf_external_uris(file.string())) {
        const size_t colon = f.uri.find(':');
        if (f.uri.empty() || f.uri[0] == '/' || f.uri.find('\\') != std::string::npos ||
            (colon != std::string::npos && colon < f.uri.find('/')))
            continue;
        std::error_code error;
        const fs::path real = fs::canonical(f.file, error);
        if (error || !fs::is_regular_file(real, error)) continue;  // the page says what it misses
        if (std::none_of(roots.begin(), roots.end(), [&](const fs::path& root) { return inside(real, root); })) {
            say("not serving " + real.string() + " (named by " + file.string() +
                "): it lies outside the folders of the files given");
            continue;
        }
        const std::string reference = f.uri.substr(0, f.uri.find_first_of("?#"));
        std::string key;
        if (!canonical_path(prefix + reference, key)) continue;
        const auto [at, added] = site.files.emplace(key, real);
        if (!added && fs::canonical(at->second, error) != real) {
            say("not serving " + real.string() + " at " + key + ": that URL is " + at->second.string() + "'s");
            continue;
        }
        if (added) say("serving " + real.string() + " at " + key);
    }
    return url;
}

// What a named file is sent as: glTF, an image, else bytes (never a page or a script: a file a
// glTF names runs nothing on the viewer's origin).
std::string named_content_type(const fs::path& path) {
    const std::string e = file_extension(path.string());
    if (e == ".glb") return "model/gltf-binary";
    if (e == ".gltf") return "model/gltf+json";
    if (e == ".png") return "image/png";
    if (e == ".jpg" || e == ".jpeg") return "image/jpeg";
    if (e == ".webp") return "image/webp";
    if (e == ".ktx2") return "image/ktx2";
    return "application/octet-stream";
}

// One client's socket, the time by which what is under way (reading the request, then sending
// the response) must be done, and the server's stop flag.
struct Connection {
    int fd;
    const std::atomic<bool>& stopping;
    Clock::time_point deadline;
    // Whether to go on: before the deadline, and the server not stopping.
    bool may_go_on() const { return !stopping && Clock::now() < deadline; }
};

// Whether a socket call that failed may be tried again (it timed out after its second, or a
// signal came).
bool try_again(int error) { return error == EAGAIN || error == EWOULDBLOCK || error == EINTR; }

// `size` bytes sent whole; false when the client went away, the deadline passed or the server stops.
// A client that takes no byte for kStallSeconds is dropped (a browser reads as the bytes come), so
// that clients which never read free their workers long before their deadlines.
bool send_all(const Connection& c, const char* data, size_t size) {
    size_t sent = 0;
    Clock::time_point progress = Clock::now();
    while (sent < size) {
        if (!c.may_go_on() || Clock::now() - progress > std::chrono::seconds(kStallSeconds)) return false;
        const ssize_t n = ::send(c.fd, data + sent, size - sent, MSG_NOSIGNAL);
        if (n < 0 && try_again(errno)) continue;
        if (n <= 0) return false;  // the browser went away: nothing to do
        sent += size_t(n);
        progress = Clock::now();
    }
    return true;
}

// The response head, then `body` unless the request was HEAD (`length`: the body's length).
std::string response_head(int code, const std::string& status, const std::string& type, size_t length,
                          const std::string& extra = "") {
    return "HTTP/1.1 " + std::to_string(code) + " " + status + "\r\nContent-Type: " + type +
           "\r\nContent-Length: " + std::to_string(length) + "\r\nCache-Control: no-store\r\nConnection: close\r\n" +
           extra + "\r\n";
}

// A short answer: status line, headers and `body` (not for HEAD).
void respond(const Connection& c, int code, const std::string& status, const std::string& type, const std::string& body,
             bool head, const std::string& extra = "") {
    std::string bytes = response_head(code, status, type, body.size(), extra);
    if (!head) bytes += body;
    send_all(c, bytes.data(), bytes.size());
}

// Whether the canonical path `path` is `base` or lies below it.
bool inside(const fs::path& path, const fs::path& base) {
    const auto [b, p] = std::mismatch(base.begin(), base.end(), path.begin(), path.end());
    (void)p;
    return b == base.end();
}

// The file a URL path names, or empty when it names none we serve. Its real path (links
// followed) must lie below the real viewer/ for /viewer/..., below the real js/ for /js/...; for
// /viewer/node_modules/PACKAGE/... (PACKAGE one name, or @scope/name) it must lie below the real
// path of viewer/node_modules/PACKAGE, and that folder's real path must lie strictly below the
// real site.root. So a package npm installed, or one linked to a folder inside the repository
// (viewer/node_modules/animorder -> ../../js), is served; a link to anywhere outside the
// repository (`npm link` of a folder elsewhere, or of `/`), or to the repository's root itself,
// is not, nor is a link inside a package that leads out of it.
fs::path resolve(const Site& site, const std::string& url) {
    if (url == "/model.glb") return site.model;
    if (url == "/original.glb") return site.original;
    if (url.rfind("/viewer/", 0) != 0 && url.rfind("/js/", 0) != 0) {
        std::string key;
        const auto it = canonical_path(url, key) ? site.files.find(key) : site.files.end();
        return it == site.files.end() ? fs::path() : it->second;
    }
    if (url.find("..") != std::string::npos || url.find('%') != std::string::npos ||
        url.find('\\') != std::string::npos)
        return {};
    for (const char* prefix : {"/viewer/", "/js/"}) {
        if (url.rfind(prefix, 0) != 0) continue;
        fs::path path = site.root / url.substr(1);
        if (url.back() == '/') path /= "index.html";
        std::error_code ec;
        const fs::path real = fs::canonical(path, ec);
        if (ec || !fs::is_regular_file(real, ec)) return {};
        const std::string modules = "/viewer/node_modules/";
        if (url.rfind(modules, 0) != 0) {
            const std::string folder(prefix + 1, std::char_traits<char>::length(prefix) - 2);
            const fs::path base = fs::canonical(site.root / folder, ec);
            return !ec && inside(real, base) ? real : fs::path();
        }
        const std::string rest = url.substr(modules.size());
        size_t cut = rest.find('/');
        if (!rest.empty() && rest[0] == '@' && cut != std::string::npos) cut = rest.find('/', cut + 1);
        if (cut == 0 || cut == std::string::npos) return {};
        const fs::path package = fs::canonical(site.root / "viewer" / "node_modules" / rest.substr(0, cut), ec);
        if (ec) return {};
        const fs::path root = fs::canonical(site.root, ec);
        if (ec || package == root || !inside(package, root)) return {};
        return inside(real, package) ? real : fs::path();
    }
    return {};
}

// The request head, read until it is complete, bad or too large; incomplete when the client went
// away, the deadline passed or the server stops first.
HttpParse read_request(const Connection& c, HttpRequest& request) {
    std::string bytes;
    char buffer[2048];
    while (c.may_go_on()) {
        const ssize_t n = ::recv(c.fd, buffer, sizeof buffer, 0);
        if (n < 0 && try_again(errno)) continue;
        if (n <= 0) break;
        bytes.append(buffer, size_t(n));
        const HttpParse parsed = parse_http_request(bytes, request);
        if (parsed != HttpParse::incomplete) return parsed;
    }
    return HttpParse::incomplete;
}

// The file at `path` as a 200 response (its head only for HEAD), read and sent in pieces.
void send_file(const Connection& c, const std::string& type, const std::string& extra, std::ifstream& in, size_t size,
               bool head) {
    const std::string start = response_head(200, "OK", type, size, extra);
    if (!send_all(c, start.data(), start.size()) || head) return;
    std::vector<char> piece(1 << 16);
    size_t left = size;
    while (left > 0 && in) {
        in.read(piece.data(), std::streamsize(std::min(left, piece.size())));
        const size_t got = size_t(in.gcount());
        if (got == 0 || !send_all(c, piece.data(), got)) return;
        left -= got;
    }
}

// One connection: its request read and answered, each within its deadline.
void serve_one(int fd, const Site& site, const std::atomic<bool>& stopping) {
    const timeval second{1, 0};  // no single call waits longer: the deadlines and the stop flag are checked between
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &second, sizeof second);
    setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &second, sizeof second);
    Connection c{fd, stopping, Clock::now() + std::chrono::seconds(kReadSeconds)};
    HttpRequest request;
    const HttpParse parsed = read_request(c, request);
    if (parsed == HttpParse::incomplete) return;
    c.deadline = Clock::now() + std::chrono::seconds(kResponseSeconds);
    if (parsed == HttpParse::too_large) {
        respond(c, 431, "Request Header Fields Too Large", "text/plain", "request head over 8 KiB\n", false);
        return;
    }
    if (parsed == HttpParse::bad) {
        respond(c, 400, "Bad Request", "text/plain", "bad request\n", false);
        return;
    }
    const std::string& url = request.target;
    // HTTP/1.0 may leave Host out (no browser does, so no rebound page can); HTTP/1.1 may not (the parser refuses it).
    if (request.has_host && !host_is_loopback(request.host, site.port)) {
        if (!site.quiet)
            std::fprintf(stderr, "view: 421 %s (Host: %s)\n", escape_for_log(url).c_str(),
                         escape_for_log(request.host).c_str());
        respond(c, 421, "Misdirected Request", "text/plain",
                "only Host 127.0.0.1:" + std::to_string(site.port) + " or localhost:" + std::to_string(site.port) +
                    " is served\n",
                false);
        return;
    }
    const bool head = request.method == "HEAD";
    if (request.method != "GET" && !head) {
        respond(c, 405, "Method Not Allowed", "text/plain", "GET or HEAD only\n", false);
        return;
    }
    if (url == "/") {
        respond(c, 302, "Found", "text/plain", "", head,
                "Location: /viewer/?file=" + percent_encode(site.model_url, true) +
                    (site.original.empty() ? "" : "&original=" + percent_encode(site.original_url, true)) + "\r\n");
        return;
    }
    const fs::path path = resolve(site, url);
    std::error_code ec;
    const size_t size = path.empty() ? 0 : size_t(fs::file_size(path, ec));
    std::ifstream in;
    if (!path.empty() && !ec) in.open(path, std::ios::binary);
    if (path.empty() || ec || !in) {
        if (!site.quiet) std::fprintf(stderr, "view: 404 %s\n", escape_for_log(url).c_str());
        respond(c, 404, "Not Found", "text/plain", "not found\n", head);
        return;
    }
    // A file the model or the original names: sent as what it is, with nothing a browser would run.
    const bool named = url.rfind("/viewer/", 0) != 0 && url.rfind("/js/", 0) != 0;
    send_file(c, named ? named_content_type(path) : content_type(path),
              named ? "X-Content-Type-Options: nosniff\r\nContent-Security-Policy: sandbox\r\n" : "", in, size, head);
}

// The workers: kWorkers threads that each serve one accepted connection at a time. The accept
// loop hands a connection over only while a worker is idle (wait_for_idle), so the others wait in
// the listen backlog. stop() (also on destruction) shuts down the sockets being served, so that
// their workers return at once, and joins the workers.
class Pool {
public:
    explicit Pool(const Site& site) : site_(site) {
        // SIGINT and SIGTERM go to the accept loop's thread (its poll returns at once), not to a worker.
        sigset_t block, old;
        sigemptyset(&block);
        sigaddset(&block, SIGINT);
        sigaddset(&block, SIGTERM);
        pthread_sigmask(SIG_BLOCK, &block, &old);
        try {
            for (size_t i = 0; i < kWorkers; ++i) workers_.emplace_back([this] { work(); });
        } catch (...) {
            pthread_sigmask(SIG_SETMASK, &old, nullptr);
            stop();
            throw;
        }
        pthread_sigmask(SIG_SETMASK, &old, nullptr);
    }
    ~Pool() { stop(); }
    Pool(const Pool&) = delete;
    Pool& operator=(const Pool&) = delete;

    // Whether a worker is idle (and not yet promised a connection), waiting up to `wait` for one.
    bool wait_for_idle(Clock::duration wait) {
        std::unique_lock<std::mutex> lock(mutex_);
        return idle_changed_.wait_for(lock, wait, [this] { return idle_ > waiting_.size(); });
    }

    // `fd`, an accepted connection, to an idle worker (which closes it).
    void hand_over(int fd) {
        {
            std::lock_guard<std::mutex> lock(mutex_);
            waiting_.push_back(fd);
        }
        work_.notify_one();
    }

    // The workers told to stop (the sockets they serve shut down) and joined; connections not yet
    // taken closed.
    void stop() {
        {
            std::lock_guard<std::mutex> lock(mutex_);
            stopping_ = true;
            for (const int fd : active_) ::shutdown(fd, SHUT_RDWR);
        }
        work_.notify_all();
        for (std::thread& worker : workers_)
            if (worker.joinable()) worker.join();
        for (const int fd : waiting_) ::close(fd);
        waiting_.clear();
    }

private:
    // A worker: takes connections until the pool stops.
    void work() {
        std::unique_lock<std::mutex> lock(mutex_);
        for (;;) {
            ++idle_;
            idle_changed_.notify_all();
            work_.wait(lock, [this] { return stopping_ || !waiting_.empty(); });
            --idle_;
            if (stopping_) return;
            const int fd = waiting_.front();
            waiting_.pop_front();
            active_.push_back(fd);
            lock.unlock();
            try {
                serve_one(fd, site_, stopping_);
            } catch (...) {
                // out of memory while answering: this connection only
            }
            lock.lock();
            active_.erase(std::find(active_.begin(), active_.end(), fd));
            ::close(fd);  // under the lock: stop() never shuts down a number already reused
        }
    }

    const Site& site_;
    std::mutex mutex_;
    std::condition_variable work_, idle_changed_;
    std::deque<int> waiting_;  // handed over, not yet taken
    std::vector<int> active_;  // being served
    size_t idle_ = 0;
    std::atomic<bool> stopping_{false};
    std::vector<std::thread> workers_;
};

// The bundled character, optimised, in `dir`: char.glb (input) and character.glb (optimised).
void make_bundled(const fs::path& dir, bool quiet) {
    SubdivideOptions s;
    s.common.quiet = quiet;
    s.levels = 0;
    s.output = (dir / "char.glb").string();
    if (run_subdivide(s) != 0) throw std::runtime_error("could not write the bundled character");
    OptimizeOptions o;
    o.common.quiet = quiet;
    o.common.input = s.output;
    o.output = (dir / "character.glb").string();
    if (run_optimize(o) != 0) throw std::runtime_error("could not optimise the bundled character");
}

// The scratch folders of earlier `view` runs whose process is gone (killed while optimising the
// bundled character, before it could remove its folder): removed. Only folders (not links) of
// this user named as `view` names them: nothing another user of the shared temporary folder
// planted is followed or removed.
void remove_stale_scratch_folders(const fs::path& temp) {
    const std::string prefix = "animorder-view-";
    std::error_code error;
    for (auto it = fs::directory_iterator(temp, error); !error && it != fs::directory_iterator(); it.increment(error)) {
        // "animorder-view-PID-RANDOM" (and "animorder-view-PID", as earlier versions named them).
        const std::string name = it->path().filename().string(),
                          rest = name.substr(std::min(name.size(), prefix.size())),
                          pid = rest.substr(0, rest.find('-')),
                          random = rest.substr(std::min(rest.size(), pid.size() + 1));
        auto digits = [](const std::string& text, const char* allowed) {
            return text.find_first_not_of(allowed) == std::string::npos;
        };
        struct stat entry {};
        if (name.rfind(prefix, 0) != 0 || pid.empty() || pid.size() > 9 || !digits(pid, "0123456789") ||
            (rest.size() > pid.size() && (random.size() != 16 || !digits(random, "0123456789abcdef"))) ||
            ::lstat(it->path().c_str(), &entry) != 0 || !S_ISDIR(entry.st_mode) || entry.st_uid != ::geteuid() ||
            process_may_run(std::stol(pid)))
            continue;
        std::error_code ignored;
        fs::remove_all(it->path(), ignored);
    }
}

// The server's socket and the scratch folder, released on every way out (an error included).
struct Resources {
    int server = -1;
    fs::path scratch;
    ~Resources() {
        if (server >= 0) ::close(server);
        std::error_code ignored;
        if (!scratch.empty()) fs::remove_all(scratch, ignored);
    }
};

}  // namespace

int run_view(const ViewOptions& options) {
    Site site;
    site.quiet = options.common.quiet;
    site.root = options.viewer_root.empty() ? fs::path(ANIMORDER_SOURCE_DIR) : fs::path(options.viewer_root);
    if (!fs::is_regular_file(site.root / "viewer" / "index.html"))
        throw std::runtime_error("the viewer is not at " + (site.root / "viewer").string() + " (give --viewer-root)");
    if (!fs::is_regular_file(site.root / "viewer" / "node_modules" / "three" / "build" / "three.module.js"))
        throw std::runtime_error("three.js is not installed in " + (site.root / "viewer" / "node_modules").string() +
                                 " (run scripts/install-deps.sh)");
    // The port first: one that is taken is refused before any work.
    Resources held;
    held.server = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    if (held.server < 0) throw std::runtime_error("cannot open a socket");
    const int server = held.server;
    const int yes = 1;
    setsockopt(server, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);  // loopback only
    address.sin_port = htons(options.port);
    if (::bind(server, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 || ::listen(server, kBacklog) != 0)
        throw std::runtime_error("cannot listen on 127.0.0.1:" + std::to_string(options.port) + " (try --port 0)");

    std::error_code error;
    const fs::path temp = fs::temp_directory_path(error);
    if (!error) remove_stale_scratch_folders(temp);
    fs::path& scratch = held.scratch;
    if (options.common.input.empty()) {
        if (error) throw std::runtime_error("no folder for temporary files: " + error.message());
        // A new folder of its own, under a name nobody can plant a link or folder at in advance
        // (the temporary folder is shared; a container's PID is 1): mkdir fails on any existing name.
        std::random_device random;
        for (int attempt = 0;; ++attempt) {
            char suffix[20];
            std::snprintf(suffix, sizeof suffix, "-%08x%08x", random(), random());
            const fs::path candidate = temp / ("animorder-view-" + std::to_string(::getpid()) + suffix);
            if (::mkdir(candidate.c_str(), 0700) == 0) {
                scratch = candidate;
                break;
            }
            if (errno != EEXIST || attempt == 63)
                throw std::runtime_error("cannot create a scratch folder in " + temp.string() + ": " +
                                         std::strerror(errno));
        }
        if (!options.common.quiet) std::fprintf(stderr, "view: optimising the bundled character (about 25 s)\n");
        make_bundled(scratch, options.common.quiet);
        site.model = scratch / "character.glb";
        site.original = scratch / "char.glb";
    } else {
        site.model = options.common.input;
        if (!fs::is_regular_file(site.model)) throw std::runtime_error("cannot read " + site.model.string());
    }
    if (!options.original.empty()) {
        site.original = options.original;
        if (!fs::is_regular_file(site.original)) throw std::runtime_error("cannot read " + site.original.string());
    }
    // The external files the two name, from below their folders only.
    std::vector<fs::path> roots;
    for (const fs::path* file : {&site.model, &site.original}) {
        std::error_code ec;
        const fs::path root = file->empty() ? fs::path() : fs::canonical(fs::absolute(*file).parent_path(), ec);
        if (!root.empty() && !ec) roots.push_back(root);  // never an empty root: everything lies below it
    }
    site.model_url = serve_with_its_files(site, "/model/", site.model, roots, options.common.quiet);
    if (!site.original.empty())
        site.original_url = serve_with_its_files(site, "/original/", site.original, roots, options.common.quiet);

    socklen_t length = sizeof address;
    getsockname(server, reinterpret_cast<sockaddr*>(&address), &length);
    site.port = ntohs(address.sin_port);
    const std::string url = "http://127.0.0.1:" + std::to_string(site.port) + "/";
    std::printf("animorder view: serving %s on %s\n", site.model.string().c_str(), url.c_str());
    std::fflush(stdout);
    if (options.open) {
        const std::string command = "xdg-open '" + url + "' >/dev/null 2>&1 &";
        if (std::system(command.c_str()) != 0 && !options.common.quiet)
            std::fprintf(stderr, "view: could not start a browser; open %s\n", url.c_str());
    }
    const Clock::time_point end =
        options.seconds == 0 ? Clock::time_point::max() : Clock::now() + std::chrono::seconds(options.seconds);
    install_signal_handlers();
    Pool pool(site);  // after `held`: the workers are joined before the scratch folder goes
    for (Clock::time_point now = Clock::now(); !interrupted && now < end; now = Clock::now()) {
        // Wake up at least every kSlice to honour --seconds and signals (a signal ends poll at once).
        const auto slice = std::chrono::duration_cast<std::chrono::milliseconds>(
            std::min<Clock::duration>(kSlice, end - now) + std::chrono::microseconds(999));
        if (!pool.wait_for_idle(slice)) continue;  // every worker busy: new connections wait in the backlog
        pollfd ready{server, POLLIN, 0};
        if (::poll(&ready, 1, int(slice.count())) <= 0) continue;
        const int client = ::accept4(server, nullptr, nullptr, SOCK_CLOEXEC);
        if (client >= 0) pool.hand_over(client);
    }
    pool.stop();
    return 0;  // `held` closes the socket and removes the scratch folder
}

}  // namespace animorder::tool
