// The glTF-Transform extension against the hand-written example of docs/extension (a quad: order
// 0 = 0 1 2 0 2 3, order 1 = 0 2 3 0 1 2, a 2 x 2 table 0 1 1 0, centre (0.5, 0.5, 0)).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import { Logger, NodeIO } from '@gltf-transform/core';
import { dedup, prune, resample, sparse } from '@gltf-transform/functions';
import { AnimorderTriangleOrders, NAME, nearestCentroids, staleReason } from '../index.js';

const example = fileURLToPath(new URL('../../../docs/extension/example.gltf', import.meta.url));

// A logger that keeps the warnings.
class Recorder extends Logger {
  constructor() { super(Logger.Verbosity.WARN); this.warnings = []; }
  warn(text) { this.warnings.push(text); }
}

async function load(register = true) {
  const io = new NodeIO();
  if (register) io.registerExtensions([AnimorderTriangleOrders]);
  const logger = new Recorder();
  const document = await io.read(example);
  document.setLogger(logger);
  return { io, document, logger };
}

// Writes GLB bytes and reads them back as JSON + binary (what a consumer sees).
async function roundTrip(io, document) {
  const glb = await io.writeBinary(document);
  const plain = new NodeIO();  // no extension registered: the raw JSON
  const json = (await plain.binaryToJSON(glb)).json;
  return { glb, json };
}


test('reads and writes the example unchanged in meaning', async () => {
  const { io, document } = await load();
  const root = document.getRoot().getExtension(NAME);
  assert.equal(root.getBufferCount(), 2);
  assert.equal(root.getFallback(), 0);
  assert.equal(root.getMethod(), 'single');
  const [clip] = root.listClips();
  assert.equal(clip.getName(), 'still');
  assert.deepEqual([clip.getKeyframes(), clip.getThetaSteps(), clip.getPhiSteps(), clip.getBufferBase()], [1, 2, 2, 0]);
  assert.deepEqual(Array.from(clip.getTable().getArray()), [0, 1, 1, 0]);
  assert.deepEqual(Array.from(clip.getCenters().getArray()), [0.5, 0.5, 0]);
  assert.equal(clip.getAnimation(), document.getRoot().listAnimations()[0]);
  const primitive = document.getRoot().listMeshes()[0].listPrimitives()[0];
  const orders = primitive.getExtension(NAME);
  assert.equal(orders.getOrderCount(), 2);
  assert.deepEqual(Array.from(orders.getOrders().getArray()), [0, 1, 2, 0, 2, 3, 0, 2, 3, 0, 1, 2]);
  assert.equal(staleReason(primitive, orders, 2, 0), null);

  const { json } = await roundTrip(io, document);
  assert.ok(json.extensionsUsed.includes(NAME));
  assert.ok(!(json.extensionsRequired || []).includes(NAME));
  const ext = json.extensions[NAME];
  assert.deepEqual([ext.bufferCount, ext.fallback, ext.method], [2, 0, 'single']);
  assert.equal(ext.clips[0].animation, 0);
  const prim = json.meshes[0].primitives[0];
  const ordersAccessor = json.accessors[prim.extensions[NAME].orders];
  assert.equal(ordersAccessor.count, 12);
  assert.equal(ordersAccessor.componentType, 5123);
  // Its own buffer view, as an index buffer, shared with nothing else.
  const view = ordersAccessor.bufferView;
  assert.equal(json.bufferViews[view].target, 34963);
  assert.equal(json.accessors.filter((a) => a.bufferView === view).length, 1);
  assert.equal(json.accessors[ext.clips[0].table].count, 4);
  assert.equal(json.accessors[ext.clips[0].centers].type, 'VEC3');
});

test('prune, dedup and resample keep the orders', async () => {
  const { io, document, logger } = await load();
  await document.transform(prune(), dedup(), resample());
  const { glb } = await roundTrip(io, document);
  const back = await io.readBinary(glb);
  const primitive = back.getRoot().listMeshes()[0].listPrimitives()[0];
  const orders = primitive.getExtension(NAME);
  assert.ok(orders, 'orders kept');
  assert.deepEqual(Array.from(orders.getOrders().getArray()), [0, 1, 2, 0, 2, 3, 0, 2, 3, 0, 1, 2]);
  assert.deepEqual(Array.from(back.getRoot().getExtension(NAME).listClips()[0].getTable().getArray()), [0, 1, 1, 0]);
  assert.deepEqual(logger.warnings, []);
});

