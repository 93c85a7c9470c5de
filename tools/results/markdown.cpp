// Markdown and number formatting for RESULTS.md (markdown.h); numbers through format_fixed
// (svg_chart.h), so tables and charts round alike.
#include "markdown.h"

#include <cctype>
#include <cmath>

#include "svg_chart.h"

namespace animorder::results {

const char* const kDash = "—";

std::string f3(double v) { return std::isfinite(v) ? format_fixed(v, 3) : kDash; }
std::string f1(double v) { return std::isfinite(v) ? format_fixed(v, 1) : kDash; }
std::string count(long long v) { return v >= 0 ? std::to_string(v) : kDash; }

std::string lambda_text(double v) {
    if (!std::isfinite(v)) return kDash;
    for (int d = 0; d < 4; ++d) {
        const double scaled = v * std::pow(10.0, d);
        if (std::fabs(scaled - std::round(scaled)) < 1e-6) return format_fixed(v, d);
    }
    return format_fixed(v, 4);
}

bool same_lambda(double a, double b) { return std::isfinite(a) && std::isfinite(b) && std::fabs(a - b) < 1e-9; }

namespace {

std::string row(const std::vector<std::string>& cells) {
    std::string s = "|";
    for (const std::string& c : cells) s += " " + c + " |";
    return s + "\n";
}

}  // namespace

std::string table(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows,
                  size_t text_columns) {
    std::string s = row(header) + "|";
    for (size_t i = 0; i < header.size(); ++i) s += i < text_columns ? "---|" : "---:|";
    s += "\n";
    for (const auto& r : rows) s += row(r);
    return s;
}

std::string slug(const std::string& heading) {
    std::string s;
    for (unsigned char c : heading) {
        if (std::isalnum(c) || c == '-' || c == '_')
            s += char(std::tolower(c));
        else if (c == ' ')
            s += '-';
    }
    return s;
}

std::string not_run(const std::string& file) { return "not run: " + file + " missing\n"; }

std::string code_block(const std::string& text) {
    const std::string fence = text.find("```") == std::string::npos ? "```" : "~~~~";
    return fence + "text\n" + text + (text.empty() || text.back() == '\n' ? "" : "\n") + fence + "\n";
}

std::string trimmed(std::string text) {
    while (!text.empty() && (text.back() == '\n' || text.back() == ' ' || text.back() == '\r')) text.pop_back();
    return text;
}

}  // namespace animorder::results
