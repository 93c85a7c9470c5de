// node js/test/corpus.mjs — the JS runtime (AnimorderRuntime.fromGltf) on the shared corpus of
// hostile files (tests/extension-corpus/, docs/extension/VALIDITY.md): each file gets its
// manifest's verdict, as `animorder check` gives it (GltfExtension.EveryCorpusFileGetsItsManifestVerdict):
// accepted when valid, else refused with an AnimorderError of one line holding the manifest's
// phrase. Then the amplification files of amplify.mjs: accessors shared by 1000 clips or 2000
// primitives read once (accepted in seconds), distinct (orders, indices) pairs refused by the cap.
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { AnimorderError, AnimorderRuntime } from '../runtime/animorder.js';
import { sharedTable, sharedOrders, distinctIndices } from '../../tests/extension-corpus/amplify.mjs';

const corpus = new URL('../../tests/extension-corpus/', import.meta.url);
const manifest = JSON.parse(readFileSync(new URL('manifest.json', corpus)));
assert.ok(manifest.length >= 40);
for (const entry of manifest) {
    const json = JSON.parse(readFileSync(new URL(entry.file, corpus)));
    let error = null;
    try {
        assert.ok(AnimorderRuntime.fromGltf(json), `${entry.file}: no runtime`);
    } catch (e) {
        if (!(e instanceof AnimorderError)) throw e;
        error = e.message;
    }
    if (entry.valid) {
        assert.equal(error, null, entry.file);
    } else {
        assert.notEqual(error, null, `${entry.file} was accepted`);
        assert.ok(error.includes(entry.phrase), `${entry.file}: '${entry.phrase}' not in: ${error}`);
        assert.doesNotMatch(error, /[\x00-\x1f\x7f]/, entry.file);
    }
}
console.log(`corpus: ${manifest.length} files, every verdict as the manifest's`);

for (const [name, make, valid] of [['shared table', sharedTable, true], ['shared orders', sharedOrders, true],
    ['distinct indices', distinctIndices, false]]) {
    const json = make(), started = Date.now();
    let error = null;
    try {
        AnimorderRuntime.fromGltf(json);
    } catch (e) {
        error = e.message;
    }
    const seconds = (Date.now() - started) / 1000;
    if (valid) assert.equal(error, null, name);
    else assert.match(error ?? '', /more work than its file's size allows/, name);
    assert.ok(seconds < 10, `${name} took ${seconds} s`);
}
console.log('corpus: all checks passed');
