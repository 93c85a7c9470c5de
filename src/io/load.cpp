// Which loader reads a file: by its extension (glTF, MD2 and IQM have readers of their own; every
// other format goes through assimp), and clip folders expanded to their files in name order.
#include "animorder/load.h"

#include "animorder/animated_mesh.h"
#include "animorder/assimp_loader.h"
#include "animorder/gltf_loader.h"
#include "animorder/iqm_loader.h"
#include "animorder/md2_loader.h"

#include <algorithm>
#include <cctype>
#include <filesystem>

namespace animorder {

AnimatedMesh load_character(const std::string& path, const std::vector<std::string>& clip_files,
                            const LoadOptions& options) {
    std::vector<std::string> files;
    for (const std::string& c : clip_files) {
        if (std::filesystem::is_directory(c)) {
            std::vector<std::string> inside;
            for (const auto& entry : std::filesystem::directory_iterator(c))
                if (entry.is_regular_file()) inside.push_back(entry.path().string());
            std::sort(inside.begin(), inside.end());
            if (inside.empty()) throw LoadError(c + ": the clip folder is empty");
            files.insert(files.end(), inside.begin(), inside.end());
        } else {
            files.push_back(c);
        }
    }
    std::string extension = std::filesystem::path(path).extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char ch) { return char(std::tolower(ch)); });
    if (extension == ".gltf" || extension == ".glb" || extension == ".md2" || extension == ".iqm") {
        if (!files.empty())
            throw LoadError(path + ": clip files apply to assimp formats (this file carries its clips)");
        if (extension == ".md2") return load_md2(path, options);
        if (extension == ".iqm") return load_iqm(path, options);
        return load_gltf(path, options);
    }
    return load_assimp(path, files, options);
}

}  // namespace animorder
