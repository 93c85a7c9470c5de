// What the glTF writers replace, left out of the file (src/io/gltf_prune.h), checked on thousands
// of random models against rules stated here independently of the code: every reference names
// the same object (by name) as before; every kept view reads the same bytes, moved by a multiple
// of 4; an accessor leaves exactly when it was replaced and nothing names it; no buffer is left
// empty. (A buffer emptied and left out: GltfWriter.ABufferThatHeldOnlyTheReplacedIndicesLeavesWithThem
// and OddValuesAndATrailingRunOfIndices below.)
#include "gltf_prune.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

namespace {

using namespace tinygltf;

const char* const kOrders = "ANIMORDER_animated_triangle_orders";

struct RandomModel {
    std::mt19937 rng;
    explicit RandomModel(unsigned seed) : rng(seed) {}
    int below(int n) { return int(rng() % unsigned(n)); }

    // Buffers of random bytes, views at aligned offsets (some overlapping), scalar accessors over
    // them (some without a view, some sparse), and references from every place that may name one.
    Model make() {
        Model m;
        for (int b = 0, n = 1 + below(3); b < n; ++b) {
            Buffer buffer;
            buffer.name = "B" + std::to_string(b);
            for (int i = 0, length = 16 + below(400); i < length; ++i) buffer.data.push_back(uint8_t(below(256)));
            m.buffers.push_back(buffer);
        }
        const int views = 1 + below(10);
        for (int v = 0; v < views; ++v) {
            BufferView view;
            view.buffer = below(int(m.buffers.size()));
            const int length = int(m.buffers[size_t(view.buffer)].data.size()), align = 1 << below(3);
            view.byteOffset = size_t(below(length - 8) / align * align);
            view.byteLength = size_t(1 + below(std::min(length - int(view.byteOffset), 64)));
            view.name = "V" + std::to_string(v);
            m.bufferViews.push_back(view);
        }
        const int accessors = 1 + below(12);
        for (int a = 0; a < accessors; ++a) {
            Accessor accessor;
            accessor.name = "A" + std::to_string(a);
            accessor.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
            accessor.type = TINYGLTF_TYPE_SCALAR;
            accessor.count = 1;
            accessor.bufferView = below(8) == 0 ? -1 : below(views);
            if (below(5) == 0) {
                accessor.sparse.isSparse = true;
                accessor.sparse.count = 1;
                accessor.sparse.indices.bufferView = below(views);
                accessor.sparse.values.bufferView = below(views);
            }
            m.accessors.push_back(accessor);
        }
        Mesh mesh;
        for (int p = 0, n = 1 + below(3); p < n; ++p) {
            Primitive prim;
            prim.attributes["POSITION"] = below(accessors);
            if (below(2)) prim.indices = below(accessors);
            if (below(3) == 0) prim.targets.push_back({{"POSITION", below(accessors)}});
            if (below(3) == 0) {
                Value::Object ours;
                ours["orders"] = Value(below(accessors));
                prim.extensions[kOrders] = Value(ours);
            }
            mesh.primitives.push_back(prim);
        }
        m.meshes.push_back(mesh);
        if (below(2)) {
            Skin skin;
            skin.inverseBindMatrices = below(accessors);
            m.skins.push_back(skin);
        }
        if (below(2)) {
            Animation animation;
            AnimationSampler sampler;
            sampler.input = below(accessors);
            sampler.output = below(accessors);
            animation.samplers.push_back(sampler);
            m.animations.push_back(animation);
        }
        if (below(2)) {
            Image image;
            image.bufferView = below(views);
            m.images.push_back(image);
        }
        if (below(2)) {
            Node node;
            node.mesh = 0;
            Value::Object attributes, instancing;
            attributes["TRANSLATION"] = Value(below(accessors));
            instancing["attributes"] = Value(attributes);
            node.extensions["EXT_mesh_gpu_instancing"] = Value(instancing);
            m.nodes.push_back(node);
        }
        if (below(2)) {
            Value::Object clip, root;
            clip["table"] = Value(below(accessors));
            clip["centers"] = Value(below(accessors));
            root["clips"] = Value(Value::Array{Value(clip)});
            m.extensions[kOrders] = Value(root);
        }
        return m;
    }
};

// What each reference names, by the named object's name, in a fixed order.
std::vector<std::string> named(const Model& m) {
    const auto accessor = [&](int a) { return a >= 0 && size_t(a) < m.accessors.size() ? m.accessors[a].name : "-"; };
    const auto view = [&](int v) { return v >= 0 && size_t(v) < m.bufferViews.size() ? m.bufferViews[v].name : "-"; };
    std::vector<std::string> out;
    for (const Primitive& p : m.meshes[0].primitives) {
        out.push_back(accessor(p.attributes.at("POSITION")));
        out.push_back(accessor(p.indices));
        for (const auto& target : p.targets) out.push_back(accessor(target.at("POSITION")));
        const auto ours = p.extensions.find(kOrders);
        if (ours != p.extensions.end()) out.push_back(accessor(ours->second.Get("orders").GetNumberAsInt()));
    }
    for (const Skin& s : m.skins) out.push_back(accessor(s.inverseBindMatrices));
    for (const Animation& a : m.animations)
        for (const AnimationSampler& s : a.samplers) {
            out.push_back(accessor(s.input));
            out.push_back(accessor(s.output));
        }
    for (const Node& n : m.nodes)
        out.push_back(
            accessor(n.extensions.at("EXT_mesh_gpu_instancing").Get("attributes").Get("TRANSLATION").GetNumberAsInt()));
    const auto root = m.extensions.find(kOrders);
    if (root != m.extensions.end()) {
        const Value& clip = root->second.Get("clips").Get(0);
        out.push_back(accessor(clip.Get("table").GetNumberAsInt()));
        out.push_back(accessor(clip.Get("centers").GetNumberAsInt()));
    }
    for (const Image& image : m.images) out.push_back(view(image.bufferView));
    // Then each accessor's views and each view's buffer ("owner:named"), sorted: slots move.
    std::vector<std::string> listing;
    for (const Accessor& a : m.accessors) {
        listing.push_back(a.name + ":" + view(a.bufferView));
        if (a.sparse.isSparse)
            listing.push_back(a.name + ":" + view(a.sparse.indices.bufferView) + "," +
                              view(a.sparse.values.bufferView));
    }
    for (const BufferView& v : m.bufferViews) listing.push_back(v.name + ":" + m.buffers[size_t(v.buffer)].name);
    std::sort(listing.begin(), listing.end());
    out.insert(out.end(), listing.begin(), listing.end());
    return out;
}

std::vector<unsigned char> bytes_of(const Model& m, const BufferView& v) {
    const std::vector<unsigned char>& data = m.buffers[size_t(v.buffer)].data;
    return {data.begin() + ptrdiff_t(v.byteOffset), data.begin() + ptrdiff_t(v.byteOffset + v.byteLength)};
}

}  // namespace

