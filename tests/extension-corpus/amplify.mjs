// The amplification files of the extension corpus (docs/extension/VALIDITY.md, "Work"): small
// files whose accessors many clips or primitives share, generated at run time by the tests (and
// by make.mjs --amplified for measuring). Each returns a glTF JSON object with one embedded buffer.
const EXT = 'ANIMORDER_animated_triangle_orders';

// A glTF of `parts` ([Uint8Array...], each 4-byte aligned) in one data-URI buffer; returns the
// JSON and each part's buffer view index.
function gltf(parts) {
    const views = [], chunks = [];
    let offset = 0;
    for (const p of parts) {
        views.push({ buffer: 0, byteOffset: offset, byteLength: p.length });
        const pad = (4 - (p.length % 4)) % 4;
        chunks.push(p, new Uint8Array(pad));
        offset += p.length + pad;
    }
    const data = Buffer.concat(chunks);
    return {
        asset: { version: '2.0', generator: 'animorder extension corpus (tests/extension-corpus/amplify.mjs)' },
        extensionsUsed: [EXT], scene: 0, scenes: [{ nodes: [0] }], nodes: [{ mesh: 0 }],
        bufferViews: views,
        buffers: [{ byteLength: data.length, uri: 'data:application/octet-stream;base64,' + data.toString('base64') }],
    };
}
const bytesOf = (typed) => new Uint8Array(typed.buffer, typed.byteOffset, typed.byteLength);

// A strip of `triangles` triangles (t, t+1, t+2), windings alternating, as positions and indices;
// order b is the triangles rotated b places along the strip, its fallback order 0.
function strip(triangles, orderCount) {
    const vertices = triangles + 2, positions = new Float32Array(3 * vertices);
    for (let v = 0; v < vertices; ++v) positions.set([v >> 1, v & 1, 0], 3 * v);
    const triangle = (t) => (t % 2 === 0 ? [t, t + 1, t + 2] : [t + 1, t, t + 2]);
    const indices = new Uint16Array(3 * triangles), orders = new Uint16Array(3 * triangles * orderCount);
    for (let t = 0; t < triangles; ++t) indices.set(triangle(t), 3 * t);
    for (let b = 0; b < orderCount; ++b)
        for (let t = 0; t < triangles; ++t) orders.set(triangle((t + b) % triangles), 3 * (b * triangles + t));
    return { positions, indices, orders, vertices };
}

// `clips` clips (all of animation 0, a still one) naming one table of thetaSteps × phiSteps cells
// and one centres accessor; a quad with 2 orders.
export function sharedTable(clips = 1000, thetaSteps = 1000, phiSteps = 1800) {
    const s = strip(2, 2);
    const table = new Uint8Array(thetaSteps * phiSteps);
    for (let i = 0; i < table.length; ++i) table[i] = i % 2;
    const g = gltf([bytesOf(s.positions), bytesOf(s.indices), bytesOf(s.orders), table,
        bytesOf(new Float32Array([0.5, 0.5, 0])), bytesOf(new Float32Array([0])), bytesOf(new Float32Array([0, 0, 0]))]);
    g.accessors = [
        { bufferView: 0, componentType: 5126, count: s.vertices, type: 'VEC3', min: [0, 0, 0], max: [1, 1, 0] },
        { bufferView: 1, componentType: 5123, count: s.indices.length, type: 'SCALAR' },
        { bufferView: 2, componentType: 5123, count: s.orders.length, type: 'SCALAR' },
        { bufferView: 3, componentType: 5121, count: table.length, type: 'SCALAR' },
        { bufferView: 4, componentType: 5126, count: 1, type: 'VEC3' },
        { bufferView: 5, componentType: 5126, count: 1, type: 'SCALAR', min: [0], max: [0] },
        { bufferView: 6, componentType: 5126, count: 1, type: 'VEC3' },
    ];
    g.meshes = [{ primitives: [{ attributes: { POSITION: 0 }, indices: 1, mode: 4, extensions: { [EXT]: { orders: 2, orderCount: 2 } } }] }];
    g.animations = [{ name: 'still', channels: [{ sampler: 0, target: { node: 0, path: 'translation' } }],
        samplers: [{ input: 5, output: 6, interpolation: 'LINEAR' }] }];
    const clip = { name: 'still', animation: 0, startTime: 0, sampleRate: 30, keyframes: 1, bufferBase: 0, thetaSteps,
        phiSteps, table: 3, centers: 4 };
    g.extensions = { [EXT]: { method: 'single', bufferCount: 2, fallback: 0, clips: Array.from({ length: clips }, () => clip) } };
    return g;
}

// `primitives` primitives of one mesh sharing one POSITION, one indices and one orders accessor (a
// strip of `triangles` triangles, `orderCount` orders); `distinctIndices`: each primitive has an
// indices accessor of its own over the same bytes (distinct pairs: the work cap must refuse it).
export function sharedOrders(primitives = 2000, triangles = 5000, orderCount = 24, distinctIndices = false) {
    const s = strip(triangles, orderCount);
    const g = gltf([bytesOf(s.positions), bytesOf(s.indices), bytesOf(s.orders), new Uint8Array(2 * orderCount),
        bytesOf(new Float32Array([0.5, 0.5, 0]))]);
    const table = new Uint8Array(2 * orderCount);
    g.accessors = [
        { bufferView: 0, componentType: 5126, count: s.vertices, type: 'VEC3', min: [0, 0, 0], max: [(s.vertices - 1) >> 1, 1, 0] },
        { bufferView: 2, componentType: 5123, count: s.orders.length, type: 'SCALAR' },
        { bufferView: 3, componentType: 5121, count: table.length, type: 'SCALAR' },
        { bufferView: 4, componentType: 5126, count: 1, type: 'VEC3' },
        { bufferView: 1, componentType: 5123, count: s.indices.length, type: 'SCALAR' },
    ];
    const prims = [];
    for (let p = 0; p < primitives; ++p) {
        let indices = 4;
        if (distinctIndices && p > 0) {
            indices = g.accessors.length;
            g.accessors.push({ bufferView: 1, componentType: 5123, count: s.indices.length, type: 'SCALAR' });
        }
        prims.push({ attributes: { POSITION: 0 }, indices, mode: 4, extensions: { [EXT]: { orders: 1, orderCount } } });
    }
    g.meshes = [{ primitives: prims }];
    g.extensions = { [EXT]: { method: 'joint', bufferCount: orderCount, fallback: 0, clips: [{ name: 'posed',
        sampleRate: 30, keyframes: 1, bufferBase: 0, thetaSteps: 2, phiSteps: orderCount, table: 2, centers: 3 }] } };
    return g;
}

// sharedOrders with an indices accessor per primitive: refused by the work cap.
export function distinctIndices() {
    return sharedOrders(500, 2000, 16, true);
}
