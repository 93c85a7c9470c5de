// node js/test/three-plugin.mjs — the three.js plugin (js/three/animorder-three.js) in node with
// three.js's own GLTFLoader (viewer/node_modules/three), on docs/extension/example.gltf made a GLB
// and broken in the ways a hostile or careless file is: the plugin must load the file, refusing
// the orders (userData.animorderError, the file's own indices drawn) where the runtime and
// `animorder check` refuse them, and never draw one primitive with another's orders.
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { register } from 'node:module';

// 'three' and 'three/addons/...' as the viewer's import map gives them.
const three = new URL('../../viewer/node_modules/three/', import.meta.url);
const hooks = `export async function resolve(specifier, context, next) {
    if (specifier === 'three') return { url: ${JSON.stringify(new URL('build/three.module.js', three).href)}, shortCircuit: true };
    if (specifier.startsWith('three/addons/'))
        return { url: ${JSON.stringify(new URL('examples/jsm/', three).href)} + specifier.slice(13), shortCircuit: true };
    return next(specifier, context);
}`;
register('data:text/javascript,' + encodeURIComponent(hooks));
const { AnimorderGLTFPlugin } = await import('../three/animorder-three.js');
const { GLTFLoader } = await import('three/addons/loaders/GLTFLoader.js');

const EXT = 'ANIMORDER_animated_triangle_orders';
const example = JSON.parse(readFileSync(new URL('../../docs/extension/example.gltf', import.meta.url)));
// The example's embedded buffer as a GLB's binary chunk.
const bin = Buffer.from(example.buffers[0].uri.split(',')[1], 'base64');
delete example.buffers[0].uri;

function glb(json) {
    const pad = (b, c) => Buffer.concat([b, Buffer.alloc((4 - (b.length % 4)) % 4, c)]);
    const text = pad(Buffer.from(JSON.stringify(json)), 0x20), data = pad(bin, 0);
    const header = Buffer.alloc(12), jsonHead = Buffer.alloc(8), binHead = Buffer.alloc(8);
    header.writeUInt32LE(0x46546c67, 0), header.writeUInt32LE(2, 4), header.writeUInt32LE(28 + text.length + data.length, 8);
    jsonHead.writeUInt32LE(text.length, 0), jsonHead.writeUInt32LE(0x4e4f534a, 4);
    binHead.writeUInt32LE(data.length, 0), binHead.writeUInt32LE(0x004e4942, 4);
    const out = Buffer.concat([header, jsonHead, text, binHead, data]);
    return out.buffer.slice(out.byteOffset, out.byteOffset + out.length);
}

// Loads the example after `mutate`: the glTF, its character (null when refused) and the error.
async function load(mutate = () => {}) {
    const json = structuredClone(example);
    mutate(json);
    const warn = console.warn;
    console.warn = () => {};  // the plugin's one-line warning of a refusal
    try {
        const gltf = await new GLTFLoader().register((parser) => new AnimorderGLTFPlugin(parser)).parseAsync(glb(json), '');
        return { gltf, character: gltf.userData.animorder, error: gltf.userData.animorderError };
    } finally {
        console.warn = warn;
    }
}
const meshesOf = (gltf) => {
    const meshes = [];
    gltf.scene.traverse((o) => { if (o.isMesh) meshes.push(o); });
    return meshes;
};
const indices = [...new Uint16Array(bin.buffer, bin.byteOffset + 48, 6)];  // accessor 1, the file's own

// The example as it is: its one primitive draws from the 2 × 6 orders.
const base = await load();
assert.ok(base.character, base.error);
assert.equal(base.character.meshes.length, 1);
assert.equal(base.character.meshes[0].mesh.geometry.index.count, 12);

// A second primitive with the same attributes and indices but no orders: GLTFLoader gives both one
// geometry. The second keeps the file's indices, in a geometry of its own with the same attributes.
const twin = (json, ext) => {
    json.meshes.push({ primitives: [{ attributes: { POSITION: 0 }, indices: 1, mode: 4, ...(ext ? { extensions: { [EXT]: ext } } : {}) }] });
    json.nodes.push({ mesh: 1 });
    json.scenes[0].nodes.push(1);
};
{
    const { gltf, character, error } = await load((json) => twin(json, null));
    assert.ok(character, error);
    const ordered = character.meshes[0].mesh, plain = meshesOf(gltf).find((m) => m !== ordered);
    assert.notEqual(plain.geometry, ordered.geometry);
    assert.deepEqual([...plain.geometry.index.array], indices);
    assert.equal(plain.geometry.attributes.position, ordered.geometry.attributes.position);  // shared, not copied
    assert.equal(ordered.geometry.index.count, 12);
}
// The same geometry with other orders (accessor 7, a copy of 2) cannot be drawn from one index
// buffer: refused; with the same orders, both draw them.
{
    const { character, error } = await load((json) => {
        json.accessors.push({ ...json.accessors[2] });
        twin(json, { orders: 7, orderCount: 2 });
    });
    assert.equal(character, null);
    assert.match(error, /orders 7, where a primitive of the same geometry has 2/);
    const same = await load((json) => twin(json, { orders: 2, orderCount: 2 }));
    assert.equal(same.character.meshes.length, 2);
}
// Orders on lines (three.js draws them as LineSegments, not a mesh) refuse the file, as the runtime does.
assert.match((await load((json) => { json.meshes[0].primitives[0].mode = 1; })).error, /is not a TRIANGLES primitive/);
// Accessors as the runtime reads them: an index that is a string, a sparse accessor, one past its
// buffer view, a buffer view that does not exist: one clear line each, the file's indices drawn.
assert.match((await load((json) => { json.extensions[EXT].clips[0].table = '3'; })).error, /table is missing or not an integer/);
assert.match((await load((json) => { json.accessors[2].sparse = { count: 1, indices: { bufferView: 1, componentType: 5123 }, values: { bufferView: 1 } }; })).error, /sparse/);
assert.match((await load((json) => { json.accessors[3].byteOffset = 4096; })).error, /more than its buffer view holds/);
assert.match((await load((json) => { json.accessors[3].bufferView = 99; })).error, /has no valid buffer view/);
assert.match((await load((json) => { json.extensions[EXT].clips[0].sampleRate = '30'; })).error, /sampleRate is missing or not a positive number/);
{
    const refused = await load((json) => { json.accessors[2].normalized = true; });
    assert.equal(refused.character, null);
    assert.deepEqual([...meshesOf(refused.gltf)[0].geometry.index.array], indices);
}

