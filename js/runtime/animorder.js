// animorder runtime for JavaScript: pick the triangle order (index buffer) to draw for a clip, a
// time and a camera position. ES module, no dependencies. It chooses exactly what the C runtime
// include/animorder_runtime.h chooses (animorder_select_keyframe / animorder_select_time); a test
// (js/test/equivalence.mjs) compares both on the same file for 100,000+ queries.
//
// Two sources hold the same tables:
//   * the sidecar OUT.animorder.bin (layout: the comment at the top of animorder_runtime.h):
//       AnimorderRuntime.fromSidecar(arrayBuffer)
//   * the glTF extension ANIMORDER_animated_triangle_orders (docs/extension/README.md), in a .glb
//     or a .gltf whose buffers are embedded data URIs:
//       AnimorderRuntime.fromGlb(arrayBuffer), AnimorderRuntime.fromGltf(json, binChunk)
//
//   const rt = AnimorderRuntime.fromGlb(bytes);
//   const buffer = rt.selectTime(clip, secondsFromClipStart, [x, y, z]);   // -1: no answer
//
// Cell (f, i, j) stands for θ = i·π/(thetaSteps − 1) from +Y and φ = j·2π/phiSteps from +Z towards
// +X; the buffer is bufferBase + cell. Every number is rounded as the C code rounds it: the camera
// and the centres are float32, the sample rate float32, the arithmetic double.

export const EXTENSION_NAME = 'ANIMORDER_animated_triangle_orders';

export class AnimorderError extends Error {
    constructor(message) {
        super(message);
        this.name = 'AnimorderError';
    }
}

const f32 = Math.fround;
const UINT32_MAX = 4294967295;
const INT_MAX = 2147483647;

function fail(message) {
    throw new AnimorderError(message);
}

function isCount(value) {
    return Number.isInteger(value) && value >= 0 && value <= UINT32_MAX;
}

export class AnimorderRuntime {
    // bufferCount: the number of buffers (orders); clips: [{ name, animation, startTime, sampleRate,
    // keyframes, thetaSteps, phiSteps, bufferBase, cells: Uint8Array, centres: Float32Array }].
    // Checked as animorder_runtime_open checks the sidecar: a bad table throws AnimorderError.
    constructor({ bufferCount, clips, method = null, fallback = 0, buffers = null, indexCount = 0 }) {
        if (!isCount(bufferCount) || bufferCount > INT_MAX) fail(`bad buffer count ${bufferCount}`);
        if (!Array.isArray(clips)) fail('clips must be an array');
        this.bufferCount = bufferCount;
        this.method = method;
        this.fallback = fallback;
        this.indexCount = indexCount;
        this._buffers = buffers; // sidecar only: b → the bytes' Uint32 view of buffer b, or null
        this._bufferViews = new Map();
        this.clips = clips.map((c, index) => checkClip(c, index, bufferCount));
    }

    // The clip-local keyframe a time gives (seconds from the clip's first keyframe): rounded to the
    // nearest, clamped, NaN → 0. -1 for a bad clip.
    keyframeAt(clip, seconds) {
        const c = this.clips[clip];
        if (!c) return -1;
        return clampKeyframe(c, seconds * c.sampleRate);
    }

    // animorder_select_keyframe: buffer id, or -1 (bad clip, camera at the centre or not finite).
    // camera and centre are [x, y, z] in model space; centre null/undefined → the stored one.
    selectKeyframe(clip, keyframe, camera, centre = null) {
        const c = Number.isInteger(clip) && clip >= 0 ? this.clips[clip] : undefined;
        if (!c || !camera) return -1;
        return select(this, c, keyframe, camera, centre);
    }

    // animorder_select_time: `seconds` counts from the clip's first keyframe.
    selectTime(clip, seconds, camera, centre = null) {
        const c = Number.isInteger(clip) && clip >= 0 ? this.clips[clip] : undefined;
        if (!c || !camera) return -1;
        return select(this, c, seconds * c.sampleRate, camera, centre);
    }

