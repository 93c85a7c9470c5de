// Reading RESULTS_DIR for make_results (report_reader.h): every report parsed with nlohmann::json
// and copied field by field into the typed structs, each field checked (type, presence, integer
// range), an error naming the file and the key ("methods[2].acmr").
#include "report_reader.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

namespace animorder::results {

namespace fs = std::filesystem;
using nlohmann::json;

const std::vector<std::string> kSectionIds = {"settings", "table1",      "characters", "views",     "lambda",
                                              "clusters", "clips",       "measured",   "materials", "render-time",
                                              "nehab06",  "performance", "other"};

const Report* Inputs::get(const std::string& name) const {
    const auto it = reports.find(name);
    return it == reports.end() ? nullptr : &it->second;
}

namespace {

// The checked accessors of one file's JSON; fail() throws "FILE: WHERE: WHAT".
class Reader {
public:
    explicit Reader(std::string file) : file_(std::move(file)) {}

    [[noreturn]] void fail(const std::string& where, const std::string& what) const {
        throw std::runtime_error(file_ + ": " + (where.empty() ? "" : where + ": ") + what);
    }
    static std::string kind(const json& v) { return v.type_name(); }

    const json& member(const json& object, const std::string& key, const std::string& where) const {
        if (!object.is_object()) fail(where, "expected an object, got " + kind(object));
        const auto it = object.find(key);
        if (it == object.end()) fail(at(where, key), "missing");
        return *it;
    }
    const json* optional(const json& object, const std::string& key) const {
        if (!object.is_object()) return nullptr;
        const auto it = object.find(key);
        return it == object.end() || it->is_null() ? nullptr : &*it;
    }
    static std::string at(const std::string& where, const std::string& key) {
        return where.empty() ? key : where + "." + key;
    }

