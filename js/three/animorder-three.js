// animorder for three.js: a GLTFLoader plugin that reads ANIMORDER_animated_triangle_orders into
// each optimised primitive's geometry (all K orders in one index buffer, order b = the index range
// [b·n, (b+1)·n)), and a per-character object whose update(camera, mixer) picks the order for the
// current clip time and camera (js/runtime/animorder.js, identical to the C runtime) and sets the
// draw range. Works with Mesh and SkinnedMesh, several primitives, several characters in a scene
// (each object keeps its own range, applied in onBeforeRender, so clones that share a geometry
// draw their own order), and files without the extension (gltf.userData.animorder stays null).
//
//   import { AnimorderGLTFPlugin } from './js/three/animorder-three.js';
//   loader.register((parser) => new AnimorderGLTFPlugin(parser));
//   const gltf = await loader.loadAsync('character.glb');
//   const orders = gltf.userData.animorder;              // AnimorderCharacter, or null
//   ... each frame: mixer.update(dt); orders?.update(camera, mixer); renderer.render(scene, camera);
import { BufferAttribute, BufferGeometry, Vector3 } from 'three';
import { AccessorReader, AnimorderError, AnimorderRuntime, EXTENSION_NAME, extensionProblems, ordersProblem } from '../runtime/animorder.js';

export { AnimorderRuntime, EXTENSION_NAME };

export class AnimorderGLTFPlugin {
    constructor(parser) {
        this.parser = parser;
        this.name = EXTENSION_NAME;
    }

    async afterRoot(gltf) {
        gltf.userData = gltf.userData || {};
        gltf.userData.animorder = null;
        const json = this.parser.json;
        const root = json.extensions && json.extensions[EXTENSION_NAME];
        if (!root) return;
        try {
            gltf.userData.animorder = await this.read(gltf, root);
        } catch (error) {
            // The spec: a file whose orders do not check out draws its `indices` (the fallback).
            gltf.userData.animorderError = error.message;
            console.warn(`${EXTENSION_NAME}: ${error.message}; drawing the fallback order`);
        }
    }

    // An extension accessor as the runtime reads it (AccessorReader: every index, offset and count
    // checked against the JSON and the buffer's bytes before anything is allocated; sparse and
    // view-less accessors refused), its buffer's bytes from GLTFLoader.
    async accessor(index) {
        const json = this.parser.json;
        this.reader = this.reader || new AccessorReader(json, null);
        const def = Number.isInteger(index) ? (json.accessors || [])[index] : undefined;
        const view = def && Number.isInteger(def.bufferView) ? (json.bufferViews || [])[def.bufferView] : undefined;
        const b = view ? view.buffer : undefined;
        if (Number.isInteger(b) && (json.buffers || [])[b] && !this.reader.buffers[b])
            this.reader.buffers[b] = new Uint8Array(await this.parser.getDependency('buffer', b));
        return this.reader.read(index);
    }