    // The same with the time of the glTF animation the clip was sampled from (its startTime first).
    selectAnimationTime(clip, animationSeconds, camera, centre = null) {
        const c = this.clips[clip];
        if (!c) return -1;
        return this.selectTime(clip, animationSeconds - c.startTime, camera, centre);
    }

    // The clip sampled from glTF animation `animation`, or -1.
    clipForAnimation(animation) {
        return this.clips.findIndex((c) => c.animation === animation);
    }

    // Sidecar only: buffer b's indexCount indices (Uint32Array), or null.
    buffer(b) {
        if (!this._buffers || !Number.isInteger(b) || b < 0 || b >= this.bufferCount) return null;
        if (!this._bufferViews.has(b)) this._bufferViews.set(b, this._buffers(b));
        return this._bufferViews.get(b);
    }

    // ---- sources ----

    // The sidecar's bytes (ArrayBuffer or a typed array over one).
    static fromSidecar(bytes) {
        const { view, u8 } = viewOf(bytes);
        const size = u8.length;
        if (size < 20) fail('sidecar truncated: no header');
        if (String.fromCharCode(u8[0], u8[1], u8[2], u8[3]) !== 'AOR1' || view.getUint32(4, true) !== 1)
            fail('not an animorder sidecar (bad magic or version)');
        const bufferCount = view.getUint32(8, true);
        const indexCount = view.getUint32(12, true);
        const clipCount = view.getUint32(16, true);
        const buffersEnd = 20 + clipCount * 32 + bufferCount * indexCount * 4; // < 2^67: exact enough to compare
        if (buffersEnd > size) fail('sidecar truncated: clip records or index buffers past the end');
        if (bufferCount > INT_MAX) fail('sidecar: too many buffers');
        // As the C runtime: no buffer would leave the fallback (buffer 0) unbound, and an index
        // count that is not whole triangles is a partial triangle.
        if (bufferCount === 0) fail('sidecar: no buffer');
        if (indexCount % 3 !== 0) fail(`sidecar: ${indexCount} indices are not whole triangles`);
        const clips = [];
        let tables = 0;
        for (let c = 0; c < clipCount; ++c) {
            const q = 20 + c * 32;
            const keyframes = view.getUint32(q, true), thetaSteps = view.getUint32(q + 4, true);
            const phiSteps = view.getUint32(q + 8, true), sampleRate = view.getFloat32(q + 12, true);
            const bufferBase = view.getUint32(q + 16, true), cells = view.getUint32(q + 20, true);
            const centres = view.getUint32(q + 24, true);
            if (keyframes === 0 || thetaSteps < 2 || phiSteps === 0) fail(`sidecar clip ${c}: impossible dimensions`);
            const cellBytes = keyframes * thetaSteps * phiSteps, centreBytes = keyframes * 12;
            if (cells < buffersEnd || cells + cellBytes > size || centres < buffersEnd || centres + centreBytes > size)
                fail(`sidecar clip ${c}: table or centres out of bounds`);
            tables += cellBytes + centreBytes;
            if (tables > size - buffersEnd) fail(`sidecar clip ${c}: tables overlap`);
            const centreValues = new Float32Array(keyframes * 3);
            for (let k = 0; k < keyframes * 3; ++k) centreValues[k] = view.getFloat32(centres + 4 * k, true);
            clips.push({
                name: `clip ${c}`, animation: -1, startTime: 0, sampleRate, keyframes, thetaSteps, phiSteps,
                bufferBase, cells: u8.subarray(cells, cells + cellBytes), centres: centreValues,
            });
        }
        // Each buffer's view made when first asked for: opening costs nothing per buffer (a header
        // may claim 2^31 buffers of 0 indices).
        const base = u8.byteOffset + 20 + clipCount * 32;
        const buffers = (b) => {
            const start = base + b * indexCount * 4;
            return start % 4 === 0 ? new Uint32Array(u8.buffer, start, indexCount)
                                   : new Uint32Array(u8.slice(start - u8.byteOffset, start - u8.byteOffset + indexCount * 4).buffer);
        };
        return new AnimorderRuntime({ bufferCount, clips, method: null, fallback: 0, buffers, indexCount });
    }

