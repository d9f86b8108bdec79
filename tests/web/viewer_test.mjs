// The browser viewer end to end: a real deformd serving --http, Debian's chromium (headless,
// WebGL in software through SwiftShader) driven by puppeteer-core.
//
//   node tests/web/viewer_test.mjs --deformd build/server/deformd/deformd --artifacts DIR
//
// Checks: the static root serves the page and nothing outside it (path traversal, encoded or
// not); the page loads the phantom over the WebSocket LoadMesh, shows it, and streams frames;
// moving the knee slider to 90 degrees brings frames for that pose, and the screenshot differs
// from the rest-pose screenshot where the shin is (and far less at the hip); the page logs no
// console error. Frame encodings, decoded in the page by frame_codec.js: for a few knee poses, the
// quantized and predicted frames' every decoded coordinate is within the frame's stated max_error
// (plus float32 rounding) of the float32 frame for the same pose, predicted frames are smaller
// than quantized ones, which are smaller than float32; for one pose the page's decoding equals, bit
// for bit, what the C++ client library decodes (deform-vr --encoding X --out, a PLY of doubles);
// malformed frames are refused by name; the encoding selector restarts the stream and the picture
// matches the float32 one. With a token
// file, an upgrade without a valid token is refused (401) and one with the token as its
// subprotocol is upgraded. The screenshots stay in DIR (rest.png, knee90.png, knee90-quantized.png,
// knee90-predicted.png; the whole page with its panel: page-quantized.png, page-predicted.png).
// --deform-vr PATH names the C++ client (default build/client/vr/deform-vr). Exit code 0 when
// every check passes, 1 with the failed check on stderr.
import { spawn } from 'node:child_process';
import { createHash } from 'node:crypto';
import { createRequire } from 'node:module';
import fs from 'node:fs';
import http from 'node:http';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const here = path.dirname(fileURLToPath(import.meta.url));
const repo = path.resolve(here, '../..');
const args = Object.fromEntries(
  process.argv.slice(2).reduce((pairs, a, i, all) => (a.startsWith('--') ? [...pairs, [a.slice(2), all[i + 1]]] : pairs), []));
const deformd = path.resolve(args.deformd || path.join(repo, 'build/server/deformd/deformd'));
const deformVr = path.resolve(args['deform-vr'] || path.join(repo, 'build/client/vr/deform-vr'));
const artifacts = path.resolve(args.artifacts || path.join(repo, 'build/web-test-artifacts'));
const chromium = process.env.DEFORM_CHROMIUM || '/usr/bin/chromium';
const deadline = Date.now() + 170_000;  // the whole test, bounded

function fail(message) {
  console.error(`viewer_test: FAILED: ${message}`);
  process.exitCode = 1;
  throw new Error(message);
}
function check(condition, message) { if (!condition) fail(message); console.log(`ok: ${message}`); }

const children = [];
// Starts deformd with `extra` flags; resolves with its HTTP and gRPC ports once it logs both.
function startDeformd(extra) {
  return new Promise((resolve, reject) => {
    const child = spawn(deformd, ['--listen', '127.0.0.1:0', '--http', '127.0.0.1:0', '--workers', '2', ...extra],
                        { stdio: ['ignore', 'pipe', 'pipe'] });
    children.push(child);
    let log = '';
    const timer = setTimeout(() => reject(new Error(`deformd did not listen within 30 s:\n${log}`)), 30_000);
    const onData = (data) => {
      log += data;
      const match = log.match(/http listening on ([0-9.]+):(\d+)/);
      const grpc = log.match(/\] listening on ([0-9.]+):(\d+) \(/);
      if (match && grpc) {
        clearTimeout(timer);
        resolve({ child, port: Number(match[2]), grpcPort: Number(grpc[2]), log: () => log });
      }
    };
    child.stdout.on('data', onData);
    child.stderr.on('data', onData);
    child.on('exit', (code) => { clearTimeout(timer); reject(new Error(`deformd exited (${code}):\n${log}`)); });
  });
}

// A raw HTTP request (no path normalization); resolves with {status, headers, body} or, for an
// upgrade, {upgraded: true, headers}.
function rawRequest(port, method, target, headers = {}, body = null) {
  return new Promise((resolve, reject) => {
    const request = http.request({ host: '127.0.0.1', port, method, path: target, headers });
    request.setTimeout(10_000, () => request.destroy(new Error('timeout')));
    request.on('response', (response) => {
      let data = '';
      response.on('data', (c) => { data += c; });
      response.on('end', () => resolve({ status: response.statusCode, headers: response.headers, body: data }));
    });
    request.on('upgrade', (response, socket) => {
      socket.destroy();
      resolve({ upgraded: true, status: response.statusCode, headers: response.headers });
    });
    request.on('error', reject);
    request.end(body);
  });
}

