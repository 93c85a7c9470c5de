// The HTTP request head that `animorder view` reads, parsed without any input or output (so that
// fuzz/fuzz_http_request.cpp can call it on any bytes), the check of its Host header and the
// escaping of what view's log lines quote from a request.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>

namespace animorder::tool {

// The longest request head (request line, headers and the blank line) view reads.
constexpr size_t kMaxRequestHead = 8192;

enum class HttpParse {
    complete,    // a whole head: the request's fields are set
    incomplete,  // no blank line yet in fewer than kMaxRequestHead bytes: read more
    bad,         // not an HTTP/1.0 or HTTP/1.1 request head (answer 400)
    too_large,   // no blank line within the first kMaxRequestHead bytes (answer 431)
};

struct HttpRequest {
    std::string method;     // as sent (a token: "GET", "HEAD", "POST", ...)
    std::string target;     // the request target as sent, its query ("?..." on) dropped
    int minor_version = 1;  // HTTP/1.0 or HTTP/1.1
    bool has_host = false;  // a Host header was sent (always, for HTTP/1.1: one without it is bad)
    std::string host;       // its value, without the spaces and tabs around it
};

// `bytes` (what a client sent so far) as a request head: the request line "METHOD SP TARGET SP
// HTTP/1.x" and header lines "Name: value", each ended by CRLF, then an empty line; whatever follows
// it is ignored. Bad: any other shape, a bare CR or LF, NUL anywhere, a folded header line, a header
// name that is not a token, two Host headers, or an HTTP/1.1 request without Host. The target may
// hold any other byte, control bytes and non-ASCII included (they name no file view serves, and
// its log escapes them). `request` is set only when the answer is `complete`.
HttpParse parse_http_request(std::string_view bytes, HttpRequest& request);

// Whether `host` (a Host header's value) names this server: 127.0.0.1, localhost or [::1] with its
// port (the name in any case; the port may be left out only when it is 80). Anything else is a
// name a page may have rebound to 127.0.0.1 (DNS rebinding), whose requests are refused.
bool host_is_loopback(std::string_view host, unsigned port);

// `text` for a log line: control bytes, non-ASCII bytes and backslashes written as \xNN.
std::string escape_for_log(std::string_view text);

}  // namespace animorder::tool
