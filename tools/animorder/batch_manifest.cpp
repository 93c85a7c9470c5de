// The manifest reader of `animorder batch`: a JSON manifest ({"items": [...]} or a list), a CSV
// one (RFC 4180 quoting, a header naming the columns), each item's options, and errors naming lines.
#include "batch_manifest.h"

#include "animorder/load.h"
#include "animorder/regular_file.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <string>
#include <unordered_set>
#include <vector>

namespace animorder::tool {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

// Items' relative paths are relative to the manifest's folder, so a manifest moves with its data.
std::string resolve(const fs::path& base, const std::string& path) {
    if (path.empty() || fs::path(path).is_absolute() || base.empty()) return path;
    return (base / path).string();
}

std::vector<std::string> split_words(const std::string& text) {
    std::vector<std::string> words;
    std::istringstream in(text);
    for (std::string w; in >> w;) words.push_back(w);
    return words;
}

}  // namespace

// A manifest or a report: a regular file of at most kMaxTextBytes (a FIFO or a device would never end).
constexpr uintmax_t kMaxTextBytes = uintmax_t(1) << 30;
std::string read_text(const std::string& path, const char* what) {
    RegularFile file(path);
    const std::string why = file.why();
    if (why == "a folder") throw std::runtime_error(path + ": is a folder, not " + what);
    if (!file.ok())
        throw std::runtime_error(path + (why == "missing" ? ": does not exist" : ": is " + why) + " (expected " + what +
                                 ")");
    if (file.size() > kMaxTextBytes) throw std::runtime_error(path + ": larger than 1 GiB, too large for " + what);
    std::string text(size_t(file.size()), '\0');
    if (file.read(text.data(), text.size()) != text.size()) throw std::runtime_error(path + ": cannot read " + what);
    return text;
}

// Text that the JSON reports can hold: valid UTF-8 (a report names items and paths).
bool is_utf8(const std::string& text) {
    try {
        (void)json(text).dump();
        return true;
    } catch (const json::exception&) {
        return false;
    }
}

namespace {

// Valid UTF-8 without a NUL (JSON's \u0000, or one in a CSV field): a path or an option is used
// as a C string, which a NUL would cut short, so that another file than the one named is read.
void require_utf8(const std::string& text, const std::string& where) {
    if (!is_utf8(text)) throw std::runtime_error(where + " is not valid UTF-8 (the reports are JSON)");
    if (text.find('\0') != std::string::npos)
        throw std::runtime_error(where + " holds a NUL character, which no path or option may hold");
}

// "options" as a string of optimize arguments, a list of them, or an object {"lambda": 3, "joint": true}.
std::vector<std::string> options_from_json(const json& value, const std::string& where) {
    std::vector<std::string> out;
    if (value.is_null()) return out;
    if (value.is_string()) return split_words(value.get<std::string>());
    if (value.is_array()) {
        for (const json& v : value) {
            if (!v.is_string()) throw std::runtime_error(where + ": \"options\" list entries must be strings");
            out.push_back(v.get<std::string>());
        }
        return out;
    }
    if (value.is_object()) {
        for (auto it = value.begin(); it != value.end(); ++it) {
            if (it.key().empty() || it.key()[0] == '-')
                throw std::runtime_error(where + ": option name \"" + it.key() +
                                         "\" (an object's keys are option names without dashes: {\"lambda\": 3})");
            const std::string flag = (it.key().size() == 1 ? "-" : "--") + it.key();
            if (it.value().is_boolean()) {
                if (it.value().get<bool>()) out.push_back(flag);
            } else if (it.value().is_string()) {
                out.insert(out.end(), {flag, it.value().get<std::string>()});
            } else if (it.value().is_number_float() &&
                       std::nearbyint(it.value().get<double>()) == it.value().get<double>() &&
                       std::fabs(it.value().get<double>()) < 9e15) {  // 3.0 → "3", for integer options
                out.insert(out.end(), {flag, std::to_string(int64_t(it.value().get<double>()))});
            } else if (it.value().is_number()) {
                out.insert(out.end(), {flag, it.value().dump()});
            } else {
                throw std::runtime_error(where + ": option \"" + it.key() + "\" must be a string, number or boolean");
            }
        }
        return out;
    }
    throw std::runtime_error(where + ": \"options\" must be a string, a list or an object");
}

// The first key given twice in one object, found in a pass of its own over the text (the parser
// keeps the last of two equal keys). The parser's callback form found them too, but it was
// quadratic in the items: after each item it searched the list so far for discarded values.
class DuplicateKeys : public nlohmann::json_sax<json> {
public:
    std::string duplicate;