    // A .glb's bytes. Returns null when the file does not use the extension.
    static fromGlb(bytes) {
        return asAnimorderError(() => {
            const { json, bin } = parseGlb(bytes);
            return AnimorderRuntime.fromGltf(json, bin);
        });
    }

    // A glTF JSON object and the GLB binary chunk (a Uint8Array, or null for a .gltf whose buffers are
    // data URIs). Returns null when the file does not use the extension.
    static fromGltf(json, bin = null) {
        return asAnimorderError(() => {
            const root = json && json.extensions && json.extensions[EXTENSION_NAME];
            if (!root) return null;
            const reader = new AccessorReader(json, bin);
            const runtime = AnimorderRuntime.fromExtension(root, (index) => reader.read(index));
            checkPrimitives(json, runtime.bufferCount, reader);
            return runtime;
        });
    }

    // The root extension object, with `readAccessor(index)` returning { array, itemSize, count,
    // componentType, normalized } for an accessor (a typed array of count·itemSize values, tightly
    // packed): AccessorReader's read, which the three.js plugin uses too.
    static fromExtension(root, readAccessor) {
        if (!isCount(root.bufferCount)) fail(`${EXTENSION_NAME}: bufferCount must be a count`);
        if (!Array.isArray(root.clips)) fail(`${EXTENSION_NAME}: clips must be an array`);
        const clips = root.clips.map((c, index) => {
            const table = readAccessor(c.table), centres = readAccessor(c.centers);
            if (!table || table.componentType !== 5121 || table.itemSize !== 1 || table.normalized)
                fail(`${EXTENSION_NAME}: clip ${index}'s table must be a SCALAR UNSIGNED_BYTE accessor, not normalized`);
            if (!centres || centres.componentType !== 5126 || centres.itemSize !== 3 || centres.normalized)
                fail(`${EXTENSION_NAME}: clip ${index}'s centers must be a VEC3 FLOAT accessor, not normalized`);
            return {
                name: c.name, animation: c.animation, startTime: c.startTime ?? 0, sampleRate: c.sampleRate,
                keyframes: c.keyframes, thetaSteps: c.thetaSteps, phiSteps: c.phiSteps, bufferBase: c.bufferBase,
                cells: table.array, centres: centres.array,
            };
        });
        const fallback = root.fallback;  // required (the schema): the order a reader draws without a pick
        if (!Number.isInteger(fallback) || fallback < 0 || fallback >= root.bufferCount)
            fail(`${EXTENSION_NAME}: fallback ${fallback} is not a buffer`);
        return new AnimorderRuntime({ bufferCount: root.bufferCount, clips, method: root.method ?? null, fallback });
    }
}

// Any failure as an AnimorderError (a TypeError from a null clip, a SyntaxError from the JSON...),
// so that a caller catches one kind of error.
function asAnimorderError(make) {
    try {
        return make();
    } catch (error) {
        if (error instanceof AnimorderError) throw error;
        fail(`${EXTENSION_NAME}: ${error && error.message ? error.message : String(error)}`);
    }
}

// Why a primitive's orders accessor does not fit it, or null: `animorder check`'s rules, shared by
// this runtime, the three.js plugin and the glTF-Transform extension. `orders` is { itemSize,
// componentType, count, normalized, sparse } and valueAt(e) its e-th value: orderCount × the
// indices' count unsigned shorts or ints, not normalized or sparse, each a vertex of the
// primitive (an unsigned short never 65535, WebGL 2's primitive restart).
export function ordersProblem(orders, valueAt, orderCount, indexCount, vertexCount) {
    const wide = orders.componentType === 5125;
    if (orders.itemSize !== 1 || (!wide && orders.componentType !== 5123) || orders.count !== orderCount * indexCount ||
        orders.normalized || orders.sparse)
        return `orders must be ${orderCount}×${indexCount} unsigned short or int indices, not normalized or sparse`;
    const limit = wide ? vertexCount : Math.min(vertexCount, 65535);
    for (let e = 0; e < orders.count; ++e) {
        const v = valueAt(e);
        if (v >= limit) return `an order names vertex ${v} of ${vertexCount}${v === 65535 ? ' (primitive restart)' : ''}`;
    }
    return null;
}