function upgradeHeaders(protocols) {
  return { Connection: 'Upgrade', Upgrade: 'websocket', 'Sec-WebSocket-Version': '13',
           'Sec-WebSocket-Key': 'dGhlIHNhbXBsZSBub25jZQ==', 'Sec-WebSocket-Protocol': protocols };
}

async function staticChecks(port) {
  const index = await rawRequest(port, 'GET', '/');
  check(index.status === 200 && index.body.includes('deformd viewer'), 'GET / serves the viewer page');
  const three = await rawRequest(port, 'GET', '/vendor/three.module.js');
  check(three.status === 200 && three.headers['content-type'].startsWith('text/javascript'),
        'three.js is served from the static root (copied from node_modules by the build)');
  const meshopt = await rawRequest(port, 'GET', '/vendor/meshopt_decoder.mjs');
  check(meshopt.status === 200 && meshopt.headers['content-type'].startsWith('text/javascript')
        && meshopt.body.includes('export { MeshoptDecoder }'),
        "meshoptimizer's decoder is served from the static root (copied from node_modules by the build)");
  for (const target of ['/../CMakeLists.txt', '/../../../../etc/passwd', '/%2e%2e/%2e%2e/%2e%2e/CMakeLists.txt',
                        '/vendor/..%2f..%2f..%2fdeformd', '/..\\..\\deformd', '/%00index.html', '//etc/passwd']) {
    const response = await rawRequest(port, 'GET', target);
    check(response.status === 404, `path traversal refused: GET ${target} -> ${response.status}`);
  }
  const crossOrigin = await rawRequest(port, 'POST', '/api/ListMeshes',
                                       { 'Content-Type': 'application/x-protobuf', Origin: 'http://evil.example' }, '');
  check(crossOrigin.status === 403, 'a POST from another origin is refused (403)');
}

async function tokenChecks() {
  const token = 'web-viewer-test-token';
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'deform-web-'));
  const tokenFile = path.join(dir, 'tokens');
  fs.writeFileSync(tokenFile, `${createHash('sha256').update(token).digest('hex')} ward-web tenant\n`);
  const server = await startDeformd(['--token-file', tokenFile]);
  const b64url = (t) => Buffer.from(t).toString('base64url');
  const none = await rawRequest(server.port, 'GET', '/ws/Deform', upgradeHeaders('deform.v1'));
  check(!none.upgraded && none.status === 401, `an upgrade without a token is refused (${none.status})`);
  const wrong = await rawRequest(server.port, 'GET', '/ws/Deform', upgradeHeaders(`deform.v1, bearer.${b64url('wrong')}`));
  check(!wrong.upgraded && wrong.status === 401, `an upgrade with a wrong token is refused (${wrong.status})`);
  const good = await rawRequest(server.port, 'GET', '/ws/Deform', upgradeHeaders(`deform.v1, bearer.${b64url(token)}`));
  check(good.upgraded && good.status === 101 && good.headers['sec-websocket-protocol'] === 'deform.v1',
        'an upgrade with the token as its subprotocol is upgraded, answering "deform.v1" only');
  // A balancer's routing key (docs/cluster.md): the page's Deform URL carries ?mesh=<id> and its
  // POSTs naming a mesh the deform-mesh-key header; the server routes on the path alone.
  const keyed = await rawRequest(server.port, 'GET', '/ws/Deform?mesh=mesh-0a%2Fb',
                                 upgradeHeaders(`deform.v1, bearer.${b64url(token)}`));
  check(keyed.upgraded && keyed.status === 101, `an upgrade whose URL carries ?mesh= is upgraded (${keyed.status})`);
  const keyedPost = await rawRequest(server.port, 'POST', '/api/ListMeshes',
                                     { 'Content-Type': 'application/x-protobuf', Authorization: `Bearer ${token}`,
                                       'deform-mesh-key': 'mesh-0a' }, '');
  check(keyedPost.status === 200, `a POST with the deform-mesh-key header is answered (${keyedPost.status})`);
  const list = await rawRequest(server.port, 'POST', '/api/ListMeshes', { 'Content-Type': 'application/x-protobuf' }, '');
  check(list.status === 401 && list.headers['deform-status'] === '16', 'ListMeshes without a token is 401 (UNAUTHENTICATED)');
  const listed = await rawRequest(server.port, 'POST', '/api/ListMeshes',
                                  { 'Content-Type': 'application/x-protobuf', Authorization: `Bearer ${token}` }, '');
  check(listed.status === 200, 'ListMeshes with the token is 200');
  server.child.kill('SIGTERM');
  fs.rmSync(dir, { recursive: true, force: true });
}

