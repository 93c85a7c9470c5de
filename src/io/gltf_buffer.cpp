// Buffer views for the glTF writers, and a glTF file read into a tinygltf model and written back
// (gltf_buffer.h). Internal to src/io.
#include "gltf_buffer.h"

#include "animorder/load.h"
#include "animorder/regular_file.h"

#include "gltf_diagnose.h"
#include "gltf_prune.h"

#include <tiny_gltf.h>
#include <nlohmann/json.hpp>

#include <sys/stat.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

namespace animorder::io {
namespace {

// tinygltf's file access of regular_file_callbacks (gltf_buffer.h), through RegularFile.
bool regular_file_exists(const std::string& path, void*) {
    struct stat st {};
    return ::stat(path.c_str(), &st) == 0 && S_ISREG(st.st_mode);
}

bool read_regular_file(std::vector<unsigned char>* out, std::string* error, const std::string& path, void* limit) {
    RegularFile file(path);
    const uint64_t most = limit ? *static_cast<const uint64_t*>(limit) : UINT64_MAX;
    std::string why = file.ok() ? "" : std::string("is ") + file.why();
    if (why.empty() && file.size() > most)
        why = "is larger than the loading budget of " + std::to_string(most) + " bytes (raise it with --max-memory)";
    if (why.empty()) {
        out->resize(size_t(file.size()));
        if (file.read(out->data(), out->size()) != out->size())
            why = "cannot be read whole";
        else if (out->empty())
            why = "is empty";
    }
    if (!why.empty() && error) *error += path + " " + why + "\n";
    return why.empty();
}

// The most JSON text gltf_json_text reads: 1 GiB.
constexpr uint64_t kMaxJsonBytes = uint64_t(1) << 30;

// LoadError when the file requires an extension that changes how its geometry is stored and
// that tinygltf does not decode (compressed meshes or buffers): read as if plain, its bytes would
// give garbage indices or a misleading size error. Other required extensions (quantised
// attributes, materials, textures) leave the geometry readable.
void refuse_undecodable_geometry(const std::vector<std::string>& required, const std::string& path) {
    for (const std::string& e : required)
        if (e == "KHR_draco_mesh_compression" || e == "EXT_meshopt_compression" || e == "KHR_meshopt_compression")
            throw LoadError(path + ": requires " + e +
                            ", compressed geometry that animorder cannot decode; give the file from before the "
                            "compression (gltfpack without -c or -cc, say)");
}

// `glb` (a whole GLB file) with its JSON chunk replaced by `json` (padded with spaces to 4 bytes),
// its lengths set; "" when `glb` has no readable JSON chunk first, or the result exceeds the 32-bit
// lengths GLB has.
std::string glb_with_json(const std::string& glb, std::string json) {
    uint32_t json_length = 0;
    if (glb.size() < 20 || std::memcmp(glb.data() + 16, "JSON", 4) != 0) return {};
    std::memcpy(&json_length, glb.data() + 12, 4);
    if (size_t(json_length) > glb.size() - 20) return {};
    while (json.size() % 4) json.push_back(' ');
    const size_t total = glb.size() - json_length + json.size();
    if (total > UINT32_MAX) return {};
    const uint32_t length = uint32_t(json.size()), whole = uint32_t(total);
    std::string out = glb.substr(0, 12);
    std::memcpy(&out[8], &whole, 4);
    out.append(reinterpret_cast<const char*>(&length), 4);
    out.append("JSON", 4);
    out += json;
    out.append(glb, 20 + size_t(json_length), std::string::npos);
    return out;
}

// An input object's `extras` on the output object, verbatim (tinygltf's values drop a null,
// shifting an array's elements); whether that changed it.
bool restore_extras(const nlohmann::ordered_json& in, nlohmann::ordered_json& out) {
    if (!in.contains("extras") || (out.contains("extras") && out["extras"] == in["extras"])) return false;
    out["extras"] = in["extras"];
    return true;
}

// An input object's `extras` (verbatim: tinygltf's values drop a null, shifting an array's
// elements) and each of its `extensions` the output lacks (tinygltf 2.7 writes neither for skins,
// channel targets, accessors, buffer views, buffers, samplers), put back on the output object it
// became, then the same for the objects nested under the same keys (a material's texture infos,
// a mesh's primitives, an animation's channels). The orders extension is never put back: the
// writer names the orders it wrote, and left out the stale ones on purpose (gltf_prune.h).
bool restore_extras_and_extensions(const nlohmann::ordered_json& in, nlohmann::ordered_json& out) {
    if (!in.is_object() || !out.is_object()) return false;
    bool changed = restore_extras(in, out);
    if (in.contains("extensions") && in["extensions"].is_object())
        for (const auto& [name, value] : in["extensions"].items()) {
            if (name == "ANIMORDER_animated_triangle_orders") continue;
            if (out.contains("extensions") && !out["extensions"].is_object()) break;
            if (out.contains("extensions") && out["extensions"].contains(name)) continue;
            out["extensions"][name] = value;
            changed = true;
        }
    for (const auto& [key, value] : in.items()) {
        if (key == "extras" || key == "extensions" || !out.contains(key)) continue;
        nlohmann::ordered_json& nested = out[key];
        if (value.is_object()) {
            changed = restore_extras_and_extensions(value, nested) || changed;
        } else if (value.is_array() && nested.is_array() && nested.size() == value.size()) {
            for (size_t i = 0; i < value.size(); ++i)
                changed = restore_extras_and_extensions(value[i], nested[i]) || changed;
        }
    }
    return changed;
}

// What tinygltf 2.7 changes between reading and writing a file, put back from the input's JSON:
// - the placeholder node of each animation channel whose target had none (json_with_placeholder_
//   nodes), taken out again;
// - a perspective camera's absent zfar (an infinite projection), written as 0, which glTF forbids;
// - an image given as a data: URI, whose bytes tinygltf decodes and then writes as no image at
//   all (no URI, buffer view -1): the URI, as the input has it;
// - extras and extensions tinygltf leaves out (restore_extras_and_extensions): on every object of
//   the top-level arrays, accessors, views and buffers followed through `renumbering` (the writer
//   left some out and moved others: gltf_prune.h), the others by their unchanged index.
// Returns whether `output` changed.
bool restore_what_tinygltf_drops(const nlohmann::ordered_json& input, nlohmann::ordered_json& output,
                                 const Renumbering& renumbering = {}) {
    bool changed = false;
    const auto array = [](const nlohmann::ordered_json& j, const char* key) {
        return j.is_object() && j.contains(key) && j[key].is_array();
    };
    const auto object = [](const nlohmann::ordered_json& j, const char* key) {
        return j.is_object() && j.contains(key) && j[key].is_object();
    };
    const size_t placeholder = size_t(kPlaceholderNode);
    if (array(output, "animations"))
        for (nlohmann::ordered_json& animation : output["animations"]) {
            if (!array(animation, "channels")) continue;
            for (nlohmann::ordered_json& channel : animation["channels"])
                if (object(channel, "target") && channel["target"].contains("node") &&
                    channel["target"]["node"].is_number_unsigned() &&
                    channel["target"]["node"].get<size_t>() == placeholder) {
                    channel["target"].erase("node");
                    changed = true;
                }
        }
    // `restore` on each object of the input's array `key` and the output's at the same index.
    const auto each_pair = [&](const char* key, const auto& restore) {
        if (array(input, key) && array(output, key))
            for (size_t i = 0; i < input[key].size() && i < output[key].size(); ++i)
                restore(input[key][i], output[key][i]);
    };
    each_pair("cameras", [&](const nlohmann::ordered_json& in, nlohmann::ordered_json& out) {
        if (object(in, "perspective") && !in["perspective"].contains("zfar") && object(out, "perspective") &&
            out["perspective"].contains("zfar")) {
            out["perspective"].erase("zfar");
            changed = true;
        }
    });
    each_pair("images", [&](const nlohmann::ordered_json& in, nlohmann::ordered_json& out) {
        if (!in.is_object() || !out.is_object() || !in.contains("uri") || !in["uri"].is_string() ||
            in["uri"].get<std::string>().rfind("data:", 0) != 0 || (out.contains("uri") && out["uri"] != ""))
            return;
        out["uri"] = in["uri"];
        for (const char* key : {"bufferView", "mimeType"})  // as the input has them (a data: URI needs neither)
            if (in.contains(key))
                out[key] = in[key];
            else
                out.erase(key);
        changed = true;
    });
    for (const auto& [key, list] : input.items()) {
        if (!list.is_array() || !array(output, key.c_str())) continue;
        const std::vector<int>* moved = key == "accessors"     ? &renumbering.accessors
                                        : key == "bufferViews" ? &renumbering.views
                                        : key == "buffers"     ? &renumbering.buffers
                                                               : nullptr;
        nlohmann::ordered_json& written = output[key];
        for (size_t i = 0; i < list.size(); ++i) {
            const int to = moved && !moved->empty() ? (i < moved->size() ? (*moved)[i] : -1) : int(i);
            if (to >= 0 && size_t(to) < written.size())
                changed = restore_extras_and_extensions(list[i], written[size_t(to)]) || changed;
        }
    }
    if (input.is_object() && output.is_object()) changed = restore_extras(input, output) || changed;
    return changed;
}

// `written` (tinygltf's output: GLB bytes when `binary`, else JSON text) with
// restore_what_tinygltf_drops applied against the input file's JSON.
std::string restore_from_input(const std::string& input_path, std::string written, bool binary,
                               const Renumbering& renumbering = {}) {
    const std::string input_text = gltf_json_text(input_path);
    const nlohmann::ordered_json input = nlohmann::ordered_json::parse(input_text, nullptr, false);
    if (input.is_discarded()) return written;
    std::string json_text = written;
    if (binary) {
        uint32_t json_length = 0;
        if (written.size() < 20 || std::memcmp(written.data() + 16, "JSON", 4) != 0) return written;
        std::memcpy(&json_length, written.data() + 12, 4);
        if (size_t(json_length) > written.size() - 20) return written;
        json_text = written.substr(20, json_length);
    }
    nlohmann::ordered_json output = nlohmann::ordered_json::parse(json_text, nullptr, false);
    if (output.is_discarded() || !restore_what_tinygltf_drops(input, output, renumbering)) return written;
    if (!binary) return output.dump(2);
    const std::string glb = glb_with_json(written, output.dump());
    return glb.empty() ? written : glb;
}

}  // namespace

int append_buffer_view(tinygltf::Model& model, const void* data, size_t bytes, int target) {
    if (model.buffers.empty()) model.buffers.emplace_back();
    std::vector<unsigned char>& buffer = model.buffers[0].data;
    while (buffer.size() % 4) buffer.push_back(0);
    tinygltf::BufferView view;
    view.buffer = 0;
    view.byteOffset = buffer.size();
    view.byteLength = bytes;
    view.target = target;
    const unsigned char* p = static_cast<const unsigned char*>(data);
    buffer.insert(buffer.end(), p, p + bytes);
    model.bufferViews.push_back(view);
    return int(model.bufferViews.size() - 1);
}

int append_accessor(tinygltf::Model& model, int view, int component, int type, size_t count, const std::string& name) {
    tinygltf::Accessor a;
    a.bufferView = view;
    a.byteOffset = 0;
    a.componentType = component;
    a.type = type;
    a.count = count;
    a.name = name;
    model.accessors.push_back(a);
    return int(model.accessors.size() - 1);
}

tinygltf::FsCallbacks regular_file_callbacks(const uint64_t* limit) {
    return {regular_file_exists, tinygltf::ExpandFilePath, read_regular_file, tinygltf::WriteWholeFile,
            const_cast<uint64_t*>(limit)};
}

std::string magic_of(const std::string& path) {
    RegularFile file(path);
    if (!file.ok())
        throw LoadError(
            path + (std::string(file.why()) == "missing" ? ": cannot open file" : std::string(": is ") + file.why()));
    std::string magic(4, '\0');
    const size_t got = file.read(magic.data(), 4);
    if (got == 0) throw LoadError(path + ": file is empty or truncated");
    magic.resize(got);
    return magic;
}

std::string gltf_json_text(const std::string& path) {
    RegularFile file(path);
    if (!file.ok()) return {};
    const uint64_t size = file.size();
    char header[20] = {};
    const size_t got = file.read(header, sizeof header);
    if (got >= 4 && std::memcmp(header, "glTF", 4) == 0) {
        if (got < 20) return {};
        uint32_t length = 0;
        std::memcpy(&length, header + 12, 4);  // chunk 0: length, type "JSON", then the text
        if (std::memcmp(header + 16, "JSON", 4) != 0 || uint64_t(length) > size - 20) return {};
        if (length > kMaxJsonBytes) throw LoadError(path + ": its glTF JSON is larger than 1 GiB");
        std::string text(length, '\0');
        return file.read(text.data(), length) == length ? text : std::string();
    }
    if (size > kMaxJsonBytes) throw LoadError(path + ": its glTF JSON is larger than 1 GiB");
    if (got < size_t(std::min<uint64_t>(size, sizeof header))) return {};
    std::string text(header, got);
    text.resize(size_t(size));
    return file.read(text.data() + got, text.size() - got) == text.size() - got ? text : std::string();
}

void check_json_depth(const std::string& path) {
    if (nests_too_deep(gltf_json_text(path)))
        throw LoadError(path + ": its JSON nests arrays and objects more than " + std::to_string(kMaxJsonDepth) +
                        " levels deep");
}

void finish_load(bool ok, std::string error, const tinygltf::Model& model, const std::string& path) {
    // glTF 1.0 (scenes named by strings, techniques...) reads as an empty 2.0 file: say what it is.
    const auto refuse_version = [&path](const std::string& version) {
        if (version.rfind("1.", 0) == 0 || version == "1")
            throw LoadError(path + ": is glTF " + version +
                            "; animorder reads glTF 2.0 (gltf-pipeline -i FILE -o NEW.gltf upgrades it)");
    };
    if (ok) {
        refuse_version(model.asset.version);
        return refuse_undecodable_geometry(model.extensionsRequired, path);
    }
    const nlohmann::json doc = nlohmann::json::parse(gltf_json_text(path), nullptr, false);
    if (doc.is_object() && doc.contains("asset") && doc["asset"].is_object() && doc["asset"].contains("version") &&
        doc["asset"]["version"].is_string())
        refuse_version(doc["asset"]["version"].get<std::string>());
    if (doc.is_object() && doc.contains("extensionsRequired") && doc["extensionsRequired"].is_array()) {
        std::vector<std::string> required;
        for (const nlohmann::json& e : doc["extensionsRequired"])
            if (e.is_string()) required.push_back(e.get<std::string>());
        refuse_undecodable_geometry(required, path);
    }
    error = why_unreadable(path, error);  // gltf_diagnose.h: its GLB structure or JSON looked at again
    for (char& c : error)
        if (c == '\n' || c == '\r') c = ' ';
    // tinygltf quotes what it could not read, a whole data: URI included: the start of it says enough.
    constexpr size_t kShown = 300;
    if (error.size() > kShown) {
        size_t cut = kShown;
        while (cut > 0 && (uint8_t(error[cut]) & 0xC0) == 0x80) --cut;  // not inside a UTF-8 character
        error = error.substr(0, cut) + "... (" + std::to_string(error.size()) + " characters)";
    }
    throw LoadError(path + ": not a readable glTF 2.0 file: " + error);
}

std::string json_with_placeholder_nodes(const std::string& text) {
    nlohmann::ordered_json j = nlohmann::ordered_json::parse(text, nullptr, false);
    if (!j.is_object() || !j.contains("animations") || !j["animations"].is_array()) return {};
    bool changed = false;
    for (nlohmann::ordered_json& animation : j["animations"])
        if (animation.is_object() && animation.contains("channels") && animation["channels"].is_array())
            for (nlohmann::ordered_json& channel : animation["channels"])
                if (channel.is_object() && channel.contains("target") && channel["target"].is_object() &&
                    !channel["target"].contains("node")) {
                    channel["target"]["node"] = kPlaceholderNode;
                    changed = true;
                }
    return changed ? j.dump() : std::string();
}

bool load_gltf_file(tinygltf::TinyGLTF& loader, tinygltf::Model& model, std::string& error, std::string& warning,
                    const std::string& path, bool binary, const uint64_t* budget) {
    try {
        const std::string patched = json_with_placeholder_nodes(gltf_json_text(path));
        if (patched.empty())
            return binary ? loader.LoadBinaryFromFile(&model, &error, &warning, path)
                          : loader.LoadASCIIFromFile(&model, &error, &warning, path);
        const size_t slash = path.find_last_of("/\\");
        const std::string base = slash == std::string::npos ? std::string() : path.substr(0, slash);  // tinygltf's
        constexpr size_t kMost = UINT32_MAX;  // tinygltf takes an unsigned length
        if (!binary) {
            if (patched.size() > kMost) return error = path + " is too large", false;
            return loader.LoadASCIIFromString(&model, &error, &warning, patched.data(), unsigned(patched.size()), base);
        }
        std::vector<unsigned char> bytes;
        if (!read_regular_file(&bytes, &error, path, const_cast<uint64_t*>(budget))) return false;
        const std::string glb = glb_with_json(std::string(bytes.begin(), bytes.end()), patched);
        if (glb.empty()) return loader.LoadBinaryFromFile(&model, &error, &warning, path);  // its own error
        return loader.LoadBinaryFromMemory(&model, &error, &warning, reinterpret_cast<const unsigned char*>(glb.data()),
                                           unsigned(glb.size()), base);
    } catch (const std::exception& e) {
        error = e.what();
        return false;
    }
}

tinygltf::Model read_model(const std::string& path) {
    require_regular_files(path);
    tinygltf::Model model;
    tinygltf::TinyGLTF loader;
    static const uint64_t budget = LoadOptions{}.file_budget();
    loader.SetFsCallbacks(regular_file_callbacks(&budget));
    loader.SetImageLoader([](tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*,
                             int, void*) { return true; },
                          nullptr);
    std::string error, warning;
    const std::string magic = magic_of(path);
    check_json_depth(path);
    const bool ok = load_gltf_file(loader, model, error, warning, path, magic == "glTF", &budget);
    finish_load(ok, error, model, path);
    return model;
}

std::string write_model(tinygltf::Model& model, const std::string& input_path, const std::string& output_path,
                        bool binary, const Renumbering& renumbering) {
    for (tinygltf::Buffer& b : model.buffers) b.uri.clear();
    namespace fs = std::filesystem;
    const fs::path from = fs::absolute(fs::path(input_path)).parent_path();
    const fs::path to = fs::absolute(fs::path(output_path)).parent_path();
    for (tinygltf::Image& image : model.images)
        if (!image.uri.empty() && image.uri.rfind("data:", 0) != 0 && image.uri.find("://") == std::string::npos &&
            fs::path(image.uri).is_relative() && from != to)
            image.uri = fs::relative(from / image.uri, to).generic_string();
    tinygltf::TinyGLTF writer;
    writer.SetImageWriter(
        [](const std::string*, const std::string*, const tinygltf::Image* image, bool, std::string* uri, void*) {
            *uri = image->uri;  // never decoded, never rewritten: external images keep their URIs
            return true;
        },
        nullptr);
    std::ostringstream out;
    if (!writer.WriteGltfSceneToStream(&model, out, !binary, binary))
        throw LoadError(input_path + ": writing the glTF output failed");
    return restore_from_input(input_path, out.str(), binary, renumbering);
}

}  // namespace animorder::io
