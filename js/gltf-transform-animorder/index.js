// ANIMORDER_animated_triangle_orders for glTF-Transform (docs/extension/README.md of animorder).
//
// Registering AnimorderTriangleOrders makes @gltf-transform/core read, keep and write the
// extension: the orders, table and centre accessors are graph references of extension
// properties, so prune, dedup, resample and friends track them like any other accessor. Before
// writing, every primitive's orders are checked against its current triangles. Where a transform
// renumbered vertices or re-sequenced triangles (weld, reorder) the orders are re-derived: each
// triangle is found again by its corners' attributes as they were when the file was read, and
// `indices` becomes the fallback order again. Where the triangles themselves changed (simplify, a
// moved vertex) each current triangle is placed where the original triangle with the nearest
// centroid was (positions as read; within a tenth of their bounding-box diagonal): every order
// draws the current triangles in its order of the originals they stand for, with a warning.
// Where even that fails (quantised positions, a mesh moved away) the orders are dropped with a
// warning (and the whole extension when no primitive keeps valid orders): never written stale. A
// file whose extension does not check out (the rules of animorder's runtime and `animorder
// check`) is read without it, with a warning: a pipeline never carries, nor rewrites `indices`
// from, orders that an engine would refuse.
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

// Each triangle's centroid (x, y, z) from `indices` [begin, end) and the primitive's POSITION, or
// null without positions.
function centroids(primitive, indices, begin, end) {
  const position = primitive.getAttribute('POSITION');
  if (!position) return null;
  const out = new Float64Array(end - begin);
  const v = [0, 0, 0];
  for (let i = begin, t = 0; i < end; i += 3, t += 3)
    for (let c = 0; c < 3; ++c) {
      position.getElement(indices[i + c], v);
      for (let a = 0; a < 3; ++a) out[t + a] += v[a] / 3;
    }
  return out;
}

/**
 * What placing needs, made when the file is read: the centroids of order 0's triangles, each
 * one's position in every order (`keys`: cornerKeys of each order, triangles paired in sequence),
 * and the diagonal of the bounding box of the vertices they use. Null when an order is no
 * permutation of order 0.
 */
function placementOf(primitive, all, n, keys) {
  const centres = centroids(primitive, all, 0, n);
  if (!centres) return null;
  const ranks = [];
  for (const orderKeys of keys) {
    const where = new Map();
    orderKeys.forEach((k, q) => { if (!where.has(k.key)) where.set(k.key, []); where.get(k.key).push(q); });
    for (const list of where.values()) list.reverse();
    const rank = new Uint32Array(n / 3);
    for (let q = 0; q < n / 3; ++q) {
      const list = where.get(keys[0][q].key);
      if (!list || list.length === 0) return null;
      rank[q] = list.pop();
    }
    ranks.push(rank);
  }
  // The bounding box of the vertices the triangles use.
  const position = primitive.getAttribute('POSITION'), v = [0, 0, 0];
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < n; ++i) {
    position.getElement(all[i], v);
    for (let a = 0; a < 3; ++a) { lo[a] = Math.min(lo[a], v[a]); hi[a] = Math.max(hi[a], v[a]); }
  }
  const diagonal = Math.hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
  return { centres, ranks, diagonal };
}

/**
 * For each centroid of `to`, the index of the nearest centroid of `from` (lowest index among
 * equally near ones), or null when one lies farther than `limit` from all of them. A uniform grid
 * over `from`, searched in shells of cells around each query until no nearer one can lie beyond.
 */