// The fraction of pixels inside `rect` whose colour differs by more than 24 (of 255, any
// channel) between two PNG data URLs, computed in the page.
function pixelDifference(page, pngA, pngB, rect) {
  return page.evaluate(async (a, b, r) => {
    const load = (src) => new Promise((ok, ko) => { const im = new Image(); im.onload = () => ok(im); im.onerror = ko; im.src = src; });
    const [ia, ib] = await Promise.all([load(a), load(b)]);
    const pixels = (im) => {
      const c = document.createElement('canvas');
      c.width = im.width; c.height = im.height;
      const g = c.getContext('2d');
      g.drawImage(im, 0, 0);
      return g.getImageData(r.x, r.y, r.w, r.h).data;
    };
    const pa = pixels(ia), pb = pixels(ib);
    let changed = 0;
    for (let i = 0; i < pa.length; i += 4) {
      if (Math.max(Math.abs(pa[i] - pb[i]), Math.abs(pa[i + 1] - pb[i + 1]), Math.abs(pa[i + 2] - pb[i + 2])) > 24) changed++;
    }
    return changed / (pa.length / 4);
  }, pngA, pngB, rect);
}

async function waitFor(page, predicate, what, timeoutMs = 30_000, arg = null) {
  try {
    await page.waitForFunction(predicate, { timeout: Math.min(timeoutMs, deadline - Date.now()), polling: 50 }, arg);
  } catch (error) {
    const state = await page.evaluate(() => JSON.stringify({ ...window.viewerState, latencies: undefined, summary: undefined }));
    fail(`${what} (waited ${timeoutMs} ms): ${error.message}; viewer state ${state}`);
  }
}

// ---- frame encodings ----
// Poses as deform-vr's --pose spells them (JOINT:AXIS:DEGREES[,...]) and as the page sends them.
const CODEC_POSES = ['knee:flexion:0', 'knee:flexion:30', 'knee:flexion:90,knee:rotation:10',
                     'knee:flexion:120,hip:flexion:20', 'knee:flexion:75,knee:rotation:-8'];
const BIT_FOR_BIT_POSE = CODEC_POSES[4];
const ENCODINGS = ['float32', 'quantized', 'predicted'];
const poseAngles = (spec) => spec.split(',').map((term) => {
  const [joint, axis, degrees] = term.split(':');
  return { joint, axis, degrees: Number(degrees) };
});

// In the page: one stream per encoding, each pose sent and its frame decoded by frame_codec.js
// (as the viewer does); each decode is then repeated 200 times to time it. Returns, per encoding, per pose:
// the frame's encoding, its message bytes, stated max_error, bone transform count and the decoded
// positions' float32 bits (as uint32: JSON would turn -0 into 0); positionsOf() makes them floats.
function framesInEveryEncoding(page, meshId, poses) {
  return page.evaluate(async (id, posesAngles, encodings) => {
    const { DeformApi, DeformStream } = await import(`${location.origin}/deform_api.js`);
    const codec = await import(`${location.origin}/frame_codec.js`);
    await codec.frameCodecReady();
    const api = new DeformApi();
    const info = await api.meshInfo(id, true);
    const decoder = new codec.FrameDecoder(info.summary.vertexCount, info.restPositions, info.predictionWeights);
    const framesFor = (encoding) => new Promise((resolve, reject) => {
      const frames = [];
      let sequence = 0, done = false;
      const stream = new DeformStream(api, id, {
        encoding: codec.encodingFromName(encoding),
        onOpen: () => { sequence = stream.sendPose(posesAngles[0]); },
        onFrame: (frame, length) => {
          if (frame.sequence !== sequence) return;
          frames.push({ frame, length });
          if (frames.length < posesAngles.length) { sequence = stream.sendPose(posesAngles[frames.length]); return; }
          done = true;
          stream.close();
          resolve(frames);
        },
        onNotice: (notice) => { if (!done) reject(new Error(`notice ${notice.kind}: ${notice.message}`)); },
        onEnd: (code, message) => { if (!done) reject(new Error(`stream ended ${code} ${message}`)); },
      });
    });
    const result = { numBones: info.predictionWeights ? info.predictionWeights.numBones : -1, encodings: {}, decodeMs: {} };
    for (const encoding of encodings) {
      const frames = await framesFor(encoding);
      const decodeMs = [];
      result.encodings[encoding] = frames.map(({ frame, length }) => {
        const positions = decoder.decode(frame);
        const repeats = 200;  // the page's clock ticks in 0.1 ms (not cross-origin isolated)
        const start = performance.now();
        for (let r = 0; r < repeats; ++r) decoder.decode(frame);
        decodeMs.push((performance.now() - start) / repeats);
        return { encoding: frame.encoded ? codec.ENCODING_NAMES[frame.encoded.encoding] : 'float32', bytes: length,
                 maxError: frame.encoded ? frame.encoded.maxError : 0,
                 boneTransforms: frame.encoded ? frame.encoded.boneTransforms.length : 0,
                 bits: Array.from(new Uint32Array(positions.buffer)) };
      });
      decodeMs.sort((a, b) => a - b);
      result.decodeMs[encoding] = decodeMs[decodeMs.length >> 1];
    }
    return result;
  }, meshId, poses.map(poseAngles), ENCODINGS).then((result) => {
    for (const frames of Object.values(result.encodings)) {
      for (const frame of frames) frame.positions = new Float32Array(new Uint32Array(frame.bits).buffer);
    }
    return result;
  });
}

