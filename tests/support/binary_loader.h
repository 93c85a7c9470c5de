// Tests of the loaders of binary formats (MD2, IQM): a little-endian byte image built field by
// field, written into the test's scratch folder, and the checks every such loader must pass — a
// one-line LoadError that starts with the file name for a hostile file, and every single-byte
// mutation of a small valid file loading cleanly or failing with a LoadError.
#pragma once

#include "animorder/animated_mesh.h"
#include "animorder/load.h"

#include "support/files.h"
#include "support/load_error.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

namespace animorder::test {

// A little-endian byte image that grows as values are written at given offsets.
struct ByteImage {
    std::vector<unsigned char> bytes;
    template <typename T>
    void put(size_t at, T value) {
        if (bytes.size() < at + sizeof(T)) bytes.resize(at + sizeof(T), 0);
        std::memcpy(bytes.data() + at, &value, sizeof(T));
    }
    void put_text(size_t at, const char* text, size_t room) {
        if (bytes.size() < at + room) bytes.resize(at + room, 0);
        std::memcpy(bytes.data() + at, text, std::min(std::strlen(text), room));
    }
};

using BinaryLoader = std::function<AnimatedMesh(const std::string&, const LoadOptions&)>;

class BinaryLoaderTest : public ScratchFolderTest {
protected:
    BinaryLoaderTest(std::string prefix, BinaryLoader loader)
        : ScratchFolderTest(std::move(prefix)), loader_(std::move(loader)) {}

    std::string write(const std::string& name, const ByteImage& image) {
        const std::filesystem::path p = path(name);
        std::ofstream(p, std::ios::binary)
            .write(reinterpret_cast<const char*>(image.bytes.data()), std::streamsize(image.bytes.size()));
        return p.string();
    }

    // Loading `image` fails with a one-line LoadError that starts with the file name and holds `message`.
    void expect_error(const std::string& name, const ByteImage& image, const std::string& message,
                      const LoadOptions& options = {}) {
        const std::string file = write(name, image);
        expect_one_line_load_error(file, message, [&] { loader_(file, options); });
    }

    // `base` with one field set to `value` at byte `at` fails as expect_error says.
    template <typename T>
    void expect_field_error(const ByteImage& base, const std::string& name, size_t at, T value,
                            const std::string& message) {
        ByteImage m = base;
        m.put<T>(at, value);
        expect_error(name, m, message);
    }

    // Every byte of `tiny` set in turn to 0x00, 0x7F, 0x80 and 0xFF (counts, offsets, indices,
    // floats become huge, negative, NaN): each copy loads a valid mesh or fails with a LoadError
    // naming the file, nothing else (under scripts/test-sanitized.sh: no memory error, no
    // undefined behaviour). Both outcomes must occur.
    void expect_every_byte_mutation_loads_or_fails(const ByteImage& tiny, const std::string& name) {
        size_t loaded = 0, refused = 0;
        for (size_t at = 0; at < tiny.bytes.size(); ++at)
            for (unsigned char value : {0x00, 0x7F, 0x80, 0xFF}) {
                ByteImage m = tiny;
                m.bytes[at] = value;
                const std::string file = write(name, m);
                try {
                    const AnimatedMesh mesh = loader_(file, LoadOptions{});
                    EXPECT_NO_THROW(validate_animated_mesh(mesh)) << "byte " << at << " = " << int(value);
                    ++loaded;
                } catch (const LoadError& e) {
                    EXPECT_EQ(std::string(e.what()).rfind(file, 0), 0u) << e.what();
                    ++refused;
                }
            }
        EXPECT_GT(loaded, 0u);
        EXPECT_GT(refused, 0u);
    }

private:
    BinaryLoader loader_;
};

}  // namespace animorder::test