// What the extension asks of each primitive that carries orders (the checks of `animorder check`
// an engine needs before binding them): triangles with indices and positions, orderCount =
// bufferCount, an orders accessor inside its buffer view and buffer (`reader`) that fits
// (ordersProblem).
function checkPrimitives(json, bufferCount, reader) {
    const accessors = json.accessors || [];
    (json.meshes || []).forEach((mesh, m) => (mesh && mesh.primitives || []).forEach((primitive, p) => {
        const ext = primitive && primitive.extensions && primitive.extensions[EXTENSION_NAME];
        if (!ext) return;
        const where = `mesh ${m} primitive ${p}`;
        if (primitive.mode !== undefined && primitive.mode !== 4) fail(`${where}: orders on a primitive that is not triangles`);
        const indices = accessors[primitive.indices];
        if (!Number.isInteger(primitive.indices) || !indices || !isCount(indices.count)) fail(`${where}: orders on a primitive without indices`);
        if (ext.orderCount !== bufferCount) fail(`${where}: orderCount ${ext.orderCount} != bufferCount ${bufferCount}`);
        const position = primitive.attributes ? accessors[primitive.attributes.POSITION] : undefined;
        if (!position || !isCount(position.count)) fail(`${where}: orders on a primitive without positions`);
        const at = reader.locate(ext.orders);  // sparse or view-less accessors refused there
        const wide = at.accessor.componentType === 5125;
        const valueAt = (e) => wide ? at.data.getUint32(at.start + e * at.stride, true) : at.data.getUint16(at.start + e * at.stride, true);
        const problem = ordersProblem({ itemSize: at.itemSize, componentType: at.accessor.componentType, count: at.count,
            normalized: at.accessor.normalized === true, sparse: false }, valueAt, ext.orderCount, indices.count, position.count);
        if (problem) fail(`${where}: ${problem}`);
    }));
}

function checkClip(c, index, bufferCount) {
    const where = `clip ${index}`;
    for (const key of ['keyframes', 'thetaSteps', 'phiSteps', 'bufferBase'])
        if (!isCount(c[key])) fail(`${where}: ${key} must be a count`);
    if (c.keyframes === 0 || c.thetaSteps < 2 || c.phiSteps === 0) fail(`${where}: impossible table dimensions`);
    const sampleRate = typeof c.sampleRate === 'number' ? f32(c.sampleRate) : NaN;  // f32("30") would be 30
    if (!(sampleRate > 0 && Number.isFinite(sampleRate))) fail(`${where}: sample rate must be a positive number`);
    if (c.bufferBase >= bufferCount) fail(`${where}: bufferBase ${c.bufferBase} >= bufferCount ${bufferCount}`);
    const cellCount = c.keyframes * c.thetaSteps * c.phiSteps;
    if (!c.cells || c.cells.length !== cellCount) fail(`${where}: the table has ${c.cells ? c.cells.length : 0} cells, not ${cellCount}`);
    if (!c.centres || c.centres.length !== c.keyframes * 3) fail(`${where}: ${c.keyframes} keyframes need ${c.keyframes} centres`);
    for (let k = 0; k < cellCount; ++k)
        if (c.bufferBase + c.cells[k] >= bufferCount) fail(`${where}: a cell names buffer ${c.bufferBase + c.cells[k]} >= ${bufferCount}`);
    const startTime = c.startTime ?? 0;
    if (!Number.isFinite(startTime)) fail(`${where}: startTime must be a number`);
    return {
        name: c.name ?? where, animation: Number.isInteger(c.animation) ? c.animation : -1, startTime,
        sampleRate, keyframes: c.keyframes, thetaSteps: c.thetaSteps, phiSteps: c.phiSteps, bufferBase: c.bufferBase,
        cells: c.cells, centres: c.centres instanceof Float32Array ? c.centres : Float32Array.from(c.centres),
    };
}

