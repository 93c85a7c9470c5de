// The manifest of `animorder batch`: its items as a JSON or CSV manifest writes them, their paths
// resolved against the manifest's folder; and the text files batch reads (manifests, reports).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace animorder::tool {

struct ManifestItem {
    std::string name;                // for the summary: "name", else the output
    std::string input;               // resolved against the manifest's folder; empty: the bundled character
    std::vector<std::string> clips;  // names, or clip files/folders (resolved when they exist)
    std::string method;              // empty: optimize's default
    std::vector<std::string> options;
    std::string output;  // resolved against the manifest's folder
    // The paths as the manifest writes them: what the stamp hashes, so that it does not depend on
    // how the manifest's own path was spelled, nor on the current folder.
    std::string input_as_written, output_as_written;
    std::vector<std::string> clips_as_written;
    bool input_given = false;  // an "input" key or column: then it may not be blank
    size_t line = 0;           // a CSV manifest's line, which its errors name (0: a JSON item)
};

// The items of a manifest (.json, .csv, or JSON text under another name), in order, checked:
// every item has an output, its fields are UTF-8 without a NUL, and its paths are resolved.
// Errors name the manifest and the item (JSON) or the line (CSV).
std::vector<ManifestItem> read_manifest(const std::string& path);

// A manifest or a report: a regular file of at most 1 GiB (a FIFO or a device would never end),
// `what` naming it in errors.
std::string read_text(const std::string& path, const char* what);

// Text that the JSON reports can hold: valid UTF-8 (a report names items and paths).
bool is_utf8(const std::string& text);

}  // namespace animorder::tool