export function nearestCentroids(from, to, limit) {
  const count = from.length / 3;
  if (count === 0) return null;
  const lo = [Infinity, Infinity, Infinity], hi = [-Infinity, -Infinity, -Infinity];
  for (let i = 0; i < from.length; i += 3)
    for (let a = 0; a < 3; ++a) { lo[a] = Math.min(lo[a], from[i + a]); hi[a] = Math.max(hi[a], from[i + a]); }
  const extent = Math.max(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
  const h = Math.max(extent / Math.max(1, Math.cbrt(count)), limit / 64, 1e-12);
  const cell = (x, a) => Math.floor((x - lo[a]) / h);
  const grid = new Map();
  for (let q = 0; q < count; ++q) {
    const k = `${cell(from[3 * q], 0)},${cell(from[3 * q + 1], 1)},${cell(from[3 * q + 2], 2)}`;
    if (!grid.has(k)) grid.set(k, []);
    grid.get(k).push(q);
  }
  const rings = Math.ceil(limit / h) + 1;
  const out = new Uint32Array(to.length / 3);
  for (let t = 0; t < to.length / 3; ++t) {
    const x = to[3 * t], y = to[3 * t + 1], z = to[3 * t + 2];
    const c = [cell(x, 0), cell(y, 1), cell(z, 2)];
    let best = Infinity, bestQ = -1;
    for (let r = 0; r <= rings; ++r) {
      // Every cell at Chebyshev distance r: a point there lies at least (r − 1)·h away.
      if (bestQ >= 0 && best <= (r - 1) * h) break;
      for (let dx = -r; dx <= r; ++dx)
        for (let dy = -r; dy <= r; ++dy)
          for (let dz = -r; dz <= r; ++dz) {
            if (Math.max(Math.abs(dx), Math.abs(dy), Math.abs(dz)) !== r) continue;
            const list = grid.get(`${c[0] + dx},${c[1] + dy},${c[2] + dz}`);
            if (!list) continue;
            for (const q of list) {
              const d = Math.hypot(from[3 * q] - x, from[3 * q + 1] - y, from[3 * q + 2] - z);
              if (d < best || (d === best && q < bestQ)) { best = d; bestQ = q; }
            }
          }
    }
    if (bestQ < 0 || best > limit) return null;
    out[t] = bestQ;
  }
  return out;
}

/**
 * The orders placed for a primitive whose triangles a transform changed (simplify, a moved
 * vertex): each current triangle stands for the original triangle with the nearest centroid
 * (within `limit` of the original bounding-box diagonal), and order b draws the current triangles
 * in order b's order of the originals they stand for, several standing for one in their current
 * sequence. Returns the new K × n index array, or null when a triangle lies farther (or the
 * primitive has no positions, or its orders were not placeable when read).
 */
export function place(primitive, orders, bufferCount, limit = 0.1) {
  const p = orders.placement;
  if (!p || primitive.getMode() !== 4 || orders.getOrderCount() !== bufferCount || p.ranks.length !== bufferCount) return null;
  const indices = primitive.getIndices();
  if (!indices) return null;
  const current = indices.getArray(), n = indices.getCount();
  if (n === 0 || n % 3 !== 0) return null;
  const here = centroids(primitive, current, 0, n);
  if (!here) return null;
  const near = nearestCentroids(p.centres, here, limit * p.diagonal);
  if (!near) return null;
  const out = new Uint32Array(bufferCount * n);
  const sequence = Array.from({ length: n / 3 }, (_, t) => t);
  for (let b = 0; b < bufferCount; ++b) {
    const rank = p.ranks[b];
    sequence.sort((x, y) => rank[near[x]] - rank[near[y]] || x - y);
    sequence.forEach((t, q) => { for (let c = 0; c < 3; ++c) out[b * n + 3 * q + c] = current[3 * t + c]; });
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
    const keysOf = new Map(), placements = new Map();
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
        if (keysOf.get(key)) {
          orders.cornerKeys = keysOf.get(key);
          if (!placements.has(key)) {
            let placement = null;
            try {
              placement = placementOf(primitive, orders.getOrders().getArray(), primitive.getIndices().getCount(),
                                      orders.cornerKeys);
            } catch {
              placement = null;
            }
            placements.set(key, placement);
          }
          if (placements.get(key)) orders.placement = placements.get(key);
        }
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
        let derived = root ? rederive(primitive, orders, root.getBufferCount()) : null;
        const placed = !derived && root ? place(primitive, orders, root.getBufferCount()) : null;
        derived = derived || placed;
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
          logger.warn(placed
            ? `${NAME}: placed the triangles of mesh "${mesh.getName()}" by the nearest original triangle (${why}).`
            : `${NAME}: re-derived the orders of mesh "${mesh.getName()}" (${why}).`);
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
