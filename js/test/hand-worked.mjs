// node js/test/hand-worked.mjs — the JS runtime on docs/extension/example.gltf (a .gltf with an
// embedded data-URI buffer) against answers worked out by hand, and its refusals of broken input.
//
// The example: one keyframe, centre (0.5, 0.5, 0), thetaSteps 2, phiSteps 2, table [0, 1, 1, 0]
// (cell (i, j) at 2i + j), bufferBase 0. θ = acos(d.y/|d|): i = floor(θ/π·1 + 0.5), so i = 0 for
// θ < π/2 and 1 from π/2 on; φ = atan2(d.x, d.z) in [0, 2π): j = floor(φ/(2π)·2 + 0.5) mod 2, so
// j = 0 for φ < π/2 or ≥ 3π/2 (towards +Z), 1 for π/2 ≤ φ < 3π/2 (towards −Z).
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { AnimorderError, AnimorderRuntime } from '../runtime/animorder.js';

const example = JSON.parse(readFileSync(new URL('../../docs/extension/example.gltf', import.meta.url)));
const rt = AnimorderRuntime.fromGltf(example);
assert.equal(rt.bufferCount, 2);
assert.equal(rt.fallback, 0);
assert.deepEqual([...rt.clips[0].cells], [0, 1, 1, 0]);
assert.deepEqual([...rt.clips[0].centres], [0.5, 0.5, 0]);
const at = (dx, dy, dz) => [0.5 + dx, 0.5 + dy, dz];
const cases = [
    [at(0, 1, 0), 0],        // straight up: θ 0 → i 0; φ atan2(0, 0) = 0 → j 0: cell 0 → 0
    [at(0, 0.2, -1), 1],     // above the horizon towards −Z: i 0, φ π → j 1: cell 1 → 1
    [at(0, -1, 0.001), 1],   // below, towards +Z: i 1, j 0: cell 2 → 1
    [at(0, 0, -1), 0],       // on the horizon (θ = π/2 rounds up to i 1), towards −Z: cell 3 → 0
    [at(1, 0.5, 0), 1],      // +X, up: θ = acos(0.5/√1.25) ≈ 0.35π → i 0; φ = π/2 → floor(0.5 + 0.5) = 1 → j 1: cell 1 → 1
];
for (const [camera, expected] of cases) assert.equal(rt.selectKeyframe(0, 0, camera), expected, `camera ${camera}`);
assert.equal(rt.selectTime(0, 12.5, at(0, 1, 0)), 0);            // any time: the only keyframe
assert.equal(rt.selectAnimationTime(0, NaN, at(0, 0.2, -1)), 1);  // NaN: the first keyframe
assert.equal(rt.selectKeyframe(0, 0, [0.5, 0.5, 0]), -1);         // at the centre: no answer
assert.equal(rt.selectKeyframe(0, 0, [Infinity, 0, 0]), -1);
assert.equal(rt.selectKeyframe(1, 0, at(0, 1, 0)), -1);           // no clip 1
assert.equal(rt.selectKeyframe(-1, 0, at(0, 1, 0)), -1);
assert.equal(rt.clipForAnimation(0), 0);

