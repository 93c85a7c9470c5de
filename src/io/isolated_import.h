// Running a loader in a child process, so that a crash inside a third-party parser (assimp) on a
// hostile file becomes a LoadError instead of killing us. Private to src/io.
#pragma once

#include "animorder/animated_mesh.h"
#include "animorder/load.h"

#include <functional>
#include <string>
#include <vector>

namespace animorder::io {

// Called by the child's loader with i before it starts reading files[i], so that a crash is
// blamed on the right file.
using ReadingFile = std::function<void(size_t)>;

// What the child's loader gets: reading(i) before it reads files[i], and `opened`, to which it
// adds every file it opens or looks for (passed back with the mesh).
struct ChildContext {
    ReadingFile reading;
    std::vector<std::string>& opened;
};

// Called in the child around each third-party parse of a file of `bytes` bytes: from
// begin_parsing to end_parsing the child may use options.parse_seconds · (1 + MiB) more seconds
// of processor time, after which the kernel stops it (SIGXCPU) and load_isolated reports a file
// the parser could not finish.
void begin_parsing(uint64_t bytes, const LoadOptions& options);
void end_parsing();

// Runs load(reading) in a forked child and returns the AnimatedMesh it produced. files[0] is
// the character (the file errors are about when nothing better is known), the rest are the
// clip files the loader reads. The child passes the mesh back through an in-memory file
// (memfd); the parent reads it with every count and size checked against the bytes actually
// there and options.max_keyframe_bytes (the child's bytes are treated as hostile), then
// validates the mesh. Errors, all LoadError with one line starting with a file name:
//  - the loader's own exception (its message, passed back and cleaned to one line);
//  - the child killed by a signal: "FILE: assimp crashed reading it (signal 11: SIGSEGV)",
//    followed by the last meaningful line the child wrote to stderr, if any;
//  - the child exiting non-zero (AddressSanitizer does this after a report): "FILE: assimp
//    crashed reading it (exit code N)" and the same stderr line;
//  - the child over its processor time for a parse (begin_parsing): "FILE: assimp did not finish
//    reading it in N s of processor time (...)".
// The child dies with the parent (a killed animorder leaves no reader running) and dumps no core.
// The child's stdout and stderr are captured, never shown. The files the child opened or looked
// for are added to options.files_read (when set) if not there already.
AnimatedMesh load_isolated(const std::vector<std::string>& files, const LoadOptions& options,
                           const std::function<AnimatedMesh(const ChildContext& child)>& load);

}  // namespace animorder::io
