// `animorder batch MANIFEST`: a library of characters through optimize, as a farm runs it.
//
// Each item of the manifest is one optimize run (the same library call as `animorder optimize`,
// optimize.h) whose files — glTF, sidecar, sidecar description and the item report
// OUT.animorder.report.json — appear together or not at all (OutputSet). The item report holds
// the item's stamp: a SHA-256 (nettle) of the tool version, the item's resolved options, its paths
// as the manifest writes them and the bytes of every file it reads as known before loading, plus
// the side files the importer opened (an OBJ's .mtl), each with its digest. An item whose report
// carries the stamp it would have now, with its side files unchanged and every output present,
// is up to date and skipped (`--dry-run` says which items would run and why: the report keeps the
// stamp's parts); so a run killed at any moment and started
// again redoes only the items it had not finished, and a changed option or input re-runs only the
// items it affects. A failing item leaves OUT.animorder.error.json (its stamp and the error) and
// the batch goes on. `--shard I/N` runs items i with i % N == I (and reads their files only);
// the summary (SUMMARY.json and SUMMARY.md) is always merged from the items' files in manifest
// order, so it is the same whichever process ran which item.
#include "commands.h"
#include "input.h"
#include "optimize.h"
#include "report.h"

#include "animorder/atomic_write.h"
#include "animorder/evaluation.h"
#include "animorder/load.h"
#include "animorder/regular_file.h"

#include <nettle/sha2.h>
#include <signal.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace animorder::tool {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;
using Clock = std::chrono::steady_clock;

// Exit codes beyond 0 (all done) and 1 (an error before any work).
constexpr int kExitItemsFailed = 3;       // at least one item failed (each has its error line)
constexpr int kExitItemsMissing = 4;      // merge: some items have no up-to-date result yet
constexpr int kExitFailedAndMissing = 5;  // merge: both (a farm learns of unfinished shards either way)
constexpr int kExitNoSummary = 6;         // the items ran (or were merged) but the summary could not be written

// ---------------------------------------------------------------------------------------------
// The manifest

struct ManifestItem {
    std::string name;                // for the summary: "name", else the output
    std::string input;               // resolved against the manifest's folder; empty: the bundled character
    std::vector<std::string> clips;  // names, or clip files/folders (resolved when they exist)
    std::string method;              // empty: optimize's default
    std::vector<std::string> options;
    std::string output;  // resolved against the manifest's folder
    // The paths as the manifest writes them: what the stamp hashes, so that it does not depend on
    // how the manifest's own path was spelled, nor on the current folder.
    std::string input_as_written, output_as_written;
    std::vector<std::string> clips_as_written;
    bool input_given = false;  // an "input" key or column: then it may not be blank
    size_t line = 0;           // a CSV manifest's line, which its errors name (0: a JSON item)
};

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