// Refusals: a one-line AnimorderError, never a wrong answer.
const broken = (mutate) => {
    const copy = structuredClone(example);
    mutate(copy);
    return () => AnimorderRuntime.fromGltf(copy);
};
const ext = (g) => g.extensions.ANIMORDER_animated_triangle_orders;
assert.throws(broken((g) => { ext(g).bufferCount = 1; }), AnimorderError);            // a cell names buffer 1
assert.throws(broken((g) => { ext(g).clips[0].keyframes = 2; }), AnimorderError);     // table too short
assert.throws(broken((g) => { ext(g).clips[0].thetaSteps = 1; }), AnimorderError);
assert.throws(broken((g) => { ext(g).clips[0].table = 0; }), AnimorderError);         // a VEC3 FLOAT accessor
assert.throws(broken((g) => { ext(g).clips[0].centers = 99; }), AnimorderError);      // no such accessor
assert.throws(broken((g) => { ext(g).fallback = 2; }), AnimorderError);
assert.throws(broken((g) => { ext(g).clips[0].sampleRate = 0; }), AnimorderError);
assert.throws(broken((g) => { g.bufferViews[3].byteLength = 2; }), AnimorderError);    // accessor past its view
assert.equal(AnimorderRuntime.fromGltf({ asset: { version: '2.0' } }), null);         // no extension: null
assert.throws(() => AnimorderRuntime.fromSidecar(new Uint8Array(10)), AnimorderError);
assert.throws(() => AnimorderRuntime.fromSidecar(new TextEncoder().encode('AOR2'.padEnd(20, '\0'))), AnimorderError);
assert.throws(() => AnimorderRuntime.fromGlb(new Uint8Array(30)), AnimorderError);
// As the C runtime: a sidecar without a buffer (no fallback to bind) or of partial triangles.
const sidecar = (buffers, indices) => {
    const bytes = new Uint8Array(20 + 4 * buffers * indices), header = new DataView(bytes.buffer);
    bytes.set(new TextEncoder().encode('AOR1'));
    header.setUint32(4, 1, true), header.setUint32(8, buffers, true), header.setUint32(12, indices, true);
    return bytes;
};
assert.equal(AnimorderRuntime.fromSidecar(sidecar(1, 3)).buffer(0).length, 3);
assert.throws(() => AnimorderRuntime.fromSidecar(sidecar(0, 0)), /no buffer/);
assert.throws(() => AnimorderRuntime.fromSidecar(sidecar(1, 4)), /not whole triangles/);
// The primitives (what an engine binds): orders that do not fit are refused, as `animorder check` does.
const prim = (g) => g.meshes[0].primitives[0];
assert.throws(broken((g) => { prim(g).extensions.ANIMORDER_animated_triangle_orders.orderCount = 3; }), AnimorderError);
assert.throws(broken((g) => { g.accessors[2].count = 9; }), AnimorderError);          // orders of 1.5 buffers
assert.throws(broken((g) => { g.accessors[2].componentType = 5126; }), AnimorderError);  // float orders
assert.throws(broken((g) => { delete prim(g).indices; }), AnimorderError);
assert.throws(broken((g) => { prim(g).mode = 5; }), AnimorderError);                   // a strip
const table = (g) => g.accessors[ext(g).clips[0].table];
// The orders accessor as `animorder check` reads it: inside its view and buffer, not normalized,
// every value one of the primitive's 4 vertices.
assert.throws(broken((g) => { g.accessors[2].bufferView = 99; }), AnimorderError);
assert.throws(broken((g) => { g.accessors[2].byteOffset = 1000; }), AnimorderError);
assert.throws(broken((g) => { g.bufferViews[2].byteOffset = 4096; }), AnimorderError);  // the view past the buffer
assert.throws(broken((g) => { g.bufferViews[2].byteStride = 4; }), /more than its buffer view holds/);  // 12 values 4 bytes apart
assert.throws(broken((g) => { g.accessors[2].normalized = true; }), AnimorderError);
assert.throws(broken((g) => { g.accessors[0].count = 3; }), /names vertex 3 of 3/);     // the orders name vertex 3
assert.throws(broken((g) => { g.bufferViews[2].buffer = '0'; }), AnimorderError);
// Fields of the wrong type, which numeric conversion would let through ("30" → 30), and the
// required fallback.
assert.throws(broken((g) => { ext(g).clips[0].sampleRate = '30'; }), /sampleRate is missing or not a positive number/);
assert.throws(broken((g) => { ext(g).clips[0].sampleRate = [30]; }), /sampleRate is missing or not a positive number/);
assert.throws(broken((g) => { ext(g).clips[0].sampleRate = true; }), /sampleRate is missing or not a positive number/);
assert.throws(broken((g) => { delete ext(g).fallback; }), /fallback/);
assert.throws(broken((g) => { table(g).normalized = true; }), /is normalized/);
// Accessors: never read outside their view, never `count` zeros without one (4 GB for a big count).
assert.throws(broken((g) => { table(g).byteOffset = -1; }), AnimorderError);
assert.throws(broken((g) => { delete g.bufferViews[table(g).bufferView].byteLength; }), AnimorderError);
assert.throws(broken((g) => { delete table(g).bufferView; table(g).count = 4294967295; }), AnimorderError);
// Anything else wrong is an AnimorderError too, not a TypeError or a SyntaxError.
assert.throws(broken((g) => { ext(g).clips[0] = null; }), AnimorderError);
const glb = (text) => {
    const json = new TextEncoder().encode(text.padEnd(Math.ceil(text.length / 4) * 4, ' '));
    const out = new Uint8Array(20 + json.length), view = new DataView(out.buffer);
    view.setUint32(0, 0x46546c67, true), view.setUint32(4, 2, true), view.setUint32(8, out.length, true);
    view.setUint32(12, json.length, true), view.setUint32(16, 0x4e4f534a, true);
    out.set(json, 20);
    return out;
};
assert.throws(() => AnimorderRuntime.fromGlb(glb('{"asset": NaN}')), AnimorderError);
// A sidecar claiming 2^31 − 1 buffers of no indices opens at once (its views are made when asked).
const bomb = new Uint8Array(20), bombView = new DataView(bomb.buffer);
bomb.set(new TextEncoder().encode('AOR1'));
bombView.setUint32(4, 1, true), bombView.setUint32(8, 0x7fffffff, true);
const started = Date.now();
const empty = AnimorderRuntime.fromSidecar(bomb);  // before: 2^31 views made, out of memory
assert.ok(Date.now() - started < 5000, 'the sidecar took seconds to open');
assert.equal(empty.buffer(123456).length, 0);
assert.equal(empty.buffer(0x7fffffff), null);
console.log('hand-worked: all checks passed');
