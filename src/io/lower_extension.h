// A file name's extension in lower case (".glb", ".md5mesh"), which the loaders dispatch and
// check on. Private to src/io.
#pragma once

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <string>

namespace animorder::io {

inline std::string lower_extension(const std::string& path) {
    std::string extension = std::filesystem::path(path).extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char ch) { return char(std::tolower(ch)); });
    return extension;
}

}  // namespace animorder::io
