// Which loader reads a file: by its extension (glTF, MD2 and IQM have readers of their own; every
// other format goes through assimp), and clip folders expanded to their files in name order.
#include "animorder/load.h"

#include "animorder/animated_mesh.h"
#include "animorder/assimp_loader.h"
#include "animorder/gltf_loader.h"
#include "animorder/iqm_loader.h"
#include "animorder/md2_loader.h"

#include "animorder/regular_file.h"

#include "gltf_buffer.h"
#include "lower_extension.h"

#include <tiny_gltf.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <unordered_set>

namespace animorder {
namespace {

using io::lower_extension;

// A clip folder stands for its regular files but hidden ones (.DS_Store), in name order.
// Filesystem errors (a link loop, a folder that cannot be listed) are LoadErrors naming the path.
std::vector<std::string> expand_clip_files(const std::vector<std::string>& clip_files) {
    namespace fs = std::filesystem;
    std::vector<std::string> files;
    for (const std::string& c : clip_files) {
        std::error_code error;
        if (!fs::is_directory(c, error)) {
            files.push_back(c);
            continue;
        }
        std::vector<std::string> inside;
        for (fs::directory_iterator it(c, error); !error && it != fs::directory_iterator(); it.increment(error)) {
            std::error_code entry_error;
            // A hidden file (.DS_Store, an editor's swap file) is no clip; any other file is read.
            if (it->is_regular_file(entry_error) && it->path().filename().string().rfind('.', 0) != 0)
                inside.push_back(it->path().string());
        }
        if (error) throw LoadError(c + ": cannot list the clip folder: " + error.message());
        std::sort(inside.begin(), inside.end());
        if (inside.empty()) throw LoadError(c + ": the clip folder is empty");
        files.insert(files.end(), inside.begin(), inside.end());
    }
    return files;
}

// tinygltf's urldecode: '+' is a space, %XY the byte XY (a digit that is not hex counts 0).
std::string decode_uri(const std::string& uri) {
    const auto hex = [](unsigned char c) -> unsigned {
        return c >= '0' && c <= '9'   ? c - '0'
               : c >= 'a' && c <= 'f' ? c - 'a' + 10
               : c >= 'A' && c <= 'F' ? c - 'A' + 10
                                      : 0;
    };
    std::string out;
    for (size_t i = 0; i < uri.size(); ++i) {
        if (uri[i] == '+') {
            out += ' ';
        } else if (uri[i] == '%' && uri.size() > i + 2) {
            out += char(hex(uri[i + 1]) << 4 | hex(uri[i + 2]));
            i += 2;
        } else {
            out += uri[i];
        }
    }
    return out;
}

// tinygltf's JoinPath: "a/b" (b alone when a is empty; no second '/' when a ends in one).
std::string join_path(const std::string& folder, const std::string& name) {
    if (folder.empty()) return name;
    return folder.back() == '/' ? folder + name : folder + "/" + name;
}

// The file tinygltf's FindFile takes for a decoded URI: the first of the glTF's folder (its
// GetBaseDir: the text before the last '/' or '\\') and the current folder where it finds the
// file, else the first (missing or irregular: the loader or require_regular_files says so).
std::string find_file(const std::string& gltf, const std::string& name) {
    const size_t slash = gltf.find_last_of("/\\");
    const std::string beside = join_path(slash == std::string::npos ? std::string() : gltf.substr(0, slash), name);
    std::error_code error;
    // As our FileExists (gltf_buffer.h): only a regular file is found; a FIFO beside the glTF with
    // a regular file in the current folder reads the latter, a FIFO in both is refused.
    if (std::filesystem::is_regular_file(beside, error)) return beside;
    const std::string here = join_path(".", name);
    return std::filesystem::is_regular_file(here, error) ? here : beside;
}

}  // namespace

std::vector<ExternalFile> gltf_external_uris(const std::string& path) {
    std::vector<ExternalFile> files;
    const std::string text = io::gltf_json_text(path);
    if (text.empty()) return files;
    const nlohmann::json doc = nlohmann::json::parse(text, nullptr, false);
    if (!doc.is_object()) return files;
    for (const char* list : {"buffers", "images"}) {
        const auto entries = doc.find(list);
        if (entries == doc.end() || !entries->is_array()) continue;
        for (const nlohmann::json& entry : *entries) {
            if (!entry.is_object()) continue;
            const auto uri = entry.find("uri");
            if (uri == entry.end() || !uri->is_string()) continue;
            const std::string& u = uri->get_ref<const std::string&>();
            // Empty: no file (a GLB's BIN chunk, an image left out); a data URI tinygltf decodes
            // (its own test: only some media types are) is inside the file.
            if (u.empty() || tinygltf::IsDataURI(u)) continue;
            files.push_back({u, find_file(path, decode_uri(u))});
        }
    }
    return files;
}

namespace {

std::vector<std::string> gltf_external_files(const std::string& path) {
    std::vector<std::string> files;
    for (const ExternalFile& f : gltf_external_uris(path)) files.push_back(f.file);
    return files;
}

}  // namespace

void add_files_read(std::vector<std::string>& files_read, const std::vector<std::string>& more) {
    std::unordered_set<std::string> listed(files_read.begin(), files_read.end());
    for (const std::string& file : more)
        if (listed.insert(file).second) files_read.push_back(file);
}

std::string file_extension(const std::string& path) { return lower_extension(path); }

bool carries_its_clips(const std::string& path) {
    const std::string extension = lower_extension(path);
    return extension == ".gltf" || extension == ".glb" || extension == ".md2" || extension == ".iqm";
}

std::vector<std::string> files_load_reads(const std::string& path, const std::vector<std::string>& clip_files) {
    std::vector<std::string> files = {path};
    const std::string extension = lower_extension(path);
    if (extension == ".gltf" || extension == ".glb") {
        const std::vector<std::string> external = gltf_external_files(path);
        files.insert(files.end(), external.begin(), external.end());
    }
    const std::vector<std::string> clips = expand_clip_files(clip_files);
    files.insert(files.end(), clips.begin(), clips.end());
    return files;
}

namespace {

// require_regular_files on the list already made.
void require_regular(const std::string& path, const std::vector<std::string>& files) {
    for (const std::string& file : files) {
        std::error_code error;
        const std::filesystem::file_status status = std::filesystem::status(file, error);
        if (std::filesystem::exists(status) && !std::filesystem::is_regular_file(status))
            throw LoadError(path + (file == path ? ": is " : ": reads " + file + ", which is ") +
                            (std::filesystem::is_directory(status) ? "a folder" : "not a regular file"));
    }
}

}  // namespace

void require_regular_files(const std::string& path, const std::vector<std::string>& clip_files) {
    // A FIFO or a device (a glTF buffer named /dev/zero, say) would never end: only regular files
    // are read. A missing one is left to its loader, which names it.
    require_regular(path, files_load_reads(path, clip_files));
}

AnimatedMesh load_character(const std::string& path, const std::vector<std::string>& clip_files,
                            const LoadOptions& options) {
    const std::vector<std::string> reads = files_load_reads(path, clip_files);
    require_regular(path, reads);
    if (options.files_read) add_files_read(*options.files_read, reads);
    const std::vector<std::string> files = expand_clip_files(clip_files);
    const std::string extension = lower_extension(path);
    if (carries_its_clips(path)) {
        if (!files.empty())
            throw LoadError(path + ": clip files apply to assimp formats (this file carries its clips)");
        if (extension == ".md2") return load_md2(path, options);
        if (extension == ".iqm") return load_iqm(path, options);
        return load_gltf(path, options);
    }
    return load_assimp(path, files, options);
}

}  // namespace animorder