test('orders made stale by rewritten triangles far from every original one are dropped with a warning', async () => {
  const { io, document, logger } = await load();
  const primitive = document.getRoot().listMeshes()[0].listPrimitives()[0];
  // A winding flipped (as a rewrite would): triangle (0 2 1) is no triangle of the orders; and the
  // quad moved 100 units away, far beyond a tenth of its diagonal: no original triangle is near.
  primitive.getIndices().setArray(new Uint16Array([0, 2, 1, 0, 2, 3]));
  const moved = Array.from(primitive.getAttribute('POSITION').getArray(), (v, i) => (i % 3 === 0 ? v + 100 : v));
  primitive.getAttribute('POSITION').setArray(new Float32Array(moved));
  const { json } = await roundTrip(io, document);
  assert.equal(json.meshes[0].primitives[0].extensions?.[NAME], undefined);
  assert.equal(json.extensions?.[NAME], undefined);
  assert.match(logger.warnings.join('\n'), /not a permutation/);
  assert.match(logger.warnings.join('\n'), /dropping the extension/);
});

test('re-sequenced triangles and renumbered vertices (reorder, weld) re-derive the orders', async () => {
  const { io, document, logger } = await load();
  const primitive = document.getRoot().listMeshes()[0].listPrimitives()[0];
  // Vertices 1 and 3 swapped (positions and indices), triangles re-sequenced and rotated.
  primitive.getAttribute('POSITION').setArray(new Float32Array([0, 0, 0, 0, 1, 0, 1, 1, 0, 1, 0, 0]));
  primitive.getIndices().setArray(new Uint16Array([2, 1, 0, 0, 3, 2]));
  const { glb } = await roundTrip(io, document);
  const back = (await io.readBinary(glb)).getRoot().listMeshes()[0].listPrimitives()[0];
  // Worked by hand: triangle (0 1 2) is now (0 3 2), triangle (0 2 3) is (0 2 1).
  assert.deepEqual(Array.from(back.getExtension(NAME).getOrders().getArray()), [0, 3, 2, 0, 2, 1, 0, 2, 1, 0, 3, 2]);
  assert.deepEqual(Array.from(back.getIndices().getArray()), [0, 3, 2, 0, 2, 1]);
  assert.match(logger.warnings.join('\n'), /re-derived/);
});

test('a simplified primitive keeps orders placed by the nearest original triangle', async () => {
  const { io, document, logger } = await load();
  // The quad cut to one triangle, (0 1 2): order 0 draws it first, order 1 second; alone it is
  // every order, and `indices`.
  document.getRoot().listMeshes()[0].listPrimitives()[0].getIndices().setArray(new Uint16Array([0, 1, 2]));
  const { glb, json } = await roundTrip(io, document);
  assert.equal(json.extensions?.[NAME]?.bufferCount, 2);
  const back = (await io.readBinary(glb)).getRoot().listMeshes()[0].listPrimitives()[0];
  assert.deepEqual(Array.from(back.getExtension(NAME).getOrders().getArray()), [0, 1, 2, 0, 1, 2]);
  assert.deepEqual(Array.from(back.getIndices().getArray()), [0, 1, 2]);
  assert.match(logger.warnings.join('\n'), /placed the triangles of mesh .* by the nearest original triangle \(orders accessor has 12 elements, not 6\)/);
});

