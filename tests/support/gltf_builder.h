// A glTF document built in a test: accessors over one embedded (base64) buffer, added one by one.
#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

namespace animorder::test {

inline std::string base64(const std::string& in) {
    static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    size_t i = 0;
    for (; i + 2 < in.size(); i += 3) {
        const uint32_t v = uint32_t(uint8_t(in[i])) << 16 | uint32_t(uint8_t(in[i + 1])) << 8 | uint8_t(in[i + 2]);
        for (int s = 18; s >= 0; s -= 6) out.push_back(table[(v >> s) & 63]);
    }
    if (i + 1 == in.size()) {
        const uint32_t v = uint32_t(uint8_t(in[i])) << 16;
        out += {table[(v >> 18) & 63], table[(v >> 12) & 63], '=', '='};
    } else if (i + 2 == in.size()) {
        const uint32_t v = uint32_t(uint8_t(in[i])) << 16 | uint32_t(uint8_t(in[i + 1])) << 8;
        out += {table[(v >> 18) & 63], table[(v >> 12) & 63], table[(v >> 6) & 63], '='};
    }
    return out;
}

inline std::string base64_decode(const std::string& text) {
    static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    uint32_t bits = 0;
    int count = 0;
    for (const char c : text) {
        const char* at = c ? std::strchr(table, c) : nullptr;
        if (!at) break;  // '=' or the end
        bits = bits << 6 | uint32_t(at - table);
        if ((count += 6) >= 8) out.push_back(char((bits >> (count -= 8)) & 0xff));
    }
    return out;
}

// A glTF document with one embedded buffer, accessors appended as they are added.
struct Gltf {
    using json = nlohmann::json;
    json doc = {{"asset", {{"version", "2.0"}}}, {"accessors", json::array()}, {"bufferViews", json::array()}};
    std::string bin;

    int add(const void* data, size_t bytes, size_t count, const char* type, int component) {
        while (bin.size() % 4) bin.push_back('\0');
        doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", bytes}});
        bin.append(static_cast<const char*>(data), bytes);
        doc["accessors"].push_back({{"bufferView", doc["bufferViews"].size() - 1},
                                    {"componentType", component},
                                    {"count", count},
                                    {"type", type}});
        return int(doc["accessors"].size() - 1);
    }
    int floats(const std::vector<float>& v, const char* type, size_t per) {
        return add(v.data(), v.size() * 4, v.size() / per, type, 5126);
    }
    int u16(const std::vector<uint16_t>& v, const char* type, size_t per) {
        return add(v.data(), v.size() * 2, v.size() / per, type, 5123);
    }
    std::string text() {
        json d = doc;
        d["buffers"] =
            json::array({{{"byteLength", bin.size()}, {"uri", "data:application/octet-stream;base64," + base64(bin)}}});
        return d.dump();
    }
};

}  // namespace animorder::test