    bool null() override { return true; }
    bool boolean(bool) override { return true; }
    bool number_integer(number_integer_t) override { return true; }
    bool number_unsigned(number_unsigned_t) override { return true; }
    bool number_float(number_float_t, const string_t&) override { return true; }
    bool string(string_t&) override { return true; }
    bool binary(binary_t&) override { return true; }
    bool start_object(std::size_t) override {
        keys_.emplace_back();
        return true;
    }
    bool key(string_t& key) override {
        if (!keys_.empty() && !keys_.back().insert(key).second && duplicate.empty()) duplicate = key;
        return true;
    }
    bool end_object() override {
        if (!keys_.empty()) keys_.pop_back();
        return true;
    }
    bool start_array(std::size_t) override { return true; }
    bool end_array() override { return true; }
    bool parse_error(std::size_t, const std::string&, const json::exception&) override { return false; }

private:
    std::vector<std::unordered_set<std::string>> keys_;  // the keys of each object being parsed
};

std::vector<ManifestItem> parse_json_manifest(const std::string& text, const std::string& path) {
    json doc;
    try {
        doc = json::parse(text);
    } catch (const json::exception& e) {
        throw std::runtime_error(path + ": not valid JSON: " + e.what());
    }
    // A manifest that says one thing twice is refused.
    DuplicateKeys keys;
    json::sax_parse(text, &keys);
    const std::string& duplicate = keys.duplicate;
    if (!duplicate.empty())
        throw std::runtime_error(path + ": the key \"" + duplicate + "\" appears twice in one object");
    const json* list = &doc;
    if (doc.is_object()) {
        if (!doc.contains("items")) throw std::runtime_error(path + ": a JSON manifest needs an \"items\" list");
        for (auto it = doc.begin(); it != doc.end(); ++it)
            if (it.key() != "items")
                throw std::runtime_error(path + ": unknown key \"" + it.key() + "\" (a manifest holds only \"items\")");
        list = &doc["items"];
    }
    if (!list->is_array())
        throw std::runtime_error(path + (doc.is_object()
                                             ? ": \"items\" must be a list"
                                             : ": a JSON manifest is {\"items\": [...]} or a list of items"));
    std::vector<ManifestItem> items;
    for (size_t i = 0; i < list->size(); ++i) {
        const json& e = (*list)[i];
        const std::string where = path + ": item " + std::to_string(i + 1);
        if (!e.is_object()) throw std::runtime_error(where + ": must be an object");
        for (auto it = e.begin(); it != e.end(); ++it)
            if (it.key() != "name" && it.key() != "input" && it.key() != "clips" && it.key() != "method" &&
                it.key() != "options" && it.key() != "output")
                throw std::runtime_error(where + ": unknown key \"" + it.key() +
                                         "\" (known: name, input, clips, method, options, output)");
        auto text_of = [&](const char* key) -> std::string {
            if (!e.contains(key) || e[key].is_null()) return "";
            if (!e[key].is_string()) throw std::runtime_error(where + ": \"" + key + "\" must be a string");
            return e[key].get<std::string>();
        };
        ManifestItem item;
        item.name = text_of("name");
        item.input = text_of("input");
        item.input_given = e.contains("input") && !e["input"].is_null();
        item.method = text_of("method");
        item.output = text_of("output");
        if (e.contains("clips")) {
            const json& c = e["clips"];
            if (c.is_string())
                item.clips = {c.get<std::string>()};
            else if (c.is_array())
                for (const json& v : c) {
                    if (!v.is_string()) throw std::runtime_error(where + ": \"clips\" entries must be strings");
                    item.clips.push_back(v.get<std::string>());
                }
            else if (!c.is_null())
                throw std::runtime_error(where + ": \"clips\" must be a string or a list");
        }
        item.options = options_from_json(e.contains("options") ? e["options"] : json(), where);
        items.push_back(item);
    }
    return items;
}

// One CSV record (RFC 4180 quoting); `pos` moves past it and its line end. A quote opens a
// field (spaces or tabs may come before it and after its closing quote); anywhere else, as in
// out/a"b, it is an error, never dropped.
std::vector<std::string> csv_record(const std::string& text, size_t& pos, const std::string& where) {
    std::vector<std::string> fields(1);
    bool quoted = false, closed = false;  // in quotes; past a field's closing quote
    const auto blank = [](const std::string& s) { return s.find_first_not_of(" \t") == std::string::npos; };
    for (; pos < text.size(); ++pos) {
        const char c = text[pos];
        if (quoted) {
            if (c == '"' && pos + 1 < text.size() && text[pos + 1] == '"')
                fields.back() += '"', ++pos;
            else if (c == '"')
                quoted = false, closed = true;
            else
                fields.back() += c;
        } else if (c == ',') {
            fields.emplace_back();
            closed = false;
        } else if (c == '\n' || c == '\r') {
            if (c == '\r' && pos + 1 < text.size() && text[pos + 1] == '\n') ++pos;
            ++pos;
            return fields;
        } else if (closed && c != ' ' && c != '\t') {
            throw std::runtime_error(where + ": field " + std::to_string(fields.size()) +
                                     ": text after its closing quote (quote the whole field, a quote inside as \"\")");
        } else if (c == '"') {
            if (closed || !blank(fields.back()))
                throw std::runtime_error(where + ": field " + std::to_string(fields.size()) +
                                         ": a quote inside an unquoted field (quote the whole field, a quote inside "
                                         "as \"\")");
            fields.back().clear();
            quoted = true;
        } else if (!closed) {
            fields.back() += c;
        }
    }
    if (quoted) throw std::runtime_error(where + ": a quoted field is not closed");
    return fields;
}

void trim(std::string& text) {
    text.erase(0, text.find_first_not_of(" \t"));
    text.erase(text.find_last_not_of(" \t") + 1);
}

// Fields are trimmed of spaces and tabs; a UTF-8 byte order mark before the header is skipped.
std::vector<ManifestItem> parse_csv_manifest(const std::string& text, const std::string& path) {
    size_t pos = text.rfind("\xEF\xBB\xBF", 0) == 0 ? 3 : 0;
    std::vector<std::string> header = csv_record(text, pos, path + ": line 1");
    if (header.size() == 1 && split_words(header[0]).empty())
        throw std::runtime_error(path +
                                 ": line 1: no header line (columns: name, input, clips, method, options, output)");
    for (size_t i = 0; i < header.size(); ++i) {
        std::string& h = header[i];
        trim(h);
        if (h != "name" && h != "input" && h != "clips" && h != "method" && h != "options" && h != "output")
            throw std::runtime_error(path + ": line 1: unknown column \"" + h +
                                     "\" (known: name, input, clips, method, options, output)");
        if (std::find(header.begin(), header.begin() + long(i), h) != header.begin() + long(i))
            throw std::runtime_error(path + ": line 1: the column \"" + h + "\" appears twice");
    }
    std::vector<ManifestItem> items;
    size_t line = 1, counted = 0;  // the line a record starts on: line ends before pos (a quoted field may hold some)
    while (pos < text.size()) {
        for (; counted < pos; ++counted)
            line += text[counted] == '\n' ||
                    (text[counted] == '\r' && (counted + 1 == text.size() || text[counted + 1] != '\n'));
        const std::string where = path + ": line " + std::to_string(line);
        const std::vector<std::string> fields = csv_record(text, pos, where);
        // A blank line, or a row of empty fields (",,": spreadsheets export them), is no item.
        if (std::all_of(fields.begin(), fields.end(), [](const std::string& f) { return split_words(f).empty(); }))
            continue;
        if (fields.size() != header.size())
            throw std::runtime_error(where + ": " + std::to_string(fields.size()) + " fields, the header has " +
                                     std::to_string(header.size()));
        ManifestItem item;
        item.line = line;
        for (size_t f = 0; f < header.size(); ++f) {
            std::string v = fields[f];
            trim(v);
            if (header[f] == "name")
                item.name = v;
            else if (header[f] == "input")
                item.input = v, item.input_given = true;
            else if (header[f] == "method")
                item.method = v;
            else if (header[f] == "output")
                item.output = v;
            else if (header[f] == "options")
                item.options = split_words(v);
            else if (header[f] == "clips") {
                std::stringstream list(v);
                for (std::string c; std::getline(list, c, ';');) {
                    trim(c);
                    if (!c.empty()) item.clips.push_back(c);
                }
            }
        }
        items.push_back(item);
    }
    return items;
}

}  // namespace