TEST(GltfPrune, RandomModelsKeepEveryReferenceAndByteTheyStillUse) {
    size_t dropped_accessors = 0, dropped_views = 0, pruned_bytes = 0;
    for (unsigned seed = 0; seed < 3000; ++seed) {
        SCOPED_TRACE("seed " + std::to_string(seed));
        RandomModel random(seed);
        Model m = random.make();
        std::vector<int> replaced;
        for (int k = 0, n = 1 + random.below(4); k < n; ++k) replaced.push_back(random.below(int(m.accessors.size())));
        // The writer stops naming some replaced accessors (a primitive's indices).
        for (Primitive& p : m.meshes[0].primitives)
            if (std::find(replaced.begin(), replaced.end(), p.indices) != replaced.end() && random.below(3))
                p.indices = -1;
        const Model before = m;
        std::vector<std::string> expected = named(before);
        ASSERT_TRUE(animorder::io::drop_replaced_accessors(m, replaced));

        // An accessor leaves exactly when replaced and named by nothing.
        std::set<std::string> named_before, kept;
        for (const std::string& n : named(before)) named_before.insert(n);
        for (const Accessor& a : m.accessors) kept.insert(a.name);
        for (size_t a = 0; a < before.accessors.size(); ++a) {
            const bool is_replaced = std::find(replaced.begin(), replaced.end(), int(a)) != replaced.end();
            const bool leaves = is_replaced && !named_before.count(before.accessors[a].name);
            EXPECT_NE(leaves, bool(kept.count(before.accessors[a].name))) << before.accessors[a].name;
        }
        // Every reference names what it named (the lists of the kept accessors and views compared
        // on the kept ones only).
        std::vector<std::string> after = named(m);
        std::set<std::string> kept_views;
        for (const BufferView& v : m.bufferViews) kept_views.insert(v.name);
        std::vector<std::string> expected_kept;
        for (const std::string& e : expected) {
            const std::string owner = e.substr(0, e.find(':'));
            const bool listing = e.find(':') != std::string::npos;
            if (!listing || kept.count(owner) || kept_views.count(owner)) expected_kept.push_back(e);
        }
        EXPECT_EQ(after, expected_kept);
        // (A view left out was read by no kept accessor or image: else a listing above names it.)
        // A kept view reads its old bytes.
        std::map<std::string, const BufferView*> old_view;
        for (const BufferView& v : before.bufferViews) old_view[v.name] = &v;
        for (const BufferView& v : m.bufferViews) {
            const BufferView& old = *old_view.at(v.name);
            EXPECT_EQ(bytes_of(m, v), bytes_of(before, old)) << v.name;
            EXPECT_EQ((old.byteOffset - v.byteOffset) % 4, 0u) << v.name;
        }
        for (const Buffer& b : m.buffers) EXPECT_FALSE(b.data.empty()) << b.name;
        dropped_accessors += before.accessors.size() - m.accessors.size();
        dropped_views += before.bufferViews.size() - m.bufferViews.size();
        for (const Buffer& b : before.buffers) pruned_bytes += b.data.size();
        for (const Buffer& b : m.buffers) pruned_bytes -= b.data.size();
    }
    // The models exercised what they test.
    std::printf("left out: %zu accessors, %zu views, %zu bytes\n", dropped_accessors, dropped_views, pruned_bytes);
    EXPECT_GT(dropped_accessors, 1000u);
    EXPECT_GT(dropped_views, 200u);
    EXPECT_GT(pruned_bytes, 1000u);
}

