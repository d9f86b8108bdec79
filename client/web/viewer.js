// The deformd browser viewer: lists the caller's meshes, loads the phantom, shows the selected
// mesh shaded (three.js), streams its deformation over a WebSocket while the joint sliders move,
// and shows frames per second, latency, bytes per frame, the frame's encoding and stated error and
// the time to decode it. The encoding selector (float32, quantized, predicted; initially `?encoding=`
// or float32) restarts the stream in the chosen encoding; frame_codec.js decodes every encoding.
// Frames carry positions only; normals are recomputed here for every frame (shown in the panel with
// their cost). window.viewerState exposes the counters (the browser test reads them).
import * as THREE from './vendor/three.module.js';
import { DeformApi, DeformStream } from './deform_api.js';
import { NOTICE_KINDS } from './proto_wire.js';
import { ENCODING_NAMES, FrameDecoder, encodingFromName, frameCodecReady } from './frame_codec.js';

const params = new URLSearchParams(location.search);
const api = new DeformApi(params.get('token') || '');
const $ = (id) => document.getElementById(id);
const codecReady = frameCodecReady();  // meshoptimizer's WebAssembly; selectMesh awaits it

const state = window.viewerState = {
  meshes: [], meshId: null, framesReceived: 0, lastFrameSequence: 0, lastPoseSequence: 0,
  lastBytes: 0, latencies: [], errors: [], streamStatus: 'none', normalsMs: 0,
  encoding: 'float32', lastFrameEncoding: null, lastMaxError: 0, decodeMs: 0, decodeTimes: [], diagonal: 0,
};
let decoder = null;  // the selected mesh's FrameDecoder

// ---- rendering ----
const renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
renderer.setPixelRatio(window.devicePixelRatio);
$('view').appendChild(renderer.domElement);
const scene = new THREE.Scene();
scene.background = new THREE.Color(0x30343c);
const camera = new THREE.PerspectiveCamera(35, 1, 0.01, 1000);
scene.add(new THREE.HemisphereLight(0xffffff, 0x404050, 1.2));
const sun = new THREE.DirectionalLight(0xffffff, 2.0);
scene.add(sun);
const material = new THREE.MeshStandardMaterial({ color: 0xd9a98c, roughness: 0.6, metalness: 0.0,
                                                  side: THREE.DoubleSide });
let mesh = null;
let orbit = { center: new THREE.Vector3(), distance: 1, yaw: 0, pitch: 0.15, up: new THREE.Vector3(0, 1, 0),
              side: new THREE.Vector3(1, 0, 0), front: new THREE.Vector3(0, 0, 1) };

function placeCamera() {
  const dir = orbit.side.clone().multiplyScalar(Math.cos(orbit.yaw) * Math.cos(orbit.pitch))
    .add(orbit.front.clone().multiplyScalar(Math.sin(orbit.yaw) * Math.cos(orbit.pitch)))
    .add(orbit.up.clone().multiplyScalar(Math.sin(orbit.pitch)));
  camera.up.copy(orbit.up);
  camera.position.copy(orbit.center).addScaledVector(dir, orbit.distance);
  camera.lookAt(orbit.center);
  sun.position.copy(camera.position).addScaledVector(orbit.up, orbit.distance);
}

function resize() {
  const { clientWidth: w, clientHeight: h } = $('view');
  renderer.setSize(w, h, false);
  camera.aspect = w / Math.max(h, 1);
  camera.updateProjectionMatrix();
  render();
}
function render() { placeCamera(); renderer.render(scene, camera); }
window.addEventListener('resize', resize);

// Drag to turn around the mesh, wheel to zoom.
let drag = null;
renderer.domElement.addEventListener('pointerdown', (e) => { drag = { x: e.clientX, y: e.clientY }; });
window.addEventListener('pointerup', () => { drag = null; });
window.addEventListener('pointermove', (e) => {
  if (!drag) return;
  orbit.yaw -= (e.clientX - drag.x) * 0.01;
  orbit.pitch = Math.max(-1.5, Math.min(1.5, orbit.pitch + (e.clientY - drag.y) * 0.01));
  drag = { x: e.clientX, y: e.clientY };
  render();
});
renderer.domElement.addEventListener('wheel', (e) => {
  orbit.distance *= Math.exp(e.deltaY * 0.001);
  render();
}, { passive: true });

