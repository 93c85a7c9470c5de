// ANIMORDER_animated_triangle_orders for glTF-Transform (docs/extension/README.md of animorder).
//
// Registering AnimorderTriangleOrders makes @gltf-transform/core read, keep and write the
// extension: the orders, table and centre accessors are graph references of extension
// properties, so prune, dedup, resample and friends track them like any other accessor. Before
// writing, every primitive's orders are checked against its current triangles. Where a transform
// renumbered vertices or re-sequenced triangles (weld, reorder) the orders are re-derived: each
// triangle is found again by its corners' attributes as they were when the file was read, and
// `indices` becomes the fallback order again. Where the triangles themselves changed (simplify, a
// moved vertex, quantised positions) the orders are dropped with a warning (and the whole
// extension when no primitive keeps valid orders): never written stale. A file whose extension
// does not check out (the rules of animorder's runtime and `animorder check`) is read without
// it, with a warning: a pipeline never carries, nor rewrites `indices` from, orders that an
// engine would refuse.
import { Extension, ExtensionProperty, PropertyType, RefList } from '@gltf-transform/core';
import { AccessorReader, extensionProblems } from '../runtime/animorder.js';

export const NAME = 'ANIMORDER_animated_triangle_orders';
const ORDERS_USAGE = 'ANIMORDER_ORDERS';
const ELEMENT_ARRAY_BUFFER = 34963;

/** The K orders of one primitive: one index accessor of K × n elements. */
export class PrimitiveOrders extends ExtensionProperty {
  static EXTENSION_NAME = NAME;
  init() {
    this.extensionName = NAME;
    this.propertyType = 'AnimorderPrimitiveOrders';
    this.parentTypes = [PropertyType.PRIMITIVE];
  }
  getDefaults() {
    return Object.assign(super.getDefaults(), { orders: null, orderCount: 1 });
  }
  getOrders() { return this.getRef('orders'); }
  setOrders(accessor) { return this.setRef('orders', accessor, { usage: ORDERS_USAGE }); }
  getOrderCount() { return this.get('orderCount'); }
  setOrderCount(count) { return this.set('orderCount', count); }
}

/** One clip: sampling, grid and the table / centre accessors. */
export class OrdersClip extends ExtensionProperty {
  static EXTENSION_NAME = NAME;
  init() {
    this.extensionName = NAME;
    this.propertyType = 'AnimorderClip';
    this.parentTypes = ['AnimorderOrders'];
  }
  getDefaults() {
    return Object.assign(super.getDefaults(), {
      animation: null, startTime: 0, sampleRate: 30, keyframes: 1, bufferBase: 0, thetaSteps: 2, phiSteps: 1,
      table: null, centers: null,
    });
  }
  getAnimation() { return this.getRef('animation'); }
  setAnimation(animation) { return this.setRef('animation', animation); }
  getTable() { return this.getRef('table'); }
  setTable(accessor) { return this.setRef('table', accessor, { usage: 'OTHER' }); }
  getCenters() { return this.getRef('centers'); }
  setCenters(accessor) { return this.setRef('centers', accessor, { usage: 'OTHER' }); }
}
for (const key of ['startTime', 'sampleRate', 'keyframes', 'bufferBase', 'thetaSteps', 'phiSteps']) {
  const Key = key[0].toUpperCase() + key.slice(1);
  OrdersClip.prototype['get' + Key] = function () { return this.get(key); };
  OrdersClip.prototype['set' + Key] = function (value) { return this.set(key, value); };
}

/** The root object: buffer count, fallback and clips. */
export class Orders extends ExtensionProperty {
  static EXTENSION_NAME = NAME;
  init() {
    this.extensionName = NAME;
    this.propertyType = 'AnimorderOrders';
    this.parentTypes = [PropertyType.ROOT];
  }
  getDefaults() {
    return Object.assign(super.getDefaults(), { method: '', bufferCount: 1, fallback: 0, clips: new RefList() });
  }
  getMethod() { return this.get('method'); }
  setMethod(method) { return this.set('method', method); }
  getBufferCount() { return this.get('bufferCount'); }
  setBufferCount(count) { return this.set('bufferCount', count); }
  getFallback() { return this.get('fallback'); }
  setFallback(fallback) { return this.set('fallback', fallback); }
  listClips() { return this.listRefs('clips'); }
  addClip(clip) { return this.addRef('clips', clip); }
}

