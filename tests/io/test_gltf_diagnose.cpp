// Why a glTF tinygltf cannot read is unreadable (src/io/gltf_diagnose.h): small broken files built
// here, one per problem the Khronos validator's test files showed tinygltf saying badly (nothing at
// all, the same sentence twice, "Invalid glTF binary."), each loaded through load_character and
// answered with one line naming the file and what is wrong in it.
#include "animorder/load.h"
#include "support/files.h"
#include "support/load_error.h"

#include "gltf_diagnose.h"  // an internal header of src/io

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

using namespace animorder;
using nlohmann::json;

namespace {

constexpr uint32_t kJson = 0x4E4F534A, kBin = 0x004E4942;

std::string le32(uint32_t v) {
    const char bytes[4] = {char(v & 0xff), char(v >> 8 & 0xff), char(v >> 16 & 0xff), char(v >> 24 & 0xff)};
    return std::string(bytes, 4);
}

struct Chunk {
    uint32_t type;
    std::string data;
    int64_t length = -1;  // the length its header says; -1: data's
};

// A GLB of `chunks`; `length` is the total its header says (-1: the real one).
std::string glb(const std::vector<Chunk>& chunks, uint32_t version = 2, int64_t length = -1) {
    std::string body;
    for (const Chunk& c : chunks)
        body += le32(uint32_t(c.length < 0 ? int64_t(c.data.size()) : c.length)) + le32(c.type) + c.data;
    return "glTF" + le32(version) + le32(uint32_t(length < 0 ? int64_t(12 + body.size()) : length)) + body;
}

// A glTF JSON text padded with spaces to 4 bytes, as a GLB's JSON chunk holds it.
std::string padded(const json& doc) {
    std::string text = doc.dump();
    while (text.size() % 4) text.push_back(' ');
    return text;
}

const json kAsset = {{"version", "2.0"}};

class GltfDiagnose : public test::ScratchFolderTest {
protected:
    GltfDiagnose() : ScratchFolderTest("animorder-diagnose") {}