// EXT_mesh_gpu_instancing: GLTFLoader draws the node as an InstancedMesh (mapped to the node
// only); it draws the orders like any mesh of the primitive, with per-instance attributes too
// (a geometry of its own that shares the file's index).
for (const attributes of [{ TRANSLATION: 6 }, { TRANSLATION: 6, _ID: 6 }]) {
    const { gltf, character, error } = await load((json) => {
        json.extensionsUsed.push('EXT_mesh_gpu_instancing');
        json.nodes[0].extensions = { EXT_mesh_gpu_instancing: { attributes } };
    });
    assert.ok(character, error);
    const instanced = meshesOf(gltf).filter((m) => m.isInstancedMesh);
    assert.equal(instanced.length, 1);
    assert.equal(character.meshes.length, 1);
    assert.equal(character.meshes[0].mesh, instanced[0]);
    assert.equal(instanced[0].geometry.index.count, 12);
    character.setBuffer(1);
    assert.deepEqual([instanced[0].geometry.drawRange.start, instanced[0].geometry.drawRange.count], [6, 6]);
}

// addOrderFrom (the viewer's --original): another file's order naming a vertex the primitive does
// not have is refused, not wrapped into the index buffer.
{
    // The example without the extension (the un-optimised file), after `mutate`.
    const withoutOrders = (mutate = () => {}) => {
        const json = structuredClone(example);
        delete json.extensions, delete json.extensionsUsed, delete json.meshes[0].primitives[0].extensions;
        mutate(json);
        return new GLTFLoader().parseAsync(glb(json), '');
    };
    // Its indices read from the centre's float 0.5 (bytes 00 00 00 3f): vertex 16128 of 4.
    const other = await withoutOrders((json) => {
        json.accessors[1] = { bufferView: 4, componentType: 5123, count: 6, type: 'SCALAR' };
    });
    assert.throws(() => base.character.addOrderFrom(other, other.parser), /names vertex 16128 of 4/);
    const original = await withoutOrders();
    assert.equal(base.character.addOrderFrom(original, original.parser), 2);
    assert.deepEqual([...base.character.meshes[0].mesh.geometry.index.array.slice(12)], indices);
}
// The shared corpus of hostile files (tests/extension-corpus/, docs/extension/VALIDITY.md): the
// plugin's verdict on each is the manifest's, as `animorder check` and the runtime give it: the
// orders bound when the file is valid, else refused with a one-line error holding the manifest's
// phrase (or the file refused by GLTFLoader itself before the plugin sees it).
{
    const corpus = new URL('../../tests/extension-corpus/', import.meta.url);
    const manifest = JSON.parse(readFileSync(new URL('manifest.json', corpus)));
    // three.js's FileLoader (the corpus's data: URI buffers) reports progress with the browser's
    // ProgressEvent, which node lacks.
    globalThis.ProgressEvent ??= class extends Event {
        constructor(type, init = {}) {
            super(type);
            Object.assign(this, init);
        }
    };
    let beforeThePlugin = 0;
    for (const entry of manifest) {
        const text = readFileSync(new URL(entry.file, corpus), 'utf8');
        const warn = console.warn;
        console.warn = () => {};
        let gltf = null, thrown = null;
        try {
            gltf = await new GLTFLoader().register((parser) => new AnimorderGLTFPlugin(parser)).parseAsync(text, '');
        } catch (e) {
            thrown = e;
        } finally {
            console.warn = warn;
        }
        if (entry.valid) {
            assert.equal(thrown, null, `${entry.file}: ${thrown}`);
            assert.ok(gltf.userData.animorder, `${entry.file}: ${gltf.userData.animorderError}`);
            continue;
        }
        if (thrown) {
            beforeThePlugin++;
            continue;
        }
        const error = gltf.userData.animorderError;
        assert.equal(gltf.userData.animorder ?? null, null, `${entry.file} was accepted`);
        assert.ok(error && error.includes(entry.phrase), `${entry.file}: '${entry.phrase}' not in: ${error}`);
        assert.doesNotMatch(error, /[\x00-\x1f\x7f]/, entry.file);
    }
    assert.ok(beforeThePlugin < manifest.length / 4, `GLTFLoader itself refused ${beforeThePlugin} files`);
    console.log(`three plugin: corpus of ${manifest.length} files, every verdict as the manifest's ` +
                `(${beforeThePlugin} refused by GLTFLoader before the plugin)`);
}
console.log('three plugin: all checks passed');