// The distance between a float32 value and the next one up in magnitude (numpy's spacing).
function float32Spacing(x) {
  const f = new Float32Array([Math.abs(x)]);
  const bits = new Uint32Array(f.buffer);
  const below = f[0];
  bits[0] += 1;
  return f[0] - below;
}

// Binary little-endian PLY of deformd's writer (double x, y, z) -> [x0, y0, z0, x1, ...].
function readPlyPositions(file) {
  const data = fs.readFileSync(file);
  const end = data.indexOf('end_header\n');
  if (end < 0) fail(`${file}: not a PLY file`);
  const header = data.subarray(0, end).toString('ascii').split('\n');
  if (!header.includes('format binary_little_endian 1.0')) fail(`${file}: not binary little-endian`);
  const vertices = Number(header.find((l) => l.startsWith('element vertex')).split(' ')[2]);
  const properties = [];
  for (const line of header) {
    if (line.startsWith('element face')) break;
    if (line.startsWith('property ')) properties.push(line.split(' ')[1]);
  }
  if (properties.join(',') !== 'double,double,double') fail(`${file}: vertex properties ${properties.join(',')}, not x, y, z doubles`);
  const body = data.subarray(end + 'end_header\n'.length);
  const positions = [];
  for (let i = 0; i < 3 * vertices; ++i) positions.push(body.readDoubleLE(8 * i));
  return positions;
}

function runDeformVr(grpcPort, meshId, encoding, pose, out) {
  return new Promise((resolve, reject) => {
    const child = spawn(deformVr, ['--target', `127.0.0.1:${grpcPort}`, '--mesh-id', meshId, '--encoding', encoding,
                                   '--pose', pose, '--frames', '1', '--out', out], { stdio: ['ignore', 'pipe', 'pipe'] });
    children.push(child);
    let log = '';
    child.stdout.on('data', (d) => { log += d; });
    child.stderr.on('data', (d) => { log += d; });
    const timer = setTimeout(() => { child.kill('SIGKILL'); reject(new Error(`deform-vr timed out:\n${log}`)); }, 60_000);
    child.on('exit', (code) => { clearTimeout(timer); if (code === 0) resolve(log); else reject(new Error(`deform-vr exited ${code}:\n${log}`)); });
  });
}

