// The HTTP request head of `animorder view`, parsed from bytes (no sockets here), the Host check
// and the log's escaping: see http_request.h.
#include "http_request.h"

#include <algorithm>
#include <cstdio>
#include <string>
#include <utility>

namespace animorder::tool {
namespace {

// Whether `c` may be part of a method or a header name (RFC 9110's tchar).
bool is_token_char(char c) {
    if ((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9')) return true;
    return std::string_view("!#$%&'*+-.^_`|~").find(c) != std::string_view::npos;
}

// Whether `text` is a non-empty token.
bool is_token(std::string_view text) { return !text.empty() && std::all_of(text.begin(), text.end(), is_token_char); }

// `text` in lower case (ASCII letters only).
std::string lower(std::string_view text) {
    std::string out(text);
    for (char& c : out)
        if (c >= 'A' && c <= 'Z') c = char(c - 'A' + 'a');
    return out;
}

// `text` without the spaces and tabs at either end.
std::string_view trim(std::string_view text) {
    while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
    while (!text.empty() && (text.back() == ' ' || text.back() == '\t')) text.remove_suffix(1);
    return text;
}

// The request line "METHOD SP TARGET SP HTTP/1.x" into `request`; false when it is not one.
bool parse_request_line(std::string_view line, HttpRequest& request) {
    const size_t a = line.find(' ');
    if (a == std::string_view::npos) return false;
    const size_t b = line.find(' ', a + 1);
    if (b == std::string_view::npos || line.find(' ', b + 1) != std::string_view::npos) return false;
    const std::string_view method = line.substr(0, a), target = line.substr(a + 1, b - a - 1),
                           version = line.substr(b + 1);
    if (!is_token(method) || target.empty()) return false;
    if (version == "HTTP/1.1")
        request.minor_version = 1;
    else if (version == "HTTP/1.0")
        request.minor_version = 0;
    else
        return false;
    request.method = std::string(method);
    request.target = std::string(target.substr(0, target.find('?')));
    return true;
}

}  // namespace

HttpParse parse_http_request(std::string_view bytes, HttpRequest& request) {
    const size_t end = bytes.find("\r\n\r\n");
    if (end == std::string_view::npos)
        return bytes.size() >= kMaxRequestHead ? HttpParse::too_large : HttpParse::incomplete;
    if (end + 4 > kMaxRequestHead) return HttpParse::too_large;
    const std::string_view head = bytes.substr(0, end + 2);  // each line with its CRLF
    // No NUL anywhere, and CR and LF only as the CRLF that ends a line.
    for (size_t i = 0; i < head.size(); ++i) {
        const char c = head[i];
        if (c == '\0') return HttpParse::bad;
        if (c == '\r' && (i + 1 == head.size() || head[i + 1] != '\n')) return HttpParse::bad;
        if (c == '\n' && (i == 0 || head[i - 1] != '\r')) return HttpParse::bad;
    }
    HttpRequest parsed;
    size_t at = head.find("\r\n");
    if (!parse_request_line(head.substr(0, at), parsed)) return HttpParse::bad;
    at += 2;
    while (at < head.size()) {
        const size_t line_end = head.find("\r\n", at);
        const std::string_view line = head.substr(at, line_end - at);
        at = line_end + 2;
        const size_t colon = line.find(':');
        // A folded line (one that starts with a space or tab) has no token before its colon either.
        if (colon == std::string_view::npos || !is_token(line.substr(0, colon))) return HttpParse::bad;
        if (lower(line.substr(0, colon)) != "host") continue;
        if (parsed.has_host) return HttpParse::bad;  // two Host headers
        parsed.has_host = true;
        parsed.host = std::string(trim(line.substr(colon + 1)));
    }
    if (parsed.minor_version == 1 && !parsed.has_host) return HttpParse::bad;  // RFC 9112, 3.2
    request = std::move(parsed);
    return HttpParse::complete;
}

bool host_is_loopback(std::string_view host, unsigned port) {
    const std::string name = lower(host), suffix = ":" + std::to_string(port);
    for (const char* loopback : {"127.0.0.1", "localhost", "[::1]"}) {
        if (name == loopback + suffix) return true;
        if (port == 80 && name == loopback) return true;
    }
    return false;
}

std::string escape_for_log(std::string_view text) {
    std::string out;
    out.reserve(text.size());
    for (const char c : text) {
        const unsigned char u = static_cast<unsigned char>(c);
        if (u < 0x20 || u >= 0x7f || c == '\\') {
            char code[5];
            std::snprintf(code, sizeof code, "\\x%02x", u);
            out += code;
        } else {
            out += c;
        }
    }
    return out;
}

}  // namespace animorder::tool
