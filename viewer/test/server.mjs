// node viewer/test/server.mjs ANIMORDER_EXE GLB [SCRATCH] — `animorder view GLB` answers only what it should:
// the viewer's files, the model, GET/HEAD only; nothing above its folders (.., %2e, backslashes,
// absolute paths), a 404 for the rest, a 421 for another Host, a 400 for garbage and for HTTP/1.1
// without Host, a one-line error for a missing file; and for a glTF that names files, those from
// below its folder only, at the URLs its URIs resolve to, never sent as a page or a script.
// Prints one line per request; exit 0 when every status is the expected one.
import { spawn, spawnSync } from 'node:child_process';
import { mkdirSync, mkdtempSync, rmSync, writeFileSync } from 'node:fs';
import net from 'node:net';
import { tmpdir } from 'node:os';
import { join } from 'node:path';

const [exe, glb, scratch] = process.argv.slice(2);
const server = spawn(exe, ['view', glb, '--port', '0', '--no-open', '--seconds', '60', '-q'], { stdio: ['ignore', 'pipe', 'inherit'] });
let port = await new Promise((resolve, reject) => {
    server.stdout.on('data', (d) => { const m = /127\.0\.0\.1:(\d+)\//.exec(String(d)); if (m) resolve(Number(m[1])); });
    server.on('exit', (code) => reject(new Error(`animorder view exited (${code})`)));
});
// One raw request (no URL normalisation by a client library): the response's text, or the status
// code alone.
function response(raw) {
    return new Promise((resolve) => {
        const socket = net.connect(port, '127.0.0.1', () => socket.end(raw));
        let text = '';
        socket.on('data', (d) => { text += d; });
        socket.on('close', () => resolve(text));
        socket.on('error', () => resolve(''));
    });
}
async function status(raw) {
    return Number((/^HTTP\/1\.1 (\d+)/.exec(await response(raw)) || [])[1] || 0);
}
// A browser's request line for each case (with its Host), then raw ones.
const host = `Host: 127.0.0.1:${port}\r\n`;
const cases = [
    ['GET / HTTP/1.1', 302],
    ['GET /viewer/ HTTP/1.1', 200],
    ['GET /viewer/viewer.js?x=1 HTTP/1.1', 200],
    ['GET /js/runtime/animorder.js HTTP/1.1', 200],
    ['GET /viewer/node_modules/three/build/three.module.js HTTP/1.1', 200],
    ['GET /model.glb HTTP/1.1', 200],
    ['HEAD /model.glb HTTP/1.1', 200],
    ['GET /original.glb HTTP/1.1', 404],  // none given
    ['GET /viewer/../CMakeLists.txt HTTP/1.1', 404],
    ['GET /viewer/%2e%2e/CMakeLists.txt HTTP/1.1', 404],
    ['GET /viewer/..\\CMakeLists.txt HTTP/1.1', 404],
    ['GET /CMakeLists.txt HTTP/1.1', 404],
    ['GET /etc/passwd HTTP/1.1', 404],
    ['GET /js/ HTTP/1.1', 404],
    ['POST /model.glb HTTP/1.1', 405],
].map(([line, expected]) => [`${line}\r\n${host}\r\n`, expected]).concat([
    ['GET /model.glb HTTP/1.1\r\nHost: evil.example\r\n\r\n', 421],  // DNS rebinding
    ['GET /model.glb HTTP/1.1\r\n\r\n', 400],  // HTTP/1.1 without Host
    ['GET /model.glb HTTP/1.0\r\n\r\n', 200],  // HTTP/1.0 may leave it out
    ['garbage\r\n\r\n', 400],
]);
let failures = 0;
for (const [raw, expected] of cases) {
    const got = await status(raw);
    const line = raw.split('\r\n')[0];
    console.log(`${got === expected ? 'ok  ' : 'FAIL'} ${JSON.stringify(line)} → ${got} (expected ${expected})`);
    if (got !== expected) failures++;
}
server.kill();

// A glTF's named files: served from below its folder only, each under the URL its URI resolves to,
// as bytes or an image (never a page a browser would run, whatever its name), and nothing else.
const dir = mkdtempSync(join(scratch || tmpdir(), 'animorder-view-named-'));
mkdirSync(join(dir, 'a', 'sub'), { recursive: true });
writeFileSync(join(dir, 'a', 'scene.bin'), 'bytes');
writeFileSync(join(dir, 'a', 'evil.html'), '<script>alert(1)</script>');
writeFileSync(join(dir, 'a', 'sub', 'tex a.png'), 'png');
writeFileSync(join(dir, 'secret.txt'), 'secret');
writeFileSync(join(dir, 'a', 'scene.gltf'), JSON.stringify({
    asset: { version: '2.0' }, buffers: [{ uri: 'scene.bin', byteLength: 5 }],
    images: [{ uri: '../secret.txt' }, { uri: '../../../../../../../../etc/passwd' }, { uri: 'evil.html' },
             { uri: 'sub/tex%20a.png' }, { uri: '/abs.png' }],
}));
const named = spawn(exe, ['view', join(dir, 'a', 'scene.gltf'), '--port', '0', '--no-open', '--seconds', '60', '-q'],
                    { stdio: ['ignore', 'pipe', 'inherit'] });
port = await new Promise((resolve, reject) => {
    named.stdout.on('data', (d) => { const m = /127\.0\.0\.1:(\d+)\//.exec(String(d)); if (m) resolve(Number(m[1])); });
    named.on('exit', (code) => reject(new Error(`animorder view exited (${code})`)));
});
const host2 = `Host: 127.0.0.1:${port}\r\n`;
for (const [path, expected, type] of [
    ['/', 302, null],
    ['/model/scene.gltf', 200, 'model/gltf+json'],
    ['/model/scene.bin', 200, 'application/octet-stream'],
    ['/model/sub/tex%20a.png', 200, 'image/png'],
    ['/model/sub/./tex%20a.png', 200, 'image/png'],
    ['/model/evil.html', 200, 'application/octet-stream'],  // named, so served: as bytes, sandboxed
    ['/secret.txt', 404, null],       // outside the folder of the file given
    ['/etc/passwd', 404, null],
    ['/model/../../etc/passwd', 404, null],
    ['/model/%2e%2e/secret.txt', 404, null],
    ['/model/scene%00.bin', 404, null],
    ['/model/other.bin', 404, null],  // beside it, but not named
    ['/abs.png', 404, null],
]) {
    const text = await response(`GET ${path} HTTP/1.1\r\n${host2}\r\n`);
    const got = Number((/^HTTP\/1\.1 (\d+)/.exec(text) || [])[1] || 0);
    const head = text.split('\r\n\r\n')[0];
    const sent = (/\r\nContent-Type: ([^\r]*)/.exec(head) || [])[1];
    const guarded = !type || (/\r\nX-Content-Type-Options: nosniff/.test(head) && /\r\nContent-Security-Policy: sandbox/.test(head));
    const ok = got === expected && (!type || sent === type) && guarded;
    console.log(`${ok ? 'ok  ' : 'FAIL'} named files: ${JSON.stringify(path)} → ${got} ${sent || ''} (expected ${expected} ${type || ''})`);
    if (!ok) failures++;
}
named.kill();
rmSync(dir, { recursive: true, force: true });

const missing = spawnSync(exe, ['view', '/nonexistent/x.glb', '--no-open', '--port', '0'], { encoding: 'utf8' });
const oneLine = missing.status === 1 && missing.stderr.trim().split('\n').length === 1 && /cannot read/.test(missing.stderr);
console.log(`${oneLine ? 'ok  ' : 'FAIL'} a missing file: exit ${missing.status}, "${missing.stderr.trim()}"`);
if (!oneLine) failures++;
process.exit(failures ? 1 : 0);