    async read(gltf, root) {
        const json = this.parser.json;
        // The file checked as `animorder check` and the runtime check it (extensionProblems: the
        // rules of docs/extension/VALIDITY.md, each accessor read once, the work capped), on the
        // buffers GLTFLoader loaded.
        this.reader = this.reader || new AccessorReader(json, null);
        const used = new Set((json.bufferViews || []).map((view) => view && view.buffer));
        for (const b of used)
            if (Number.isInteger(b) && (json.buffers || [])[b] && !this.reader.buffers[b])
                this.reader.buffers[b] = new Uint8Array(await this.parser.getDependency('buffer', b));
        const problems = extensionProblems(json, this.reader);
        if (problems && problems.length) throw new AnimorderError(problems[0]);
        const needed = new Map();
        for (const clip of root.clips || [])
            for (const index of [clip.table, clip.centers])
                if (!needed.has(index)) needed.set(index, await this.accessor(index));
        const runtime = AnimorderRuntime.fromExtension(root, (index) => needed.get(index));
        // Orders on points or lines (which three.js draws as Points and Lines, not meshes) refuse the
        // file, as the runtime does.
        (json.meshes || []).forEach((mesh, m) => ((mesh && mesh.primitives) || []).forEach((primitive, p) => {
            const ext = primitive && primitive.extensions && primitive.extensions[EXTENSION_NAME];
            if (ext && primitive.mode !== undefined && primitive.mode !== 4)
                throw new AnimorderError(`mesh ${m} primitive ${p}: orders on a primitive that is not triangles`);
        }));
        const meshes = [];
        // geometry → { n: index count, orders: accessor }: GLTFLoader shares one geometry between
        // primitives of equal attributes and indices, whatever their extensions.
        const done = new Map();
        const toIndex = [];     // geometries and their orders, set once all are checked
        const plain = [];       // meshes whose primitive has no orders: they keep the file's indices
        const objects = [];
        for (const scene of gltf.scenes || [gltf.scene]) scene.traverse((o) => { if (o.isMesh) objects.push(o); });
        // GLTFLoader's EXT_mesh_gpu_instancing makes an InstancedMesh of the node's mesh, mapped to the
        // node only: its primitive is the one of the node's mesh (as GLTFLoader made it, cached)
        // whose geometry it shares (or whose index, when per-instance attributes gave it a geometry
        // of its own).
        const instanced = async (mesh, where) => {
            const node = where && where.nodes !== undefined && json.nodes && json.nodes[where.nodes];
            if (!node || node.mesh === undefined) return where;
            const made = await this.parser.getDependency('mesh', node.mesh);
            const parts = made.isGroup ? made.children : [made];
            const p = parts.findIndex((o) => o.geometry === mesh.geometry ||
                (o.geometry.index !== null && o.geometry.index === mesh.geometry.index));
            return p >= 0 ? { meshes: node.mesh, primitives: p } : where;
        };
        let primitiveOrder = 0;
        for (const mesh of objects) {
            let where = this.parser.associations.get(mesh);
            if (mesh.isInstancedMesh && (!where || where.primitives === undefined)) where = await instanced(mesh, where);
            if (!where || where.meshes === undefined || where.primitives === undefined) continue;
            const primitive = json.meshes[where.meshes].primitives[where.primitives];
            const ext = primitive.extensions && primitive.extensions[EXTENSION_NAME];
            if (!ext) {
                plain.push(mesh);
                continue;
            }
            const geometry = mesh.geometry, at = `mesh ${where.meshes} primitive ${where.primitives}`;
            if (ext.orderCount !== runtime.bufferCount)
                throw new AnimorderError(`${at}: orderCount ${ext.orderCount} != bufferCount ${runtime.bufferCount}`);
            const seen = done.get(geometry);
            if (seen !== undefined && seen.orders !== ext.orders)
                throw new AnimorderError(`${at}: orders ${ext.orders}, where a primitive of the same geometry has ${seen.orders}`);
            let n = seen && seen.n;
            if (seen === undefined) {
                if (!geometry.index) throw new AnimorderError(`${at} has no indices`);
                n = geometry.index.count;
                const orders = await this.accessor(ext.orders);
                const problem = ordersProblem(orders, (e) => orders.array[e], ext.orderCount, n, geometry.attributes.position.count);
                if (problem) throw new AnimorderError(`${at}: ${problem}`);
                toIndex.push({ geometry, array: orders.array });
                done.set(geometry, { n, orders: ext.orders });
            }
            meshes.push({ mesh, n, mesh_index: where.meshes, primitive_index: where.primitives, drawOrder: primitiveOrder++ });
        }
        // A primitive without orders whose geometry GLTFLoader shares with one that has them keeps
        // the file's indices in a geometry of its own (the same attributes, not copied).
        for (const mesh of plain)
            if (done.has(mesh.geometry)) mesh.geometry = withOwnIndex(mesh.geometry);
        // Only once every primitive checks out: a later one that does not leaves every geometry
        // drawing its own indices (the spec's fallback), none half switched to the orders.
        for (const { geometry, array } of toIndex) {
            geometry.userData.animorderFallbackIndex = geometry.index;
            geometry.setIndex(new BufferAttribute(array, 1));
        }
        const character = new AnimorderCharacter(runtime, gltf.scene, meshes, gltf.animations || []);
        character.setBuffer(runtime.fallback);
        return character;
    }
}

// A geometry with `geometry`'s attributes, morph targets, groups and bounds (shared, not copied)
// and its index.
function withOwnIndex(geometry) {
    const copy = new BufferGeometry();
    copy.setIndex(geometry.index);
    for (const name of Object.keys(geometry.attributes)) copy.setAttribute(name, geometry.attributes[name]);
    for (const name of Object.keys(geometry.morphAttributes)) copy.morphAttributes[name] = geometry.morphAttributes[name];
    copy.morphTargetsRelative = geometry.morphTargetsRelative;
    for (const group of geometry.groups) copy.addGroup(group.start, group.count, group.materialIndex);
    copy.boundingBox = geometry.boundingBox ? geometry.boundingBox.clone() : null;
    copy.boundingSphere = geometry.boundingSphere ? geometry.boundingSphere.clone() : null;
    copy.name = geometry.name;
    copy.userData = { ...geometry.userData };
    return copy;
}

// One loaded character: its runtime, its scene root (the glTF scene's model space), its meshes.
export class AnimorderCharacter {
    constructor(runtime, root, meshes, animations) {
        this.runtime = runtime;
        this.root = root;
        this.meshes = meshes;
        this.animations = animations;
        this.orderCount = runtime.bufferCount; // grows when extra orders are appended (addOrderFrom)
        this.fixed = null;       // a buffer id to draw always, or null: the runtime chooses
        this.buffer = -1;        // the buffer drawn now
        this.clip = -1;          // the clip the last update used (-1: none playing → fallback)
        this.keyframe = -1;
        for (const entry of meshes) {
            const mesh = entry.mesh;
            const previous = mesh.onBeforeRender;
            mesh.onBeforeRender = function (renderer, scene, camera, geometry, material, group) {
                const range = mesh.userData.animorderRange;
                if (range) geometry.setDrawRange(range[0], range[1]);
                if (previous) previous.call(this, renderer, scene, camera, geometry, material, group);
            };
        }
    }

