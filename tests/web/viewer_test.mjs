// The browser viewer end to end: a real deformd serving --http, Debian's chromium (headless,
// WebGL in software through SwiftShader) driven by puppeteer-core.
//
//   node tests/web/viewer_test.mjs --deformd build/server/deformd/deformd --artifacts DIR
//
// Checks: the static root serves the page and nothing outside it (path traversal, encoded or
// not); the page loads the phantom over the WebSocket LoadMesh, shows it, and streams frames;
// moving the knee slider to 90 degrees brings frames for that pose, and the screenshot differs
// from the rest-pose screenshot where the shin is (and far less at the hip); the page logs no
// console error. With a token file, an upgrade without a valid token is refused (401) and one
// with the token as its subprotocol is upgraded. The screenshots stay in DIR (rest.png,
// knee90.png). Exit code 0 when every check passes, 1 with the failed check on stderr.
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
// Starts deformd with `extra` flags; resolves with its HTTP port once it logs "http listening on".
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
      if (match) { clearTimeout(timer); resolve({ child, port: Number(match[2]), log: () => log }); }
    };
    child.stdout.on('data', onData);
    child.stderr.on('data', onData);
    child.on('exit', (code) => { clearTimeout(timer); reject(new Error(`deformd exited (${code}):\n${log}`)); });
  });
}

// A raw HTTP request (no path normalisation); resolves with {status, headers, body} or, for an
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

async function browserChecks(port) {
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
    await page.goto(`http://127.0.0.1:${port}/`, { waitUntil: 'load', timeout: 30_000 });
    await waitFor(page, () => window.viewerState && Array.isArray(window.viewerState.meshes), 'the viewer starts');

    await page.click('#load-phantom');
    await waitFor(page, () => window.viewerState.streamStatus === 'open', 'the phantom loads and its Deform stream opens', 60_000);
    await waitFor(page, () => window.viewerState.framesReceived >= 1, 'a frame arrives for the rest pose');
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
    // A sweep of the knee, 0 to 120 degrees and back at the page's frame rate, for the figures.
    const sweep = await page.evaluate(async () => {
      const slider = document.querySelector('input[data-joint="knee"][data-axis="flexion"]');
      const s = window.viewerState;
      const before = s.framesReceived;
      s.latencies.length = 0;
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
               normalsMs: s.normalsMs };
    });
    console.log(`knee sweep: ${JSON.stringify(sweep)}`);
    check(sweep.frames >= 30, `frames keep arriving while the knee slider moves (${sweep.frames} frames in ${sweep.seconds.toFixed(1)} s)`);
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
  await browserChecks(server.port);
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