// In the page: frame_codec.js refuses malformed frames and prediction weights with an Error naming
// the problem (as core/codec and deform_client/codec.py do). Returns [what, message] pairs; a
// decode that did not throw gives the message 'accepted'.
function malformedFrameMessages(page, meshId) {
  return page.evaluate(async (id) => {
    const { DeformApi } = await import(`${location.origin}/deform_api.js`);
    const codec = await import(`${location.origin}/frame_codec.js`);
    await codec.frameCodecReady();
    const info = await new DeformApi().meshInfo(id, true);
    const n = info.summary.vertexCount;
    const quantized = new codec.FrameDecoder(n);
    const predicted = new codec.FrameDecoder(n, info.restPositions, info.predictionWeights);
    const encoded = (fields) => ({ encoding: codec.QUANTIZED, origin: [0, 0, 0], step: 0.1, maxError: 0.05,
                                   data: new Uint8Array(0), boneTransforms: new Float32Array(0), ...fields });
    const attempt = (what, run) => { try { run(); return [what, 'accepted']; } catch (error) { return [what, error.message]; } };
    return [
      attempt('bytes that do not decode', () => quantized.decodeEncoded(encoded({ data: new Uint8Array(10) }))),
      attempt('a zero step', () => quantized.decodeEncoded(encoded({ step: 0 }))),
      attempt('no origin', () => quantized.decodeEncoded(encoded({ origin: [] }))),
      attempt('predicted without weights', () => quantized.decodeEncoded(encoded({ encoding: codec.PREDICTED }))),
      attempt('5 transform floats', () => predicted.decodeEncoded(encoded({ encoding: codec.PREDICTED, boneTransforms: new Float32Array(5) }))),
      attempt('an unknown encoding', () => quantized.decodeEncoded(encoded({ encoding: 7 }))),
      attempt('a float32 frame of the wrong size', () => quantized.decode({ positions: new Float32Array(5), encoded: null })),
      attempt('weights naming a bone out of range', () => new codec.FrameDecoder(n, info.restPositions, { ...info.predictionWeights, numBones: 1 })),
      attempt('an unknown encoding name', () => codec.encodingFromName('png')),
    ];
  }, meshId);
}

async function codecChecks(page, server, summary) {
  const result = await framesInEveryEncoding(page, summary.meshId, CODEC_POSES);
  const exact = result.encodings.float32;
  const n = summary.vertexCount;
  let moved = 0;
  for (let k = 0; k < 3 * n; ++k) moved = Math.max(moved, Math.abs(exact[3].positions[k] - exact[0].positions[k]));
  check(exact.every((f) => f.encoding === 'float32' && f.positions.length === 3 * n) && moved > 1.0,
        `float32 frames for ${CODEC_POSES.length} poses, which move the mesh (up to ${moved.toFixed(2)} units)`);
  for (const encoding of ['quantized', 'predicted']) {
    CODEC_POSES.forEach((pose, p) => {
      const frame = result.encodings[encoding][p];
      const reference = exact[p];
      let excess = -Infinity, largest = 0;
      for (let k = 0; k < 3 * n; ++k) {
        const difference = Math.abs(frame.positions[k] - reference.positions[k]);
        largest = Math.max(largest, difference);
        excess = Math.max(excess, difference - (frame.maxError + float32Spacing(reference.positions[k])));
      }
      check(frame.encoding === encoding && frame.positions.length === 3 * n && frame.maxError > 0,
            `${encoding} ${pose}: a ${encoding} frame of ${frame.bytes} bytes stating max_error ${frame.maxError.toExponential(3)}`);
      check(excess <= 0, `${encoding} ${pose}: every decoded coordinate within max_error + float32 rounding of the float32 frame (largest difference ${largest.toExponential(3)})`);
      check(frame.boneTransforms === (encoding === 'predicted' ? 12 * result.numBones : 0),
            `${encoding} ${pose}: ${frame.boneTransforms} bone transform floats (${result.numBones} bones)`);
    });
  }
  CODEC_POSES.forEach((pose, p) => {
    const [f, q, r] = ENCODINGS.map((e) => result.encodings[e][p].bytes);
    check(r < q && q < f, `${pose}: predicted ${r} < quantized ${q} < float32 ${f} bytes`);
  });
  const bytesPerFrame = Object.fromEntries(ENCODINGS.map((e) => [e, result.encodings[e].map((f) => f.bytes)]));
  console.log(`frame encodings on ${n} vertices: bytes per frame ${JSON.stringify(bytesPerFrame)}; ` +
              `decode ms per frame in the page (median over the poses of the mean of 200 decodes) ${JSON.stringify(result.decodeMs)}`);

  const expected = [/do not decode to \d+ vertices/, /step must be positive/, /without its box origin/,
                    /needs the mesh's prediction weights/, /needs 24 transform floats, got 5/, /unknown encoding \(7\)/,
                    /float32 frame of 20 bytes/, /bone out of range/, /unknown frame encoding "png"/];
  const refusals = await malformedFrameMessages(page, summary.meshId);
  refusals.forEach(([what, message], i) => check(expected[i].test(message), `a malformed frame is refused by name: ${what} (${message})`));

  // Bit for bit against the C++ client library: deform-vr decodes the same pose's frame through
  // core/codec and writes it as doubles (lossless). Same mesh, same pose: the same frame.
  check(fs.existsSync(deformVr), `deform-vr is at ${deformVr}`);
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'deform-web-codec-'));
  try {
    const p = CODEC_POSES.indexOf(BIT_FOR_BIT_POSE);
    for (const encoding of ['quantized', 'predicted']) {
      const out = path.join(dir, `${encoding}.ply`);
      await runDeformVr(server.grpcPort, summary.meshId, encoding, BIT_FOR_BIT_POSE, out);
      const cpp = readPlyPositions(out);
      const page = result.encodings[encoding][p].positions;
      const cppBits = new Uint32Array(new Float32Array(cpp).buffer);
      const pageBits = new Uint32Array(page.buffer);
      let different = 0;
      for (let k = 0; k < cpp.length; ++k) if (cppBits[k] !== pageBits[k]) different++;
      check(cpp.length === page.length && different === 0,
            `${encoding} ${BIT_FOR_BIT_POSE}: the page decodes bit for bit what the C++ library decodes (${cpp.length / 3} vertices, ${different} coordinates differ)`);
    }
  } finally {
    fs.rmSync(dir, { recursive: true, force: true });
  }
}