// A model using an extension whose references are unknown is left exactly as it was, even its
// references written as reals, and says which extension; without it the same call prunes.
TEST(GltfPrune, AnUnknownExtensionLeavesTheModelAsItWas) {
    for (const bool vendor : {true, false}) {
        SCOPED_TRACE(vendor ? "with the unknown extension" : "without");
        RandomModel random(7);
        Model m = random.make();
        Accessor unused;  // named by nothing: prunable but for the extension
        unused.name = "unused";
        unused.bufferView = 0;
        unused.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE;
        unused.type = TINYGLTF_TYPE_SCALAR;
        unused.count = 1;
        m.accessors.push_back(unused);
        Value::Object ours;
        ours["orders"] = Value(0.0);  // a real with an integer value still names accessor 0
        m.meshes[0].primitives[0].extensions[kOrders] = Value(ours);
        if (vendor) m.extensionsUsed.push_back("VENDOR_unknown");
        const Model before = m;
        std::string unknown;
        const bool pruned = animorder::io::drop_replaced_accessors(m, {int(m.accessors.size() - 1)}, &unknown);
        const Value& orders = m.meshes[0].primitives[0].extensions[kOrders].Get("orders");
        if (vendor) {
            EXPECT_FALSE(pruned);
            EXPECT_EQ(unknown, "VENDOR_unknown");
            EXPECT_EQ(m.accessors.size(), before.accessors.size());
            EXPECT_EQ(m.bufferViews.size(), before.bufferViews.size());
            for (size_t b = 0; b < m.buffers.size(); ++b) EXPECT_EQ(m.buffers[b].data, before.buffers[b].data);
            EXPECT_TRUE(orders.IsReal());  // not even rewritten as an integer
        } else {
            EXPECT_TRUE(pruned);
            EXPECT_EQ(unknown, "");
            EXPECT_EQ(m.accessors.size(), before.accessors.size() - 1);
            EXPECT_EQ(m.accessors[size_t(orders.GetNumberAsInt())].name, before.accessors[0].name);
        }
    }
}

// Values that name no accessor (a fraction, a real beyond int, a negative number) are neither
// followed nor rewritten; a buffer whose last bytes were the replaced indices (6 of them: no
// multiple of 4) loses all of them, and leaves when nothing else was in it.
TEST(GltfPrune, OddValuesAndATrailingRunOfIndices) {
    Model m;
    Buffer positions, indices;
    positions.data.assign(16, 7);
    indices.data.assign(6, 9);
    m.buffers = {positions, indices};
    BufferView pv, iv;
    pv.buffer = 0, pv.byteLength = 16, pv.name = "positions";
    iv.buffer = 1, iv.byteLength = 6, iv.name = "indices";
    m.bufferViews = {pv, iv};
    Accessor p, i;
    p.bufferView = 0, p.count = 1, p.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT, p.type = TINYGLTF_TYPE_VEC3;
    i.bufferView = 1, i.count = 3, i.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT,
    i.type = TINYGLTF_TYPE_SCALAR;
    m.accessors = {p, i};
    Primitive prim;
    prim.attributes["POSITION"] = 0;
    Value::Object ours;
    ours["orders"] = Value(1e20);
    prim.extensions[kOrders] = Value(ours);
    Mesh mesh;
    mesh.primitives = {prim};
    m.meshes = {mesh};
    Value::Object clip, root;
    clip["table"] = Value(2.5);
    clip["centers"] = Value(-1);
    root["clips"] = Value(Value::Array{Value(clip)});
    m.extensions[kOrders] = Value(root);
    EXPECT_EQ(animorder::io::accessors_to_replace(m, {{0, 0}}), std::vector<int>{-1});  // no indices, no orders
    ASSERT_TRUE(animorder::io::drop_replaced_accessors(m, {1}));
    ASSERT_EQ(m.accessors.size(), 1u);
    ASSERT_EQ(m.buffers.size(), 1u);
    EXPECT_EQ(m.buffers[0].data, positions.data);
    EXPECT_EQ(m.meshes[0].primitives[0].extensions[kOrders].Get("orders").Get<double>(), 1e20);
    EXPECT_EQ(m.extensions[kOrders].Get("clips").Get(0).Get("table").Get<double>(), 2.5);
}