std::vector<ManifestItem> parse_json_manifest(const std::string& text, const std::string& path) {
    json doc;
    // The parser keeps the last of two equal keys; a manifest that says one thing twice is refused.
    std::vector<std::unordered_set<std::string>> keys;  // the keys of each object being parsed
    std::string duplicate;
    const json::parser_callback_t no_duplicate_keys = [&](int, json::parse_event_t event, json& parsed) {
        if (event == json::parse_event_t::object_start) keys.emplace_back();
        if (event == json::parse_event_t::object_end && !keys.empty()) keys.pop_back();
        if (event == json::parse_event_t::key && !keys.empty()) {
            std::string key = parsed.get<std::string>();
            if (!keys.back().insert(key).second && duplicate.empty()) duplicate = std::move(key);
        }
        return true;
    };
    try {
        doc = json::parse(text, no_duplicate_keys);
    } catch (const json::exception& e) {
        throw std::runtime_error(path + ": not valid JSON: " + e.what());
    }
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

// ---------------------------------------------------------------------------------------------
// Items as optimize runs, and their stamps

struct PlannedItem {
    ManifestItem item;
    OptimizeOptions options;
    OptimizePlan plan;
    std::string report, error;  // OUT.animorder.report.json, OUT.animorder.error.json
};

std::string stem_of(const std::string& output) {
    const std::string ext = file_extension(output);
    return ext == ".glb" || ext == ".gltf" ? output.substr(0, output.size() - ext.size()) : output;
}

// An option that names an output, which batch names itself: -o, -r, --output, --report, also
// glued to its value (-oOUT) or after flags in one word (-qrOUT).
bool names_an_output(const std::string& o) {
    if (o.rfind("--output", 0) == 0 || o.rfind("--report", 0) == 0) return true;
    if (o.size() < 2 || o[0] != '-' || o[1] == '-') return false;
    const size_t first = o.find_first_not_of("qh", 1);  // optimize's short flags that take no value
    return first != std::string::npos && (o[first] == 'o' || o[first] == 'r');
}

PlannedItem plan_item(const ManifestItem& item, size_t index, const BatchOptions& batch, const ItemParser& parse) {
    PlannedItem p;
    p.item = item;
    const std::string label = (item.line ? "line " + std::to_string(item.line) : "item " + std::to_string(index + 1)) +
                              " (" + item.name + ")";
    // The item's own fields first, its options last (so an option missing its value says so).
    std::vector<std::string> args = {"-o", item.output};
    if (!item.input.empty()) args.push_back(item.input);
    for (const std::string& c : item.clips) args.insert(args.end(), {"--clip", c});
    if (!item.method.empty()) args.insert(args.end(), {"--method", item.method});
    for (const std::string& o : item.options) {
        if (names_an_output(o))
            throw std::runtime_error(label + ": option " + o + ": batch names the outputs (use the item's \"output\")");
        if (o == "--clip" || o.rfind("--clip=", 0) == 0)
            throw std::runtime_error(label + ": option " + o +
                                     ": use the item's \"clips\" (resolved against the manifest's folder)");
        if (o == "--threads" || o.rfind("--threads=", 0) == 0)
            throw std::runtime_error(label + ": option " + o +
                                     ": threads are the batch's (animorder batch --threads N)");
        args.push_back(o);
    }
    try {
        p.options = parse(args);
        if (p.options.common.input != item.input)
            throw std::runtime_error("the options name a file (" + p.options.common.input +
                                     "): give it as the item's \"input\" (resolved against the manifest's folder)");
        p.options.common.clip_files_absolute = true;
        if (batch.quiet) p.options.common.quiet = true;
        p.options.methods.settings.clustering.threads = batch.threads;
        p.options.report_path = stem_of(item.output) + ".animorder.report.json";
        p.plan = plan_optimize(p.options);
    } catch (const std::exception& e) {
        throw std::runtime_error(label + ": " + e.what());
    }
    p.report = p.options.report_path;
    p.error = stem_of(item.output) + ".animorder.error.json";
    return p;
}

class Sha256 {
public:
    Sha256() { sha256_init(&ctx_); }
    void add(const std::string& text) {
        const uint64_t n = text.size();  // length-prefixed, so concatenations cannot collide
        sha256_update(&ctx_, sizeof n, reinterpret_cast<const uint8_t*>(&n));
        sha256_update(&ctx_, text.size(), reinterpret_cast<const uint8_t*>(text.data()));
    }
    // A file's name and bytes (never its folder: a library moved whole keeps its stamps). A path
    // that is no regular file (missing, a folder, a FIFO or a device, which would never end:
    // checked on the open file) hashes as that: the item then fails to load it.
    void add_file(const fs::path& path) {
        add("file:" + path.filename().string());
        RegularFile file(path.string());  // never opens a FIFO or a device (some act on open)
        if (!file.ok()) return add(std::string(file.why()) == "a folder" ? "not a regular file" : file.why());
        std::vector<uint8_t> block(1 << 16);
        uint64_t total = 0;
        for (size_t got; (got = file.read(block.data(), block.size())) > 0; total += got)
            sha256_update(&ctx_, got, block.data());
        add("bytes:" + std::to_string(total));
    }
    // What add_file adds for a file of this name holding `data`, from the bytes in memory.
    void add_data(const fs::path& path, const std::string& data) {
        add("file:" + path.filename().string());
        sha256_update(&ctx_, data.size(), reinterpret_cast<const uint8_t*>(data.data()));
        add("bytes:" + std::to_string(data.size()));
    }
    std::string hex() {
        uint8_t digest[SHA256_DIGEST_SIZE];
        sha256_digest(&ctx_, sizeof digest, digest);
        static const char* digits = "0123456789abcdef";
        std::string out;
        for (uint8_t b : digest) out += {digits[b >> 4], digits[b & 15]};
        return out;
    }

private:
    sha256_ctx ctx_;
};

// The tool: its version and the bytes of its executable, since a rebuild that changes the outputs
// may keep the version string.
const std::string& tool_digest() {
    static const std::string tool = [] {
        Sha256 hash;
        hash.add(ANIMORDER_VERSION);
        std::error_code error;
        const fs::path executable = fs::read_symlink("/proc/self/exe", error);
        if (error)
            hash.add("executable unknown");
        else
            hash.add_file(executable);
        return hash.hex();
    }();
    return tool;
}

json read_json_file(const std::string& path) {
    std::error_code error;
    if (!fs::is_regular_file(path, error)) return json();
    try {
        return json::parse(read_text(path, "a report"));
    } catch (const std::exception&) {
        return json();  // unreadable: as if absent
    }
}

// object[key] when it is a string, else "" (a report edited by hand is stale, never an error).
std::string string_at(const json& object, const char* key) {
    if (!object.is_object()) return "";
    const auto it = object.find(key);
    return it != object.end() && it->is_string() ? it->get<std::string>() : "";
}

// A file's name and bytes, hashed.
std::string file_digest(const fs::path& path) {
    Sha256 hash;
    hash.add_file(path);
    return hash.hex();
}

fs::path folder_of(const std::string& path) {
    const fs::path p(path);
    return p.has_parent_path() ? p.parent_path() : fs::path(".");
}

// A side file's path from the report's folder, as the report keeps it: "file" when it is UTF-8,
// else "file_bytes" with every byte outside printable ASCII (and '%') as %XY, so that it reads
// back as the same bytes (a JSON string cannot hold them).
json side_file_name(const std::string& path) {
    if (is_utf8(path)) return {{"file", path}};
    std::string escaped;
    static const char* digits = "0123456789ABCDEF";
    for (const unsigned char c : path)
        if (c < 0x20 || c >= 0x7f || c == '%')
            escaped += {'%', digits[c >> 4], digits[c & 15]};
        else
            escaped += char(c);
    return {{"file_bytes", escaped}};
}

std::string side_file_path(const json& entry) {
    const std::string file = string_at(entry, "file");
    if (!file.empty()) return file;
    const std::string escaped = string_at(entry, "file_bytes");
    std::string out;
    for (size_t i = 0; i < escaped.size(); ++i) {
        if (escaped[i] == '%' && i + 2 < escaped.size() && std::isxdigit(uint8_t(escaped[i + 1])) &&
            std::isxdigit(uint8_t(escaped[i + 2]))) {
            out += char(std::stoi(escaped.substr(i + 1, 2), nullptr, 16));
            i += 2;
        } else {
            out += escaped[i];
        }
    }
    return out;
}

// A file's path from the item report's folder, as the report names the files the item read.
std::string from_report_folder(const PlannedItem& p, const std::string& file) {
    std::error_code error;
    // Both absolute first: relative() leaves a relative path whose folders are all missing as
    // it is, and the result was empty (the absolute path was kept, tying the report to a place).
    fs::path from_report = fs::relative(fs::absolute(file, error), fs::absolute(folder_of(p.report), error), error);
    if (error || from_report.empty()) from_report = fs::absolute(file, error);
    return from_report.generic_string();
}

// The stamp of an item: everything its outputs depend on (not --threads, which changes nothing),
// in parts, each a digest: the tool (version and executable), the settings, the manifest's
// spellings of its paths, the batch's evaluation, and the bytes of every file it reads as far as
// known before loading (OptimizePlan::inputs: the character, a glTF's external buffers and images,
// clip files, the files of clip folders). The report keeps the parts too ("stamp_parts"), so that
// an item that is not up to date can say which of them changed.
struct StampParts {
    std::string settings, paths, eval;
    std::vector<std::pair<std::string, std::string>> inputs;  // (file as named, digest)
};

StampParts stamp_parts(const PlannedItem& p, const BatchOptions& batch) {
    StampParts parts;
    Sha256 settings;
    settings.add(optimize_settings_json(p.options, p.plan, false).dump());
    settings.add("max_memory:" + std::to_string(p.options.common.max_memory));
    parts.settings = settings.hex();
    Sha256 paths;
    paths.add("input:" + p.item.input_as_written);
    paths.add("output:" + p.item.output_as_written);
    for (const std::string& c : p.item.clips_as_written) paths.add("clip:" + c);
    parts.paths = paths.hex();
    parts.eval = std::to_string(batch.eval_views) + "/" + std::to_string(batch.eval_resolution) +
                 (batch.no_timings ? "/no-timings" : "");
    for (const std::string& file : p.plan.inputs) {
        Sha256 bytes;
        bytes.add_file(file);
        parts.inputs.emplace_back(from_report_folder(p, file), bytes.hex());
    }
    return parts;
}

std::string item_stamp(const StampParts& parts) {
    Sha256 hash;
    hash.add("animorder batch stamp 4");
    hash.add(tool_digest());
    hash.add(parts.settings);
    hash.add(parts.paths);
    hash.add("eval:" + parts.eval);
    for (const auto& [file, digest] : parts.inputs) hash.add(digest);
    return hash.hex();
}

// An item's stamp as taken now: its parts (which name what changed, when it did) and the digest.
struct Stamp {
    StampParts parts;
    std::string digest;
};

Stamp stamp_of(const PlannedItem& p, const BatchOptions& batch) {
    Stamp stamp{stamp_parts(p, batch), {}};
    stamp.digest = item_stamp(stamp.parts);
    return stamp;
}

json stamp_parts_json(const StampParts& parts) {
    json inputs = json::array();
    for (const auto& [file, digest] : parts.inputs) {
        json entry = side_file_name(file);
        entry["sha256"] = digest;
        inputs.push_back(entry);
    }
    return {{"settings", parts.settings}, {"paths", parts.paths}, {"eval", parts.eval}, {"inputs", inputs}};
}

// The files loading read beyond the stamp's (an OBJ's .mtl: only the importer knows them, found
// or not), each with its path from the report's folder and its digest taken as it was loaded,
// for the report's "side_files". A missing file in a missing folder is left out: importers look
// for names made from the input's path (assimp's MD5 reader tries "chars/chars/Bob.md5anim" and
// names cut from the path; load_assimp runs it from the character's folder, so those no longer
// depend on the spelling, but such guesses still name folders nobody made), and a file to
// appear there would need its folder made first.
json side_files(const PlannedItem& p, const std::vector<std::string>& files_read) {
    std::unordered_set<std::string> known;
    for (const std::string& input : p.plan.inputs) known.insert(file_identity(input));
    json list = json::array();
    std::unordered_set<std::string> listed;
    for (const std::string& file : files_read) {
        if (known.count(file_identity(file))) continue;
        std::error_code error;
        if (!fs::exists(file, error) && !fs::is_directory(folder_of(file), error)) continue;
        const std::string name = from_report_folder(p, file);
        if (!listed.insert(name).second) continue;
        json entry = side_file_name(name);
        // The digest of the path as kept (relative() normalises "dir/" to "dir"), as current_report
        // will take it.
        entry["sha256"] = file_digest(folder_of(p.report) / name);
        list.push_back(entry);
    }
    return list;
}

// The summary's figures in a report as run_item writes them: counts, ACMRs, and OVRs and the time
// as numbers or null (no evaluation; --no-timings).
bool summary_fields_hold(const json& batch) {
    if (!batch.is_object() || string_at(batch, "status") != "ok") return false;
    for (const char* key : {"triangles", "clips", "buffers", "index_bytes_added"})
        if (!batch.contains(key) || !batch[key].is_number_unsigned()) return false;
    for (const char* key : {"acmr_before", "acmr_after"})
        if (!batch.contains(key) || !batch[key].is_number()) return false;
    for (const char* key : {"ovr_before", "ovr_after", "time_s"})
        if (!batch.contains(key) || !(batch[key].is_number() || batch[key].is_null())) return false;
    return true;
}

// Why an item's result is not up to date, as far as its files tell ("" when it is: its report
// carries the stamp the item has now, the summary's figures as written, every output present as
// it was written, and every side file it lists with its digest). `kind` tells the merge which
// hint to add.
struct Staleness {
    enum Kind { kCurrent, kNoResult, kOtherBuild, kOtherEvaluation, kChanged } kind = kCurrent;
    std::string why;
};

// An output's path as the manifest writes it (the item's output stem as written).
std::string output_as_written(const PlannedItem& p, const std::string& out) {
    const std::string stem = stem_of(p.item.output);
    return out.rfind(stem, 0) == 0 ? stem_of(p.item.output_as_written) + out.substr(stem.size()) : out;
}

// A file named from the item report's folder (as reports keep them), as the manifest would write
// it: from the manifest's folder.
std::string as_manifest_writes(const PlannedItem& p, const std::string& from_report) {
    const fs::path out(p.item.output_as_written);
    return (out.parent_path() / from_report).lexically_normal().generic_string();
}

// Which part of the stamp changed since the report was written (its "stamp_parts").
Staleness stamp_change(const PlannedItem& p, const json& then, const StampParts& now) {
    using S = Staleness;
    if (string_at(then, "tool") != tool_digest())
        return {S::kOtherBuild, "its result was written by another animorder build"};
    const auto old = then.find("stamp_parts");
    if (old == then.end() || !old->is_object())
        return {S::kChanged, "its result is out of date: its inputs, options or paths changed since it ran"};
    if (string_at(*old, "eval") != now.eval)
        return {S::kOtherEvaluation, "its result was evaluated with other --eval-views/--eval-resolution/--no-timings"};
    if (string_at(*old, "settings") != now.settings) return {S::kChanged, "its options changed since it ran"};
    if (string_at(*old, "paths") != now.paths)
        return {S::kChanged, "its input, output or clip paths in the manifest changed since it ran"};
    std::vector<std::pair<std::string, std::string>> before;
    if (old->contains("inputs") && (*old)["inputs"].is_array())
        for (const json& entry : (*old)["inputs"])
            before.emplace_back(side_file_path(entry), string_at(entry, "sha256"));
    for (const auto& [file, digest] : now.inputs) {
        const auto same_name =
            std::find_if(before.begin(), before.end(), [&](const auto& b) { return b.first == file; });
        if (same_name == before.end())
            return {S::kChanged, "it now reads " + as_manifest_writes(p, file) + ", which it did not when it ran"};
        if (same_name->second != digest)
            return {S::kChanged, "its input " + as_manifest_writes(p, file) + " changed since it ran"};
    }
    for (const auto& [file, digest] : before) {
        const auto still =
            std::find_if(now.inputs.begin(), now.inputs.end(), [&](const auto& n) { return n.first == file; });
        if (still == now.inputs.end())
            return {S::kChanged, "it no longer reads " + as_manifest_writes(p, file) + ", which it read when it ran"};
    }
    return {S::kChanged, "its result is out of date: its inputs, options or paths changed since it ran"};
}

Staleness staleness_of_report(const PlannedItem& p, const Stamp& stamp, json* report_out) {
    using S = Staleness;
    json report = read_json_file(p.report);
    if (!report.is_object() || !report.contains("batch") || !report["batch"].is_object())
        return {S::kNoResult, "no result yet (not run, or its run did not finish)"};
    const json& b = report["batch"];
    if (string_at(b, "stamp") != stamp.digest) return stamp_change(p, b, stamp.parts);
    if (!summary_fields_hold(b)) return {S::kChanged, "its report was edited: its figures are not as written"};
    std::error_code error;
    for (const std::string& out : p.plan.outputs)
        if (!fs::is_regular_file(out, error))
            return {S::kChanged, "its output " + output_as_written(p, out) + " is missing"};
    // Every output but the report as it was written (a truncated or emptied one is not up to date).
    const auto outputs = b.find("outputs");
    if (outputs == b.end() || !outputs->is_array()) return {S::kChanged, "its report was edited: it lists no outputs"};
    for (const std::string& out : p.plan.outputs) {
        if (out == p.report) continue;
        const std::string name = fs::path(out).filename().string();
        const auto entry =
            std::find_if(outputs->begin(), outputs->end(), [&](const json& e) { return string_at(e, "file") == name; });
        if (entry == outputs->end() || string_at(*entry, "sha256") != file_digest(out))
            return {S::kChanged, "its output " + output_as_written(p, out) + " changed since it was written"};
    }
    const auto side = b.find("side_files");
    if (side != b.end()) {
        if (!side->is_array()) return {S::kChanged, "its report was edited: its side files are not a list"};
        for (const json& entry : *side) {
            const std::string file = side_file_path(entry);
            if (file.empty() || string_at(entry, "sha256") != file_digest(folder_of(p.report) / file))
                return {S::kChanged, "its input " + as_manifest_writes(p, file) + " changed since it ran"};
        }
    }
    if (report_out) *report_out = std::move(report);
    return {};
}

// The same, and a failure the item's last run left (OUTPUT.animorder.error.json, with the stamp
// and its parts of that run, the last attempt: a success removes it): named, with what changed
// since.
Staleness staleness(const PlannedItem& p, const Stamp& stamp, json* report_out = nullptr) {
    Staleness s = staleness_of_report(p, stamp, report_out);
    if (s.kind == Staleness::kCurrent) return s;
    const json failure = read_json_file(p.error);
    const std::string error = string_at(failure, "error");
    if (error.empty()) return s;
    if (string_at(failure, "stamp") == stamp.digest)
        return {Staleness::kChanged, "it failed when it last ran: " + error};
    // The failure is the last attempt (a success removes it): what changed since, as far as known.
    if (failure.contains("stamp_parts"))
        s = stamp_change(p, failure, stamp.parts);
    else if (s.kind == Staleness::kNoResult)
        s = {Staleness::kChanged, "its inputs, options or build changed since"};
    s.why += "; it failed when it last ran: " + error;
    return s;
}

// The item's report when it is up to date, else null.
json current_report(const PlannedItem& p, const Stamp& stamp) {
    json report;
    return staleness(p, stamp, &report).kind == Staleness::kCurrent ? report : json();
}

// Wall times out (--no-timings): every key of seconds set to null, wherever it is, and the thread
// count they ran with (settings.threads), which changes nothing else.
void drop_timings(json& value) {
    if (value.is_array())
        for (json& v : value) drop_timings(v);
    if (!value.is_object()) return;
    for (auto it = value.begin(); it != value.end(); ++it) {
        const std::string& k = it.key();
        if (k == "time_s" || k == "timings_s" || k == "stages_s" || k == "threads" || k.rfind("seconds", 0) == 0)
            it.value() = nullptr;
        else
            drop_timings(it.value());
    }
}

// What a run killed part-way left of an item (atomic_write.h's remove_stale_temporaries), removed
// when the item is redone or found up to date.
void remove_stale_temporaries(const std::vector<std::string>& outputs) {
    for (const std::string& out : outputs) animorder::remove_stale_temporaries(out);
}

json number_or_null(double v, bool have) { return have ? json(v) : json(nullptr); }

// Runs one item into one OutputSet (the report, with its stamp, last): all files or none.
// Where a file is, whether or not it exists yet: its folder resolved, then its name. A commit
// renames a new file into place, so an output keeps its place but not its inode.
std::string place_of(const std::string& path) {
    const fs::path p(path);
    std::error_code error;
    const fs::path folder = fs::weakly_canonical(fs::absolute(folder_of(path), error), error);
    return (folder / p.filename()).string();
}

// Every output of the batch by place_of, for checking the files an item's loading read (an
// importer's side files are known only then).
using OutputsByPlace = std::unordered_map<std::string, std::string>;

void run_item(const PlannedItem& p, const Stamp& stamp, const BatchOptions& batch, const OutputsByPlace& all_outputs) {
    const Clock::time_point start = Clock::now();
    std::vector<std::string> files_of_item = p.plan.outputs;
    files_of_item.push_back(p.error);
    remove_stale_temporaries(files_of_item);
    OutputSet files;
    json written = json::array();  // each output but the report: its name and digest
    files.observe([&](const std::string& path, const std::string& data) {
        if (path == p.report) return;
        Sha256 hash;
        hash.add_data(path, data);
        written.push_back({{"file", fs::path(path).filename().string()}, {"sha256", hash.hex()}});
    });
    json side;  // digests as loaded: an edit while the method runs makes the item stale
    OptimizeProduct product = produce_optimize(p.options, p.plan, files, [&](const std::vector<std::string>& read) {
        for (const std::string& file : read) {
            std::error_code error;  // the file as named, and where a link there leads
            auto output = all_outputs.find(place_of(file));
            if (output == all_outputs.end())
                output = all_outputs.find(fs::weakly_canonical(fs::absolute(file, error), error).string());
            if (output != all_outputs.end())
                throw OutputError(output->second + ": is an input of this run (loading " + p.options.common.input +
                                  " reads it): refusing to overwrite the input; name another output");
        }
        side = side_files(p, read);
    });
    const AnimatedMesh& mesh = product.mesh;
    const MethodResult& run = product.run;

    bool have_ovr = false;
    double ovr_before = 0, ovr_after = 0;
    if (batch.eval_views > 0 && mesh.keyframe_count() > 0) {
        MethodBuffers input_order;
        input_order.orders.emplace_back(mesh.triangle_count());
        std::iota(input_order.orders[0].begin(), input_order.orders[0].end(), 0u);
        EvaluationSettings evaluation;
        evaluation.views = batch.eval_views;
        evaluation.resolution = batch.eval_resolution;
        evaluation.threads = batch.threads;
        evaluation.progress = progress_printer(p.options.common, "evaluating OVR before and after");
        const std::vector<OrderEvaluation> ovr = evaluate_methods(mesh, {input_order, run.buffers}, evaluation);
        ovr_before = ovr[0].overall.ovr_mean;
        ovr_after = ovr[1].overall.ovr_mean;
        have_ovr = true;
    }
    const size_t buffers = run.buffers.orders.size();
    json& report = product.report;
    // Paths as the manifest writes them (relative to its folder), so that the report is the same
    // bytes whatever folder the batch starts in and however the manifest's path is spelled.
    if (p.item.input_given && report["input"] == p.options.common.input) report["input"] = p.item.input_as_written;
    for (auto& [kind, path] : report["outputs"].items())  // OUT.glb, OUT.animorder.bin, ...: all from the stem
        if (path.is_string()) path = output_as_written(p, path.get<std::string>());
    report["batch"] = {{"stamp", stamp.digest},
                       {"stamp_parts", stamp_parts_json(stamp.parts)},
                       {"item", p.item.name},
                       {"status", "ok"},
                       {"triangles", mesh.triangle_count()},
                       {"clips", mesh.clips.size()},
                       {"keyframes", mesh.keyframe_count()},
                       {"buffers", buffers},
                       {"acmr_before", product.before.acmr},
                       {"acmr_after", run.acmr_mean},
                       {"ovr_before", number_or_null(ovr_before, have_ovr)},
                       {"ovr_after", number_or_null(ovr_after, have_ovr)},
                       {"eval_views", batch.eval_views},
                       {"eval_resolution", batch.eval_resolution},
                       {"index_bytes_added", uint64_t(buffers > 0 ? buffers - 1 : 0) * mesh.indices.size() * 4},
                       {"side_files", side},
                       {"outputs", written},
                       {"tool", tool_digest()},
                       {"time_s", std::chrono::duration<double>(Clock::now() - start).count()}};
    if (batch.no_timings) drop_timings(report);
    // An input edited while the item ran (between its stamp and its load): the outputs may come
    // from other bytes than the stamp's, so none is kept and the next run redoes the item.
    if (stamp_of(p, batch).digest != stamp.digest)
        throw std::runtime_error("an input changed while the item ran; run the batch again to redo it");
    files.add(p.report, report_text(report));
    files.commit();
    std::error_code error;
    fs::remove(p.error, error);  // an earlier failure of this item is over
}

// ---------------------------------------------------------------------------------------------
// The summary, merged from the items' files in manifest order

// Why an item has no up-to-date result, for the merge's summary (with what to do about it when
// the merge itself is the cause).
std::string why_missing(const PlannedItem& p, const Stamp& stamp) {
    const Staleness s = staleness(p, stamp);
    if (s.kind == Staleness::kOtherBuild) return s.why + " (run the merge with the build that ran the items)";
    if (s.kind == Staleness::kOtherEvaluation) return s.why + " (give the merge the same)";
    return s.why;
}

// `failed_now`: the error of this run's attempt, when the item failed in it (its earlier report,
// still matching, does not make it ok).
json summary_row(const PlannedItem& p, const Stamp& stamp, const std::string& failed_now) {
    json row = {{"name", p.item.name},
                {"input", p.item.input_as_written.empty() ? "(bundled)" : p.item.input_as_written},
                {"output", p.item.output_as_written},
                {"method", method_name(p.plan.method)}};
    const json report = failed_now.empty() ? current_report(p, stamp) : json();
    if (report.is_object()) {
        const json& b = report["batch"];
        for (const char* key : {"triangles", "clips", "buffers", "acmr_before", "acmr_after", "ovr_before", "ovr_after",
                                "index_bytes_added", "time_s"})
            row[key] = b.contains(key) ? b[key] : json(nullptr);
        row["status"] = "ok";
        row["error"] = nullptr;
        return row;
    }
    const json failure = read_json_file(p.error);
    const bool failed = !failed_now.empty() || string_at(failure, "stamp") == stamp.digest;
    for (const char* key : {"triangles", "clips", "buffers", "acmr_before", "acmr_after", "ovr_before", "ovr_after",
                            "index_bytes_added", "time_s"})
        row[key] = nullptr;
    row["status"] = failed ? "failed" : "missing";
    row["error"] = !failed_now.empty() ? failed_now : failed ? string_at(failure, "error") : why_missing(p, stamp);
    return row;
}

std::string cell(const json& v, int digits) {
    if (v.is_null()) return "—";
    if (v.is_number_float()) {
        char text[32];
        std::snprintf(text, sizeof text, "%.*f", digits, v.get<double>());
        return text;
    }
    if (v.is_string()) {  // as text: Markdown's punctuation escaped, a line end as a space
        std::string s;
        for (const char c : v.get<std::string>()) {
            if (c == '\n' || c == '\r') {
                s += ' ';
                continue;
            }
            if (std::strchr("\\`*_[]<>|~", c) && c != '\0') s += '\\';
            s += c;
        }
        return s;
    }
    return v.dump();
}

std::string summary_markdown(const json& summary) {
    std::string md = "# animorder batch summary\n\n";
    md += std::to_string(summary["items"].size()) + " items: " + summary["ok"].dump() + " ok, " +
          summary["failed"].dump() + " failed, " + summary["missing"].dump() + " missing (animorder " +
          summary["version"].get<std::string>() + ").\n\n";
    md +=
        "| item | method | triangles | clips | OVR before | OVR after | ACMR before | ACMR after | index bytes added | "
        "time (s) | status |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const json& r : summary["items"]) {
        std::string status = r["status"].get<std::string>();
        if (!r["error"].is_null()) status += ": " + cell(r["error"], 0);
        md += "| " + cell(r["name"], 0) + " | " + cell(r["method"], 0) + " | " + cell(r["triangles"], 0) + " | " +
              cell(r["clips"], 0) + " | " + cell(r["ovr_before"], 3) + " | " + cell(r["ovr_after"], 3) + " | " +
              cell(r["acmr_before"], 3) + " | " + cell(r["acmr_after"], 3) + " | " + cell(r["index_bytes_added"], 0) +
              " | " + cell(r["time_s"], 1) + " | " + status + " |\n";
    }
    return md;
}

