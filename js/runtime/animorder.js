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
            const problems = extensionProblems(json, reader);
            if (problems.length) fail(`${EXTENSION_NAME}: ${problems[0]}`);
            return AnimorderRuntime.fromExtension(root, (index) => reader.read(index));
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

// The largest value of a table, found once per table (clips may share one: a thousand clips of one
// table must not cost a thousand passes over it).
const largestCells = new WeakMap();
function largestCell(cells) {
    if (typeof cells === 'object' && largestCells.has(cells)) return largestCells.get(cells);
    let m = 0;
    for (let k = 0; k < cells.length; ++k) if (cells[k] > m) m = cells[k];
    if (typeof cells === 'object') largestCells.set(cells, m);
    return m;
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
    const largest = largestCell(c.cells);
    if (c.bufferBase + largest >= bufferCount) fail(`${where}: a cell names buffer ${c.bufferBase + largest} >= ${bufferCount}`);
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

// ---- the rules of docs/extension/VALIDITY.md, as `animorder check` applies them ----

const INT32_MAX = 2147483647;
const COMPONENT_SIZE = { 5120: 1, 5121: 1, 5122: 2, 5123: 2, 5125: 4, 5126: 4 };

// `text` with every control character (below 0x20, and 0x7f) written as \xNN and backslashes
// doubled: a name from a file quoted in a one-line message.
export function printable(text) {
    return String(text).replace(/[\x00-\x1f\x7f\\]/g, (c) => c === '\\' ? '\\\\' : '\\x' + c.charCodeAt(0).toString(16).padStart(2, '0'));
}

// A whole JSON number, as `animorder check` reads one (strings, fractions and NaN are not).
function integer(value) {
    return typeof value === 'number' && Number.isInteger(value) && Math.abs(value) < 9e15;
}

// The problems of a glTF's ANIMORDER_animated_triangle_orders extension (an array of one-line
// messages, empty when its orders are usable; null when the file does not use it): the rules of
// docs/extension/VALIDITY.md, in `animorder check`'s words, and at most its work (each accessor
// read once however many clips or primitives name it, each (orders, indices) pair compared once,
// all of it at most 8 × the bytes of the file's buffers + 2^20). `reader` is an AccessorReader of
// the file: its bufferBytes give the bytes, and the accessors read here are left in its cache for
// read().
export function extensionProblems(json, reader) {
    const root = json && json.extensions && json.extensions[EXTENSION_NAME];
    if (root === undefined) return null;
    return new ExtensionCheck(json, reader).run(root);
}

class ExtensionCheck {
    constructor(json, reader) {
        this.json = json;
        this.reader = reader;
        this.problems = [];
        this.budget = 2 ** 20;
        for (const b of json.buffers || []) if (b && isCount(b.byteLength)) this.budget += 8 * b.byteLength;
        this.used = 0;
        this.over = false;
        this.decoded = new Map();  // accessor → { error } or { count, array, largest, ... }
        this.pairs = new Map();    // "orders,indices" → { equal, permutation: [bool] }
    }

    add(problem) {
        this.problems.push(problem);
    }

    // Adds `error` unless the budget ran out (then the one problem that says so stands for it).
    report(error) {
        if (!this.over) this.add(error);
    }

    // Counts `elements` of work; false (with one problem said) once past the budget.
    charge(elements) {
        if (this.over) return false;
        if (elements > this.budget - this.used) {
            this.over = true;
            this.add(`the extension asks for more work than its file's size allows: over ${this.budget} accessor elements ` +
                'read and compared (8 x the buffers\' bytes + 2^20; accessors shared by many clips or primitives?)');
            return false;
        }
        this.used += elements;
        return true;
    }

    // A required integer in [low, high] of object `o`, or undefined (a problem added).
    bounded(o, key, low, high, where) {
        const value = o[key];
        if (!Object.hasOwn(o, key) || !integer(value)) {
            this.add(`${where}.${key} is missing or not an integer`);
            return undefined;
        }
        if (value < low || value > high) {
            this.add(`${where}.${key} = ${value} is out of range [${low}, ${high}]`);
            return undefined;
        }
        return value;
    }

    // Accessor `index` as `type` of one of `components`, not normalized: { decoded } or { error }.
    get(index, type, components, what) {
        const name = `${what} (accessor ${index})`;
        const accessors = this.json.accessors || [];
        const a = integer(index) && index >= 0 && index < accessors.length ? accessors[index] : undefined;
        if (!a || typeof a !== 'object') return { error: `${what}: accessor ${index} does not exist` };
        if (a.type !== type) return { error: `${name} has the wrong type (expected ${type})` };
        if (!components.includes(a.componentType))
            return { error: `${name} has component type ${a.componentType}, not one the extension allows` };
        if (a.normalized === true) return { error: `${name} is normalized` };
        if (!this.decoded.has(index)) this.decoded.set(index, this.decode(index, a));
        const d = this.decoded.get(index);
        return d.error !== undefined ? { error: name + d.error } : { decoded: d };
    }

    decode(index, a) {
        if (a.sparse !== undefined) return { error: ' is sparse' };
        const views = this.json.bufferViews || [];
        const v = integer(a.bufferView) && a.bufferView >= 0 ? views[a.bufferView] : undefined;
        if (!v || typeof v !== 'object') return { error: ' has no valid buffer view' };
        const buffers = this.json.buffers || [];
        if (!integer(v.buffer) || v.buffer < 0 || !buffers[v.buffer]) return { error: '\'s buffer view names no buffer' };
        const data = this.reader.bufferBytes(v.buffer);
        const Type = TYPES[a.componentType], itemSize = COMPONENTS[a.type];
        const size = COMPONENT_SIZE[a.componentType], element = size * itemSize;
        const stride = v.byteStride || element;
        if (stride < element || stride % size !== 0)
            return { error: `'s buffer view has byteStride ${stride}, not a multiple of ${size} of at least its element size ${element}` };
        const viewOffset = v.byteOffset ?? 0, offset = a.byteOffset ?? 0;
        if (!isCount(viewOffset) || !isCount(v.byteLength) || viewOffset + v.byteLength > data.length)
            return { error: '\'s buffer view lies outside its buffer' };
        const count = a.count;
        if (!isCount(count) || !isCount(offset) || (count > 0 && (count - 1) * stride + element + offset > v.byteLength))
            return { error: ` has ${count} elements, more than its buffer view holds` };
        if (!this.charge(count * itemSize)) return { error: ' was not read (the work cap)' };
        const view = new DataView(data.buffer, data.byteOffset, data.byteLength);
        const get = {
            5120: (o) => view.getInt8(o), 5121: (o) => view.getUint8(o), 5122: (o) => view.getInt16(o, true),
            5123: (o) => view.getUint16(o, true), 5125: (o) => view.getUint32(o, true), 5126: (o) => view.getFloat32(o, true),
        }[a.componentType];
        const array = new Type(count * itemSize), start = viewOffset + offset;
        for (let e = 0; e < count; ++e)
            for (let k = 0; k < itemSize; ++k) array[e * itemSize + k] = get(start + e * stride + k * size);
        // Left for the reader's read(): the runtime's tables and centres are these arrays.
        this.reader.read_.set(index, { array, itemSize, count, componentType: a.componentType, normalized: false });
        return { count, array };
    }

    // The largest value of a decoded accessor, found once.
    static largest(d) {
        if (d.largest === undefined) {
            let m = 0;
            for (const v of d.array) if (v > m) m = v;
            d.largest = m;
        }
        return d.largest;
    }

    run(root) {
        const json = this.json;
        // What tinygltf hides from `check`, checked on the JSON: offsets and strides.
        for (const list of ['accessors', 'bufferViews'])
            (Array.isArray(json[list]) ? json[list] : []).forEach((item, i) => {
                if (item && typeof item === 'object' && Object.hasOwn(item, 'byteOffset') &&
                    !(integer(item.byteOffset) && item.byteOffset >= 0))
                    this.add(`${list}[${i}].byteOffset ${JSON.stringify(item.byteOffset)} is not a non-negative integer`);
            });
        (Array.isArray(json.bufferViews) ? json.bufferViews : []).forEach((item, i) => {
            if (!item || typeof item !== 'object' || !Object.hasOwn(item, 'byteStride')) return;
            const s = item.byteStride;
            if (!(integer(s) && s >= 4 && s <= 252 && s % 4 === 0))
                this.add(`bufferViews[${i}].byteStride ${JSON.stringify(s)} is not an integer from 4 to 252, a multiple of 4`);
        });
        // Integers past 32 bits, which tinygltf would wrap for `check`: quoted as written.
        const wide = (value, where) => {
            if (Array.isArray(value)) value.forEach((v, i) => wide(v, `${where}[${i}]`));
            else if (value !== null && typeof value === 'object') for (const k of Object.keys(value)) wide(value[k], `${where}.${k}`);
            else if (Number.isInteger(value) && (value > INT32_MAX || value < -INT32_MAX - 1))
                this.add(`${where} = ${value} is out of range (an integer here is below 2^31)`);
        };
        wide(root, EXTENSION_NAME);
        (json.meshes || []).forEach((mesh, m) => ((mesh && mesh.primitives) || []).forEach((primitive, q) => {
            const ext = primitive && primitive.extensions && primitive.extensions[EXTENSION_NAME];
            if (ext !== undefined) wide(ext, `mesh ${m} primitive ${q}`);
        }));
        if (root !== null && typeof root === 'object' && Array.isArray(root.clips))
            root.clips.forEach((c, i) => { if (c === null || typeof c !== 'object' || Array.isArray(c)) this.add(`clips[${i}] is not an object`); });
        if (!(json.extensionsUsed || []).includes(EXTENSION_NAME)) this.add(`${EXTENSION_NAME} is not listed in extensionsUsed`);
        if ((json.extensionsRequired || []).includes(EXTENSION_NAME))
            this.add(`${EXTENSION_NAME} must not be listed in extensionsRequired`);
        if (root === null || typeof root !== 'object' || Array.isArray(root)) {
            this.add('the root extension object is not an object');
            return this.problems;
        }
        if (Object.hasOwn(root, 'method') && typeof root.method !== 'string') this.add('root.method is not a string');
        const bufferCount = this.bounded(root, 'bufferCount', 1, 65536, 'root');
        if (bufferCount === undefined) return this.problems;
        const fallback = this.bounded(root, 'fallback', 0, bufferCount - 1, 'root');
        if (fallback === undefined) return this.problems;
        if (!Array.isArray(root.clips) || root.clips.length === 0) this.add('root.clips is missing or empty');
        else
            for (let c = 0; c < root.clips.length && !this.over; ++c)
                if (root.clips[c] !== null && typeof root.clips[c] === 'object' && !Array.isArray(root.clips[c]))
                    this.clip(root.clips[c], c, bufferCount);
        let carried = 0;
        (json.meshes || []).forEach((mesh, m) => ((mesh && mesh.primitives) || []).forEach((primitive, p) => {
            const ext = primitive && primitive.extensions && primitive.extensions[EXTENSION_NAME];
            if (ext === undefined || this.over) return;
            if (ext === null || typeof ext !== 'object' || Array.isArray(ext)) {
                this.add(`meshes[${m}].primitives[${p}] extension is not an object`);
                return;
            }
            carried += this.primitive(primitive, ext, m, p, bufferCount, fallback);
        }));
        if (carried === 0 && this.problems.length === 0) this.add('no primitive carries the orders');
        return this.problems;
    }

    clip(o, c, bufferCount) {
        const where = `clips[${c}]`, animations = this.json.animations || [];
        if (Object.hasOwn(o, 'name') && typeof o.name !== 'string') return this.add(`${where}.name is not a string`);
        let animation = -1;
        if (Object.hasOwn(o, 'animation')) {
            animation = this.bounded(o, 'animation', 0, animations.length - 1, where);
            if (animation === undefined) return;
            // The clip's name is its animation's (an unnamed one's "animationN").
            const own = animations[animation] && typeof animations[animation].name === 'string' ? animations[animation].name : '';
            const expected = own === '' ? `animation${animation}` : own;
            if (Object.hasOwn(o, 'name') && o.name !== expected)
                return this.add(`${where}.name '${printable(o.name)}' is not the name of animation ${animation} ('${printable(expected)}')`);
        }
        const startTime = Object.hasOwn(o, 'startTime') ? o.startTime : 0;
        if (typeof startTime !== 'number' || !Number.isFinite(startTime)) return this.add(`${where}.startTime is not a finite number`);
        const rate = o.sampleRate;
        if (typeof rate !== 'number' || !Number.isFinite(rate) || !(rate > 0) || !(f32(rate) > 0) || !Number.isFinite(f32(rate)))
            return this.add(`${where}.sampleRate is missing or not a positive number a 32-bit float holds (from about ` +
                '1.2e-38 to 3.4e38)');
        const keyframes = this.bounded(o, 'keyframes', 1, 100000, where);
        const thetaSteps = this.bounded(o, 'thetaSteps', 2, 100000, where);
        const phiSteps = this.bounded(o, 'phiSteps', 1, 100000, where);
        const bufferBase = this.bounded(o, 'bufferBase', 0, bufferCount - 1, where);
        const table = this.bounded(o, 'table', 0, INT32_MAX, where);
        const centers = this.bounded(o, 'centers', 0, INT32_MAX, where);
        if ([keyframes, thetaSteps, phiSteps, bufferBase, table, centers].includes(undefined)) return;
        const t = this.get(table, 'SCALAR', [5121], `${where}.table`);
        if (t.error) return this.report(t.error);
        const cells = keyframes * thetaSteps * phiSteps;
        if (t.decoded.count !== cells)
            return this.add(`${where}.table has ${t.decoded.count} cells; keyframes x thetaSteps x phiSteps = ${cells}`);
        if (bufferBase + ExtensionCheck.largest(t.decoded) >= bufferCount) {
            const first = t.decoded.array.findIndex((v) => bufferBase + v >= bufferCount);
            return this.add(`${where}.table cell ${first} names order ${bufferBase + t.decoded.array[first]}, not below bufferCount ${bufferCount}`);
        }
        const m = this.get(centers, 'VEC3', [5126], `${where}.centers`);
        if (m.error) return this.report(m.error);
        if (m.decoded.count !== keyframes)
            return this.add(`${where}.centers has ${m.decoded.count} elements, not keyframes = ${keyframes}`);
        if (m.decoded.finite === undefined) m.decoded.finite = m.decoded.array.every(Number.isFinite);
        if (!m.decoded.finite) return this.add(`${where}.centers holds a value that is not finite`);
        // The table covers the animation's time range: keyframe f at startTime + f / sampleRate.
        if (animation >= 0) {
            let t0 = Infinity, t1 = -Infinity;
            for (const s of (animations[animation].samplers || [])) {
                const input = s && s.input;
                const accessor = integer(input) && input >= 0 ? (this.json.accessors || [])[input] : undefined;
                if (!accessor) continue;
                const keys = this.get(input, 'SCALAR', [5126], '');
                if (!keys.error) {
                    if (keys.decoded.t0 === undefined) {
                        let lo = Infinity, hi = -Infinity;
                        for (const k of keys.decoded.array) lo = Math.min(lo, k), hi = Math.max(hi, k);
                        keys.decoded.t0 = lo, keys.decoded.t1 = hi;
                    }
                    t0 = Math.min(t0, keys.decoded.t0), t1 = Math.max(t1, keys.decoded.t1);
                } else if (Array.isArray(accessor.min) && Array.isArray(accessor.max) && accessor.min.length === 1 &&
                           accessor.max.length === 1) {
                    t0 = Math.min(t0, accessor.min[0]), t1 = Math.max(t1, accessor.max[0]);
                }
            }
            if (this.over) return;
            if (t0 <= t1) {
                const step = 1 / rate;
                if (Math.abs(startTime - t0) > 0.5 * step)
                    this.add(`${where}.startTime ${startTime.toFixed(6)} is not animation ${animation}'s first key time ${t0.toFixed(6)}`);
                else if (startTime + (keyframes - 1) * step < t1 - step - 1e-6)
                    this.add(`${where} has ${keyframes} keyframes; animation ${animation} lasts to ${t1.toFixed(6)} s and needs ` +
                        `${Math.floor((t1 - startTime) * rate + 1e-9) + 1}`);
            }
        }
    }

    // 1 when the primitive's orders were read (whatever they hold), else 0.
    primitive(primitive, o, m, p, bufferCount, fallback) {
        const where = `meshes[${m}].primitives[${p}]`;
        const orders = this.bounded(o, 'orders', 0, INT32_MAX, where);
        const orderCount = this.bounded(o, 'orderCount', 1, INT32_MAX, where);
        if (orders === undefined || orderCount === undefined) return 0;
        if (orderCount !== bufferCount) return this.add(`${where}.orderCount ${orderCount} differs from bufferCount ${bufferCount}`), 0;
        if (primitive.mode !== undefined && primitive.mode !== 4) return this.add(`${where} is not a TRIANGLES primitive`), 0;
        const indexIndex = Object.hasOwn(primitive, 'indices') ? primitive.indices : -1;
        const ind = this.get(indexIndex, 'SCALAR', [5121, 5123, 5125], `${where}.indices`);
        if (ind.error) return this.report(ind.error), 0;
        const ord = this.get(orders, 'SCALAR', [5121, 5123, 5125], `${where}.orders`);
        if (ord.error) return this.report(ord.error), 0;
        const type = this.json.accessors[orders].componentType;
        if (type === 5121) return this.add(`${where}.orders is UNSIGNED_BYTE`), 0;
        const n = ind.decoded.count;
        if (n % 3 !== 0) return this.add(`${where}.indices holds ${n} indices, not whole triangles`), 0;
        if (ord.decoded.count !== n * orderCount)
            return this.add(`${where}.orders has ${ord.decoded.count} elements; orderCount x indices = ${n * orderCount}`), 0;
        // Every order names vertices of the primitive (an unsigned short never 65535, WebGL 2's
        // primitive restart).
        const position = primitive.attributes ? primitive.attributes.POSITION : undefined;
        const positions = integer(position) && position >= 0 ? (this.json.accessors || [])[position] : undefined;
        if (!positions) return this.add(`${where} has no POSITION accessor`), 0;
        const largest = ExtensionCheck.largest(ord.decoded);
        if (ord.decoded.count > 0 && largest >= positions.count) return this.add(`${where}.orders names vertex ${largest} of ${positions.count}`), 0;
        if (type === 5123 && largest === 65535) return this.add(`${where}.orders names vertex 65535 (primitive restart)`), 0;
        const verdict = this.pair(orders, indexIndex, ord.decoded, ind.decoded, orderCount, fallback);
        if (!verdict) return 0;
        if (!verdict.equal) this.add(`${where}.indices differs from order ${fallback} (fallback)`);
        const bad = verdict.permutation.indexOf(false);
        if (bad >= 0) {
            const more = verdict.permutation.filter((x) => !x).length - 1;
            this.add(`${where} order ${bad} is not a permutation of the primitive's triangles with their winding (stale orders?)` +
                (more ? ` (and ${more} more orders)` : ''));
        }
        return 1;
    }

    // The permutation verdicts of an (orders, indices) pair of accessors, compared once.
    pair(orders, indices, o, ind, orderCount, fallback) {
        const key = `${orders},${indices}`;
        if (this.pairs.has(key)) return this.pairs.get(key);
        if (!this.charge(o.count)) return null;
        const n = ind.count, all = o.array, base = ind.array;
        let equal = true;
        for (let i = 0; i < n && equal; ++i) equal = base[i] === all[fallback * n + i];
        const rotated = (v, i) => {
            const a = v[i], b = v[i + 1], c = v[i + 2];
            return a <= b && a <= c ? `${a},${b},${c}` : b <= c ? `${b},${c},${a}` : `${c},${a},${b}`;
        };
        const counts = new Map();
        for (let i = 0; i < n; i += 3) { const k = rotated(base, i); counts.set(k, (counts.get(k) || 0) + 1); }
        const permutation = [];
        for (let b = 0; b < orderCount; ++b) {
            const left = new Map(counts);
            let ok = true;
            for (let i = b * n; i < (b + 1) * n && ok; i += 3) {
                const k = rotated(all, i), c = left.get(k);
                if (!c) ok = false;
                else left.set(k, c - 1);
            }
            permutation.push(ok);
        }
        const verdict = { equal, permutation };
        this.pairs.set(key, verdict);
        return verdict;
    }
}