test('placing draws the current triangles in each order of the originals they stand for', async () => {
  const { io, document, logger } = await load();
  const primitive = document.getRoot().listMeshes()[0].listPrimitives()[0];
  // Each of the quad's two triangles shrunk by a tenth towards its centroid, on new vertices (as a
  // rewrite that moved every vertex would leave them: no corner is found again), and given in the
  // other sequence. Order 0 draws (0 1 2) first and order 1 (0 2 3) first: placed, order 0 must
  // draw the first shrunk triangle first and order 1 the second.
  const p = Array.from(primitive.getAttribute('POSITION').getArray());
  const stored = Array.from(primitive.getExtension(NAME).getOrders().getArray());
  const shrunk = (a, b, c) => {
    const centre = [0, 1, 2].map((k) => (p[3 * a + k] + p[3 * b + k] + p[3 * c + k]) / 3);
    return [a, b, c].flatMap((v) => [0, 1, 2].map((k) => p[3 * v + k] + 0.1 * (centre[k] - p[3 * v + k])));
  };
  const first = shrunk(stored[0], stored[1], stored[2]), second = shrunk(stored[3], stored[4], stored[5]);
  primitive.getAttribute('POSITION').setArray(new Float32Array([...p, ...first, ...second]));
  primitive.getIndices().setArray(new Uint16Array([7, 8, 9, 4, 5, 6]));  // the second, then the first
  const { glb } = await roundTrip(io, document);
  const back = (await io.readBinary(glb)).getRoot().listMeshes()[0].listPrimitives()[0];
  assert.deepEqual(Array.from(back.getExtension(NAME).getOrders().getArray()), [4, 5, 6, 7, 8, 9, 7, 8, 9, 4, 5, 6]);
  assert.deepEqual(Array.from(back.getIndices().getArray()), [4, 5, 6, 7, 8, 9]);
  assert.match(logger.warnings.join('\n'), /placed the triangles/);
});

test('nearestCentroids against a brute-force search; farther than the limit gives null', () => {
  let seed = 7;
  const random = () => ((seed = (seed * 1103515245 + 12345) % 2147483648) / 2147483648) * 2 - 1;
  const from = Float64Array.from({ length: 3 * 500 }, random), to = Float64Array.from({ length: 3 * 200 }, random);
  const got = nearestCentroids(from, to, 10);
  for (let t = 0; t < 200; ++t) {
    let best = Infinity, bestQ = -1;
    for (let q = 0; q < 500; ++q) {
      const d = Math.hypot(from[3 * q] - to[3 * t], from[3 * q + 1] - to[3 * t + 1], from[3 * q + 2] - to[3 * t + 2]);
      if (d < best) { best = d; bestQ = q; }
    }
    assert.equal(got[t], bestQ, `centroid ${t}`);
  }
  assert.equal(nearestCentroids(from, Float64Array.from([50, 50, 50]), 1), null);
  assert.deepEqual(Array.from(nearestCentroids(Float64Array.from([1, 0, 0, -1, 0, 0]), Float64Array.from([0, 0, 0]), 5)), [0]);
});

test('without the extension registered, glTF-Transform drops it (why registering matters)', async () => {
  const { io, document } = await load(false);
  const { json } = await roundTrip(io, document);
  assert.equal(json.extensions?.[NAME], undefined);
  assert.equal(JSON.stringify(readFileSync(example, 'utf8')).includes(NAME), true);
});

// The example with its JSON changed by `mutate`, read with the warnings recorded from the start.
async function loadMutated(mutate) {
  const json = JSON.parse(readFileSync(example, 'utf8'));
  mutate(json);
  const logger = new Recorder();
  const io = new NodeIO().setLogger(logger).registerExtensions([AnimorderTriangleOrders]);
  const document = await io.readJSON({ json, resources: {} });
  return { io, document, logger };
}
const ext = (json) => json.extensions[NAME];
const primitiveExt = (json) => json.meshes[0].primitives[0].extensions[NAME];

test('an extension that does not check out is read without it, never carried or used', async () => {
  // Each as the runtime and `animorder check` refuse it. A fallback out of range had made the
  // prewrite rewrite `indices` from it: an empty accessor for every loader.
  const broken = {
    'fallback 5': (j) => { ext(j).fallback = 5; },
    'fallback missing': (j) => { delete ext(j).fallback; },
    'fallback "0"': (j) => { ext(j).fallback = '0'; },
    'clips 5': (j) => { ext(j).clips = 5; },
    'clips [null]': (j) => { ext(j).clips = [null]; },
    'table 99': (j) => { ext(j).clips[0].table = 99; },
    'centers missing': (j) => { delete ext(j).clips[0].centers; },
    'sampleRate -1': (j) => { ext(j).clips[0].sampleRate = -1; },
    'thetaSteps "x"': (j) => { ext(j).clips[0].thetaSteps = 'x'; },
    'bufferBase 7': (j) => { ext(j).clips[0].bufferBase = 7; },
    'bufferCount "2"': (j) => { ext(j).bufferCount = '2'; primitiveExt(j).orderCount = '2'; },
  };
  for (const [name, mutate] of Object.entries(broken)) {
    const { io, document, logger } = await loadMutated(mutate);
    assert.equal(document.getRoot().getExtension(NAME), null, name);
    const { json } = await roundTrip(io, document);
    assert.equal(json.extensions?.[NAME], undefined, name);
    assert.equal(json.meshes[0].primitives[0].extensions?.[NAME], undefined, name);
    assert.deepEqual(Array.from(document.getRoot().listMeshes()[0].listPrimitives()[0].getIndices().getArray()),
      [0, 1, 2, 0, 2, 3], name);  // the file's own indices
    assert.match(logger.warnings.join('\n'), /does not check out/, name);
  }
});