// Builds and writes the summary; returns the exit code it implies. failed_now: per item, the
// error of this run's attempt when it failed (empty otherwise).
int write_summary(const std::vector<PlannedItem>& items, const std::vector<Stamp>& stamps,
                  const std::vector<std::string>& failed_now, const std::string& stem, const std::string& manifest,
                  const BatchOptions& batch) {
    json summary = {
        {"tool", "animorder"}, {"version", ANIMORDER_VERSION}, {"manifest", fs::path(manifest).filename().string()}};
    json rows = json::array();
    size_t ok = 0, failed = 0, missing = 0;
    for (size_t i = 0; i < items.size(); ++i) {
        rows.push_back(summary_row(items[i], stamps[i], failed_now[i]));
        const std::string status = rows.back()["status"].get<std::string>();
        (status == "ok" ? ok : status == "failed" ? failed : missing) += 1;
    }
    summary["ok"] = ok;
    summary["failed"] = failed;
    summary["missing"] = missing;
    summary["items"] = rows;
    remove_stale_temporaries({stem + ".json", stem + ".md"});
    OutputSet files;
    files.add(stem + ".json", report_text(summary));
    files.add(stem + ".md", summary_markdown(summary));
    files.commit();
    if (!batch.quiet)
        std::fprintf(stderr, "animorder: batch: summary %s.json / .md: %zu ok, %zu failed, %zu missing\n", stem.c_str(),
                     ok, failed, missing);
    return failed && missing ? kExitFailedAndMissing : failed ? kExitItemsFailed : missing ? kExitItemsMissing : 0;
}

