// ANIMORDER_animated_triangle_orders for glTF-Transform (docs/extension/README.md of animorder).
//
// Registering AnimorderTriangleOrders makes @gltf-transform/core read, keep and write the
// extension: the orders, table and centre accessors are graph references of extension
// properties, so prune, dedup, resample and friends track them like any other accessor. Before
// writing, every primitive's orders are checked against its current triangles: a transform that
// rewrote them (reorder, simplify, a merging weld, join…) leaves orders that are no permutation
// of the triangles, or `indices` that are no longer the fallback order; such orders are dropped
// with a warning (and the whole extension when no primitive keeps valid orders), never written
// stale.
import { Extension, ExtensionProperty, PropertyType, RefList } from '@gltf-transform/core';

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

export class AnimorderTriangleOrders extends Extension {
  static EXTENSION_NAME = NAME;
  extensionName = NAME;
  prewriteTypes = [PropertyType.ACCESSOR];

  createOrders() { return new Orders(this.document.getGraph()); }
  createClip() { return new OrdersClip(this.document.getGraph()); }
  createPrimitiveOrders() { return new PrimitiveOrders(this.document.getGraph()); }

  read(context) {
    const json = context.jsonDoc.json;
    const rootDef = json.extensions && json.extensions[NAME];
    if (rootDef) {
      const root = this.createOrders()
        .setMethod(rootDef.method || '')
        .setBufferCount(rootDef.bufferCount)
        .setFallback(rootDef.fallback);
      for (const c of rootDef.clips || []) {
        const clip = this.createClip()
          .setStartTime(c.startTime || 0).setSampleRate(c.sampleRate).setKeyframes(c.keyframes)
          .setBufferBase(c.bufferBase).setThetaSteps(c.thetaSteps).setPhiSteps(c.phiSteps)
          .setTable(context.accessors[c.table]).setCenters(context.accessors[c.centers]);
        clip.setName(c.name || '');
        if (c.animation !== undefined && context.animations[c.animation]) clip.setAnimation(context.animations[c.animation]);
        root.addClip(clip);
      }
      this.document.getRoot().setExtension(NAME, root);
    }
    (json.meshes || []).forEach((meshDef, m) => {
      (meshDef.primitives || []).forEach((primDef, p) => {
        const def = primDef.extensions && primDef.extensions[NAME];
        if (!def) return;
        const orders = this.createPrimitiveOrders().setOrders(context.accessors[def.orders]).setOrderCount(def.orderCount);
        context.meshes[m].listPrimitives()[p].setExtension(NAME, orders);
      });
    });
    return this;
  }

  // Stale orders are dropped here, before any accessor is written.
  prewrite(context) {
    const logger = this.document.getLogger();
    const root = this.document.getRoot().getExtension(NAME);
    let kept = 0;
    for (const mesh of this.document.getRoot().listMeshes())
      for (const primitive of mesh.listPrimitives()) {
        const orders = primitive.getExtension(NAME);
        if (!orders) continue;
        const why = root ? staleReason(primitive, orders, root.getBufferCount(), root.getFallback()) : 'no root object';
        if (why === null) { ++kept; continue; }
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