test('orders that do not fit their primitive are dropped when read, never re-derived', async () => {
  const broken = {
    'a strip': [(j) => { j.meshes[0].primitives[0].mode = 5; }, /not a TRIANGLES primitive/],
    'VEC2 orders': [(j) => { Object.assign(j.accessors[2], { type: 'VEC2', count: 6 }); }, /orders \(accessor 2\) has the wrong type/],
    'normalized orders': [(j) => { j.accessors[2].normalized = true; }, /orders \(accessor 2\) is normalized/],
    'orders naming vertex 4': [(j) => { j.accessors[0].count = 3; j.bufferViews[0].byteLength = 36; }, /vertex 3 of 3/],
    'orderCount 3': [(j) => { primitiveExt(j).orderCount = 3; }, /orderCount 3 differs from bufferCount 2/],
  };
  for (const [name, [mutate, why]] of Object.entries(broken)) {
    const { io, document, logger } = await loadMutated(mutate);
    const { json } = await roundTrip(io, document);
    assert.equal(json.meshes[0].primitives[0].extensions?.[NAME], undefined, name);
    assert.equal(json.extensions?.[NAME], undefined, name);  // no primitive left with orders
    assert.match(logger.warnings.join('\n'), why, name);
    assert.doesNotMatch(logger.warnings.join('\n'), /re-derived/, name);
  }
});

test('sparse() leaves the extension accessors dense (readers refuse sparse ones)', async () => {
  const { io, document } = await loadMutated((j) => {});
  await document.transform(sparse({ ratio: 1 }));  // sparse wherever zeros could be left out
  const { glb, json } = await roundTrip(io, document);
  const accessors = [ext(json).clips[0].table, ext(json).clips[0].centers, primitiveExt(json).orders];
  for (const a of accessors) assert.equal(json.accessors[a].sparse, undefined);
  const back = await io.readBinary(glb);
  assert.deepEqual(Array.from(back.getRoot().getExtension(NAME).listClips()[0].getTable().getArray()), [0, 1, 1, 0]);
});

test('re-deriving tells apart triangles that share corner positions but not other attributes', async () => {
  const { io, document, logger } = await load();
  const primitive = document.getRoot().listMeshes()[0].listPrimitives()[0];
  const buffer = document.getRoot().listBuffers()[0];
  // Two triangles on the same three positions, told apart by their texture coordinates; order 1
  // draws the second first.
  primitive.getAttribute('POSITION').setArray(new Float32Array([0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 0, 0, 1, 0, 0, 1, 1, 0]));
  primitive.setAttribute('TEXCOORD_0', document.createAccessor().setType('VEC2').setBuffer(buffer)
    .setArray(new Float32Array([0, 0, 1, 0, 1, 1, 0.5, 0.5, 0.5, 0.5, 0.5, 0.5])));
  primitive.getIndices().setArray(new Uint16Array([0, 1, 2, 3, 4, 5]));
  primitive.getExtension(NAME).getOrders().setArray(new Uint16Array([0, 1, 2, 3, 4, 5, 3, 4, 5, 0, 1, 2]));
  const first = await io.readBinary((await roundTrip(io, document)).glb);
  // Re-sequenced, as reorder does: order 0 must stay (0 1 2, 3 4 5), not swap the look-alikes.
  first.setLogger(logger);
  first.getRoot().listMeshes()[0].listPrimitives()[0].getIndices().setArray(new Uint16Array([3, 4, 5, 0, 1, 2]));
  const back = (await io.readBinary((await roundTrip(io, first)).glb)).getRoot().listMeshes()[0].listPrimitives()[0];
  assert.deepEqual(Array.from(back.getExtension(NAME).getOrders().getArray()), [0, 1, 2, 3, 4, 5, 3, 4, 5, 0, 1, 2]);
  assert.deepEqual(Array.from(back.getIndices().getArray()), [0, 1, 2, 3, 4, 5]);
  assert.match(logger.warnings.join('\n'), /re-derived/);
});

