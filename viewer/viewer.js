// The animorder viewer: loads an optimised glb (?file=URL, default /model.glb as `animorder view`
// serves it; ?original=URL adds the input file's order for comparison), plays its clips, orbits the
// camera and shows the buffer the runtime picks, and — in the overdraw view — the GPU's own count of
// fragments that pass the depth test: each adds one to a float target with additive blending; the
// heat image and OVR = passed / covered pixels are read back from that target. window.animorderViewer
// exposes the same for the browser tests (viewer/test/browser.mjs).
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { RoomEnvironment } from 'three/addons/environments/RoomEnvironment.js';
import { AnimorderGLTFPlugin, EXTENSION_NAME } from '../js/three/animorder-three.js';

const $ = (id) => document.getElementById(id);
const params = new URLSearchParams(location.search);
const fileUrl = params.get('file') || '/model.glb';
const originalUrl = params.get('original');
const COUNT_SIZE = Number(params.get('countSize') || 256);

const renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
renderer.setPixelRatio(1);
renderer.setSize(innerWidth, innerHeight);
$('view').appendChild(renderer.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0x30343c);
// An environment, so that glTF's default material (metallic 1) is not black.
if (params.get('environment') !== '0') scene.environment = new THREE.PMREMGenerator(renderer).fromScene(new RoomEnvironment(), 0.04).texture;
scene.add(new THREE.HemisphereLight(0xffffff, 0x404050, 2.2));
const sun = new THREE.DirectionalLight(0xffffff, 1.5);
sun.position.set(2, 4, 3);
scene.add(sun);
const camera = new THREE.PerspectiveCamera(40, innerWidth / innerHeight, 0.01, 1000);
const controls = new OrbitControls(camera, renderer.domElement);
let lastTime = performance.now();

// The counting pass: every fragment that passes the depth test (LESS, as DESIGN.md) adds 1.
const floatBlend = renderer.extensions.has('EXT_float_blend');
const countTarget = new THREE.WebGLRenderTarget(COUNT_SIZE, COUNT_SIZE, {
    type: floatBlend ? THREE.FloatType : THREE.HalfFloatType, format: THREE.RGBAFormat,
    minFilter: THREE.NearestFilter, magFilter: THREE.NearestFilter, depthBuffer: true,
});
const countMaterial = new THREE.MeshBasicMaterial({
    color: 0xffffff, blending: THREE.CustomBlending, blendEquation: THREE.AddEquation,
    blendSrc: THREE.OneFactor, blendDst: THREE.OneFactor, depthTest: true, depthWrite: true,
    depthFunc: THREE.LessDepth, side: THREE.FrontSide, toneMapped: false,
});
const countPixels = floatBlend ? new Float32Array(COUNT_SIZE * COUNT_SIZE * 4) : new Uint16Array(COUNT_SIZE * COUNT_SIZE * 4);

const state = {
    ready: false, error: null, hasExtension: false, message: '', gltf: null, orders: null, mixer: null,
    clip: 0, mode: 'runtime', originalBuffer: -1, history: [], last: null, paused: false,
};

function message(text, kind = '') {
    state.message = text;
    $('message').textContent = text;
    $('message').className = kind;
}

// Passed fragments and covered pixels of the character as `cam` sees it now, drawing buffer `b`
// (or the current one when b is undefined), in a COUNT_SIZE² float target.
function countPass(cam, b) {
    const orders = state.orders;
    const keep = orders ? orders.buffer : -1;
    if (orders && b !== undefined) orders.setBuffer(b);
    const background = scene.background;
    scene.background = null;
    scene.overrideMaterial = countMaterial;
    renderer.setRenderTarget(countTarget);
    renderer.setClearColor(0x000000, 0);
    renderer.clear(true, true, true);
    renderer.render(scene, cam);
    renderer.readRenderTargetPixels(countTarget, 0, 0, COUNT_SIZE, COUNT_SIZE, countPixels);
    renderer.setRenderTarget(null);
    scene.overrideMaterial = null;
    scene.background = background;
    if (orders && b !== undefined) orders.setBuffer(keep);
    let passed = 0, visible = 0;
    const counts = new Float32Array(COUNT_SIZE * COUNT_SIZE);
    for (let p = 0; p < COUNT_SIZE * COUNT_SIZE; ++p) {
        const v = floatBlend ? countPixels[4 * p] : THREE.DataUtils.fromHalfFloat(countPixels[4 * p]);
        counts[p] = v;
        passed += v;
        if (v > 0) visible++;
    }
    return { passed: Math.round(passed), visible, ovr: visible ? passed / visible : 0, counts };
}

