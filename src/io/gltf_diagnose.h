// Why tinygltf could not read a glTF file, said plainly (finish_load in gltf_buffer.h calls it once
// tinygltf has failed; a file tinygltf reads never comes here). tinygltf 2.7 says "Invalid glTF
// binary." for every broken GLB, nothing at all for a skin without joints, and the same sentence
// several times over: the file is looked at again here, its GLB structure (glTF 2.0 §4.4) and its
// JSON, and the first problem found is named. Internal to src/io.
//
// The file is hostile: its sizes are checked before they are used (64-bit sums of 32-bit fields,
// nothing allocated beyond what the file holds), and it is read through RegularFile, never more
// than kMaxDiagnosedJson bytes of JSON.
#pragma once

#include <cstddef>
#include <string>

namespace animorder::io {

// The deepest nesting of arrays and objects a glTF's JSON may have (check_json_depth in
// gltf_buffer.h refuses deeper files before tinygltf reads them).
inline constexpr size_t kMaxJsonDepth = 512;

// Whether `text` nests arrays and objects deeper than kMaxJsonDepth (brackets inside strings do
// not count).
bool nests_too_deep(const std::string& text);

// Why the glTF at `path` is unreadable, tinygltf's load having failed with `tinygltf_error`: the
// first problem found in its GLB structure or JSON, else tinygltf's message with its repeats left
// out, else (tinygltf said nothing) a pointer to the Khronos validator. Never empty, one line.
std::string why_unreadable(const std::string& path, const std::string& tinygltf_error);

namespace diagnose_detail {

// `error` with each sentence or line said once: tinygltf appends the same complaint for every
// object it meets, and some checks twice over. Lines are joined with "; ".
std::string deduplicated(const std::string& error);

}  // namespace diagnose_detail

}  // namespace animorder::io