test('join() drops the orders of the primitives it merges, with a warning', async () => {
  // A second, still node drawing a mesh of two primitives with orders: join() merges them.
  const { io, document, logger } = await loadMutated((j) => {
    j.meshes.push(structuredClone(j.meshes[0]));
    j.meshes[1].primitives.push(structuredClone(j.meshes[1].primitives[0]));
    j.nodes.push({ mesh: 1 });
    j.scenes[0].nodes.push(1);
  });
  const { join } = await import('@gltf-transform/functions');
  await document.transform(join());
  const { json } = await roundTrip(io, document);
  assert.match(logger.warnings.join('\n'), /dropping the orders of 2 primitive\(s\) that a transform removed or merged/);
  assert.ok(primitiveExt(json), 'the animated node keeps its orders');
});

// The shared corpus of hostile files (tests/extension-corpus/, docs/extension/VALIDITY.md): read
// with the extension registered, each keeps the extension exactly when its manifest says valid,
// else loses it with a warning holding the manifest's phrase (as `animorder check` and the runtime
// word it); io.read never throws for the extension's sake (glTF-Transform's own accessor reading
// throws on a negative or odd byteStride before any extension runs: the file is refused all the
// same, and the test checks the throw is not ours).
const corpus = new URL('../../../tests/extension-corpus/', import.meta.url);

async function readCorpus(json) {
  const logger = new Recorder();
  const io = new NodeIO().setLogger(logger).registerExtensions([AnimorderTriangleOrders]);
  const document = await io.readJSON({ json, resources: {} });
  return { kept: document.getRoot().getExtension(NAME) !== null, warnings: logger.warnings.join('\n') };
}

test('every file of the shared corpus gets its manifest verdict, never a throw', async () => {
  const manifest = JSON.parse(readFileSync(new URL('manifest.json', corpus), 'utf8'));
  assert.ok(manifest.length >= 40);
  for (const entry of manifest) {
    let read;
    try {
      read = await readCorpus(JSON.parse(readFileSync(new URL(entry.file, corpus), 'utf8')));
    } catch (error) {
      assert.ok(!entry.valid && /byteStride/.test(entry.phrase), `${entry.file}: ${error.stack}`);
      assert.doesNotMatch(error.stack, /gltf-transform-animorder\/index\.js/, entry.file);
      continue;
    }
    const { kept, warnings } = read;
    if (entry.valid) {
      assert.ok(kept, `${entry.file}: ${warnings}`);
      assert.equal(warnings, '', entry.file);
    } else {
      assert.ok(!kept, `${entry.file} was kept`);
      if (entry.phrase.includes('extensionsUsed')) continue;  // glTF-Transform never runs an unlisted extension
      assert.match(warnings, /does not check out/, entry.file);
      assert.ok(warnings.includes(entry.phrase), `${entry.file}: '${entry.phrase}' not in: ${warnings}`);
      assert.doesNotMatch(warnings, /[\x00-\x09\x0b-\x1f\x7f]/, entry.file);
    }
  }
});

test('accessors shared by 1000 clips or 2000 primitives are read once; distinct pairs hit the cap', async () => {
  const { sharedTable, sharedOrders, distinctIndices } = await import('../../../tests/extension-corpus/amplify.mjs');
  for (const [name, make, valid] of [['shared table', sharedTable, true], ['shared orders', sharedOrders, true],
    ['distinct indices', distinctIndices, false]]) {
    const started = Date.now();
    const { kept, warnings } = await readCorpus(make());
    assert.equal(kept, valid, `${name}: ${warnings}`);
    if (!valid) assert.match(warnings, /more work than its file's size allows/, name);
    assert.ok(Date.now() - started < 20000, `${name} took ${(Date.now() - started) / 1000} s`);
  }
});