function clampKeyframe(c, keyframe) {
    const k = Number.isNaN(keyframe) ? 0 : Math.floor(keyframe + 0.5);
    return k <= 0 ? 0 : k >= c.keyframes - 1 ? c.keyframes - 1 : k;
}

// animorder__select, operation for operation.
function select(rt, c, keyframe, camera, centre) {
    const f = clampKeyframe(c, keyframe);
    let cx, cy, cz;
    if (centre == null) {
        cx = c.centres[3 * f];
        cy = c.centres[3 * f + 1];
        cz = c.centres[3 * f + 2];
    } else {
        cx = f32(centre[0]);
        cy = f32(centre[1]);
        cz = f32(centre[2]);
    }
    const dx = f32(camera[0]) - cx, dy = f32(camera[1]) - cy, dz = f32(camera[2]) - cz;
    const length = Math.sqrt(dx * dx + dy * dy + dz * dz);
    if (!(length > 0 && length <= Number.MAX_VALUE)) return -1; // at the centre, NaN or infinite
    const theta = Math.acos(Math.max(-1, Math.min(1, dy / length)));
    let phi = Math.atan2(dx, dz);
    if (phi < 0) phi += 2.0 * Math.PI;
    let x = Math.floor((theta / Math.PI) * (c.thetaSteps - 1) + 0.5);
    const i = x <= 0 ? 0 : x >= c.thetaSteps - 1 ? c.thetaSteps - 1 : x;
    x = Math.floor((phi / (2.0 * Math.PI)) * c.phiSteps + 0.5);
    const j = x <= 0 || x >= c.phiSteps ? 0 : x; // φ = 2π is φ = 0
    const buffer = c.bufferBase + c.cells[(f * c.thetaSteps + i) * c.phiSteps + j];
    return buffer < rt.bufferCount ? buffer : -1;
}

function viewOf(bytes) {
    const u8 = bytes instanceof Uint8Array ? bytes
        : ArrayBuffer.isView(bytes) ? new Uint8Array(bytes.buffer, bytes.byteOffset, bytes.byteLength)
        : new Uint8Array(bytes);
    return { u8, view: new DataView(u8.buffer, u8.byteOffset, u8.byteLength) };
}

// The JSON and the binary chunk of a .glb (glTF 2.0 §4.4).
export function parseGlb(bytes) {
    const { u8, view } = viewOf(bytes);
    if (u8.length < 20 || view.getUint32(0, true) !== 0x46546c67) fail('not a GLB file (bad magic)');
    if (view.getUint32(4, true) !== 2) fail('GLB version is not 2');
    const length = Math.min(view.getUint32(8, true), u8.length);
    let json = null, bin = null;
    for (let at = 12; at + 8 <= length;) {
        const chunkLength = view.getUint32(at, true), type = view.getUint32(at + 4, true);
        if (at + 8 + chunkLength > length) fail('GLB chunk past the end of the file');
        const data = u8.subarray(at + 8, at + 8 + chunkLength);
        if (type === 0x4e4f534a && json === null) json = JSON.parse(new TextDecoder().decode(data));
        else if (type === 0x004e4942 && bin === null) bin = data;
        at += 8 + chunkLength + ((4 - (chunkLength % 4)) % 4);
    }
    if (!json) fail('GLB without a JSON chunk');
    return { json, bin };
}

const COMPONENTS = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4, MAT4: 16 };
const TYPES = { 5120: Int8Array, 5121: Uint8Array, 5122: Int16Array, 5123: Uint16Array, 5125: Uint32Array, 5126: Float32Array };

// Reads accessors of a glTF (GLB binary chunk or base64 data URIs), strides included; no sparse.
export class AccessorReader {
    constructor(json, bin) {
        this.json = json;
        this.bin = bin;
        this.buffers = [];
        this.read_ = new Map(); // accessor → what read() gave: one accessor named by many clips is read once
    }

