// The glTF-Transform extension against the hand-written example of docs/extension (a quad: order
// 0 = 0 1 2 0 2 3, order 1 = 0 2 3 0 1 2, a 2 x 2 table 0 1 1 0, centre (0.5, 0.5, 0)).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { fileURLToPath } from 'node:url';
import { Logger, NodeIO } from '@gltf-transform/core';
import { dedup, prune, resample } from '@gltf-transform/functions';
import { AnimorderTriangleOrders, NAME, staleReason } from '../index.js';

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

test('orders made stale by rewritten triangles are dropped with a warning', async () => {
  for (const [indices, why] of [
    [[0, 2, 1, 0, 2, 3], /not a permutation/],        // a winding flipped (as a rewrite would)
    [[0, 2, 3, 0, 1, 2], /no longer the fallback/],   // triangles re-sequenced (reorder)
  ]) {
    const { io, document, logger } = await load();
    document.getRoot().listMeshes()[0].listPrimitives()[0].getIndices().setArray(new Uint16Array(indices));
    const { json } = await roundTrip(io, document);
    assert.equal(json.meshes[0].primitives[0].extensions?.[NAME], undefined);
    assert.equal(json.extensions?.[NAME], undefined);
    assert.match(logger.warnings.join('\n'), why);
  }
});

test('a simplified primitive (fewer triangles) loses its orders', async () => {
  const { io, document, logger } = await load();
  document.getRoot().listMeshes()[0].listPrimitives()[0].getIndices().setArray(new Uint16Array([0, 1, 2]));
  const { json } = await roundTrip(io, document);
  assert.equal(json.extensions?.[NAME], undefined);
  assert.match(logger.warnings.join('\n'), /orders accessor has 12 elements, not 6/);
});

test('without the extension registered, glTF-Transform drops it (why registering matters)', async () => {
  const { io, document } = await load(false);
  const { json } = await roundTrip(io, document);
  assert.equal(json.extensions?.[NAME], undefined);
  assert.equal(JSON.stringify(readFileSync(example, 'utf8')).includes(NAME), true);
});
