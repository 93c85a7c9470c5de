// Writing results: atomically (temp file in the same folder, then rename), never a half file.
#pragma once

#include <string>

namespace animorder::tool {

// Writes data to path atomically. Throws std::runtime_error naming the path on failure; the
// temporary file is removed then. An existing file at path is replaced: callers only pass paths
// the user named as outputs.
void write_file_atomically(const std::string& path, const std::string& data);

}  // namespace animorder::tool