    double number(const json& v, const std::string& where) const {
        if (!v.is_number()) fail(where, "expected a number, got " + kind(v));
        return v.get<double>();
    }
    long long integer(const json& v, const std::string& where) const {
        if (v.is_number_unsigned() && v.get<unsigned long long>() > 1ull << 62) fail(where, "out of range");
        if (v.is_number_integer()) return v.get<long long>();
        if (v.is_number_float()) {
            const double d = v.get<double>();
            if (std::floor(d) == d && std::fabs(d) < 4e18) return static_cast<long long>(d);
        }
        fail(where,
             "expected an integer, got " + (v.is_number() ? std::string("a fraction or out of range") : kind(v)));
    }
    // An object member that may be absent or null, but is an object if present.
    const json* optional_object(const json& object, const std::string& key) const {
        const json* v = optional(object, key);
        if (v && !v->is_object()) fail(key, "expected an object, got " + kind(*v));
        return v;
    }
    std::string string(const json& v, const std::string& where) const {
        if (!v.is_string()) fail(where, "expected a string, got " + kind(v));
        return v.get<std::string>();
    }
    double required_number(const json& o, const std::string& key, const std::string& where) const {
        return number(member(o, key, where), at(where, key));
    }
    // A number or null (or absent): NaN for null.
    double nullable_number(const json& o, const std::string& key, const std::string& where) const {
        const json* v = optional(o, key);
        return v ? number(*v, at(where, key)) : kNaN;
    }
    long long nullable_integer(const json& o, const std::string& key, const std::string& where) const {
        const json* v = optional(o, key);
        return v ? integer(*v, at(where, key)) : -1;
    }
    // An array member that may be absent or null, but is an array if present.
    const json* optional_array(const json& o, const std::string& key, const std::string& where) const {
        const json* v = optional(o, key);
        if (v && !v->is_array()) fail(at(where, key), "expected an array, got " + kind(*v));
        return v;
    }
    const json& array(const json& o, const std::string& key, const std::string& where) const {
        const json& v = member(o, key, where);
        if (!v.is_array()) fail(at(where, key), "expected an array, got " + kind(v));
        return v;
    }

private:
    std::string file_;
};

std::string read_text(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error(path.string() + ": cannot open: " + std::strerror(errno));
    std::stringstream ss;
    ss << in.rdbuf();
    if (in.bad()) throw std::runtime_error(path.string() + ": read failed");
    return ss.str();
}

json parse_json(const fs::path& path, const std::string& name) {
    try {
        return json::parse(read_text(path));
    } catch (const json::parse_error& e) {
        throw std::runtime_error(name + ": not valid JSON: " + e.what());
    }
}

BlendResult load_blend(const Reader& r, const json& o, const std::string& key, const std::string& where) {
    BlendResult b;
    const json* v = r.optional_object(o, key);
    if (!v) return b;
    const std::string w = Reader::at(where, key);
    b.present = true;
    b.missorted_pair_fraction = r.required_number(*v, "missorted_pair_fraction", w);
    b.missorted_pixel_fraction = r.required_number(*v, "missorted_pixel_fraction", w);
    b.pairs = r.nullable_integer(*v, "pairs", w);
    b.covered_pixels = r.nullable_integer(*v, "covered_pixels", w);
    b.nodes = r.nullable_integer(*v, "nodes", w);
    return b;
}

Report load_report(const fs::path& path, const std::string& name) {
    const json j = parse_json(path, name);
    const Reader r(name);
    if (!j.is_object()) r.fail("", "expected a JSON object (an `animorder evaluate --report` file)");
    Report report;
    report.file = name;
    report.input = r.string(r.member(j, "input", ""), "input");
    report.triangles = r.integer(r.member(j, "triangles", ""), "triangles");
    report.vertices = r.nullable_integer(j, "vertices", "");
    report.nodes = r.nullable_integer(j, "nodes", "");
    if (const json* s = r.optional_object(j, "settings")) {
        report.eval_views = r.nullable_integer(*s, "eval_views", "settings");
        report.eval_resolution = r.nullable_integer(*s, "eval_resolution", "settings");
        report.eval_seed = r.nullable_integer(*s, "eval_seed", "settings");
        report.resolution = r.nullable_integer(*s, "resolution", "settings");
        report.seed = r.nullable_integer(*s, "seed", "settings");
        report.cache_size = r.nullable_integer(*s, "cache_size", "settings");
        if (const json* bc = r.optional(*s, "blend_clusters")) {
            if (!bc->is_boolean()) r.fail("settings.blend_clusters", "expected a boolean, got " + Reader::kind(*bc));
            report.blend_clusters = bc->get<bool>();
        }
        if (const json* ss = r.optional(*s, "single_sided")) {
            if (!ss->is_boolean()) r.fail("settings.single_sided", "expected a boolean, got " + Reader::kind(*ss));
            report.single_sided = ss->get<bool>();
        }
        const auto list = [&](const char* key, auto convert) {
            if (const json* v = r.optional(*s, key)) {
                const std::string where = std::string("settings.") + key;
                if (v->is_array())
                    for (size_t i = 0; i < v->size(); ++i) convert((*v)[i], where + "[" + std::to_string(i) + "]");
                else
                    convert(*v, where);
            }
        };
        list("lambda", [&](const json& v, const std::string& w) { report.lambdas.push_back(r.number(v, w)); });
        list("clusters", [&](const json& v, const std::string& w) { report.clusters.push_back(r.integer(v, w)); });
        list("views", [&](const json& v, const std::string& w) { report.views.push_back(r.integer(v, w)); });
    }
    if (const json* clips = r.optional_array(j, "clips", "")) {
        for (size_t i = 0; i < clips->size(); ++i) {
            const std::string where = "clips[" + std::to_string(i) + "]";
            report.clips.push_back({r.string(r.member((*clips)[i], "name", where), where + ".name"),
                                    r.integer(r.member((*clips)[i], "keyframes", where), where + ".keyframes")});
        }
    }
    const json& methods = r.array(j, "methods", "");
    for (size_t i = 0; i < methods.size(); ++i) {
        const std::string where = "methods[" + std::to_string(i) + "]";
        const json& m = methods[i];
        Method method;
        method.name = r.string(r.member(m, "name", where), where + ".name");
        method.lambda = r.nullable_number(m, "lambda", where);
        method.clusters = r.nullable_integer(m, "clusters", where);
        method.views = r.nullable_integer(m, "views", where);
        method.buffers = r.integer(r.member(m, "buffers", where), where + ".buffers");
        method.acmr = r.required_number(m, "acmr", where);
        method.atvr = r.required_number(m, "atvr", where);
        method.ovr_mean = r.required_number(m, "ovr_mean", where);
        method.ovr_pooled = r.required_number(m, "ovr_pooled", where);
        method.time_s = r.nullable_number(m, "time_s", where);
        method.peak_rss_bytes = r.nullable_number(m, "peak_rss_bytes", where);
        if (const json* per_clip = r.optional_array(m, "per_clip", where)) {
            for (size_t c = 0; c < per_clip->size(); ++c) {
                const std::string w = where + ".per_clip[" + std::to_string(c) + "]";
                const json& pc = (*per_clip)[c];
                ClipResult cr;
                cr.clip = r.string(r.member(pc, "clip", w), w + ".clip");
                cr.ovr_mean = r.required_number(pc, "ovr_mean", w);
                cr.ovr_pooled = r.nullable_number(pc, "ovr_pooled", w);
                cr.time_s = r.nullable_number(pc, "time_s", w);
                cr.nodes = r.nullable_integer(pc, "nodes", w);
                method.per_clip.push_back(cr);
            }
        }
        if (const json* runs = r.optional_array(m, "runs", where)) {
            for (size_t k = 0; k < runs->size(); ++k) {
                const std::string w = where + ".runs[" + std::to_string(k) + "]";
                const json* clips = r.optional((*runs)[k], "clips");
                const json* iterations = r.optional((*runs)[k], "iterations");
                if (clips && clips->is_string() && iterations && iterations->is_array())
                    method.iterations[clips->get<std::string>()] = iterations->size();
            }
        }
        method.blend = load_blend(r, m, "blend", where);
        if (const json* stages = r.optional_object(m, "stages_s"))
            for (auto it = stages->begin(); it != stages->end(); ++it)
                method.stages[it.key()] = r.number(it.value(), where + ".stages_s." + it.key());
        report.methods.push_back(method);
    }
    report.blend_input_order = load_blend(r, j, "blend_input_order", "");
    report.blend_bound = load_blend(r, j, "blend_bound", "");
    if (const json* t = r.optional_object(j, "timings_s")) {
        report.t_methods = r.nullable_number(*t, "methods", "timings_s");
        report.t_evaluation = r.nullable_number(*t, "evaluation", "timings_s");
        report.t_total = r.nullable_number(*t, "total", "timings_s");
    }
    if (const json* machine = r.optional_object(j, "machine"))
        report.threads = r.nullable_integer(*machine, "threads", "machine");
    return report;
}

RenderTime load_render_time(const fs::path& path, const std::string& name) {
    const json j = parse_json(path, name);
    const Reader r(name);
    if (!j.is_object()) r.fail("", "expected a JSON object (a `render_time --json` file)");
    RenderTime rt;
    rt.renderer = r.string(r.member(j, "renderer", ""), "renderer");
    if (const json* input = r.optional(j, "input")) rt.input = r.string(*input, "input");
    rt.nodes = r.integer(r.member(j, "nodes", ""), "nodes");
    rt.resolution = r.nullable_integer(j, "resolution", "");
    rt.shader_iterations = r.nullable_integer(j, "shader_iterations", "");
    rt.triangles = r.nullable_integer(j, "triangles", "");
    rt.views = r.nullable_integer(j, "views", "");
    rt.keyframe_stride = r.nullable_integer(j, "keyframe_stride", "");
    rt.repeats = r.nullable_integer(j, "repeats", "");
    const json& methods = r.array(j, "methods", "");
    for (size_t i = 0; i < methods.size(); ++i) {
        const std::string where = "methods[" + std::to_string(i) + "]";
        RenderTime::Row row;
        row.name = r.string(r.member(methods[i], "name", where), where + ".name");
        row.ovr = r.required_number(methods[i], "ovr", where);
        row.seconds = r.required_number(methods[i], "seconds", where);
        row.buffers = r.nullable_integer(methods[i], "buffers", where);
        rt.methods.push_back(row);
    }
    rt.time_ratio = r.required_number(j, "time_ratio", "");
    rt.ovr_ratio = r.required_number(j, "ovr_ratio", "");
    rt.correlation = r.nullable_number(j, "correlation", "");
    rt.unshaded_seconds = r.nullable_number(j, "unshaded_seconds", "");
    return rt;
}

// Every report of a subfolder into `reports`, keyed "folder/name.json"; the keys, sorted.
std::vector<std::string> load_folder(const fs::path& dir, const std::string& folder,
                                     std::map<std::string, Report>& reports) {
    std::vector<std::string> keys;
    if (!fs::is_directory(dir / folder)) return keys;
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir / folder))
        if (entry.is_regular_file() && entry.path().extension() == ".json")
            names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    for (const std::string& n : names) {
        const std::string key = folder + "/" + n;
        reports.emplace(key, load_report(dir / folder / n, key));
        keys.push_back(key);
    }
    return keys;
}

}  // namespace