// Poses the character at keyframe `keyframe` of clip `clip` (the clip's own sampling).
function pose(clip, keyframe) {
    const orders = state.orders, mixer = state.mixer;
    const c = orders.runtime.clips[clip];
    mixer.stopAllAction();
    const action = mixer.clipAction(state.gltf.animations[c.animation]);
    action.play();
    action.time = c.startTime + keyframe / c.sampleRate;
    mixer.update(0);
    state.gltf.scene.updateMatrixWorld(true);
    return action;
}

// The protocol's node camera (include/animorder/camera.h): `viewProjection` (16 numbers,
// column-major, as node_view_projection gives them) applied to positions minus `centre`.
function nodeCamera(viewProjection, centre) {
    const cam = new THREE.Camera();
    const vp = new THREE.Matrix4().fromArray(viewProjection);
    const shift = new THREE.Matrix4().makeTranslation(-centre[0], -centre[1], -centre[2]);
    cam.projectionMatrix.multiplyMatrices(vp, shift);
    cam.projectionMatrixInverse.copy(cam.projectionMatrix).invert();
    cam.updateMatrixWorld(true);
    return cam;
}

function heatImage(counts) {
    const canvas = $('heat'), ctx = canvas.getContext('2d');
    const image = ctx.createImageData(COUNT_SIZE, COUNT_SIZE);
    for (let y = 0; y < COUNT_SIZE; ++y)
        for (let x = 0; x < COUNT_SIZE; ++x) {
            const v = counts[(COUNT_SIZE - 1 - y) * COUNT_SIZE + x], o = 4 * (y * COUNT_SIZE + x);
            const t = Math.min(v / 4, 1);
            image.data[o] = v > 0 ? 255 * Math.min(1, 2 * t) : 0;
            image.data[o + 1] = v > 0 ? 255 * Math.max(0, 2 * t - 1) : 0;
            image.data[o + 2] = v === 1 ? 90 : 0;
            image.data[o + 3] = 255;
        }
    const scratch = new OffscreenCanvas(COUNT_SIZE, COUNT_SIZE);
    scratch.getContext('2d').putImageData(image, 0, 0);
    ctx.drawImage(scratch, 0, 0, canvas.width, canvas.height);
}

function chart() {
    const canvas = $('chart'), ctx = canvas.getContext('2d'), now = performance.now() / 1000;
    ctx.fillStyle = '#111';
    ctx.fillRect(0, 0, canvas.width, canvas.height);
    const points = state.history.filter((h) => now - h.t < 10);
    state.history = points;
    if (points.length < 2) return;
    let lo = Infinity, hi = -Infinity;
    for (const p of points) for (const v of [p.a, p.b]) if (v > 0) { lo = Math.min(lo, v); hi = Math.max(hi, v); }
    lo = Math.max(1, lo - 0.02);
    hi = hi + 0.02;
    const x = (t) => canvas.width * (1 - (now - t) / 10), y = (v) => canvas.height * (1 - (v - lo) / (hi - lo));
    for (const [key, colour] of [['b', '#e05050'], ['a', '#50d070']]) {
        ctx.strokeStyle = colour;
        ctx.beginPath();
        points.forEach((p, k) => (k ? ctx.lineTo(x(p.t), y(p[key])) : ctx.moveTo(x(p.t), y(p[key]))));
        ctx.stroke();
    }
    ctx.fillStyle = '#aaa';
    ctx.fillText(`OVR ${lo.toFixed(2)}–${hi.toFixed(2)}`, 4, 12);
}

function comparisonBuffer() {
    return state.originalBuffer >= 0 ? state.originalBuffer : state.orders.runtime.fallback;
}

function frame() {
    const now = performance.now(), dt = Math.min(0.1, (now - lastTime) / 1000);
    lastTime = now;
    if (state.paused) {  // the tests drive the page themselves
        requestAnimationFrame(frame);
        return;
    }
    if (state.ready) {
        if ($('orbit').checked) controls.autoRotate = true, controls.autoRotateSpeed = 4;
        else controls.autoRotate = false;
        controls.update(dt);
        if (state.mixer) state.mixer.update(dt);
        const orders = state.orders;
        if (orders) {
            orders.fixed = state.mode === 'runtime' ? null : state.mode === 'original' ? state.originalBuffer : orders.runtime.fallback;
            orders.update(camera, state.mixer);
            $('buffer').textContent = `${orders.buffer}${orders.fixed === null ? '' : ' (fixed)'}`;
            $('keyframe').textContent = `${orders.keyframe}`;
        }
        if ($('overdraw').checked && orders) {
            const drawn = countPass(camera);
            const other = countPass(camera, state.mode === 'runtime' ? comparisonBuffer() : runtimeChoice());
            heatImage(drawn.counts);
            $('ovr').textContent = drawn.ovr.toFixed(3);
            $('ovr-other').textContent = other.ovr.toFixed(3);
            const optimised = state.mode === 'runtime' ? drawn.ovr : other.ovr;
            const comparison = state.mode === 'runtime' ? other.ovr : drawn.ovr;
            state.history.push({ t: performance.now() / 1000, a: optimised, b: comparison });
            state.last = { optimised, comparison };
            chart();
        }
    }
    renderer.render(scene, camera);
    requestAnimationFrame(frame);
}