// An item's error with its paths as the manifest writes them (the loaders name them as resolved
// against the manifest's folder, or made absolute), so that the summary is the same bytes whatever
// folder the batch starts in.
std::string as_written(const ManifestItem& item, std::string message) {
    std::vector<std::pair<std::string, std::string>> paths = {{item.input, item.input_as_written},
                                                              {item.output, item.output_as_written}};
    for (size_t c = 0; c < item.clips.size() && c < item.clips_as_written.size(); ++c)
        paths.emplace_back(item.clips[c], item.clips_as_written[c]);
    std::sort(paths.begin(), paths.end(), [](const auto& a, const auto& b) { return a.first.size() > b.first.size(); });
    for (const auto& [resolved, written] : paths) {
        if (resolved.empty() || resolved == written) continue;
        for (size_t at = message.find(resolved); at != std::string::npos;
             at = message.find(resolved, at + written.size()))
            message.replace(at, resolved.size(), written);
    }
    return message;
}

// --shard I/N or env/N → (I, N).
std::pair<size_t, size_t> parse_shard(const std::string& text) {
    const size_t slash = text.find('/');
    auto number = [&](const std::string& s, const char* what) {
        if (s.empty() || s.size() > 9 ||
            !std::all_of(s.begin(), s.end(), [](char c) { return std::isdigit(uint8_t(c)); }))
            throw std::runtime_error("--shard " + text + ": " + what +
                                     " must be a whole number below 10^9 (I/N, or env/N)");
        return size_t(std::stoul(s));
    };
    if (slash == std::string::npos) throw std::runtime_error("--shard " + text + ": expected I/N (or env/N)");
    std::string index = text.substr(0, slash);
    const size_t count = number(text.substr(slash + 1), "N");
    if (count == 0) throw std::runtime_error("--shard " + text + ": N must be at least 1");
    if (index == "env") {
        const char* k8s = std::getenv("JOB_COMPLETION_INDEX");
        const char* slurm = std::getenv("SLURM_ARRAY_TASK_ID");
        const char* variable = k8s && *k8s ? "JOB_COMPLETION_INDEX" : slurm && *slurm ? "SLURM_ARRAY_TASK_ID" : nullptr;
        if (!variable)
            throw std::runtime_error("--shard env/N: neither JOB_COMPLETION_INDEX nor SLURM_ARRAY_TASK_ID is set");
        index = std::getenv(variable);
        const bool digits = !index.empty() && index.size() <= 9 && std::all_of(index.begin(), index.end(), [](char c) {
            return std::isdigit(uint8_t(c)) != 0;
        });
        if (!digits || size_t(std::stoul(index)) >= count)
            throw std::runtime_error("--shard " + text + ": " + variable + "=" + index +
                                     " is not a shard index from 0 to " + std::to_string(count - 1));
    }
    const size_t i = number(index, "I");
    if (i >= count) throw std::runtime_error("--shard " + text + ": needs 0 <= I < N (I = " + index + ")");
    return {i, count};
}

}  // namespace