// The triangle (a, b, c) rotated so that its smallest index comes first (windings stay apart).
function key(a, b, c) {
  if (a <= b && a <= c) return a + ',' + b + ',' + c;
  if (b <= c) return b + ',' + c + ',' + a;
  return c + ',' + a + ',' + b;
}

// The triangles of `indices` (a flat array of vertex ids) as keys: per triangle the three
// corners' values of every attribute (position, normal, texture coordinates...: two triangles
// that only share positions stay apart), rotated so that the smallest comes first (windings
// stay apart).
function cornerKeys(primitive, indices, begin, end) {
  if (!primitive.getAttribute('POSITION')) return null;
  const attributes = primitive.listSemantics().sort().map((semantic) => primitive.getAttribute(semantic));
  const corner = (v) => attributes.map((a) => a.getElement(v, []).join(',')).join(';');
  const keys = [];
  for (let i = begin; i < end; i += 3) {
    const c = [corner(indices[i]), corner(indices[i + 1]), corner(indices[i + 2])];
    const r = c[0] <= c[1] && c[0] <= c[2] ? 0 : (c[1] <= c[2] ? 1 : 2);
    keys.push({ key: c[r] + '|' + c[(r + 1) % 3] + '|' + c[(r + 2) % 3], rotation: r });
  }
  return keys;
}

/**
 * The orders re-derived for a primitive whose vertex ids or triangle sequence a transform
 * changed (weld that merged identical vertices, reorder): each stored triangle, known by its
 * corners' attributes when the file was read, found among the current triangles. Returns the new
 * K × n index array, or null when the triangles themselves changed (simplify, a moved vertex).
 */
export function rederive(primitive, orders, bufferCount) {
  const stored = orders.cornerKeys;
  const indices = primitive.getIndices();
  // Only triangles, with one order per buffer: anything else is dropped, never re-derived.
  if (primitive.getMode() !== 4 || orders.getOrderCount() !== bufferCount) return null;
  if (!stored || !indices || stored.length !== bufferCount) return null;
  const current = indices.getArray(), n = indices.getCount();
  if (stored[0].length * 3 !== n) return null;
  const keys = cornerKeys(primitive, current, 0, n);
  if (!keys) return null;
  const out = new Uint32Array(bufferCount * n);
  for (let b = 0; b < bufferCount; ++b) {
    const pool = new Map();
    keys.forEach((k, t) => { if (!pool.has(k.key)) pool.set(k.key, []); pool.get(k.key).push(t); });
    for (const list of pool.values()) list.reverse();
    for (let q = 0; q < stored[b].length; ++q) {
      const list = pool.get(stored[b][q].key);
      if (!list || list.length === 0) return null;
      const t = list.pop(), r = keys[t].rotation;
      // The current triangle, rotated as the stored one was (same corner first, same winding).
      const shift = (r - stored[b][q].rotation + 3) % 3;
      for (let c = 0; c < 3; ++c) out[b * n + 3 * q + c] = current[3 * t + (c + shift) % 3];
    }
  }
  return out;
}

/**
 * Why a primitive's orders are not usable with its current triangles (a string), or null when
 * they are: every order a permutation of the triangles of `indices` with their winding, and
 * `indices` equal to order `fallback`.
 */