// The buffer the runtime would draw now (whatever the mode).
function runtimeChoice() {
    const orders = state.orders, fixed = orders.fixed, buffer = orders.buffer;
    orders.fixed = null;
    const b = orders.update(camera, state.mixer);
    orders.fixed = fixed;
    orders.setBuffer(buffer);
    return b;
}

function frameCamera(object) {
    const box = new THREE.Box3().setFromObject(object);
    const centre = box.getCenter(new THREE.Vector3()), radius = box.getSize(new THREE.Vector3()).length() / 2 || 1;
    controls.target.copy(centre);
    camera.position.copy(centre).add(new THREE.Vector3(0, radius * 0.3, radius * 2.2));
    camera.near = radius / 100;
    camera.far = radius * 100;
    camera.updateProjectionMatrix();
}

function playClip(index) {
    state.clip = index;
    if (!state.mixer) return;
    state.mixer.stopAllAction();
    const animation = state.gltf.animations[index];
    if (animation) state.mixer.clipAction(animation).play();
}

async function load() {
    $('file').textContent = fileUrl;
    const loader = new GLTFLoader();
    let plugin = null;
    loader.register((parser) => (plugin = new AnimorderGLTFPlugin(parser)));
    let gltf;
    try {
        gltf = await loader.loadAsync(fileUrl, (e) => {
            if (e.total) $('progress').value = e.loaded / e.total;
            message(`loading… ${(e.loaded / 1e6).toFixed(1)} MB`);
        });
    } catch (error) {
        state.error = `cannot load ${fileUrl}: ${error.message || error}`;
        message(state.error, 'error');
        $('progress').value = 0;
        return;
    }
    $('progress').value = 1;
    state.gltf = gltf;
    scene.add(gltf.scene);
    gltf.scene.traverse((o) => { if (o.isMesh) o.frustumCulled = false; });
    state.orders = gltf.userData.animorder;
    state.hasExtension = !!state.orders;
    if (state.orders) {
        // Draw primitives in file order (mesh, then primitive), as the sidecar and `evaluate` do.
        [...state.orders.meshes].sort((a, b) => a.mesh_index - b.mesh_index || a.primitive_index - b.primitive_index)
            .forEach((entry, k) => { entry.mesh.renderOrder = k; });
    }
    if (gltf.animations.length) state.mixer = new THREE.AnimationMixer(gltf.scene);
    gltf.animations.forEach((a, k) => $('clip').add(new Option(a.name || `animation ${k}`, k)));
    $('clip').onchange = () => playClip(Number($('clip').value));
    playClip(0);
    frameCamera(gltf.scene);
    if (state.orders && originalUrl) {
        try {
            const plain = new GLTFLoader();
            let parser = null;
            plain.register((p) => { parser = p; return { name: 'animorder-original-parser' }; });
            const original = await plain.loadAsync(originalUrl);
            state.originalBuffer = state.orders.addOrderFrom(original, parser);
            $('mode').querySelector('[value=original]').disabled = false;
        } catch (error) {
            message(`cannot use ${originalUrl} as the original order: ${error.message}`, 'warning');
        }
    }
    $('mode').onchange = () => { state.mode = $('mode').value; };
    if (!state.orders) {
        const why = gltf.userData.animorderError ? ` (${gltf.userData.animorderError})` : '';
        message(`This file has no usable ${EXTENSION_NAME}${why}: it is drawn in its own order; nothing to compare.`, 'warning');
    } else {
        const rt = state.orders.runtime;
        message(`${rt.bufferCount} orders, ${rt.clips.length} clips (${rt.method || 'method not named'}); fallback ${rt.fallback}` +
                (state.originalBuffer >= 0 ? '; original order loaded' : ''));
    }
    void plugin;
    state.ready = true;
}

window.animorderViewer = {
    state, renderer, scene, camera, countPass, pose, nodeCamera, countSize: COUNT_SIZE, floatBlend,
    // The runtime's buffer for the current orbit camera and clip time, as update() sets it.
    current: () => ({ buffer: state.orders ? state.orders.buffer : -1, clip: state.orders ? state.orders.clip : -1,
                      keyframe: state.orders ? state.orders.keyframe : -1 }),
};

if (params.get('overdraw') === '1') $('overdraw').checked = true;
requestAnimationFrame(frame);
load();
