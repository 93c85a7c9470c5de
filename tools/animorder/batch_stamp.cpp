// Content stamps of batch items, hashed with nettle's SHA-256: the parts an item's outputs depend
// on, the side files its loading read, and which part changed since its report was written.
#include "batch_stamp.h"

#include "animorder/atomic_write.h"
#include "animorder/regular_file.h"

#include <nettle/sha2.h>
#include <nlohmann/json.hpp>

#include <sys/stat.h>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <ctime>
#include <filesystem>
#include <mutex>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

namespace animorder::tool {
namespace {

namespace fs = std::filesystem;
using json = nlohmann::ordered_json;

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

}  // namespace

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

namespace {

// A file's name and bytes, hashed.
std::string file_digest(const fs::path& path) {
    Sha256 hash;
    hash.add_file(path);
    return hash.hex();
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

// The digests of the files items read, each file read and hashed once in a run however many
// items share it (a library's items often share a character, its buffers, a clip folder): kept
// by the file's device and inode, size, modification and change times, and its name (which the
// digest hashes too). A file changed in the kSettleSeconds before it was hashed is not kept (its
// times could not tell a second change within the same tick of the file system's clock: 2 s on
// FAT), so each item reads it again; nor is one that changed while it was read.
class FileDigests {
public:
    std::string of(const fs::path& path) {
        struct stat before {};
        if (::stat(path.c_str(), &before) != 0 || !S_ISREG(before.st_mode)) return file_digest(path);
        const std::string key = identity(before) + "/" + path.filename().string();
        {
            const std::lock_guard<std::mutex> lock(mutex_);
            const auto known = known_.find(key);
            if (known != known_.end()) return known->second;
        }
        timespec now{};
        ::clock_gettime(CLOCK_REALTIME, &now);
        std::string digest = file_digest(path);
        struct stat after {};
        const auto nanoseconds = [](const timespec& t) { return int64_t(t.tv_sec) * 1000000000 + t.tv_nsec; };
        const int64_t changed = std::max(nanoseconds(before.st_mtim), nanoseconds(before.st_ctim));
        if (::stat(path.c_str(), &after) == 0 && identity(after) == identity(before) &&
            changed + kSettleSeconds * 1000000000 < nanoseconds(now)) {
            const std::lock_guard<std::mutex> lock(mutex_);
            known_.emplace(key, digest);
        }
        return digest;
    }

private:
    static constexpr int64_t kSettleSeconds = 2;
    static std::string identity(const struct stat& st) {
        return std::to_string(st.st_dev) + ":" + std::to_string(st.st_ino) + ":" + std::to_string(st.st_size) + ":" +
               std::to_string(st.st_mtim.tv_sec) + "." + std::to_string(st.st_mtim.tv_nsec) + ":" +
               std::to_string(st.st_ctim.tv_sec) + "." + std::to_string(st.st_ctim.tv_nsec);
    }
    std::mutex mutex_;
    std::unordered_map<std::string, std::string> known_;
};

// file_digest through the run's FileDigests.
std::string shared_file_digest(const fs::path& path) {
    static FileDigests digests;
    return digests.of(path);
}

// A file's path from the item report's folder, as the report names the files the item read;
// each (file, folder) worked out once in a run (relative() resolves both paths' links).
std::string from_report_folder(const PlannedItem& p, const std::string& file) {
    static std::mutex mutex;
    static std::unordered_map<std::string, std::string> known;
    const fs::path folder = folder_of(p.report);
    const std::string key = file + '\0' + folder.string();  // no path holds a NUL
    {
        const std::lock_guard<std::mutex> lock(mutex);
        const auto found = known.find(key);
        if (found != known.end()) return found->second;
    }
    std::error_code error;
    // Both absolute first: relative() leaves a relative path whose folders are all missing as
    // it is, and the result was empty (the absolute path was kept, tying the report to a place).
    fs::path from_report = fs::relative(fs::absolute(file, error), fs::absolute(folder, error), error);
    if (error || from_report.empty()) from_report = fs::absolute(file, error);
    const std::lock_guard<std::mutex> lock(mutex);
    return known.emplace(key, from_report.generic_string()).first->second;
}

// The parts of the item's stamp (StampParts) as its files are now.
StampParts stamp_parts(const PlannedItem& p, const BatchOptions& batch) {
    StampParts parts;
    std::string& settings = p.shared->settings_digest;  // the same for every item of a shared plan
    if (settings.empty()) {
        Sha256 hash;
        hash.add(optimize_settings_json(p.shared->options, p.shared->plan, false).dump());
        hash.add("max_memory:" + std::to_string(p.shared->options.common.max_memory));
        settings = hash.hex();
    }
    parts.settings = settings;
    Sha256 paths;
    paths.add("input:" + p.item.input_as_written);
    paths.add("output:" + p.item.output_as_written);
    for (const std::string& c : p.item.clips_as_written) paths.add("clip:" + c);
    parts.paths = paths.hex();
    parts.eval = std::to_string(batch.eval_views) + "/" + std::to_string(batch.eval_resolution) +
                 (batch.no_timings ? "/no-timings" : "");
    for (const std::string& file : p.shared->plan.inputs)
        parts.inputs.emplace_back(from_report_folder(p, file), shared_file_digest(file));
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

}  // namespace

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
    for (const std::string& input : p.shared->plan.inputs) known.insert(file_identity(input));
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

std::string data_digest(const std::string& path, const std::string& data) {
    Sha256 hash;
    hash.add_data(path, data);
    return hash.hex();
}

namespace {

// The most a plausible OVR or wall time may be: far beyond any character's (an OVR of 1000 is a
// thousand layers on every pixel seen), so that only an edited figure is refused.
constexpr double kMaxOvr = 1000;
constexpr double kMaxSeconds = 366.0 * 24 * 3600;

// What is wrong with the summary's figures in a report ("" when nothing): each as run_item writes
// it, with values its definitions allow (DESIGN.md): counts are whole numbers, the index bytes
// added are (buffers - 1) x triangles x 12, an ACMR (misses per triangle: at least the first
// vertex's, at most three) lies from 1/triangles to 3, an OVR (fragments that passed over pixels
// seen, a mean of per-view ratios) is 0 when nothing was seen and otherwise from 1 to the triangle
// count (and at most kMaxOvr), or null without evaluation; a wall time is from 0 to a year, or
// null (--no-timings). Every number is finite (a JSON number too large for a double reads as
// infinite).
std::string implausible_figure(const json& batch) {
    if (!batch.is_object() || string_at(batch, "status") != "ok") return "its status is not \"ok\"";
    const auto value = [&](const char* key) { return std::string(key) + " is " + batch[key].dump(); };
    for (const char* key : {"triangles", "clips", "buffers", "index_bytes_added"}) {
        if (!batch.contains(key)) return std::string(key) + " is missing";
        if (!batch[key].is_number_unsigned()) return value(key) + ", not a whole number from 0";
    }
    if (batch.contains("keyframes") && !batch["keyframes"].is_number_unsigned())
        return value("keyframes") + ", not a whole number from 0";
    const uint64_t triangles = batch["triangles"].get<uint64_t>(), buffers = batch["buffers"].get<uint64_t>();
    const uint64_t extra = buffers > 0 ? buffers - 1 : 0;
    const bool fits = triangles == 0 || extra <= UINT64_MAX / 12 / triangles;
    if (!fits || batch["index_bytes_added"].get<uint64_t>() != extra * triangles * 12)
        return value("index_bytes_added") + ", not (buffers - 1) x triangles x 12";
    const double t = double(triangles);
    for (const char* key : {"acmr_before", "acmr_after"}) {
        if (!batch.contains(key)) return std::string(key) + " is missing";
        if (!batch[key].is_number() || !std::isfinite(batch[key].get<double>())) return value(key) + ", not a number";
        const double acmr = batch[key].get<double>();
        const bool plausible = triangles == 0 ? acmr == 0 : acmr >= (1 - 1e-9) / t && acmr <= 3 * (1 + 1e-9);
        if (!plausible) return value(key) + ", not an ACMR (from 1/triangles to 3)";
    }
    for (const char* key : {"ovr_before", "ovr_after"}) {
        if (!batch.contains(key)) return std::string(key) + " is missing";
        if (batch[key].is_null()) continue;
        if (!batch[key].is_number() || !std::isfinite(batch[key].get<double>())) return value(key) + ", not a number";
        const double ovr = batch[key].get<double>();
        if (ovr != 0 && !(ovr >= 1 - 1e-9 && ovr <= std::min(t, kMaxOvr) * (1 + 1e-9)))
            return value(key) + ", not an OVR (0 when nothing was seen, else from 1 to the triangles and at most " +
                   std::to_string(int(kMaxOvr)) + ")";
    }
    if (!batch.contains("time_s")) return "time_s is missing";
    if (!batch["time_s"].is_null()) {
        const json& time = batch["time_s"];
        if (!time.is_number() || !std::isfinite(time.get<double>()) || time.get<double>() < 0 ||
            time.get<double>() > kMaxSeconds)
            return value("time_s") + ", not a wall time (seconds from 0 to a year)";
    }
    return "";
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
    // A report is put in place whole (OutputSet): one that is there but unreadable was damaged or
    // edited, which the merge says as it does of a figure no run gives.
    std::error_code error;
    const auto edited = [&](const std::string& what) {
        return Staleness{S::kEditedReport, "its report " + output_as_written(p, p.report) + " " + what};
    };
    if (report.is_null() && fs::exists(p.report, error)) return edited("is damaged: not JSON that batch can read");
    if (report.is_null()) return {S::kNoResult, "no result yet (not run, or its run did not finish)"};
    if (!report.is_object() || !report.contains("batch") || !report["batch"].is_object())
        return edited("was edited: it holds no \"batch\" object");
    const json& b = report["batch"];
    if (string_at(b, "stamp") != stamp.digest) return stamp_change(p, b, stamp.parts);
    const std::string implausible = implausible_figure(b);
    if (!implausible.empty()) return edited("was edited: " + implausible);
    for (const std::string& out : p.outputs)
        if (!fs::is_regular_file(out, error))
            return {S::kChanged, "its output " + output_as_written(p, out) + " is missing"};
    // Every output but the report as it was written (a truncated or emptied one is not up to date).
    const auto outputs = b.find("outputs");
    if (outputs == b.end() || !outputs->is_array()) return {S::kChanged, "its report was edited: it lists no outputs"};
    for (const std::string& out : p.outputs) {
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
            if (file.empty() || string_at(entry, "sha256") != shared_file_digest(folder_of(p.report) / file))
                return {S::kChanged, "its input " + as_manifest_writes(p, file) + " changed since it ran"};
        }
    }
    if (report_out) *report_out = std::move(report);
    return {};
}

}  // namespace

// The same, and a failure the item's last run left (OUTPUT.animorder.error.json, with the stamp
// and its parts of that run, the last attempt: a success removes it): named, with what changed
// since.
Staleness staleness(const PlannedItem& p, const Stamp& stamp, json* report_out) {
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

}  // namespace animorder::tool