// Shows the rest geometry, framed from the side of the first joint's first axis (the phantom's
// knee bends in view), the longest extent upward.
function showGeometry(info) {
  if (mesh) { scene.remove(mesh); mesh.geometry.dispose(); }
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(new Float32Array(info.restPositions), 3));
  geometry.setIndex(new THREE.BufferAttribute(info.triangles, 1));
  geometry.computeVertexNormals();
  geometry.computeBoundingBox();
  mesh = new THREE.Mesh(geometry, material);
  scene.add(mesh);
  const box = geometry.boundingBox;
  const size = box.getSize(new THREE.Vector3());
  state.diagonal = size.length();
  box.getCenter(orbit.center);
  const axes = [new THREE.Vector3(1, 0, 0), new THREE.Vector3(0, 1, 0), new THREE.Vector3(0, 0, 1)];
  const longest = size.x >= size.y && size.x >= size.z ? 0 : (size.y >= size.z ? 1 : 2);
  orbit.up = axes[longest];
  const axis = info.summary.joints.flatMap((j) => j.dofs.map((d) => d.axis)).find((a) => a && a.length === 3);
  orbit.side = axis ? new THREE.Vector3(...axis).normalize() : axes[(longest + 1) % 3];
  if (Math.abs(orbit.side.dot(orbit.up)) > 0.9) orbit.side = axes[(longest + 1) % 3];
  orbit.front = new THREE.Vector3().crossVectors(orbit.up, orbit.side).normalize();
  orbit.side = new THREE.Vector3().crossVectors(orbit.front, orbit.up).normalize();
  orbit.distance = Math.max(size.x, size.y, size.z) * 2.2;
  orbit.yaw = 0; orbit.pitch = 0.1;
  resize();
}

// Where a model-space point appears on the canvas, in CSS pixels from its top left (the browser
// test finds the shin this way).
state.project = (x, y, z) => {
  placeCamera();
  camera.updateMatrixWorld();
  const p = new THREE.Vector3(x, y, z).project(camera);
  const { clientWidth: w, clientHeight: h } = renderer.domElement;
  return { x: (p.x + 1) / 2 * w, y: (1 - p.y) / 2 * h };
};

function applyFrame(positions) {
  if (!mesh) return;
  const attribute = mesh.geometry.getAttribute('position');
  if (positions.length !== attribute.array.length) return;
  attribute.array.set(positions);
  attribute.needsUpdate = true;
  const start = performance.now();
  mesh.geometry.computeVertexNormals();  // frames carry no normals
  state.normalsMs = performance.now() - start;
  render();
}

// ---- the stream ----
let stream = null;
let pendingPose = false;
const angles = new Map();  // "joint\u0000axis" -> {joint, axis, degrees}

function sendPoseSoon() {
  if (pendingPose) return;
  pendingPose = true;
  requestAnimationFrame(() => {
    pendingPose = false;
    if (stream) state.lastPoseSequence = stream.sendPose([...angles.values()]) || state.lastPoseSequence;
  });
}

const frameTimes = [];
function onFrame(frame, bytes) {
  const now = performance.now();
  let positions;
  try {
    positions = decoder.decode(frame);
  } catch (error) {
    report(error);
    return;
  }
  state.decodeMs = performance.now() - now;
  state.decodeTimes.push(state.decodeMs);
  if (state.decodeTimes.length > 120) state.decodeTimes.shift();
  state.lastFrameEncoding = frame.encoded ? ENCODING_NAMES[frame.encoded.encoding] : 'float32';
  state.lastMaxError = frame.encoded ? frame.encoded.maxError : 0;
  state.framesReceived += 1;
  state.lastFrameSequence = frame.sequence;
  state.lastBytes = bytes;
  const latency = now - frame.clientTimestampNs / 1e6;
  state.latencies.push(latency);
  if (state.latencies.length > 120) state.latencies.shift();
  frameTimes.push(now);
  while (frameTimes.length && frameTimes[0] < now - 1000) frameTimes.shift();
  applyFrame(positions);
  const sorted = [...state.latencies].sort((a, b) => a - b);
  $('stat-fps').textContent = String(frameTimes.length);
  $('stat-latency').textContent = `${latency.toFixed(1)} ms, ${sorted[sorted.length >> 1].toFixed(1)} ms`;
  $('stat-bytes').textContent = `${bytes} (${(bytes / Math.max(decoder.vertexCount, 1)).toFixed(2)} per vertex)`;
  $('stat-encoding').textContent = state.lastFrameEncoding;
  $('stat-max-error').textContent = frame.encoded
    ? `${state.lastMaxError.toExponential(2)} units (${(state.lastMaxError / state.diagonal).toExponential(1)} of the diagonal)`
    : 'float32 rounding';
  // The page's clock ticks in 0.1 ms: the mean of the last frames' decodes says more than one.
  const meanDecode = state.decodeTimes.reduce((sum, t) => sum + t, 0) / state.decodeTimes.length;
  $('stat-decode').textContent = `${meanDecode.toFixed(3)} ms (mean of the last ${state.decodeTimes.length} frames)`;
  $('stat-solve').textContent = `${(frame.timings.rhsMs + frame.timings.solveMs).toFixed(2)} ms (queue ${frame.timings.queueMs.toFixed(2)} ms)`;
  $('stat-normals').textContent = `not carried by frames: recomputed here per frame (${state.normalsMs.toFixed(2)} ms)`;
}

function onNotice(notice) {
  const item = document.createElement('li');
  item.textContent = `${NOTICE_KINDS[notice.kind] || notice.kind}: ${notice.message}`;
  $('notices').prepend(item);
}