export function staleReason(primitive, orders, bufferCount, fallback) {
  const indices = primitive.getIndices();
  const accessor = orders.getOrders();
  if (!indices || !accessor) return 'no indices or no orders accessor';
  if (primitive.getMode() !== 4) return 'not a TRIANGLES primitive';
  if (orders.getOrderCount() !== bufferCount) return 'orderCount differs from bufferCount';
  const n = indices.getCount();
  if (accessor.getCount() !== n * bufferCount) return 'orders accessor has ' + accessor.getCount() + ' elements, not ' + n * bufferCount;
  if (accessor.getType() !== 'SCALAR' || accessor.getNormalized() ||
      (accessor.getComponentType() !== 5123 && accessor.getComponentType() !== 5125))
    return 'orders accessor is not SCALAR unsigned short or int indices, not normalized';
  const base = indices.getArray(), all = accessor.getArray();
  const counts = new Map();
  for (let i = 0; i < n; i += 3) { const k = key(base[i], base[i + 1], base[i + 2]); counts.set(k, (counts.get(k) || 0) + 1); }
  for (let b = 0; b < bufferCount; ++b) {
    const left = new Map(counts);
    for (let i = b * n; i < (b + 1) * n; i += 3) {
      const k = key(all[i], all[i + 1], all[i + 2]);
      const c = left.get(k);
      if (!c) return 'order ' + b + ' is not a permutation of the primitive\'s triangles (they were rewritten)';
      left.set(k, c - 1);
    }
  }
  for (let i = 0; i < n; ++i) if (base[i] !== all[fallback * n + i]) return 'indices are no longer the fallback order (triangles were reordered)';
  return null;
}

// Why the file's extension does not check out, or null: the first problem of the runtime's
// extensionProblems (the rules of docs/extension/VALIDITY.md, in `animorder check`'s words, at
// most its work), on the file's JSON and the buffers glTF-Transform read (a data URI's bytes under
// the name it gave the buffer, a GLB's binary chunk under '@glb.bin').
function extensionProblem(context) {
  const json = context.jsonDoc.json, resources = context.jsonDoc.resources || {};
  const reader = new AccessorReader(json, null);
  (json.buffers || []).forEach((buffer, b) => {
    const bytes = buffer && (buffer.uri === undefined ? resources['@glb.bin'] : resources[buffer.uri]);
    if (bytes) reader.buffers[b] = bytes instanceof Uint8Array ? bytes : new Uint8Array(bytes);
  });
  const problems = extensionProblems(json, reader);
  return problems && problems.length ? problems[0] : null;
}

export class AnimorderTriangleOrders extends Extension {
  static EXTENSION_NAME = NAME;
  extensionName = NAME;
  prewriteTypes = [PropertyType.ACCESSOR];

  createOrders() { return new Orders(this.document.getGraph()); }
  createClip() { return new OrdersClip(this.document.getGraph()); }
  createPrimitiveOrders() { return new PrimitiveOrders(this.document.getGraph()); }

  // A file whose extension does not check out is read without it, with a warning; nothing here
  // throws out of io.read.
  read(context) {
    const json = context.jsonDoc.json;
    const logger = this.document.getLogger();
    if (!json.extensions || json.extensions[NAME] === undefined) return this;
    let refused;
    try {
      refused = extensionProblem(context);
    } catch (error) {
      refused = error && error.message ? error.message : String(error);
    }
    if (refused) {
      logger.warn(`${NAME}: the file's extension does not check out (${refused.replace(`${NAME}: `, '')}); reading the file without it.`);
      return this;
    }
    const made = [];
    try {
      this.readChecked(context, made);
    } catch (error) {
      for (const property of made) if (!property.isDisposed()) property.dispose();
      this.document.getRoot().setExtension(NAME, null);
      logger.warn(`${NAME}: the file's extension could not be read (${error && error.message}); reading the file without it.`);
    }
    return this;
  }