    bufferBytes(index) {
        if (!Number.isInteger(index)) fail(`buffer ${index} does not exist`);  // buffers['0'] is buffers[0]
        if (this.buffers[index]) return this.buffers[index];
        const buffer = (this.json.buffers || [])[index];
        if (!buffer) fail(`buffer ${index} does not exist`);
        let bytes;
        if (buffer.uri === undefined) {
            if (!this.bin) fail(`buffer ${index} has no URI and there is no GLB binary chunk`);
            bytes = this.bin;
        } else {
            const m = /^data:[^,]*;base64,(.*)$/.exec(buffer.uri);
            if (!m) fail(`buffer ${index}: only embedded (data URI) buffers are read here`);
            const text = atob(m[1]);
            bytes = new Uint8Array(text.length);
            for (let k = 0; k < text.length; ++k) bytes[k] = text.charCodeAt(k);
        }
        return (this.buffers[index] = bytes);
    }

    read(index) {
        if (!this.read_.has(index)) this.read_.set(index, this.readOnce(index));
        return this.read_.get(index);
    }

    // Where accessor `index`'s elements lie, every number checked before any allocation: the
    // extension's accessors lie in buffer views (one without would be `count` zeros, any count), at
    // offsets that are counts, inside the view and its buffer. Returns { accessor, Type, itemSize,
    // count, start, stride, data } (data: a DataView of the buffer; element e at start + e·stride).
    locate(index) {
        const accessor = Number.isInteger(index) ? (this.json.accessors || [])[index] : undefined;
        if (!accessor) fail(`accessor ${index} does not exist`);
        if (accessor.sparse) fail(`accessor ${index} is sparse`);
        const Type = TYPES[accessor.componentType], itemSize = COMPONENTS[accessor.type];
        if (!Type || !itemSize) fail(`accessor ${index}: unknown type`);
        if (!isCount(accessor.count)) fail(`accessor ${index}: bad count`);
        const count = accessor.count;
        if (accessor.bufferView === undefined) fail(`accessor ${index} has no buffer view`);
        const view = Number.isInteger(accessor.bufferView) ? (this.json.bufferViews || [])[accessor.bufferView] : undefined;
        if (!view) fail(`accessor ${index}: buffer view ${accessor.bufferView} does not exist`);
        const element = Type.BYTES_PER_ELEMENT * itemSize;
        const viewOffset = view.byteOffset ?? 0, offset = accessor.byteOffset ?? 0, stride = view.byteStride || element;
        if (!isCount(viewOffset) || !isCount(offset) || !isCount(view.byteLength) || !isCount(stride) || stride < element)
            fail(`accessor ${index}: its buffer view's offsets, length or stride are not counts that fit its elements`);
        const bytes = this.bufferBytes(view.buffer);
        const start = viewOffset + offset;
        const end = count === 0 ? start : start + (count - 1) * stride + element;
        if (end > viewOffset + view.byteLength || viewOffset + view.byteLength > bytes.length)
            fail(`accessor ${index} reaches past its buffer view or buffer`);
        const data = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
        return { accessor, Type, itemSize, count, start, stride, data };
    }

    readOnce(index) {
        const { accessor, Type, itemSize, count, start, stride, data } = this.locate(index);
        const array = new Type(count * itemSize);
        const get = {
            5120: (o) => data.getInt8(o), 5121: (o) => data.getUint8(o), 5122: (o) => data.getInt16(o, true),
            5123: (o) => data.getUint16(o, true), 5125: (o) => data.getUint32(o, true), 5126: (o) => data.getFloat32(o, true),
        }[accessor.componentType];
        for (let e = 0; e < count; ++e)
            for (let k = 0; k < itemSize; ++k) array[e * itemSize + k] = get(start + e * stride + k * Type.BYTES_PER_ELEMENT);
        return { array, itemSize, count, componentType: accessor.componentType, normalized: accessor.normalized === true };
    }
}
