// node js/test/equivalence.mjs RUNTIME_ANSWERS_EXE SIDECAR SCRATCH_DIR [GLB] [COUNT]
//
// The JavaScript runtime (js/runtime/animorder.js) against the C runtime (include/animorder_runtime.h,
// run by tests/runtime/runtime_answers.c) on the same file: COUNT (default 120,000) seeded queries
// (clip, time or keyframe, camera; some with an explicit centre) are written to SCRATCH_DIR, the C
// program answers them, and every JavaScript answer must be identical: from the sidecar and, when
// GLB is given, from the glTF extension ANIMORDER_animated_triangle_orders of that file (the same
// tables written the other way). The queries include cameras on the poles, on cell borders (θ and φ
// half-way between cells), at cell centres, at φ just below 2π, at the centre itself (answer -1),
// keyframes half-way between two, times before and after the clip, NaN and infinite values, and
// clips that do not exist. Exit 0 when all agree, 1 otherwise (the first differences printed).
import { execFileSync } from 'node:child_process';
import { readFileSync, writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { AnimorderRuntime } from '../runtime/animorder.js';

const [exe, sidecarPath, scratch, glbPath, countArg] = process.argv.slice(2);
if (!exe || !sidecarPath || !scratch) {
    console.error('usage: node equivalence.mjs RUNTIME_ANSWERS_EXE SIDECAR SCRATCH_DIR [GLB] [COUNT]');
    process.exit(1);
}
const total = countArg ? Number(countArg) : 120000;
const sidecar = AnimorderRuntime.fromSidecar(readFileSync(sidecarPath));
const runtimes = [['sidecar', sidecar]];
if (glbPath && glbPath !== '-') {
    const fromGlb = AnimorderRuntime.fromGlb(readFileSync(glbPath));
    if (!fromGlb) {
        console.error(`${glbPath} does not use ANIMORDER_animated_triangle_orders`);
        process.exit(1);
    }
    runtimes.push(['glb extension', fromGlb]);
}

// xorshift128+ style generator on 32-bit words (seeded, same queries on every run).
let s0 = 0x9e3779b9, s1 = 0x243f6a88, s2 = 0xb7e15162, s3 = 0x12345678;
function nextU32() {
    const t = s0 ^ (s0 << 11);
    s0 = s1; s1 = s2; s2 = s3;
    s3 = (s3 ^ (s3 >>> 19) ^ t ^ (t >>> 8)) >>> 0;
    return s3;
}
const uniform = () => nextU32() / 4294967296;
const pick = (n) => Math.floor(uniform() * n);

const clips = sidecar.clips;
const f32 = Math.fround;
const queries = []; // { clip, flags, value, camera, centre, kind }

function centreOf(clip, keyframe) {
    const c = clips[clip];
    const f = sidecar.keyframeAt(clip, keyframe / c.sampleRate);
    return [c.centres[3 * f], c.centres[3 * f + 1], c.centres[3 * f + 2]];
}
function direction(theta, phi) {
    return [Math.sin(theta) * Math.sin(phi), Math.cos(theta), Math.sin(theta) * Math.cos(phi)];
}
function randomDirection() {
    const y = 2 * uniform() - 1, phi = 2 * Math.PI * uniform(), r = Math.sqrt(Math.max(0, 1 - y * y));
    return [r * Math.sin(phi), y, r * Math.cos(phi)];
}
function add(kind, clip, useKeyframe, value, dir, distance, explicitCentre = null) {
    const c = clips[Math.min(clip, clips.length - 1)];
    const keyframe = useKeyframe ? value : value * c.sampleRate;
    const centre = explicitCentre ?? centreOf(Math.min(clip, clips.length - 1), keyframe);
    const camera = [0, 1, 2].map((k) => f32(centre[k] + dir[k] * distance));
    queries.push({ kind, clip, flags: (useKeyframe ? 1 : 0) | (explicitCentre ? 2 : 0), value, camera, centre: explicitCentre ?? [0, 0, 0] });
}

const kinds = ['random', 'pole', 'theta border', 'phi border', 'cell centre', 'phi near 2pi', 'at centre',
               'half keyframe', 'out of range time', 'explicit centre', 'non-finite', 'bad clip'];
while (queries.length < total) {
    const kind = kinds[queries.length % kinds.length];
    const clip = pick(clips.length), c = clips[clip];
    const duration = (c.keyframes - 1) / c.sampleRate;
    const seconds = uniform() * duration, keyframe = pick(c.keyframes);
    const distance = 0.05 + 20 * uniform();
    const i = pick(c.thetaSteps), j = pick(c.phiSteps);
    const dTheta = Math.PI / (c.thetaSteps - 1), dPhi = (2 * Math.PI) / c.phiSteps;
    switch (kind) {
        case 'random': add(kind, clip, uniform() < 0.5, seconds, randomDirection(), distance); break;
        case 'pole': add(kind, clip, true, keyframe, [0, uniform() < 0.5 ? 1 : -1, 0], distance); break;
        case 'theta border': add(kind, clip, true, keyframe, direction((i + 0.5) * dTheta, j * dPhi), distance); break;
        case 'phi border': add(kind, clip, true, keyframe, direction(i * dTheta, (j + 0.5) * dPhi), distance); break;
        case 'cell centre': add(kind, clip, false, keyframe / c.sampleRate, direction(i * dTheta, j * dPhi), distance); break;
        case 'phi near 2pi': add(kind, clip, true, keyframe, direction((i + 0.5) * dTheta, 2 * Math.PI - uniform() * 1e-6), distance); break;
        case 'at centre': add(kind, clip, uniform() < 0.5, keyframe, [0, 0, 0], 0); break;
        case 'half keyframe': add(kind, clip, true, keyframe + 0.5, randomDirection(), distance); break;
        case 'out of range time': add(kind, clip, false, uniform() < 0.5 ? -1 - 10 * uniform() : duration + 10 * uniform(), randomDirection(), distance); break;
        case 'explicit centre': {
            const centre = [0, 1, 2].map(() => f32(4 * uniform() - 2));
            add(kind, clip, uniform() < 0.5, seconds, randomDirection(), distance, centre);
            break;
        }
        case 'non-finite': {
            const bad = [NaN, Infinity, -Infinity][pick(3)];
            if (uniform() < 0.5) add(kind, clip, true, NaN, randomDirection(), distance); // NaN keyframe: the first
            else {
                add(kind, clip, true, keyframe, randomDirection(), distance);
                queries[queries.length - 1].camera[pick(3)] = bad;
            }
            break;
        }
        case 'bad clip': add(kind, clips.length + pick(3), false, seconds, randomDirection(), distance); break;
    }
}

const record = new DataView(new ArrayBuffer(40 * queries.length));
queries.forEach((q, n) => {
    const o = 40 * n;
    record.setUint32(o, q.clip, true);
    record.setUint32(o + 4, q.flags, true);
    record.setFloat64(o + 8, q.value, true);
    for (let k = 0; k < 3; ++k) {
        record.setFloat32(o + 16 + 4 * k, q.camera[k], true);
        record.setFloat32(o + 28 + 4 * k, q.centre[k], true);
    }
});
const queryFile = join(scratch, 'queries.bin'), answerFile = join(scratch, 'answers.bin');
writeFileSync(queryFile, new Uint8Array(record.buffer));
execFileSync(exe, [sidecarPath, queryFile, answerFile], { stdio: 'inherit' });
const answerBytes = readFileSync(answerFile);
const answers = new Int32Array(answerBytes.buffer, answerBytes.byteOffset, answerBytes.length / 4);
if (answers.length !== queries.length) {
    console.error(`the C program answered ${answers.length} of ${queries.length} queries`);
    process.exit(1);
}

let failures = 0;
for (const [source, rt] of runtimes) {
    let differ = 0;
    const perKind = {}, distinct = new Set();
    queries.forEach((q, n) => {
        const centre = q.flags & 2 ? q.centre : null;
        const js = q.flags & 1 ? rt.selectKeyframe(q.clip, q.value, q.camera, centre)
                               : rt.selectTime(q.clip, q.value, q.camera, centre);
        perKind[q.kind] = perKind[q.kind] || { n: 0, minusOne: 0 };
        perKind[q.kind].n++;
        if (answers[n] === -1) perKind[q.kind].minusOne++;
        distinct.add(answers[n]);
        if (js !== answers[n]) {
            if (differ < 10)
                console.error(`${source}: query ${n} (${q.kind}, clip ${q.clip}, ${q.flags & 1 ? 'keyframe' : 'seconds'} ${q.value}, ` +
                              `camera ${q.camera.join(' ')}): C ${answers[n]}, JS ${js}`);
            differ++;
        }
    });
    console.log(`${source}: ${queries.length - differ} of ${queries.length} answers identical to the C runtime; ` +
                `${distinct.size} distinct answers (${[...distinct].sort((a, b) => a - b).join(' ')})`);
    for (const [kind, v] of Object.entries(perKind)) console.log(`  ${kind}: ${v.n} queries, ${v.minusOne} answered -1`);
    failures += differ;
}
process.exit(failures === 0 && queries.length >= 100000 ? 0 : 1);
