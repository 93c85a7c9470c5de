// animorder view [FILE] — serves the viewer page (viewer/, with js/ and three.js from
// viewer/node_modules) and FILE as /model.glb on 127.0.0.1 only, prints the address and opens it
// in the default browser. Without FILE it first optimises the bundled character (subdivide
// --levels 0, then optimize --method single) into a temporary folder, and serves the un-optimised
// file too (/original.glb) so the page can compare the original order with the optimised ones.
// The server is deliberately tiny: GET and HEAD, one request per connection, requests up to 8 KiB
// read with a 5 s timeout, files only below the viewer's folders (no "..", no "%", no links out),
// nothing but loopback.
#include "commands.h"

#include "animorder/atomic_write.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>

namespace fs = std::filesystem;

namespace animorder::tool {
namespace {

volatile std::sig_atomic_t interrupted = 0;  // Ctrl-C / SIGTERM: stop serving, remove the scratch folder
void on_signal(int) { interrupted = 1; }

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

void send_all(int fd, const std::string& bytes) {
    size_t sent = 0;
    while (sent < bytes.size()) {
        const ssize_t n = ::send(fd, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
        if (n <= 0) return;  // the browser went away: nothing to do
        sent += size_t(n);
    }
}

void respond(int fd, int code, const std::string& status, const std::string& type, const std::string& body, bool head,
             const std::string& extra = "") {
    std::string header = "HTTP/1.1 " + std::to_string(code) + " " + status + "\r\nContent-Type: " + type +
                         "\r\nContent-Length: " + std::to_string(body.size()) +
                         "\r\nCache-Control: no-store\r\nConnection: close\r\n" + extra + "\r\n";
    send_all(fd, head ? header : header + body);
}

struct Site {
    fs::path root;      // the folder holding viewer/ and js/
    fs::path model;     // served as /model.glb
    fs::path original;  // served as /original.glb (may be empty)
};

// The file a URL path names, or empty when it names none we serve.
fs::path resolve(const Site& site, const std::string& url) {
    if (url == "/model.glb") return site.model;
    if (url == "/original.glb") return site.original;
    if (url.find("..") != std::string::npos || url.find('%') != std::string::npos ||
        url.find('\\') != std::string::npos)
        return {};
    for (const char* prefix : {"/viewer/", "/js/"}) {
        if (url.rfind(prefix, 0) != 0) continue;
        fs::path path = site.root / url.substr(1);
        if (!url.empty() && url.back() == '/') path /= "index.html";
        std::error_code ec;
        const fs::path real = fs::canonical(path, ec);
        const fs::path base =
            fs::canonical(site.root / std::string(prefix).substr(1, std::string(prefix).size() - 2), ec);
        if (ec || !fs::is_regular_file(real)) return {};
        // The real path must stay below its folder (a link inside the viewer may not lead out of it),
        // except for viewer/node_modules, which npm may link.
        const std::string r = real.string(), b = base.string() + "/";
        if (r.rfind(b, 0) != 0 && url.rfind("/viewer/node_modules/", 0) != 0) return {};
        return real;
    }
    return {};
}

void serve_one(int fd, const Site& site, bool quiet) {
    timeval timeout{5, 0};
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
    std::string request;
    char buffer[2048];
    while (request.find("\r\n\r\n") == std::string::npos && request.size() < 8192) {
        const ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
        if (n <= 0) return;
        request.append(buffer, size_t(n));
    }
    const size_t line_end = request.find("\r\n");
    const std::string line = request.substr(0, line_end);
    const size_t a = line.find(' '), b = line.find(' ', a + 1);
    if (line_end == std::string::npos || a == std::string::npos || b == std::string::npos) {
        respond(fd, 400, "Bad Request", "text/plain", "bad request\n", false);
        return;
    }
    const std::string method = line.substr(0, a);
    std::string url = line.substr(a + 1, b - a - 1);
    url = url.substr(0, url.find('?'));
    const bool head = method == "HEAD";
    if (method != "GET" && !head) {
        respond(fd, 405, "Method Not Allowed", "text/plain", "GET or HEAD only\n", false);
        return;
    }
    if (url == "/") {
        respond(fd, 302, "Found", "text/plain", "", head,
                "Location: /viewer/?file=/model.glb" +
                    std::string(site.original.empty() ? "" : "&original=/original.glb") + "\r\n");
        return;
    }
    const fs::path path = resolve(site, url);
    std::ifstream in(path, std::ios::binary);
    if (path.empty() || !in) {
        if (!quiet) std::fprintf(stderr, "view: 404 %s\n", url.c_str());
        respond(fd, 404, "Not Found", "text/plain", "not found\n", head);
        return;
    }
    const std::string body((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    respond(fd, 200, "OK", content_type(path), body, head);
}

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
    o.method = "single";
    o.output = (dir / "character.glb").string();
    if (run_optimize(o) != 0) throw std::runtime_error("could not optimise the bundled character");
}

// The scratch folders of earlier `view` runs whose process is gone (killed while optimising the
// bundled character, before it could remove its folder): removed.
void remove_stale_scratch_folders(const fs::path& temp) {
    const std::string prefix = "animorder-view-";
    std::error_code error;
    for (auto it = fs::directory_iterator(temp, error); !error && it != fs::directory_iterator(); it.increment(error)) {
        const std::string name = it->path().filename().string(),
                          pid = name.substr(std::min(name.size(), prefix.size()));
        if (name.rfind(prefix, 0) != 0 || pid.empty() || pid.size() > 9 ||
            !std::all_of(pid.begin(), pid.end(), [](char c) { return c >= '0' && c <= '9'; }) ||
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
    site.root = options.viewer_root.empty() ? fs::path(ANIMORDER_SOURCE_DIR) : fs::path(options.viewer_root);
    if (!fs::is_regular_file(site.root / "viewer" / "index.html"))
        throw std::runtime_error("the viewer is not at " + (site.root / "viewer").string() + " (give --viewer-root)");
    if (!fs::is_regular_file(site.root / "viewer" / "node_modules" / "three" / "build" / "three.module.js"))
        throw std::runtime_error("three.js is not installed in " + (site.root / "viewer" / "node_modules").string() +
                                 " (run scripts/install-deps.sh)");
    // The port first: one that is taken is refused before any work.
    Resources held;
    held.server = ::socket(AF_INET, SOCK_STREAM, 0);
    if (held.server < 0) throw std::runtime_error("cannot open a socket");
    const int server = held.server;
    const int yes = 1;
    setsockopt(server, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);  // loopback only
    address.sin_port = htons(options.port);
    if (::bind(server, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 || ::listen(server, 16) != 0)
        throw std::runtime_error("cannot listen on 127.0.0.1:" + std::to_string(options.port) + " (try --port 0)");

    std::error_code error;
    const fs::path temp = fs::temp_directory_path(error);
    if (!error) remove_stale_scratch_folders(temp);
    fs::path& scratch = held.scratch;
    if (options.common.input.empty()) {
        if (error) throw std::runtime_error("no folder for temporary files: " + error.message());
        scratch = temp / ("animorder-view-" + std::to_string(::getpid()));
        fs::create_directories(scratch);
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

    socklen_t length = sizeof address;
    getsockname(server, reinterpret_cast<sockaddr*>(&address), &length);
    const std::string url = "http://127.0.0.1:" + std::to_string(ntohs(address.sin_port)) + "/";
    std::printf("animorder view: serving %s on %s\n", site.model.string().c_str(), url.c_str());
    std::fflush(stdout);
    if (options.open) {
        const std::string command = "xdg-open '" + url + "' >/dev/null 2>&1 &";
        if (std::system(command.c_str()) != 0 && !options.common.quiet)
            std::fprintf(stderr, "view: could not start a browser; open %s\n", url.c_str());
    }
    const auto start = std::chrono::steady_clock::now();
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    while (!interrupted &&
           (options.seconds == 0 || std::chrono::steady_clock::now() - start < std::chrono::seconds(options.seconds))) {
        timeval wait{1, 0};  // wake up now and then to honour --seconds and signals
        fd_set ready;
        FD_ZERO(&ready);
        FD_SET(server, &ready);
        if (::select(server + 1, &ready, nullptr, nullptr, &wait) <= 0) continue;
        const int client = ::accept(server, nullptr, nullptr);
        if (client < 0) continue;
        serve_one(client, site, options.common.quiet);
        ::close(client);
    }
    return 0;  // `held` closes the socket and removes the scratch folder
}

}  // namespace animorder::tool
