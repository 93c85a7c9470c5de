// Why tinygltf could not read a glTF file, said plainly (gltf_diagnose.h). Internal to src/io.
#include "gltf_diagnose.h"

#include "animorder/regular_file.h"

#include "lower_extension.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

namespace animorder::io {

bool nests_too_deep(const std::string& text) {
    size_t depth = 0;
    bool in_string = false;
    for (size_t i = 0; i < text.size(); ++i) {
        const char c = text[i];
        if (in_string) {
            if (c == '\\')
                ++i;
            else if (c == '"')
                in_string = false;
        } else if (c == '"') {
            in_string = true;
        } else if (c == '[' || c == '{') {
            if (++depth > kMaxJsonDepth) return true;
        } else if ((c == ']' || c == '}') && depth > 0) {
            --depth;
        }
    }
    return false;
}

namespace diagnose_detail {
namespace {

constexpr uint64_t kMaxDiagnosedJson = uint64_t(1) << 30;  // as gltf_json_text reads
constexpr uint32_t kChunkJson = 0x4E4F534A, kChunkBin = 0x004E4942;

std::string hex32(uint32_t v) {
    char text[16];
    std::snprintf(text, sizeof text, "0x%08x", unsigned(v));
    return text;
}

// "JSON", "BIN" or "type 0x...": a chunk's type as named in a message.
std::string chunk_name(uint32_t type) {
    return type == kChunkJson ? "JSON" : type == kChunkBin ? "BIN" : "type " + hex32(type);
}
// How a chunk is named after "chunk N is": "JSON", "BIN" or "of type 0x...".
std::string chunk_kind(uint32_t type) {
    return (type == kChunkJson || type == kChunkBin ? "" : "of ") + chunk_name(type);
}
std::string chunk_label(size_t index, uint32_t type) {
    return "chunk " + std::to_string(index) + " (" + chunk_name(type) + ")";
}

std::string counted(size_t n, const char* what) { return std::to_string(n) + " " + what + (n == 1 ? "" : "s"); }

uint32_t le32(const unsigned char* p) {
    return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}

// Reads exactly `count` bytes (false when the file ends first).
bool read_exactly(RegularFile& file, void* into, size_t count) { return file.read(into, count) == count; }

// Reads past `count` bytes through a small buffer (nothing allocated from the file's sizes).
bool skip(RegularFile& file, uint64_t count) {
    char scrap[1 << 16];
    while (count > 0) {
        const size_t step = size_t(std::min<uint64_t>(count, sizeof scrap));
        if (!read_exactly(file, scrap, step)) return false;
        count -= step;
    }
    return true;
}

std::string trimmed(const std::string& s) {
    size_t b = 0, e = s.size();
    while (b < e && std::isspace(uint8_t(s[b]))) ++b;
    while (e > b && std::isspace(uint8_t(s[e - 1]))) --e;
    return s.substr(b, e - b);
}

// What the GLB's chunk walk found; `problem` empty when its structure holds.
struct GlbWalk {
    std::string problem;
    std::string json;       // chunk 0's text, when it is a JSON chunk of at most kMaxDiagnosedJson bytes
    bool has_json = false;  // `json` was read
    bool has_bin = false;   // chunk 1 is BIN
    uint32_t bin_length = 0;
};

// The first problem of the GLB structure (glTF 2.0 §4.4) of `file`, `size` bytes long, whose
// first 4 bytes ("glTF") are read already. Problems tinygltf itself lets pass (a JSON chunk of a
// length that is no multiple of 4, bytes after the length the header says) are named only when
// `glb_error` (tinygltf failed on the GLB's structure, not on its JSON).
GlbWalk walk_glb(RegularFile& file, uint64_t size, bool glb_error) {
    GlbWalk walk;
    unsigned char header[12];  // magic, version, length
    if (size < 12 || !read_exactly(file, header + 4, 8)) {
        walk.problem =
            "its GLB header is cut short: the file has " + std::to_string(size) + " bytes, a GLB header alone 12";
        return walk;
    }
    const uint32_t version = le32(header + 4), length = le32(header + 8);
    std::string soft;  // the first problem tinygltf lets pass (it reads no version and no chunk past 1)
    if (version != 2) {
        soft = "its GLB header says version " + std::to_string(version) + (version == 1 ? " (a glTF 1.0 binary)" : "") +
               "; a glTF 2.0 GLB is version 2";
        if (glb_error) {  // a glTF 1.0 binary's header and chunks differ: that is why
            walk.problem = soft;
            return walk;
        }
    }
    if (length < 12) {
        walk.problem = "its GLB header says " + std::to_string(length) + " bytes, less than the 12 of the header";
        return walk;
    }
    if (uint64_t(length) > size) {
        walk.problem = "its GLB header says " + std::to_string(length) + " bytes, the file has " + std::to_string(size);
        return walk;
    }
    const uint64_t end = length;  // the chunks lie within what the header says (checked: <= size)
    const std::string mismatch =
        "its GLB header says " + std::to_string(length) + " bytes, the file has " + std::to_string(size);
    // Past the length the header says: that length is wrong (the file goes on), or the file ends.
    const auto past = [&](const std::string& what) { return end < size ? mismatch : what + " the end of the file"; };
    if (end < size && soft.empty()) soft = mismatch;
    // A problem of chunk i: chunks 0 and 1 are tinygltf's to read, so their problems are why it
    // failed; past them, only when tinygltf failed on the structure (else its own reason stands).
    const auto found = [&](size_t i, const std::string& what) {
        if (i <= 1)
            walk.problem = what;
        else if (soft.empty())
            soft = what;
    };
    uint64_t at = 12;
    size_t bin_chunk = 0;  // the index of the first BIN chunk; 0: none
    uint32_t chunk1_type = 0;
    for (size_t i = 0;; ++i) {
        if (at == end) {
            if (i == 0) walk.problem = "it has no chunks after its 12-byte header; a GLB needs a JSON chunk";
            break;
        }
        unsigned char chunk[8];
        if (end - at < 8 || !read_exactly(file, chunk, 8)) {
            found(i, past("chunk " + std::to_string(i) + "'s 8-byte header runs past"));
            break;
        }
        const uint32_t chunk_length = le32(chunk), type = le32(chunk + 4);
        at += 8;
        if (uint64_t(chunk_length) > end - at) {
            found(i, past(chunk_label(i, type) + " runs past") + ": it says " + std::to_string(chunk_length) +
                         " bytes, " + std::to_string(end - at) + " follow its header");
            break;
        }
        if (i == 0 && type != kChunkJson) {
            walk.problem = "chunk 0 is " + chunk_kind(type) + "; a GLB starts with its JSON chunk";
            return walk;
        }
        if (i == 0 && chunk_length == 0) {
            walk.problem = "its JSON chunk is empty";
            return walk;
        }
        if (i > 0 && type == kChunkJson) {
            found(i, "two JSON chunks (0 and " + std::to_string(i) + "); a GLB has one");
            break;
        }
        if (type == kChunkBin && bin_chunk > 0) {
            found(i, "two BIN chunks (" + std::to_string(bin_chunk) + " and " + std::to_string(i) +
                         "); a GLB has at most one");
            break;
        }
        if (type == kChunkBin && i > 1) {
            found(i, "chunk " + std::to_string(i) + " is BIN; a GLB's BIN chunk can only be its second, chunk 1");
            break;
        }
        if (chunk_length % 4 != 0) {
            const std::string unaligned =
                chunk_label(i, type) + " is " + std::to_string(chunk_length) + " bytes long, not a multiple of 4";
            if (i == 1) {  // tinygltf refuses it (it never looks past chunk 1)
                walk.problem = unaligned;
                return walk;
            }
            if (soft.empty()) soft = unaligned;
        }
        if (type == kChunkBin) bin_chunk = i, walk.has_bin = true, walk.bin_length = chunk_length;
        if (i == 1) chunk1_type = type;
        if (i == 0 && chunk_length <= kMaxDiagnosedJson) {
            walk.json.assign(chunk_length, '\0');
            walk.has_json = read_exactly(file, walk.json.data(), chunk_length);
            if (!walk.has_json) walk.json.clear();
            if (!walk.has_json) break;
        } else if (!skip(file, chunk_length)) {
            break;  // the file changed under us: say no more
        }
        at += chunk_length;
    }
    if (!walk.problem.empty() || !glb_error) return walk;  // else tinygltf's reason is about the JSON
    // The structure holds; what tinygltf (which reads chunk 0 and chunk 1 only) cannot take.
    if (chunk1_type != 0 && chunk1_type != kChunkBin)
        walk.problem = "chunk 1 is of unknown type " + hex32(chunk1_type) +
                       "; glTF says to skip such chunks, but tinygltf (the reader used) cannot";
    else if (walk.has_bin && walk.bin_length == 0)
        walk.problem = "its BIN chunk is empty, which tinygltf (the reader used) refuses; leave the chunk out";
    else
        walk.problem = soft;
    return walk;
}

bool is_object_with(const nlohmann::json& j, const char* key) { return j.is_object() && j.contains(key); }

// The JSON's first skin without joints, or whose joints are no list of node indices (tinygltf
// fails on it without a word of its own, after the other skins' complaints it lets pass: "'inverse
// BindMatrices' property is missing"); "" when none. An empty list (tinygltf takes it) counts only
// when `empty_list`.
std::string skin_problem(const nlohmann::json& doc, bool empty_list) {
    if (!is_object_with(doc, "skins") || !doc["skins"].is_array()) return {};
    for (size_t s = 0; s < doc["skins"].size(); ++s) {
        const nlohmann::json& skin = doc["skins"][s];
        if (!skin.is_object()) continue;
        const std::string name = "skin " + std::to_string(s);
        if (!skin.contains("joints") || (empty_list && skin["joints"].is_array() && skin["joints"].empty()))
            return name + " has no joints";
        const nlohmann::json& joints = skin["joints"];
        if (!joints.is_array() ||
            std::any_of(joints.begin(), joints.end(), [](const nlohmann::json& j) { return !j.is_number_integer(); }))
            return name + "'s joints are not a list of node indices";
    }
    return {};
}

// The first buffer from `first` on without a uri; -1 when none.
long buffer_without_uri(const nlohmann::json& doc, size_t first) {
    if (!is_object_with(doc, "buffers") || !doc["buffers"].is_array()) return -1;
    for (size_t b = first; b < doc["buffers"].size(); ++b)
        if (doc["buffers"][b].is_object() && !doc["buffers"][b].contains("uri")) return long(b);
    return -1;
}
std::string no_uri(long buffer) {
    return "buffer " + std::to_string(buffer) +
           " has no uri; for tinygltf (the reader used), only a .glb's first buffer (its BIN chunk) may leave it out";
}

// The first primitive whose indices name no accessor, or an accessor without a usable buffer view
// (tinygltf's "primitive indices accessor out of bounds", "accessor[N] invalid bufferView"); "" when none.
std::string indices_problem(const nlohmann::json& doc) {
    if (!is_object_with(doc, "meshes") || !doc["meshes"].is_array()) return {};
    const nlohmann::json none = nlohmann::json::array();
    const nlohmann::json& accessors = is_object_with(doc, "accessors") ? doc["accessors"] : none;
    const size_t views =
        is_object_with(doc, "bufferViews") && doc["bufferViews"].is_array() ? doc["bufferViews"].size() : 0;
    for (size_t m = 0; m < doc["meshes"].size(); ++m) {
        const nlohmann::json& mesh = doc["meshes"][m];
        if (!is_object_with(mesh, "primitives") || !mesh["primitives"].is_array()) continue;
        for (size_t p = 0; p < mesh["primitives"].size(); ++p) {
            const nlohmann::json& primitive = mesh["primitives"][p];
            if (!is_object_with(primitive, "indices") || !primitive["indices"].is_number_unsigned()) continue;
            const uint64_t a = primitive["indices"].get<uint64_t>();
            const std::string what = "mesh " + std::to_string(m) + " primitive " + std::to_string(p) + "'s indices";
            if (!accessors.is_array() || a >= accessors.size())
                return what + " name accessor " + std::to_string(a) + "; the file has " +
                       counted(accessors.is_array() ? accessors.size() : 0, "accessor");
            const nlohmann::json& accessor = accessors[size_t(a)];
            if (!is_object_with(accessor, "bufferView"))
                return what + " (accessor " + std::to_string(a) +
                       ") have no bufferView, which tinygltf (the reader used) refuses; without one they would all "
                       "be 0";
            if (accessor["bufferView"].is_number_unsigned() && accessor["bufferView"].get<uint64_t>() >= views)
                return "accessor " + std::to_string(a) + " (" + what + ") names bufferView " +
                       accessor["bufferView"].dump() + "; the file has " + counted(views, "buffer view");
        }
    }
    return {};
}

}  // namespace

std::string deduplicated(const std::string& error) {
    std::vector<std::string> seen;
    std::string out;
    size_t from = 0;
    while (from <= error.size()) {
        size_t nl = error.find_first_of("\r\n", from);
        if (nl == std::string::npos) nl = error.size();
        const std::string line = error.substr(from, nl - from);
        from = nl + 1;
        std::string kept;
        size_t s = 0;
        while (s < line.size()) {  // sentences: up to ". " or the line's end
            size_t stop = line.find(". ", s);
            stop = stop == std::string::npos ? line.size() : stop + 1;
            const std::string sentence = trimmed(line.substr(s, stop - s));
            s = stop;
            if (sentence.empty() || std::find(seen.begin(), seen.end(), sentence) != seen.end()) continue;
            seen.push_back(sentence);
            kept += (kept.empty() ? "" : " ") + sentence;
        }
        if (!kept.empty()) out += (out.empty() ? "" : out.back() == '.' ? " " : "; ") + kept;
    }
    return out;
}

namespace {

// nlohmann's message without its "[json.exception.parse_error.101] " prefix.
std::string without_exception_id(std::string what) {
    const size_t close = what.find("] ");
    if (what.rfind("[json.exception.", 0) == 0 && close != std::string::npos) what.erase(0, close + 2);
    return what;
}

// What is wrong in the glTF JSON `text` ("" when none of these checks finds it).
std::string json_problem(const std::string& text, const std::string& error, bool glb, const GlbWalk* walk) {
    if (nests_too_deep(text)) return {};  // check_json_depth refuses it before tinygltf anyway
    nlohmann::json doc;
    const std::string where = glb ? "its JSON chunk" : "its JSON";
    try {
        doc = nlohmann::json::parse(text);
    } catch (const nlohmann::json::parse_error& e) {  // "parse error at line 1, column 2: syntax error ..."
        return where + " does not parse: " + without_exception_id(e.what());
    } catch (const nlohmann::json::exception& e) {  // "number overflow parsing '1e309'"
        return where + " cannot be read: " + without_exception_id(e.what());
    }
    if (!doc.is_object()) {
        const std::string type = doc.type_name();
        return std::string(glb ? "its JSON chunk's root is " : "its JSON root is ") +
               (type == "array" || type == "object" ? "an " : "a ") + type + ", not an object";
    }
    if (!doc.contains("asset")) return where + " has no \"asset\", which every glTF 2.0 file has";
    const std::string skin = skin_problem(doc, trimmed(error).empty());
    if (!skin.empty()) return skin;
    if (!glb && error.find("'uri' is missing") != std::string::npos) {
        const long b = buffer_without_uri(doc, 0);
        if (b >= 0) return no_uri(b);
    }
    if (glb && (error.find("byteLength") != std::string::npos || error.find("binary data") != std::string::npos)) {
        const long b = buffer_without_uri(doc, 1);
        if (b >= 0) return no_uri(b);
        if (buffer_without_uri(doc, 0) == 0 && walk && !walk->has_bin)
            return "buffer 0 has no uri, and the file has no BIN chunk for it to be";
        if (walk && walk->has_bin && buffer_without_uri(doc, 0) == 0) {  // buffer 0 is the BIN chunk
            const nlohmann::json& length =
                is_object_with(doc["buffers"][0], "byteLength") ? doc["buffers"][0]["byteLength"] : nlohmann::json();
            if (length.is_number_unsigned() && length.get<uint64_t>() > walk->bin_length)
                return "buffer 0 (its BIN chunk) has a byteLength of " + length.dump() + ", but its BIN chunk holds " +
                       std::to_string(walk->bin_length) + " bytes";
        }
    }
    if (error.find("invalid bufferView") != std::string::npos ||
        error.find("indices accessor out of bounds") != std::string::npos) {
        const std::string indices = indices_problem(doc);
        if (!indices.empty()) return indices;
    }
    return {};
}

}  // namespace
}  // namespace diagnose_detail

std::string why_unreadable(const std::string& path, const std::string& tinygltf_error) {
    using namespace diagnose_detail;
    const std::string fallback = deduplicated(tinygltf_error);
    const std::string unknown =
        "tinygltf (the reader used) gave no reason; the Khronos glTF validator "
        "(https://github.khronos.org/glTF-Validator/) may say what is wrong";
    const auto told = [&](const std::string& found) {
        if (!found.empty()) return found;
        return fallback.empty() ? unknown : fallback;
    };
    // The file could not be read whole (the loading budget, a buffer's file): tinygltf said so.
    if (tinygltf_error.rfind("Failed to read file", 0) == 0) return told({});
    RegularFile file(path);
    if (!file.ok()) return told({});
    const uint64_t size = file.size();
    char magic[4] = {};
    const size_t got = file.read(magic, 4);
    if (got == 4 && std::memcmp(magic, "glTF", 4) == 0) {
        // tinygltf failed on the GLB's structure ("Invalid glTF binary.", "Invalid type for chunk1
        // data.", "BIN Chunk end does not aligned ..."), not on its JSON.
        bool glb_error = false;
        for (const char* said : {"glTF Binary", "glTF binary", "Chunk1", "chunk1", "BIN Chunk"})
            glb_error = glb_error || tinygltf_error.find(said) != std::string::npos;
        const GlbWalk walk = walk_glb(file, size, glb_error);
        if (!walk.problem.empty()) return walk.problem;
        return told(walk.has_json ? json_problem(walk.json, tinygltf_error, true, &walk) : std::string());
    }
    if (size > kMaxDiagnosedJson) return told({});
    std::string text(magic, got);
    text.resize(size_t(size));
    if (size > got && !read_exactly(file, text.data() + got, text.size() - got)) return told({});
    const std::string found = json_problem(text, tinygltf_error, false, nullptr);
    // A .glb that is no GLB: say so rather than how its bytes fail as JSON.
    if (lower_extension(path) == ".glb" && (found.rfind("its JSON does not parse", 0) == 0 || size < 4))
        return "not a GLB: it does not start with 'glTF'";
    return told(found);
}

}  // namespace animorder::io
