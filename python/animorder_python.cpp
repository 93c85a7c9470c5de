// The Python module `animorder` (pybind11): characters from files or numpy arrays, any method with
// the CLI's settings, buffers and tables as numpy arrays, the overdraw evaluation, and the sidecar
// and glTF outputs, written as the tool writes them (README.md "From Python"; tests in
// python/tests, run by CTest; bench/bench_python.py measures its overhead over the CLI). A binding layer like tools/: it converts, the library computes.
// Long work runs without the GIL; the library's one-line errors become ValueError (bad input or
// settings) and OSError (files that cannot be read).
#include "animorder/animated_mesh.h"
#include "animorder/atomic_write.h"
#include "animorder/evaluation.h"
#include "animorder/gltf_writer.h"
#include "animorder/invalid_input.h"
#include "animorder/load.h"
#include "animorder/methods.h"
#include "animorder/procedural_character.h"
#include "animorder/sidecar.h"

#include "report.h"  // tools/animorder: the CLI's report entries

#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <string>
#include <type_traits>
#include <vector>

namespace py = pybind11;
using namespace animorder;

namespace {

// A loaded character and the file it came from (glTF output rewrites that file; "" for the
// bundled character and for arrays).
struct Character {
    AnimatedMesh mesh;
    std::string source;  // the file; "" for arrays and the bundled character
    std::string name;    // the report's "input"
};

// What a result must match to be written or evaluated with a character: its triangles, vertices
// and clips (a result of another character would index past this one's triangles).
std::string shape_of(const AnimatedMesh& m) {
    std::string clips;
    for (const Clip& c : m.clips) clips += (clips.empty() ? "" : ", ") + c.name + " (" + std::to_string(c.keyframe_count) + ")";
    return std::to_string(m.triangle_count()) + " triangles, " + std::to_string(m.vertex_count) + " vertices, clips " +
           clips;
}

struct Result {
    Method method = Method::Single;
    MethodResult run;
    std::string shape;        // shape_of the character it ran on
    std::string report_json;  // the CLI's report of `optimize` without settings, outputs and timings
};

// settings["lambda"] and friends, named as the CLI's options (dashes as underscores); anything
// else is a ValueError that lists the names.
// A setting's value as T, or InvalidInput naming the setting (a negative count, a string for a number).
template <typename T>
T setting(const std::string& key, const py::handle& value) {
    try {
        return value.cast<T>();
    } catch (const py::cast_error&) {
        throw InvalidInput("setting '" + key + "': " + std::string(py::str(py::repr(value))) + " is not " +
                           (std::is_same<T, bool>::value                ? "a bool"
                            : std::is_same<T, std::string>::value       ? "a string"
                            : std::is_floating_point<T>::value          ? "a number"
                                                                        : "a whole number of 0 or more"));
    }
}

MethodSettings method_settings(const py::dict& given) {
    MethodSettings s;
    ClusteringSettings& c = s.clustering;
    for (const auto& item : given) {
        const std::string key = py::str(item.first);
        const py::handle v = item.second;
        if (key == "lambda" || key == "lambda_") s.lambda = setting<double>(key, v);
        else if (key == "clusters" || key == "k") c.clusters = setting<size_t>(key, v);
        else if (key == "views") c.views = setting<size_t>(key, v);
        else if (key == "resolution") c.resolution = setting<unsigned>(key, v);
        else if (key == "seed") c.seed = setting<uint64_t>(key, v);
        else if (key == "min_separation") c.min_separation_deg = setting<double>(key, v);
        else if (key == "max_iterations") c.max_iterations = setting<size_t>(key, v);
        else if (key == "distance") c.distance = parse_distance(setting<std::string>(key, v));
        else if (key == "update") c.update = parse_update(setting<std::string>(key, v));
        else if (key == "front_levels") c.front_levels = setting<uint32_t>(key, v);
        else if (key == "fragment_memory") c.max_cache_bytes = setting<size_t>(key, v);
        else if (key == "threads") c.threads = setting<unsigned>(key, v);
        else if (key == "cache_size") s.cache_size = setting<unsigned>(key, v);
        else if (key == "frame") s.keyframe = setting<size_t>(key, v);
        else if (key == "nehab_clusters") s.nehab_clusters = setting<size_t>(key, v);
        else if (key == "nehab_views") s.nehab_views = setting<size_t>(key, v);
        else if (key == "nehab_all_keyframes") s.nehab_all_keyframes = setting<bool>(key, v);
        else if (key == "blend_clusters") s.blend_clusters = setting<bool>(key, v);
        else if (key == "planar_units") s.measured_planar_units = setting<bool>(key, v);
        else
            throw InvalidInput("unknown setting '" + key +
                               "' (lambda, clusters, views, resolution, seed, min_separation, max_iterations, "
                               "distance, update, front_levels, fragment_memory, threads, cache_size, frame, "
                               "nehab_clusters, nehab_views, nehab_all_keyframes, blend_clusters, planar_units)");
    }
    validate_method_settings(s);  // the CLI's ranges
    return s;
}

// Progress as the CLI shows it, to a Python callable (stage, done, total), with the GIL taken
// back for the call and only one worker calling at a time; an exception it raises ends the run.
void attach_progress(MethodSettings& s, const py::object& progress, std::mutex& lock) {
    if (progress.is_none()) return;
    s.clustering.progress = [&progress, &lock](const std::string& stage, size_t done, size_t total) {
        const std::lock_guard<std::mutex> held(lock);
        py::gil_scoped_acquire gil;
        progress(stage, done, total);
    };
}

py::array_t<uint32_t> to_numpy(const std::vector<uint32_t>& v) {
    py::array_t<uint32_t> a(py::ssize_t(v.size()));
    if (!v.empty()) std::memcpy(a.mutable_data(), v.data(), v.size() * sizeof(uint32_t));
    return a;
}

Character bundled_character() { return {make_procedural_character(), "", kProceduralCharacterName}; }

py::object json_to_python(const std::string& text) { return py::module_::import("json").attr("loads")(text); }

Character load(const std::string& path, const std::vector<std::string>& clips, size_t max_memory, unsigned threads) {
    LoadOptions options;
    options.max_keyframe_bytes = max_memory;
    options.clips = clips;
    options.threads = threads;
    Character c;
    {
        py::gil_scoped_release nogil;
        c.mesh = load_character(path, {}, options);
        if (!clips.empty()) c.mesh = select_clips(c.mesh, clips);
    }
    c.source = path;
    c.name = path;
    return c;
}

// positions: (keyframes, vertices, 3) float32; indices: (triangles, 3) or flat, unsigned; clips:
// [(name, keyframes), ...] covering the keyframes in order (default: one clip "clip").
Character from_arrays(const py::array_t<float, py::array::c_style | py::array::forcecast>& positions,
                      const py::array_t<uint32_t, py::array::c_style | py::array::forcecast>& indices,
                      const std::vector<std::pair<std::string, size_t>>& clips, double sample_rate) {
    if (positions.ndim() != 3 || positions.shape(2) != 3)
        throw InvalidInput("positions must have the shape (keyframes, vertices, 3)");
    if (!(indices.ndim() == 1 || (indices.ndim() == 2 && indices.shape(1) == 3)))
        throw InvalidInput("indices must have the shape (triangles, 3) or (3 * triangles,)");
    if (indices.size() % 3 != 0) throw InvalidInput("indices: " + std::to_string(indices.size()) + " is no multiple of 3");
    if (!(sample_rate > 0 && std::isfinite(sample_rate))) throw InvalidInput("sample_rate must be a positive number");
    Character c;
    c.name = "arrays";
    AnimatedMesh& m = c.mesh;
    m.name = "arrays";
    m.vertex_count = size_t(positions.shape(1));
    const size_t keyframes = size_t(positions.shape(0));
    m.keyframe_positions.assign(positions.data(), positions.data() + positions.size());
    m.indices.assign(indices.data(), indices.data() + indices.size());
    Primitive p;
    p.name = "arrays";
    p.index_count = m.indices.size();
    p.vertex_count = m.vertex_count;
    m.primitives.push_back(p);
    const std::vector<std::pair<std::string, size_t>> given =
        clips.empty() ? std::vector<std::pair<std::string, size_t>>{{"clip", keyframes}} : clips;
    size_t first = 0;
    for (const auto& [name, count] : given) {
        if (count == 0 || count > keyframes - first)
            throw InvalidInput("clips: '" + name + "' has " + std::to_string(count) + " keyframes, but " +
                               std::to_string(keyframes - first) + " are left of the " + std::to_string(keyframes));
        Clip clip;
        clip.name = name;
        clip.sample_rate = sample_rate;
        clip.first_keyframe = first;
        clip.keyframe_count = count;
        clip.duration_s = double(count - 1) / sample_rate;
        m.clips.push_back(clip);
        first += count;
    }
    if (first != keyframes)
        throw InvalidInput("clips cover " + std::to_string(first) + " of the " + std::to_string(keyframes) + " keyframes");
    validate_animated_mesh(m);  // out-of-range indices, NaN positions, ...
    return c;
}

Result run(const Character& c, const std::string& method_name, const py::dict& settings, const py::object& progress) {
    Method method = parse_method(method_name);
    MethodSettings s = method_settings(settings);
    std::mutex lock;
    attach_progress(s, progress, lock);
    Result r;
    r.method = method;
    r.shape = shape_of(c.mesh);
    {
        py::gil_scoped_release nogil;
        r.run = run_validated_method(c.mesh, method, s);
        nlohmann::ordered_json report = tool::report_header(c.mesh, c.name);
        report["input_order"] = tool::cache_stats_json(analyze_mesh_vertex_cache(c.mesh, c.mesh.indices, s.cache_size));
        report["methods"] = nlohmann::ordered_json::array({tool::method_entry(c.mesh, r.run, s, std::nullopt)});
        r.report_json = tool::report_text(report);
    }
    return r;
}

void check_shape(const Character& c, const Result& r) {
    if (r.shape != shape_of(c.mesh))
        throw InvalidInput("this result was run on a character of " + r.shape + ", not on this one (" + shape_of(c.mesh) +
                           ")");
}

py::dict evaluate(const Character& c, const py::sequence& given, size_t views, unsigned resolution, uint64_t seed,
                  unsigned threads) {
    if (views < 1 || views > 100000) throw InvalidInput("views must be between 1 and 100000");  // the CLI's ranges
    if (resolution < 1 || resolution > 8192) throw InvalidInput("resolution must be between 1 and 8192");
    std::vector<const Result*> results;
    for (size_t i = 0; i < given.size(); ++i) {
        const py::object item = given[i];
        if (!py::isinstance<Result>(item))
            throw InvalidInput("results[" + std::to_string(i) + "] is " + std::string(py::str(py::repr(item))) +
                               ", not a result of animorder.run");
        results.push_back(&item.cast<const Result&>());
        check_shape(c, *results.back());
    }
    EvaluationSettings e;
    e.views = views;
    e.resolution = resolution;
    e.seed = seed;
    e.threads = threads;
    std::vector<MethodBuffers> buffers;
    for (const Result* r : results) buffers.push_back(r->run.buffers);
    std::vector<OrderEvaluation> out;
    {
        py::gil_scoped_release nogil;
        out = evaluate_methods(c.mesh, buffers, e);
    }
    py::list methods;
    for (size_t i = 0; i < out.size(); ++i) {
        py::dict per_clip;
        for (size_t k = 0; k < c.mesh.clips.size(); ++k)
            per_clip[py::str(c.mesh.clips[k].name)] = out[i].per_clip[k].ovr_mean;
        py::dict m;
        m["name"] = method_name(results[i]->method);
        m["ovr_mean"] = out[i].overall.ovr_mean;
        m["ovr_pooled"] = out[i].overall.ovr_pooled;
        m["nodes"] = out[i].overall.nodes;
        m["per_clip"] = per_clip;
        methods.append(m);
    }
    py::dict report;
    report["views"] = views;
    report["resolution"] = resolution;
    report["seed"] = seed;
    report["methods"] = methods;
    return report;
}

// OUT.animorder.bin and OUT.animorder.json, both or neither, as `optimize -o OUT` writes them.
void write_sidecar(const Character& c, const Result& r, const std::string& out) {
    check_shape(c, r);
    const std::string bin = out + ".animorder.bin", json = out + ".animorder.json";
    OutputSet files;
    files.add(bin, serialize_sidecar(c.mesh, r.run.buffers, r.run.framing));
    files.add(json, sidecar_json(c.mesh, r.run.buffers, method_name(r.method), r.run.fallback,
                                 std::filesystem::path(bin).filename().string()));
    files.commit();
}

// The glTF input with the orders in its extension, as `optimize IN -o OUT.glb|.gltf` writes it.
void write_gltf(const Character& c, const Result& r, const std::string& out) {
    check_shape(c, r);
    const std::string extension = file_extension(out);
    if (c.source.empty() || (file_extension(c.source) != ".gltf" && file_extension(c.source) != ".glb"))
        throw InvalidInput("write_gltf needs a character loaded from a glTF file (this one: " +
                           (c.source.empty() ? std::string("arrays or the bundled character") : c.source) + ")");
    if (extension != ".gltf" && extension != ".glb") throw InvalidInput("write_gltf: " + out + " is no .gltf or .glb");
    std::error_code error;
    if (std::filesystem::equivalent(out, c.source, error))
        throw InvalidInput("write_gltf: " + out + " is the input");
    OutputSet files;
    files.add(out, gltf_with_orders(c.source, out, c.mesh, r.run.buffers, r.run.fallback, r.run.framing,
                                    method_name(r.method), extension == ".glb", nullptr));
    files.commit();
}

}  // namespace

