// node viewer/test/server.mjs ANIMORDER_EXE GLB — `animorder view GLB` answers only what it should:
// the viewer's files, the model, GET/HEAD only; nothing above its folders (.., %2e, backslashes,
// absolute paths), a 404 for the rest, a 421 for another Host, a 400 for garbage and for HTTP/1.1
// without Host, a one-line error for a missing file.
// Prints one line per request; exit 0 when every status is the expected one.
import { spawn, spawnSync } from 'node:child_process';
import net from 'node:net';

const [exe, glb] = process.argv.slice(2);
const server = spawn(exe, ['view', glb, '--port', '0', '--no-open', '--seconds', '60', '-q'], { stdio: ['ignore', 'pipe', 'inherit'] });
const port = await new Promise((resolve, reject) => {
    server.stdout.on('data', (d) => { const m = /127\.0\.0\.1:(\d+)\//.exec(String(d)); if (m) resolve(Number(m[1])); });
    server.on('exit', (code) => reject(new Error(`animorder view exited (${code})`)));
});
// One raw request (no URL normalisation by a client library), the status code back.
function status(raw) {
    return new Promise((resolve) => {
        const socket = net.connect(port, '127.0.0.1', () => socket.end(raw));
        let text = '';
        socket.on('data', (d) => { text += d; });
        socket.on('close', () => resolve(Number((/^HTTP\/1\.1 (\d+)/.exec(text) || [])[1] || 0)));
        socket.on('error', () => resolve(0));
    });
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
const missing = spawnSync(exe, ['view', '/nonexistent/x.glb', '--no-open', '--port', '0'], { encoding: 'utf8' });
const oneLine = missing.status === 1 && missing.stderr.trim().split('\n').length === 1 && /cannot read/.test(missing.stderr);
console.log(`${oneLine ? 'ok  ' : 'FAIL'} a missing file: exit ${missing.status}, "${missing.stderr.trim()}"`);
if (!oneLine) failures++;
process.exit(failures ? 1 : 0);