  // The extension's properties of a file whose extension checks out (`made` collects them).
  readChecked(context, made) {
    const json = context.jsonDoc.json;
    const rootDef = json.extensions[NAME];
    const root = this.createOrders()
      .setMethod(rootDef.method || '')
      .setBufferCount(rootDef.bufferCount)
      .setFallback(rootDef.fallback);
    made.push(root);
    for (const c of rootDef.clips) {
      const clip = this.createClip()
        .setStartTime(c.startTime || 0).setSampleRate(c.sampleRate).setKeyframes(c.keyframes)
        .setBufferBase(c.bufferBase).setThetaSteps(c.thetaSteps).setPhiSteps(c.phiSteps)
        .setTable(context.accessors[c.table]).setCenters(context.accessors[c.centers]);
      made.push(clip);
      clip.setName(c.name || '');
      if (c.animation !== undefined) clip.setAnimation(context.animations[c.animation]);
      root.addClip(clip);
    }
    this.document.getRoot().setExtension(NAME, root);
    // Each order's triangles by their corners' attributes, to re-derive the orders after a
    // transform that renumbers vertices or re-sequences triangles (not written to the file): made
    // once per (orders, indices, attributes) and shared, at most 8 × the buffers' bytes + 2^20
    // corners in all (past that a primitive keeps its orders but cannot have them re-derived).
    const keysOf = new Map();
    let budget = 2 ** 20;
    for (const b of json.buffers || []) if (b && Number.isInteger(b.byteLength)) budget += 8 * b.byteLength;
    (json.meshes || []).forEach((meshDef, m) => {
      (meshDef.primitives || []).forEach((primDef, p) => {
        const def = primDef.extensions && primDef.extensions[NAME];
        if (!def) return;
        const primitive = context.meshes[m].listPrimitives()[p];
        const orders = this.createPrimitiveOrders().setOrders(context.accessors[def.orders]).setOrderCount(def.orderCount);
        made.push(orders);
        primitive.setExtension(NAME, orders);
        const attributes = Object.keys(primDef.attributes || {}).sort().map((k) => `${k}=${primDef.attributes[k]}`);
        const key = `${def.orders};${primDef.indices};${attributes.join(',')}`;
        if (!keysOf.has(key)) {
          const all = orders.getOrders().getArray();
          const n = primitive.getIndices().getCount();
          let keys;
          if (n > 0 && all.length === n * def.orderCount && all.length <= budget) {
            budget -= all.length;
            try {  // attributes glTF-Transform has not filled in yet (sparse ones) leave no keys
              keys = [];
              for (let b = 0; b < def.orderCount; ++b) keys.push(cornerKeys(primitive, all, b * n, (b + 1) * n));
            } catch {
              keys = undefined;
            }
          }
          keysOf.set(key, keys);
        }
        if (keysOf.get(key)) orders.cornerKeys = keysOf.get(key);
      });
    });
  }