PYBIND11_MODULE(animorder, m) {
    m.doc() = "animorder: triangle orders for animated meshes with little overdraw (Han & Sander 2017 and beyond)";
    m.attr("__version__") = library_version();
    py::register_exception<InvalidInput>(m, "InvalidInput", PyExc_ValueError);
    py::register_exception<LoadError>(m, "LoadError", PyExc_OSError);
    py::register_exception<OutputError>(m, "OutputError", PyExc_OSError);
    py::register_exception_translator([](std::exception_ptr p) {
        try {
            if (p) std::rethrow_exception(p);
        } catch (const std::filesystem::filesystem_error& e) {
            PyErr_SetString(PyExc_OSError, e.what());
        }
    });

    py::class_<Character>(m, "Character")
        .def_property_readonly("triangles", [](const Character& c) { return c.mesh.triangle_count(); })
        .def_property_readonly("vertices", [](const Character& c) { return c.mesh.vertex_count; })
        .def_property_readonly("keyframes", [](const Character& c) { return c.mesh.keyframe_count(); })
        .def_property_readonly("clips",
                               [](const Character& c) {
                                   std::vector<std::pair<std::string, size_t>> out;
                                   for (const Clip& clip : c.mesh.clips) out.emplace_back(clip.name, clip.keyframe_count);
                                   return out;
                               })
        .def_property_readonly("indices", [](const Character& c) { return to_numpy(c.mesh.indices); })
        .def_property_readonly("positions", [](const Character& c) {
            py::array_t<float> a({py::ssize_t(c.mesh.keyframe_count()), py::ssize_t(c.mesh.vertex_count), py::ssize_t(3)});
            if (!c.mesh.keyframe_positions.empty())
                std::memcpy(a.mutable_data(), c.mesh.keyframe_positions.data(),
                            c.mesh.keyframe_positions.size() * sizeof(float));
            return a;
        });

    py::class_<Result>(m, "Result")
        .def_property_readonly("method", [](const Result& r) { return std::string(method_name(r.method)); })
        .def_property_readonly("orders",
                               [](const Result& r) {
                                   py::list out;
                                   for (const auto& o : r.run.buffers.orders) out.append(to_numpy(o));
                                   return out;
                               })
        .def_property_readonly("tables",
                               [](const Result& r) {
                                   py::list out;
                                   for (const SelectionTable& t : r.run.buffers.tables) {
                                       py::array_t<uint8_t> a({py::ssize_t(t.keyframes), py::ssize_t(t.theta_steps),
                                                               py::ssize_t(t.phi_steps)});
                                       if (!t.cells.empty()) std::memcpy(a.mutable_data(), t.cells.data(), t.cells.size());
                                       out.append(a);
                                   }
                                   return out;
                               })
        .def_property_readonly("table_base", [](const Result& r) { return to_numpy(r.run.buffers.table_base); })
        .def_property_readonly("fallback", [](const Result& r) { return r.run.fallback; })
        .def_property_readonly("acmr", [](const Result& r) { return r.run.acmr_mean; })
        .def_property_readonly("report", [](const Result& r) { return json_to_python(r.report_json); },
                               "The CLI's JSON report of `optimize` as a dict (no settings, outputs or timings)");

    m.def("bundled_character", &bundled_character, "The procedural character the CLI uses without an input");
    m.def("load", &load, py::arg("path"), py::arg("clips") = std::vector<std::string>{},
          py::arg("max_memory") = size_t(4) << 30, py::arg("threads") = 0u,
          "A character from a file the CLI reads (glTF, FBX, Collada, MD2, IQM, ...), these clips only");
    m.def("from_arrays", &from_arrays, py::arg("positions"), py::arg("indices"),
          py::arg("clips") = std::vector<std::pair<std::string, size_t>>{}, py::arg("sample_rate") = 30.0,
          "A character from positions (keyframes, vertices, 3) and indices (triangles, 3)");
    m.def(
        "run",
        [](const Character& c, const std::string& method, const py::object& progress, const py::kwargs& settings) {
            return run(c, method, settings ? py::dict(settings) : py::dict(), progress);
        },
        py::arg("character"), py::arg("method") = std::string(method_name(kDefaultMethod)),
        py::arg("progress") = py::none(),
        "Runs a method with the CLI's settings as keywords (lambda_=0.85, clusters=5, views=162, ...)");
    m.def("evaluate", &evaluate, py::arg("character"), py::arg("results"), py::arg("views") = size_t(300),
          py::arg("resolution") = 512u, py::arg("seed") = kEvaluationSeed, py::arg("threads") = 0u,
          "OVR of each result's buffers over random views at every keyframe (as `animorder evaluate`)");
    m.def("write_sidecar", &write_sidecar, py::arg("character"), py::arg("result"), py::arg("out"),
          "OUT.animorder.bin and OUT.animorder.json, as `animorder optimize -o OUT`");
    m.def("write_gltf", &write_gltf, py::arg("character"), py::arg("result"), py::arg("out"),
          "The glTF input with the orders, as `animorder optimize IN -o OUT.glb`");
}