    std::string write(const std::string& name, const std::string& bytes) {
        const std::string p = path(name).string();
        std::ofstream(p, std::ios::binary) << bytes;
        written_.push_back(p);
        return p;
    }
    // Loading `bytes` as `name` fails with exactly "PATH: not a readable glTF 2.0 file: REASON".
    void expect_reason(const std::string& name, const std::string& bytes, const std::string& reason) {
        const std::string p = write(name, bytes);
        try {
            load_character(p);
            ADD_FAILURE() << p << ": no error";
        } catch (const LoadError& e) {
            EXPECT_EQ(std::string(e.what()), p + ": not a readable glTF 2.0 file: " + reason);
        }
    }
    // The same, the reason only starting with `start` (the JSON parser's words follow).
    void expect_reason_start(const std::string& name, const std::string& bytes, const std::string& start) {
        const std::string p = write(name, bytes);
        test::expect_one_line_load_error(p, ": not a readable glTF 2.0 file: " + start, [&] { load_character(p); });
    }
    std::vector<std::string> written_;
};

// 1. tinygltf fails on a skin without joints and says nothing (or only what it let pass in the
// skins before: "'inverseBindMatrices' property is missing"): the skin is named.
TEST_F(GltfDiagnose, SkinWithoutJointsIsNamed) {
    expect_reason("no_joints.gltf",
                  json{{"asset", kAsset}, {"nodes", {json::object()}}, {"skins", {json::object()}}}.dump(),
                  "skin 0 has no joints");
    const json skins = json::array({json{{"joints", {0}}}, json{{"joints", "all"}}});
    expect_reason("joints_text.gltf", json{{"asset", kAsset}, {"nodes", {json::object()}}, {"skins", skins}}.dump(),
                  "skin 1's joints are not a list of node indices");
    // Nothing better known: never an empty reason.
    const std::string p = write("quiet.gltf", json{{"asset", kAsset}}.dump());
    const std::string why = io::why_unreadable(p, "");
    EXPECT_NE(why.find("tinygltf (the reader used) gave no reason"), std::string::npos) << why;
    EXPECT_NE(why.find("Khronos glTF validator"), std::string::npos) << why;
}

// 2. tinygltf's repeated sentences (one channel after another without a sampler) are said once.
TEST_F(GltfDiagnose, RepeatedSentencesAreSaidOnce) {
    const json animation = {{"channels", {json::object(), json{{"target", json::object()}}}},
                            {"samplers", {json::object()}}};
    expect_reason(
        "channels.gltf", json{{"asset", kAsset}, {"animations", {animation}}}.dump(),
        "'sampler' property is missing in AnimationChannel. `sampler` field is missing in animation channels; "
        "'input' property is missing. `input` field is missing in animation.sampler");
    EXPECT_EQ(io::diagnose_detail::deduplicated("A is wrong.\nB too\nA is wrong.\nB too\nC. A is wrong.\n"),
              "A is wrong. B too; C.");
}

// 3. JSON whose root is no object, or that does not parse.
TEST_F(GltfDiagnose, JsonRootAndSyntaxAreNamed) {
    expect_reason("array.gltf", "[ ]\n", "its JSON root is an array, not an object");
    expect_reason("string.gltf", "\"glTF 2.0\"", "its JSON root is a string, not an object");
    expect_reason("array.glb", glb({{kJson, "[ ] "}}), "its JSON chunk's root is an array, not an object");
    expect_reason_start("syntax.gltf", "{\"asset\": {\"version\": \"2.0\"},\n \"nodes\": [}\n",
                        "its JSON does not parse: parse error at line 2, column 12: syntax error");
    // Files shorter than a GLB's magic were refused as "empty or truncated" before tinygltf read them.
    expect_reason("tiny.gltf", "[]", "its JSON root is an array, not an object");
    expect_reason_start("braces.gltf", "{]", "its JSON does not parse: parse error at line 1, column 2");
    expect_reason("object.gltf", "{}", "its JSON has no \"asset\", which every glTF 2.0 file has");
}

// 4. The GLB structure (glTF 2.0 §4.4): the first problem, not "Invalid glTF binary.".
TEST_F(GltfDiagnose, GlbStructureProblemsAreNamed) {
    const std::string text = padded(json{{"asset", kAsset}});
    const std::string good = glb({{kJson, text}});
    expect_reason("length.glb", glb({{kJson, text}}, 2, int64_t(good.size()) + 8),
                  "its GLB header says " + std::to_string(good.size() + 8) + " bytes, the file has " +
                      std::to_string(good.size()));
    expect_reason("bin_past.glb", glb({{kJson, text}, {kBin, "abcd", 40}}),
                  "chunk 1 (BIN) runs past the end of the file: it says 40 bytes, 4 follow its header");
    // Past chunk 1 (which tinygltf never reads), a problem is named only when tinygltf failed on the
    // structure (here: the header's length, 40 bytes past the end); else tinygltf's own reason, about
    // the JSON, stands.
    expect_reason("two_bin.glb", glb({{kJson, text}, {kBin, "abcd"}, {kBin, "efgh"}}, 2, int64_t(good.size()) + 56),
                  "its GLB header says " + std::to_string(good.size() + 56) + " bytes, the file has " +
                      std::to_string(good.size() + 24));
    expect_reason("two_bin_no_asset.glb", glb({{kJson, "{}  "}, {kBin, "abcd"}, {kBin, "efgh"}}),
                  "its JSON chunk has no \"asset\", which every glTF 2.0 file has");
    const json no_type = {{"asset", kAsset}, {"accessors", {json{{"count", 1}, {"type", "SCALAR"}}}}};
    const std::string plain = glb({{kJson, padded(no_type)}, {kBin, "abcd"}});
    // 4 more bytes, counted in the header's length: too short for a chunk header, which tinygltf never reads
    const std::string cut =
        write("trail.glb",
              glb({{kJson, padded(no_type)}, {kBin, "abcd"}}, 2, int64_t(plain.size()) + 4) + std::string(4, '\0'));
    try {
        load_character(cut);
        ADD_FAILURE() << "loaded";
    } catch (const LoadError& e) {
        EXPECT_NE(std::string(e.what()).find("'componentType' property is missing"), std::string::npos) << e.what();
    }
    expect_reason("empty_json.glb", glb({{kJson, ""}}), "its JSON chunk is empty");
    expect_reason("bin_first.glb", glb({{kBin, "abcd"}, {kJson, text}}),
                  "chunk 0 is BIN; a GLB starts with its JSON chunk");
    expect_reason("misplaced_bin.glb", glb({{kJson, text}, {0x12345678, "abcd"}, {kBin, "abcd"}}),
                  "chunk 1 is of unknown type 0x12345678; glTF says to skip such chunks, but tinygltf (the reader "
                  "used) cannot");
    expect_reason(
        "unknown.glb", glb({{kJson, text}, {0x004B4E55, "abcd"}}),
        "chunk 1 is of unknown type 0x004b4e55; glTF says to skip such chunks, but tinygltf (the reader used) "
        "cannot");
    expect_reason("unaligned.glb", glb({{kJson, text}, {kBin, "abcde"}}),
                  "chunk 1 (BIN) is 5 bytes long, not a multiple of 4");
    expect_reason("version1.glb", glb({{0, text}}, 1),
                  "its GLB header says version 1 (a glTF 1.0 binary); a glTF 2.0 GLB is version 2");
    expect_reason("short.glb", std::string("glTF\x02\0\0\0", 8),
                  "its GLB header is cut short: the file has 8 bytes, a GLB header alone 12");
    expect_reason("not_a.glb", std::string(12, '\0'), "not a GLB: it does not start with 'glTF'");
}

// 5. A buffer without a uri where tinygltf needs one.
TEST_F(GltfDiagnose, BufferWithoutUriIsNamed) {
    const json buffers = json::array(
        {json{{"byteLength", 4}, {"uri", "data:application/octet-stream;base64,AAAAAA=="}}, json{{"byteLength", 4}}});
    expect_reason("no_uri.gltf", json{{"asset", kAsset}, {"buffers", buffers}}.dump(),
                  "buffer 1 has no uri; for tinygltf (the reader used), only a .glb's first buffer (its BIN chunk) may "
                  "leave it out");
    const json placeholder = {{"asset", kAsset}, {"buffers", {json{{"byteLength", 4}}, json{{"byteLength", 1024}}}}};
    expect_reason("placeholder.glb", glb({{kJson, padded(placeholder)}, {kBin, "abcd"}}),
                  "buffer 1 has no uri; for tinygltf (the reader used), only a .glb's first buffer (its BIN chunk) may "
                  "leave it out");
}

// 6. Indices whose accessor has no buffer view (tinygltf: "accessor[0] invalid bufferView").
TEST_F(GltfDiagnose, IndicesWithoutBufferViewAreNamed) {
    const json doc = {{"asset", kAsset},
                      {"accessors",
                       {json{{"componentType", 5126}, {"count", 3}, {"type", "VEC3"}},
                        json{{"componentType", 5123}, {"count", 3}, {"type", "SCALAR"}}}},
                      {"meshes", {json{{"primitives", {json{{"attributes", {{"POSITION", 0}}}, {"indices", 1}}}}}}}};
    expect_reason("indices.gltf", doc.dump(),
                  "mesh 0 primitive 0's indices (accessor 1) have no bufferView, which tinygltf (the reader used) "
                  "refuses; without one they would all be 0");
}

// Every message above is one line that starts with the file's path and gives a reason.
TEST_F(GltfDiagnose, EveryMessageIsOneLineNamingTheFile) {
    const std::vector<std::pair<std::string, std::string>> files = {
        {"a.gltf", json{{"asset", kAsset}, {"skins", {json::object()}}}.dump()},
        {"b.gltf", "[ ]\n"},
        {"c.glb", glb({{kJson, ""}})},
        {"d.glb", glb({{kJson, padded(json{{"asset", kAsset}})}, {kBin, "abcd", 400}})},
        {"e.glb", "\x01\x02\x03\x04 not a glb at all"},
        {"f.gltf", json{{"asset", kAsset}, {"buffers", {json{{"byteLength", 4}}}}}.dump()},
    };
    for (const auto& [name, bytes] : files) {
        const std::string p = write(name, bytes);
        try {
            load_character(p);
            ADD_FAILURE() << p << ": no error";
        } catch (const LoadError& e) {
            const std::string what = e.what();
            const std::string head = p + ": not a readable glTF 2.0 file: ";
            EXPECT_EQ(what.rfind(head, 0), 0u) << what;
            EXPECT_GT(what.size(), head.size()) << what;
            EXPECT_EQ(what.find('\n'), std::string::npos) << what;
            EXPECT_EQ(what.find('\r'), std::string::npos) << what;
        }
    }
}

}  // namespace