// write_summary, whose failure (a full disk, say) comes after the items' work: its own exit code,
// not 1 (an error before any work), so that a farm does not take it for a bad manifest.
int summarise(const std::vector<PlannedItem>& items, const std::vector<Stamp>& stamps,
              const std::vector<std::string>& failed_now, const std::string& stem, const BatchOptions& batch) {
    try {
        return write_summary(items, stamps, failed_now, stem, batch.manifest, batch);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "animorder: batch: the items' files are written, but not the summary: %s\n", e.what());
        return kExitNoSummary;
    }
}

// --dry-run: which of the shard's items a run would redo, and why, as JSON on stdout; nothing is
// written or removed.
int print_plan(const std::vector<PlannedItem>& items, std::pair<size_t, size_t> shard, bool sharded,
               const BatchOptions& batch) {
    json rows = json::array();
    size_t run = 0, skip = 0;
    for (size_t i = 0; i < items.size(); ++i) {
        if (i % shard.second != shard.first) continue;
        const PlannedItem& p = items[i];
        Staleness s = staleness(p, stamp_of(p, batch));
        if (batch.force) s = {Staleness::kChanged, "--force"};
        const bool current = s.kind == Staleness::kCurrent;
        (current ? skip : run) += 1;
        rows.push_back({{"item", i + 1},
                        {"name", p.item.name},
                        {"output", p.item.output_as_written},
                        {"action", current ? "skip" : "run"},
                        {"why", current ? json("up to date") : json(s.why)}});
    }
    json plan = {{"manifest", fs::path(batch.manifest).filename().string()},
                 {"shard", sharded ? json::array({shard.first, shard.second}) : json(nullptr)},
                 {"run", run},
                 {"skip", skip},
                 {"items", rows}};
    std::fputs(report_text(plan).c_str(), stdout);
    return 0;
}