async function browserChecks(server) {
  const { port } = server;
  const require = createRequire(path.join(repo, 'client/web/package.json'));
  let puppeteer;
  try {
    puppeteer = require('puppeteer-core');
  } catch (error) {
    fail(`puppeteer-core is not installed in client/web/node_modules: run scripts/install-node-tools.sh (${error.message})`);
  }
  check(fs.existsSync(chromium), `chromium is at ${chromium}`);
  const userData = fs.mkdtempSync(path.join(os.tmpdir(), 'deform-chromium-'));
  const browser = await puppeteer.launch({
    executablePath: chromium,
    headless: true,
    args: ['--no-sandbox', '--disable-gpu', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
           '--disable-background-networking', `--user-data-dir=${userData}`, '--window-size=1100,700'],
    defaultViewport: { width: 1100, height: 700 },
  });
  const consoleErrors = [];
  try {
    const page = await browser.newPage();
    page.on('console', (message) => {
      if (message.type() === 'error') consoleErrors.push(message.text());
    });
    page.on('pageerror', (error) => consoleErrors.push(`page error: ${error.message}`));
    page.on('requestfailed', (request) => consoleErrors.push(`request failed: ${request.url()}`));
    // What the page sends a balancer to route on (docs/cluster.md): the WebSockets' URLs and the
    // GetMeshInfo POSTs' deform-mesh-key header.
    const socketUrls = [], infoKeys = [];
    const cdp = await page.createCDPSession();
    await cdp.send('Network.enable');
    cdp.on('Network.webSocketCreated', (event) => socketUrls.push(event.url));
    page.on('request', (request) => {
      if (request.url().endsWith('/api/GetMeshInfo')) infoKeys.push(request.headers()['deform-mesh-key']);
    });
    await page.goto(`http://127.0.0.1:${port}/`, { waitUntil: 'load', timeout: 30_000 });
    await waitFor(page, () => window.viewerState && Array.isArray(window.viewerState.meshes), 'the viewer starts');

    await page.click('#load-phantom');
    await waitFor(page, () => window.viewerState.streamStatus === 'open', 'the phantom loads and its Deform stream opens', 60_000);
    await waitFor(page, () => window.viewerState.framesReceived >= 1, 'a frame arrives for the rest pose');
    const meshId = await page.evaluate(() => window.viewerState.meshId);
    check(socketUrls.some((url) => url.endsWith(`/ws/Deform?mesh=${encodeURIComponent(meshId)}`)),
          `the Deform WebSocket's URL carries ?mesh=<id> (${socketUrls.join(' ')})`);
    check(infoKeys.includes(meshId), `GetMeshInfo sends the deform-mesh-key header (${infoKeys.join(' ')})`);
    const listed = await page.evaluate(() => window.viewerState.meshes.map((m) => m.name));
    check(listed.some((name) => name.startsWith('phantom')), `the mesh list shows the phantom (${listed.join(', ')})`);
    const summary = await page.evaluate(() => window.viewerState.summary);
    const knee = summary.joints.find((j) => j.name === 'knee');
    const ankle = summary.joints.find((j) => j.name === 'ankle');
    const hip = summary.joints.find((j) => j.name === 'hip');
    check(knee && ankle && hip, 'the phantom has hip, knee and ankle joints');
    const sliders = await page.$$eval('input[data-joint]', (all) => all.map((s) => `${s.dataset.joint}:${s.dataset.axis}[${s.min},${s.max}]`));
    check(sliders.length === summary.joints.reduce((n, j) => n + j.dofs.length, 0),
          `one slider per degree of freedom of every joint (${sliders.join(' ')})`);
    const stiffness = await page.$$eval('input[data-stiffness]', (all) => all.length);
    check(stiffness === summary.joints.length, `a stiffness control per joint (${stiffness})`);

    await new Promise((r) => setTimeout(r, 300));
    const view = await page.$('#view');
    const rest = await view.screenshot({ path: path.join(artifacts, 'rest.png') });
    const framesBefore = await page.evaluate(() => window.viewerState.framesReceived);

    await page.evaluate(() => {
      const slider = document.querySelector('input[data-joint="knee"][data-axis="flexion"]');
      slider.value = '90';
      slider.dispatchEvent(new Event('input'));
    });
    await waitFor(page, (before) => window.viewerState.framesReceived > before
      && window.viewerState.lastFrameSequence >= window.viewerState.lastPoseSequence
      && window.viewerState.lastPoseSequence > 1, 'a frame arrives for the knee at 90 degrees', 30_000, framesBefore);
    await new Promise((r) => setTimeout(r, 300));
    const bent = await view.screenshot({ path: path.join(artifacts, 'knee90.png') });

    const stats = await page.evaluate(() => ({
      fps: document.getElementById('stat-fps').textContent,
      latency: document.getElementById('stat-latency').textContent,
      bytes: document.getElementById('stat-bytes').textContent,
      normals: document.getElementById('stat-normals').textContent,
      frames: window.viewerState.framesReceived,
      lastBytes: window.viewerState.lastBytes,
    }));
    console.log(`viewer stats: ${JSON.stringify(stats)}`);
    check(stats.lastBytes >= summary.vertexCount * 12, `a frame carries the float32 positions (${stats.lastBytes} bytes for ${summary.vertexCount} vertices)`);
    check(/ms/.test(stats.latency) && stats.fps !== '-', 'the page shows frame rate and latency');
    check(/recomputed/.test(stats.normals), 'the page says normals are recomputed in the browser');

    // Where the shin is at rest: the knee-to-ankle segment projected onto the canvas, padded.
    const box = await page.evaluate((k, a) => {
      const p = window.viewerState.project;
      const points = [];
      for (let t = 0.15; t <= 1.0001; t += 0.05) {
        points.push(p(...k.map((v, i) => v + (a[i] - v) * t)));
      }
      return points;
    }, knee.restPosition, ankle.restPosition);
    const rectOf = (points, pad) => {
      const xs = points.map((q) => q.x), ys = points.map((q) => q.y);
      const x = Math.max(0, Math.floor(Math.min(...xs) - pad)), y = Math.max(0, Math.floor(Math.min(...ys) - pad));
      return { x, y, w: Math.ceil(Math.max(...xs) + pad) - x, h: Math.ceil(Math.max(...ys) + pad) - y };
    };
    const shin = rectOf(box, 12);
    const hipPoint = await page.evaluate((h) => window.viewerState.project(...h), hip.restPosition);
    const hipRect = rectOf([hipPoint], 12);
    const toUrl = (png) => `data:image/png;base64,${Buffer.from(png).toString('base64')}`;
    const shinChange = await pixelDifference(page, toUrl(rest), toUrl(bent), shin);
    const hipChange = await pixelDifference(page, toUrl(rest), toUrl(bent), hipRect);
    console.log(`shin region ${JSON.stringify(shin)}: ${(shinChange * 100).toFixed(1)}% of pixels changed; hip region ${JSON.stringify(hipRect)}: ${(hipChange * 100).toFixed(1)}%`);
    check(shinChange > 0.2, `the knee at 90 degrees changes the picture where the shin was (${(shinChange * 100).toFixed(1)}% of its pixels)`);
    check(hipChange < shinChange / 2, `and far less at the hip (${(hipChange * 100).toFixed(1)}%)`);

    await codecChecks(page, server, summary);

    // The viewer's encoding selector: the stream restarts in the chosen encoding, the page decodes
    // its frames, shows their size and stated error, and draws the same picture.
    const viewSize = await page.evaluate(() => ({ w: document.getElementById('view').clientWidth, h: document.getElementById('view').clientHeight }));
    for (const encoding of ['quantized', 'predicted']) {
      await page.select('#encoding', encoding);
      await waitFor(page, (e) => window.viewerState.lastFrameEncoding === e && window.viewerState.streamStatus === 'open',
                    `the viewer restarts its stream in ${encoding} and decodes its frames`, 30_000, encoding);
      await new Promise((r) => setTimeout(r, 300));
      const shot = await view.screenshot({ path: path.join(artifacts, `knee90-${encoding}.png`) });
      await page.screenshot({ path: path.join(artifacts, `page-${encoding}.png`) });
      const shown = await page.evaluate(() => ({
        encoding: document.getElementById('stat-encoding').textContent,
        maxError: document.getElementById('stat-max-error').textContent,
        bytes: document.getElementById('stat-bytes').textContent,
        decode: document.getElementById('stat-decode').textContent,
        lastBytes: window.viewerState.lastBytes,
      }));
      console.log(`viewer in ${encoding}: ${JSON.stringify(shown)}`);
      check(shown.encoding === encoding && /of the diagonal/.test(shown.maxError) && /ms/.test(shown.decode),
            `the page shows the frame's encoding, stated error and decode time (${shown.encoding}, ${shown.maxError}, ${shown.decode})`);
      check(shown.lastBytes * 2 < stats.lastBytes, `${encoding} frames are smaller (${shown.lastBytes} bytes against ${stats.lastBytes})`);
      const shinSame = await pixelDifference(page, toUrl(bent), toUrl(shot), shin);
      const wholeSame = await pixelDifference(page, toUrl(bent), toUrl(shot), { x: 0, y: 0, ...viewSize });
      check(shinSame < 0.01 && wholeSame < 0.01,
            `the ${encoding} picture matches the float32 one (${(shinSame * 100).toFixed(2)}% of the shin's pixels, ${(wholeSame * 100).toFixed(2)}% of the view differ)`);
    }

    // Sweeps of the knee, 0 to 120 degrees and back at the page's frame rate, for the figures:
    // in predicted (selected last above), then float32.
    for (const encoding of ['predicted', 'float32']) {
      if (encoding !== 'predicted') {
        await page.select('#encoding', encoding);
        await waitFor(page, (e) => window.viewerState.lastFrameEncoding === e && window.viewerState.streamStatus === 'open',
                      `the viewer restarts its stream in ${encoding}`, 30_000, encoding);
      }
      const sweep = await page.evaluate(async () => {
        const slider = document.querySelector('input[data-joint="knee"][data-axis="flexion"]');
        const s = window.viewerState;
        const before = s.framesReceived;
        s.latencies.length = 0;
        s.decodeTimes.length = 0;
        const start = performance.now();
        for (let i = 0; i <= 120; i++) {
          slider.value = String(i <= 60 ? i * 2 : (120 - i) * 2);
          slider.dispatchEvent(new Event('input'));
          await new Promise((r) => requestAnimationFrame(r));
        }
        await new Promise((r) => setTimeout(r, 200));
        const seconds = (performance.now() - start) / 1000;
        const sorted = [...s.latencies].sort((a, b) => a - b);
        return { frames: s.framesReceived - before, seconds, framesPerSecond: (s.framesReceived - before) / seconds,
                 latencyP50: sorted[Math.floor(sorted.length / 2)], latencyP99: sorted[Math.floor(sorted.length * 0.99)],
                 normalsMs: s.normalsMs, decodeMsMean: s.decodeTimes.reduce((sum, t) => sum + t, 0) / s.decodeTimes.length };
      });
      console.log(`knee sweep in ${encoding}: ${JSON.stringify(sweep)}`);
      check(sweep.frames >= 30, `frames keep arriving while the knee slider moves in ${encoding} (${sweep.frames} frames in ${sweep.seconds.toFixed(1)} s)`);
    }
    check(consoleErrors.length === 0, `no console error (${consoleErrors.join(' | ') || 'none'})`);
  } finally {
    await browser.close();
    fs.rmSync(userData, { recursive: true, force: true });
  }
}

async function main() {
  fs.mkdirSync(artifacts, { recursive: true });
  check(fs.existsSync(deformd), `deformd is at ${deformd}`);
  const server = await startDeformd([]);
  await staticChecks(server.port);
  await browserChecks(server);
  await tokenChecks();
  server.child.removeAllListeners('exit');
  const exited = new Promise((resolve) => server.child.once('exit', resolve));
  server.child.kill('SIGTERM');
  const code = await Promise.race([exited, new Promise((r) => setTimeout(() => r('timeout'), 10_000))]);
  check(code === 0, `deformd exits 0 on SIGTERM with the viewer's streams closed (${code})`);
  console.log(`viewer_test: passed; screenshots in ${artifacts}`);
}

main().catch((error) => {
  if (!process.exitCode) console.error(`viewer_test: FAILED: ${error.stack || error}`);
  process.exitCode = 1;
}).finally(() => {
  for (const child of children) if (child.exitCode === null) child.kill('SIGKILL');
  setTimeout(() => process.exit(process.exitCode || 0), 100).unref();
});
