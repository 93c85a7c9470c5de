// libFuzzer target: any bytes → parse_http_request (the request head `animorder view` reads;
// tools/animorder/http_request.cpp, compiled in) → the Host check and the log's escaping of what
// it parsed. Aborts when an answer breaks what http_request.h promises: a complete head has a
// token method, a target without space, CR, LF, NUL or '?', HTTP/1.0 or 1.1, a Host for 1.1, and
// the same answer with more bytes after it; incomplete means no blank line in fewer than
// kMaxRequestHead bytes; the escaped text is printable ASCII only.
#include "http_request.h"

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <string_view>

namespace {

void check(bool ok, const char* what) {
    if (!ok) {
        std::fprintf(stderr, "fuzz_http_request: %s\n", what);
        std::abort();
    }
}

// Whether `text` is printable ASCII only (what a log line may hold).
bool printable(const std::string& text) {
    for (const char c : text)
        if (c < 0x20 || c > 0x7e) return false;
    return true;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    using animorder::tool::HttpParse;
    using animorder::tool::HttpRequest;
    const std::string bytes(reinterpret_cast<const char*>(data), size);
    HttpRequest request;
    const HttpParse parsed = animorder::tool::parse_http_request(bytes, request);
    const size_t end = bytes.find("\r\n\r\n");
    if (parsed == HttpParse::incomplete)
        check(end == std::string::npos && size < animorder::tool::kMaxRequestHead, "incomplete, yet a whole head");
    if (parsed == HttpParse::too_large)
        check(size >= animorder::tool::kMaxRequestHead, "too large, yet shorter than the limit");
    if (parsed != HttpParse::complete) return 0;

    check(end != std::string::npos && end + 4 <= animorder::tool::kMaxRequestHead, "complete without a blank line");
    check(!request.method.empty(), "an empty method");
    check(request.target.find_first_of(std::string(" \r\n?\0", 5)) == std::string::npos,
          "space, CR, LF, '?' or NUL in the target");
    check(request.host.find_first_of(std::string("\r\n\0", 3)) == std::string::npos, "CR, LF or NUL in the Host");
    check(request.minor_version == 0 || request.minor_version == 1, "a version other than HTTP/1.0 or 1.1");
    check(request.minor_version == 0 || request.has_host, "HTTP/1.1 without Host");
    HttpRequest again;
    check(animorder::tool::parse_http_request(bytes + "GET / HTTP/1.1\r\n\r\n", again) == HttpParse::complete &&
              again.method == request.method && again.target == request.target && again.host == request.host,
          "another answer with more bytes after the head");

    check(printable(animorder::tool::escape_for_log(request.target)), "an escaped target that is not printable");
    check(printable(animorder::tool::escape_for_log(request.host)), "an escaped Host that is not printable");
    const unsigned port = size >= 2 ? unsigned(data[0]) << 8 | data[1] : 8417;
    if (animorder::tool::host_is_loopback(request.host, port))
        check(request.host.find(':') != std::string::npos || port == 80, "a loopback Host without the port");
    return 0;
}