int run_batch(const BatchOptions& batch, const ItemParser& parse_item) {
    const std::vector<ManifestItem> manifest = read_manifest(batch.manifest);
    std::pair<size_t, size_t> shard = {0, 1};
    if (!batch.shard.empty()) shard = parse_shard(batch.shard);
    if (batch.merge && !batch.shard.empty())
        throw std::runtime_error("--merge builds the summary of every shard: drop --shard");
    if (batch.merge && batch.force) throw std::runtime_error("--merge runs no item: drop --force");
    if (batch.merge && batch.dry_run) throw std::runtime_error("--merge runs no item: drop --dry-run");
    if (batch.merge && batch.item_failures_ok)
        throw std::runtime_error(
            "--merge runs no item: drop --item-failures-ok (the merge's exit 3 lists the failures)");

    // Every item planned and every output of every item checked before any work: folders exist
    // and are writable, no output is any item's input or the manifest, no file is named twice.
    std::vector<PlannedItem> items;
    for (size_t i = 0; i < manifest.size(); ++i) items.push_back(plan_item(manifest[i], i, batch, parse_item));
    std::string summary = batch.summary;
    if (file_extension(summary) == ".json" || file_extension(summary) == ".md")  // --summary S.json: S
        summary.erase(summary.size() - file_extension(summary).size());
    if (summary.empty()) {
        const fs::path m(batch.manifest);
        summary = (m.parent_path() / m.stem()).string() + ".summary";
    }
    check_output_stem(summary);
    // Only what this process writes is checked for writing (a shard its own items' files, the
    // merge the summary, a whole run everything); the files of the job's other processes are
    // checked against every input and every other output only.
    const bool sharded = shard.second > 1 || !batch.shard.empty();
    std::vector<std::string> written, others, inputs = {batch.manifest}, folders;
    std::vector<std::string>& summary_files = batch.merge || !sharded ? written : others;
    summary_files.insert(summary_files.end(), {summary + ".json", summary + ".md"});
    for (size_t i = 0; i < items.size(); ++i) {
        const PlannedItem& p = items[i];
        std::vector<std::string>& files = !batch.merge && i % shard.second == shard.first ? written : others;
        files.insert(files.end(), p.plan.outputs.begin(), p.plan.outputs.end());
        files.push_back(p.error);
        inputs.insert(inputs.end(), p.plan.inputs.begin(), p.plan.inputs.end());
        folders.insert(folders.end(), p.plan.input_folders.begin(), p.plan.input_folders.end());
    }
    std::vector<std::string> outputs = written;
    outputs.insert(outputs.end(), others.begin(), others.end());
    // A dry run writes nothing, not even the probes that check a folder takes a new file.
    check_output_paths(outputs, inputs, folders, batch.dry_run ? 0 : written.size());
    OutputsByPlace outputs_by_place;
    for (const std::string& output : outputs) outputs_by_place.emplace(place_of(output), output);

    // A shard stamps its own items only, each when its turn comes (so that an input edited while
    // earlier items run is read as it is then); the merge stamps every item.
    std::vector<Stamp> stamps(items.size());
    std::vector<std::string> failed_now(items.size());
    if (batch.merge) {
        for (size_t i = 0; i < items.size(); ++i) stamps[i] = stamp_of(items[i], batch);
        return summarise(items, stamps, failed_now, summary, batch);
    }

    if (batch.dry_run) return print_plan(items, shard, sharded, batch);

    size_t done = 0, skipped = 0, failed = 0, mine = 0;
    for (size_t i = 0; i < items.size(); ++i) mine += i % shard.second == shard.first;
    size_t position = 0;
    for (size_t i = 0; i < items.size(); ++i) {
        if (i % shard.second != shard.first) continue;
        const PlannedItem& p = items[i];
        std::string label = "batch [" + std::to_string(++position) + "/" + std::to_string(mine) + "] " + p.item.name;
        for (char& c : label)  // progress and failure lines stay one line each
            if (c == '\n' || c == '\r') c = ' ';
        stamps[i] = stamp_of(p, batch);
        if (!batch.force && current_report(p, stamps[i]).is_object()) {
            ++skipped;
            std::vector<std::string> files_of_item = p.plan.outputs;
            files_of_item.push_back(p.error);
            remove_stale_temporaries(files_of_item);
            std::error_code error;
            fs::remove(p.error, error);  // an earlier failure of this item is over: its result is current
            note(p.options.common, label + ": up to date, skipped");
            continue;
        }
        note(p.options.common, label + ": running");
        try {
            run_item(p, stamps[i], batch, outputs_by_place);
            ++done;
            note(p.options.common, label + ": done");
        } catch (const std::exception& e) {
            ++failed;
            std::string message = as_written(p.item, e.what());
            for (char& c : message)
                if (c == '\n' || c == '\r') c = ' ';
            std::fprintf(stderr, "animorder: %s: failed: %s\n", label.c_str(), message.c_str());
            failed_now[i] = message;
            try {
                write_file_atomically(p.error, report_text(json{{"stamp", stamps[i].digest},
                                                                {"stamp_parts", stamp_parts_json(stamps[i].parts)},
                                                                {"tool", tool_digest()},
                                                                {"item", p.item.name},
                                                                {"status", "failed"},
                                                                {"error", message}}));
            } catch (const std::exception& again) {
                std::fprintf(stderr, "animorder: %s: cannot record the failure: %s\n", label.c_str(), again.what());
            }
        }
    }
    std::printf("batch%s: %zu items: %zu done, %zu up to date, %zu failed\n",
                sharded ? (" shard " + std::to_string(shard.first) + "/" + std::to_string(shard.second)).c_str() : "",
                mine, done, skipped, failed);
    const bool failures_count = failed && !batch.item_failures_ok;
    if (sharded) return failures_count ? kExitItemsFailed : 0;  // the summary is the merge step's
    const int code = summarise(items, stamps, failed_now, summary, batch);
    return code == kExitItemsFailed && !failures_count ? 0 : code;
}

}  // namespace animorder::tool