  // Stale orders are dropped here, before any accessor is written.
  prewrite(context) {
    const logger = this.document.getLogger();
    const root = this.document.getRoot().getExtension(NAME);
    let kept = 0;
    // staleReason once per (orders, indices, mode, orderCount): primitives sharing accessors share it.
    const ids = new Map(), reasons = new Map();
    const id = (object) => { if (!ids.has(object)) ids.set(object, ids.size); return ids.get(object); };
    const stale = (primitive, orders) => {
      const key = `${id(orders.getOrders())},${id(primitive.getIndices())},${primitive.getMode()},${orders.getOrderCount()}`;
      if (!reasons.has(key)) reasons.set(key, staleReason(primitive, orders, root.getBufferCount(), root.getFallback()));
      return reasons.get(key);
    };
    for (const mesh of this.document.getRoot().listMeshes())
      for (const primitive of mesh.listPrimitives()) {
        const orders = primitive.getExtension(NAME);
        if (!orders) continue;
        const why = root ? stale(primitive, orders) : 'no root object';
        if (why === null) { ++kept; continue; }
        const derived = root ? rederive(primitive, orders, root.getBufferCount()) : null;
        if (derived) {
          // New accessors (the old ones may be shared): the orders, and `indices` = the fallback.
          const n = primitive.getIndices().getCount(), f = root.getFallback();
          const small = derived.every((v) => v < 65535);
          const make = (array) => this.document.createAccessor().setType('SCALAR').setBuffer(primitive.getIndices().getBuffer())
            .setArray(small ? Uint16Array.from(array) : array);
          const old = orders.getOrders();
          orders.setOrders(make(derived));
          if (old && old.listParents().every((p) => p.propertyType === PropertyType.ROOT)) old.dispose();
          const oldIndices = primitive.getIndices();
          primitive.setIndices(make(derived.slice(f * n, (f + 1) * n)));
          if (oldIndices.listParents().every((p) => p.propertyType === PropertyType.ROOT)) oldIndices.dispose();
          logger.warn(`${NAME}: re-derived the orders of mesh "${mesh.getName()}" (${why}).`);
          ++kept;
          continue;
        }
        logger.warn(`${NAME}: dropping the orders of mesh "${mesh.getName()}": ${why}.`);
        const accessor = orders.getOrders();
        primitive.setExtension(NAME, null);
        orders.dispose();
        if (accessor && accessor.listParents().every((p) => p.propertyType === PropertyType.ROOT)) accessor.dispose();
      }
    if (root && kept === 0) {
      logger.warn(`${NAME}: no primitive keeps valid orders; dropping the extension.`);
      for (const clip of root.listClips()) {
        for (const a of [clip.getTable(), clip.getCenters()])
          if (a && a.listParents().every((p) => p === clip || p.propertyType === PropertyType.ROOT)) { clip.setTable(null); clip.setCenters(null); a.dispose(); }
        clip.dispose();
      }
      this.document.getRoot().setExtension(NAME, null);
      root.dispose();
    }
    // Orders of a primitive that a transform removed or merged (join) go with it, said once.
    const orphans = [...this.properties].filter((p) => p instanceof PrimitiveOrders && !p.isDisposed() &&
      !p.listParents().some((parent) => parent.propertyType === PropertyType.PRIMITIVE));
    if (orphans.length) logger.warn(`${NAME}: dropping the orders of ${orphans.length} primitive(s) that a transform removed or merged.`);
    for (const orphan of orphans) {
      const accessor = orphan.getOrders();
      orphan.dispose();
      if (accessor && accessor.listParents().every((p) => p.propertyType === PropertyType.ROOT)) accessor.dispose();
    }
    // The extension's accessors, and the indices of primitives with orders, stay dense: a reader
    // refuses a sparse one (sparse() makes a mostly-zero table sparse).
    const ours = [];
    for (const mesh of this.document.getRoot().listMeshes())
      for (const primitive of mesh.listPrimitives()) if (primitive.getExtension(NAME)) ours.push(primitive.getIndices());
    for (const p of this.properties) {
      if (p.isDisposed()) continue;
      if (p instanceof PrimitiveOrders) ours.push(p.getOrders());
      if (p instanceof OrdersClip) ours.push(p.getTable(), p.getCenters());
    }
    for (const accessor of ours) if (accessor) accessor.setSparse(false);
    context.accessorUsageGroupedByParent.add(ORDERS_USAGE);  // each primitive's orders in a view of their own
    for (const p of this.properties)
      if (p instanceof PrimitiveOrders && p.getOrders()) context.addAccessorToUsageGroup(p.getOrders(), ORDERS_USAGE);
    return this;
  }

  write(context) {
    const json = context.jsonDoc.json;
    const root = this.document.getRoot().getExtension(NAME);
    if (!root) return this;
    const clips = root.listClips().map((clip) => {
      const def = {
        name: clip.getName(), startTime: clip.getStartTime(), sampleRate: clip.getSampleRate(),
        keyframes: clip.getKeyframes(), bufferBase: clip.getBufferBase(), thetaSteps: clip.getThetaSteps(),
        phiSteps: clip.getPhiSteps(), table: context.accessorIndexMap.get(clip.getTable()),
        centers: context.accessorIndexMap.get(clip.getCenters()),
      };
      const animation = clip.getAnimation();
      if (animation && context.animationIndexMap.has(animation)) def.animation = context.animationIndexMap.get(animation);
      return def;
    });
    json.extensions = json.extensions || {};
    json.extensions[NAME] = { method: root.getMethod(), bufferCount: root.getBufferCount(), fallback: root.getFallback(), clips };
    for (const mesh of this.document.getRoot().listMeshes()) {
      const meshDef = json.meshes[context.meshIndexMap.get(mesh)];
      mesh.listPrimitives().forEach((primitive, p) => {
        const orders = primitive.getExtension(NAME);
        if (!orders) return;
        const index = context.accessorIndexMap.get(orders.getOrders());
        const view = json.accessors[index].bufferView;
        if (view !== undefined) json.bufferViews[view].target = ELEMENT_ARRAY_BUFFER;
        const primDef = meshDef.primitives[p];
        primDef.extensions = primDef.extensions || {};
        primDef.extensions[NAME] = { orders: index, orderCount: orders.getOrderCount() };
      });
    }
    return this;
  }
}