function openStream(meshId) {
  if (stream) stream.close();
  state.streamStatus = 'opening';
  $('stat-status').textContent = 'opening';
  stream = new DeformStream(api, meshId, {
    encoding: encodingFromName(state.encoding),
    onOpen: () => { state.streamStatus = 'open'; $('stat-status').textContent = 'open'; sendPoseSoon(); },
    onFrame,
    onNotice,
    onEnd: (code, message) => {
      state.streamStatus = `ended ${code}`;
      $('stat-status').textContent = code === 0 ? 'ended' : `ended: ${code} ${message}`;
      if (code !== 0) console.warn(`Deform stream ended: ${code} ${message}`);
    },
  });
}

// ---- joints ----
function buildJointControls(summary) {
  const container = $('joints');
  container.replaceChildren();
  angles.clear();
  for (const joint of summary.joints) {
    const block = document.createElement('div');
    block.className = 'joint';
    const title = document.createElement('strong');
    title.textContent = joint.name;
    block.appendChild(title);
    for (const dof of joint.dofs) {
      const key = `${joint.name}\u0000${dof.name}`;
      const initial = Math.min(Math.max(0, dof.minDegrees), dof.maxDegrees);
      angles.set(key, { joint: joint.name, axis: dof.name, degrees: initial });
      const label = document.createElement('label');
      const name = document.createElement('span');
      name.textContent = dof.name;
      const slider = document.createElement('input');
      Object.assign(slider, { type: 'range', min: dof.minDegrees, max: dof.maxDegrees, step: 0.5, value: initial });
      slider.dataset.joint = joint.name;
      slider.dataset.axis = dof.name;
      const value = document.createElement('span');
      value.textContent = `${initial}°`;
      slider.addEventListener('input', () => {
        angles.get(key).degrees = Number(slider.value);
        value.textContent = `${slider.value}°`;
        sendPoseSoon();
      });
      label.append(name, slider, value);
      block.appendChild(label);
    }
    // Stiffness: one weight for the joint's region (0.1 to 10, log scale; 1 = the default).
    const label = document.createElement('label');
    const name = document.createElement('span');
    name.textContent = 'stiffness';
    const slider = document.createElement('input');
    Object.assign(slider, { type: 'range', min: -1, max: 1, step: 0.05, value: 0 });
    slider.dataset.stiffness = joint.name;
    const value = document.createElement('span');
    value.textContent = joint.hasRegion ? '1.00' : 'none';
    if (!joint.hasRegion) {
      slider.disabled = true;
      label.className = 'disabled';
      label.title = 'an end joint: no joint region to stiffen';
    }
    slider.addEventListener('change', () => {
      const weight = 10 ** Number(slider.value);
      value.textContent = weight.toFixed(2);
      if (stream) stream.sendRegionWeights([{ joint: joint.name, weight }]);
    });
    label.append(name, slider, value);
    block.appendChild(label);
    container.appendChild(block);
  }
}

// ---- meshes ----
async function selectMesh(meshId) {
  state.meshId = meshId;
  for (const li of $('meshes').children) li.classList.toggle('selected', li.dataset.meshId === meshId);
  const info = await api.meshInfo(meshId);
  await codecReady;
  decoder = new FrameDecoder(info.summary.vertexCount, info.restPositions, info.predictionWeights);
  state.summary = info.summary;
  buildJointControls(info.summary);
  showGeometry(info);
  openStream(meshId);
}

async function refreshMeshes() {
  state.meshes = await api.listMeshes();
  const list = $('meshes');
  list.replaceChildren();
  for (const m of state.meshes) {
    const li = document.createElement('li');
    li.dataset.meshId = m.meshId;
    li.textContent = `${m.name} (${m.vertexCount} vertices, ${m.joints.length} joints)`;
    li.addEventListener('click', () => selectMesh(m.meshId).catch(report));
    if (m.meshId === state.meshId) li.classList.add('selected');
    list.appendChild(li);
  }
}

function report(error) {
  state.errors.push(String(error.message || error));
  console.error(error);
  $('load-progress').textContent = String(error.message || error);
}

$('refresh').addEventListener('click', () => refreshMeshes().catch(report));
// A new encoding restarts the stream (DeformStart fixes a stream's encoding); the sliders' pose is
// sent again when it opens.
const requested = params.get('encoding');
state.encoding = Object.values(ENCODING_NAMES).includes(requested) ? requested : 'float32';
$('encoding').value = state.encoding;
$('encoding').addEventListener('change', () => {
  state.encoding = $('encoding').value;
  if (state.meshId && decoder) openStream(state.meshId);
});
$('load-phantom').addEventListener('click', async () => {
  try {
    const vertices = Number($('phantom-vertices').value) || 2000;
    const summary = await api.loadPhantom(vertices, (stage, ms) => {
      $('load-progress').textContent = `${stage} after ${ms.toFixed(0)} ms`;
    });
    await refreshMeshes();
    await selectMesh(summary.meshId);
  } catch (error) {
    report(error);
  }
});

resize();
codecReady.catch(report);
refreshMeshes().catch(report);