std::vector<ManifestItem> read_manifest(const std::string& path) {
    const std::string text = read_text(path, "a manifest");
    // Text saved as UTF-16 ("Unicode text" in spreadsheets) is named as such, not parsed into
    // columns of stray bytes.
    if (text.rfind("\xFF\xFE", 0) == 0 || text.rfind("\xFE\xFF", 0) == 0)
        throw std::runtime_error(path + ": is UTF-16 text; save the manifest as UTF-8");
    if (text.find('\0') != std::string::npos)
        throw std::runtime_error(path + ": holds NUL bytes (UTF-16 text?); a manifest is UTF-8 text");
    const std::string ext = file_extension(path);
    std::vector<ManifestItem> items;
    if (ext == ".csv")
        items = parse_csv_manifest(text, path);
    else {
        const size_t first = text.find_first_not_of(" \t\r\n");
        if (ext != ".json" && (first == std::string::npos || (text[first] != '{' && text[first] != '[')))
            throw std::runtime_error(path + ": a manifest is .json or .csv");
        items = parse_json_manifest(text, path);
    }
    const fs::path base = fs::path(path).parent_path();
    for (size_t i = 0; i < items.size(); ++i) {
        ManifestItem& item = items[i];
        const std::string where =
            path + (item.line ? ": line " + std::to_string(item.line) : ": item " + std::to_string(i + 1));
        if (item.output.empty()) throw std::runtime_error(where + " has no \"output\"");
        if (item.input_given && item.input.find_first_not_of(" \t") == std::string::npos)
            throw std::runtime_error(where + ": the input is empty (leave \"input\" out for the bundled character)");
        require_utf8(item.output, where + ": the output");  // before the name, which defaults to it
        if (item.name.empty()) item.name = item.output;
        require_utf8(item.name, where + ": the name");
        require_utf8(item.input, where + ": the input");
        for (const std::string& c : item.clips) require_utf8(c, where + ": a clip");
        for (const std::string& o : item.options) require_utf8(o, where + ": an option");
        item.input_as_written = item.input;
        item.output_as_written = item.output;
        item.clips_as_written = item.clips;
        item.input = resolve(base, item.input);
        item.output = resolve(base, item.output);
        // A clip file or folder beside the manifest (or absolute), made absolute: optimize then
        // takes an absolute clip as a file and any other as a clip name, whatever the current folder.
        for (std::string& c : item.clips) {
            if (!item.input_given || carries_its_clips(item.input)) break;  // clip names only
            std::error_code error;
            const fs::path beside = fs::path(c).is_absolute() ? fs::path(c) : base / c;
            if (fs::exists(beside, error)) c = fs::absolute(beside, error).string();
        }
    }
    return items;
}

}  // namespace animorder::tool