    // The same orders for a copy of the character's scene (SkeletonUtils.clone(gltf.scene), or
    // Object3D.clone): its meshes share the geometries, and each copy draws its own order.
    cloneFor(root) {
        const mine = [], theirs = [];
        this.root.traverse((o) => { if (o.isMesh) mine.push(o); });
        root.traverse((o) => { if (o.isMesh) theirs.push(o); });
        if (mine.length !== theirs.length) throw new AnimorderError('the copy does not have the same meshes');
        const meshes = this.meshes.map((entry) => {
            const at = mine.indexOf(entry.mesh);
            if (at < 0 || theirs[at].geometry !== entry.mesh.geometry) throw new AnimorderError('the copy does not share the geometries');
            return { ...entry, mesh: theirs[at] };
        });
        const copy = new AnimorderCharacter(this.runtime, root, meshes, this.animations);
        copy.orderCount = this.orderCount;
        copy.setBuffer(this.buffer >= 0 ? this.buffer : this.runtime.fallback);
        return copy;
    }

    // Draw buffer `b` on every optimised primitive now (and keep it while `fixed` says so).
    setBuffer(b) {
        this.buffer = b;
        for (const { mesh, n } of this.meshes) {
            mesh.userData.animorderRange = [b * n, n];
            mesh.geometry.setDrawRange(b * n, n);
        }
    }

    // The camera's position in the glTF scene's model space (the space of the table's centres).
    cameraInModelSpace(camera, target = new Vector3()) {
        camera.updateWorldMatrix(true, false);
        this.root.updateWorldMatrix(true, false);
        camera.getWorldPosition(target);
        return this.root.worldToLocal(target);
    }

    // The clip whose glTF animation plays with the largest weight in `mixer`, with its time.
    playing(mixer) {
        let best = null;
        this.runtime.clips.forEach((clip, index) => {
            const animation = this.animations[clip.animation];
            if (!animation || !mixer) return;
            const action = mixer.existingAction(animation, this.root) || mixer.existingAction(animation);
            if (!action || !action.isRunning()) return;
            const weight = action.getEffectiveWeight();
            if (weight > 0 && (!best || weight > best.weight)) best = { clip: index, time: action.time, weight };
        });
        return best;
    }

    // Pick and set the buffer for this frame: `timeSource` is an AnimationMixer (the playing clip and
    // its time) or { clip, time } (time in the glTF animation's seconds). Returns the buffer drawn.
    update(camera, timeSource) {
        if (this.fixed !== null) {
            this.setBuffer(this.fixed);
            return this.buffer;
        }
        const now = timeSource && typeof timeSource.existingAction === 'function' ? this.playing(timeSource) : timeSource;
        let b = -1;
        this.clip = -1;
        this.keyframe = -1;
        if (now && now.clip >= 0 && this.runtime.clips[now.clip]) {
            const clip = this.runtime.clips[now.clip];
            const position = this.cameraInModelSpace(camera);
            this.clip = now.clip;
            this.keyframe = this.runtime.keyframeAt(now.clip, now.time - clip.startTime);
            b = this.runtime.selectAnimationTime(now.clip, now.time, [position.x, position.y, position.z]);
        }
        this.setBuffer(b >= 0 ? b : this.runtime.fallback);
        return this.buffer;
    }

    // Appends another file's order of the same primitives (e.g. the un-optimised input, loaded
    // without the extension) as buffer id orderCount, so it can be drawn with setBuffer for
    // comparison. `other` is that file's gltf from GLTFLoader (same meshes and primitives).
    addOrderFrom(other, parser) {
        const byPrimitive = new Map();
        for (const scene of other.scenes || [other.scene])
            scene.traverse((o) => {
                const where = o.isMesh && parser.associations.get(o);
                if (where && where.primitives !== undefined) byPrimitive.set(`${where.meshes}/${where.primitives}`, o.geometry.index);
            });
        const id = this.orderCount;
        // Every primitive checked before any geometry grows: a refusal leaves the character as it was.
        const grow = new Map();  // geometry → the other file's order of it
        for (const { mesh, n, mesh_index, primitive_index } of this.meshes) {
            const index = byPrimitive.get(`${mesh_index}/${primitive_index}`);
            const at = `the other file's mesh ${mesh_index} primitive ${primitive_index}`;
            if (!index || index.count !== n) throw new AnimorderError(`${at} does not match`);
            const vertices = mesh.geometry.attributes.position.count, added = index.array.subarray(0, n);
            for (const v of added) if (v >= vertices) throw new AnimorderError(`${at} names vertex ${v} of ${vertices}`);
            grow.set(mesh.geometry, added);
        }
        for (const [geometry, added] of grow) {
            const old = geometry.index.array;
            // Unsigned shorts hold the other order's vertices below 65535 only (65535 restarts a strip).
            const Type = old instanceof Uint16Array && added.some((v) => v >= 65535) ? Uint32Array : old.constructor;
            const grown = new Type(old.length + added.length);
            grown.set(old);
            grown.set(added, old.length);
            geometry.setIndex(new BufferAttribute(grown, 1));
        }
        this.orderCount = id + 1;
        return id;
    }
}