Inputs load_inputs(const fs::path& dir, const fs::path& notes_dir) {
    if (!fs::is_directory(dir)) throw std::runtime_error(dir.string() + ": not a folder");
    if (!fs::is_directory(notes_dir)) throw std::runtime_error(notes_dir.string() + ": not a folder");
    Inputs in;
    for (const char* name : {"ganfaul-idle.json", "ganfaul-idle-sub1.json", "ganfaul-idle-sub2.json",
                             "sweep-views.json", "sweep-lambda.json", "sweep-k.json", "ganfaul-clips.json"})
        if (fs::is_regular_file(dir / name)) in.reports.emplace(name, load_report(dir / name, name));
    in.characters = load_folder(dir, "characters", in.reports);
    in.materials = load_folder(dir, "materials", in.reports);
    // Issue 15's measured cluster orders: three Ganfaul reports and one per character.
    for (const std::string& key : load_folder(dir, "measured", in.reports))
        if (key != "measured/ganfaul-idle.json" && key != "measured/sweep-k.json" &&
            key != "measured/ganfaul-clips.json")
            in.measured_characters.push_back(key);
    if (fs::is_regular_file(dir / "render-time.json"))
        in.render_time = std::make_unique<RenderTime>(load_render_time(dir / "render-time.json", "render-time.json"));
    std::vector<fs::path> files;
    for (const auto& entry : fs::directory_iterator(dir))
        if (entry.is_regular_file()) files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    for (const fs::path& p : files)
        if (p.extension() == ".txt") in.texts[p.filename().string()] = read_text(p);
    files.clear();
    for (const auto& entry : fs::directory_iterator(notes_dir))
        if (entry.is_regular_file()) files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    for (const fs::path& p : files) {
        const std::string name = p.filename().string();
        if (name == "readme.md") {
            in.readme = read_text(p);
            in.has_readme = true;
        }
        if (name.rfind("notes-", 0) == 0 && p.extension() == ".md") {
            const std::string id = name.substr(6, name.size() - 9);
            if (std::find(kSectionIds.begin(), kSectionIds.end(), id) == kSectionIds.end())
                std::fprintf(stderr,
                             "make_results: %s names no section (ids: settings, table1, characters, views, lambda, "
                             "clusters, clips, render-time, nehab06, performance, other, materials); ignored\n",
                             name.c_str());
            else
                in.notes[id] = read_text(p);
        }
    }
    return in;
}

}  // namespace animorder::results
