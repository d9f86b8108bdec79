// The few deform.v1 messages the viewer sends and reads, in protobuf's binary wire format, written
// by hand (proto/deform/v1/deform.proto is the reference; field numbers below are its). Integers
// are JavaScript numbers: exact up to 2^53, which sequences and the page's nanosecond timestamps
// stay far below. Unknown fields are skipped, so newer servers' fields do no harm.

// ---- writing ----
class Writer {
  constructor() { this.bytes = []; }
  varint(value) {
    let v = value;
    while (v >= 128) { this.bytes.push((v % 128) | 128); v = Math.floor(v / 128); }
    this.bytes.push(v);
  }
  tag(field, wire) { this.varint(field * 8 + wire); }
  uint(field, value) { if (value) { this.tag(field, 0); this.varint(value); } }
  bool(field, value) { if (value) { this.tag(field, 0); this.varint(1); } }
  double(field, value) {
    if (value === 0) return;
    this.tag(field, 1);
    const b = new Uint8Array(new Float64Array([value]).buffer);
    for (const x of b) this.bytes.push(x);
  }
  bytesField(field, data) { this.tag(field, 2); this.varint(data.length); for (const x of data) this.bytes.push(x); }
  string(field, text) { if (text) this.bytesField(field, new TextEncoder().encode(text)); }
  message(field, build) { const w = new Writer(); build(w); this.bytesField(field, w.bytes); }
  finish() { return new Uint8Array(this.bytes); }
}

export function encodeGetMeshInfoRequest(meshId, includeGeometry, includePredictionWeights = false) {
  const w = new Writer();
  w.string(1, meshId); w.bool(2, includeGeometry); w.bool(3, includePredictionWeights);
  return w.finish();
}
export function encodeListMeshesRequest() { return new Uint8Array(0); }

// LoadMeshRequest{header: LoadMeshHeader{name, phantom: PhantomSource{vertices}}}
export function encodeLoadPhantomHeader(name, vertices) {
  const w = new Writer();
  w.message(1, (h) => { h.string(1, name); h.message(2, (p) => p.uint(1, vertices)); });
  return w.finish();
}

// DeformRequest{start: DeformStart{mesh_id, encoding, max_error}}; encoding 1 =
// FRAME_ENCODING_FLOAT32, 2 = QUANTIZED, 3 = PREDICTED; maxError 0 = the server's default.
export function encodeDeformStart(meshId, encoding = 1, maxError = 0) {
  const w = new Writer();
  w.message(1, (s) => { s.string(1, meshId); s.uint(2, encoding); s.double(3, maxError); });
  return w.finish();
}

// DeformRequest{pose: PoseUpdate{sequence, client_timestamp_ns, angles: [{joint, axis, degrees}]}}
export function encodeDeformPose(sequence, timestampNs, angles) {
  const w = new Writer();
  w.message(2, (p) => {
    p.uint(1, sequence);
    p.uint(2, timestampNs);
    for (const a of angles) {
      p.message(3, (j) => { j.string(1, a.joint); j.string(2, a.axis); j.double(3, a.degrees); });
    }
  });
  return w.finish();
}

// DeformRequest{stiffness: StiffnessUpdate{region_weights: [{joint, weight}]}}
export function encodeRegionWeights(weights) {
  const w = new Writer();
  w.message(3, (s) => {
    for (const r of weights) s.message(2, (m) => { m.string(1, r.joint); m.double(2, r.weight); });
  });
  return w.finish();
}

// ---- reading ----
// The fields of one message: number -> array of values (varint: number; fixed64: {view, offset};
// length-delimited: Uint8Array; fixed32: {view, offset}).
function fields(bytes) {
  const out = new Map();
  const view = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
  let i = 0;
  const varint = () => {
    let result = 0, scale = 1, b;
    do {
      if (i >= bytes.length) throw new Error('truncated varint');
      b = bytes[i++];
      result += (b & 127) * scale;
      scale *= 128;
    } while (b & 128);
    return result;
  };
  while (i < bytes.length) {
    const key = varint();
    const field = Math.floor(key / 8), wire = key % 8;
    let value;
    if (wire === 0) value = varint();
    else if (wire === 1) { value = view.getFloat64(i, true); i += 8; }
    else if (wire === 2) { const n = varint(); if (i + n > bytes.length) throw new Error('truncated field'); value = bytes.subarray(i, i + n); i += n; }
    else if (wire === 5) { value = view.getFloat32(i, true); i += 4; }
    else throw new Error(`unsupported wire type ${wire}`);
    if (!out.has(field)) out.set(field, []);
    out.get(field).push(value);
  }
  return out;
}
const one = (f, n, d) => (f.has(n) ? f.get(n)[f.get(n).length - 1] : d);
const all = (f, n) => f.get(n) || [];
const text = (v) => (v === undefined ? '' : new TextDecoder().decode(v));
// Packed or unpacked repeated doubles.
function doubles(f, n) {
  const result = [];
  for (const v of all(f, n)) {
    if (v instanceof Uint8Array) {
      const dv = new DataView(v.buffer, v.byteOffset, v.byteLength);
      for (let k = 0; k + 8 <= v.byteLength; k += 8) result.push(dv.getFloat64(k, true));
    } else result.push(v);
  }
  return result;
}

function decodeDof(b) {
  const f = fields(b);
  return { name: text(one(f, 1)), axis: doubles(f, 2), minDegrees: one(f, 3, 0), maxDegrees: one(f, 4, 0) };
}
function decodeJoint(b) {
  const f = fields(b);
  return { name: text(one(f, 1)), index: one(f, 2, 0), restPosition: doubles(f, 3),
           dofs: all(f, 4).map(decodeDof), hasRegion: one(f, 5, 0) === 1 };
}
export function decodeMeshSummary(b) {
  const f = fields(b);
  return { meshId: text(one(f, 1)), name: text(one(f, 2)), vertexCount: one(f, 3, 0),
           triangleCount: one(f, 4, 0), joints: all(f, 5).map(decodeJoint) };
}
export function decodeListMeshesResponse(b) { return all(fields(b), 1).map(decodeMeshSummary); }

// Little-endian arrays out of a bytes field (copied: the field need not be aligned).
function float32s(v) { return v ? new Float32Array(v.slice().buffer) : new Float32Array(0); }
function uint32s(v) { return v ? new Uint32Array(v.slice().buffer) : new Uint32Array(0); }
function uint16s(v) { return v ? new Uint16Array(v.slice().buffer) : new Uint16Array(0); }
// Packed or unpacked repeated floats, as a Float32Array.
function floats(f, n) {
  const parts = all(f, n).map((v) => (v instanceof Uint8Array ? float32s(v) : [v]));
  const result = new Float32Array(parts.reduce((sum, p) => sum + p.length, 0));
  let at = 0;
  for (const p of parts) { result.set(p, at); at += p.length; }
  return result;
}

// PredictionWeights{bones: uint16 x 4 per vertex, weights: float32 x 4 per vertex, num_bones}.
function decodePredictionWeights(b) {
  const f = fields(b);
  return { bones: uint16s(one(f, 1)), weights: float32s(one(f, 2)), numBones: one(f, 3, 0) };
}

// EncodedPositions (FrameEncoding 2 QUANTIZED or 3 PREDICTED): origin (3 doubles, QUANTIZED),
// step and maxError (model units), data (meshoptimizer's vertex codec), boneTransforms
// (Float32Array, 12 per bone, PREDICTED).
export function decodeEncodedPositions(b) {
  const f = fields(b);
  return { encoding: one(f, 1, 0), origin: doubles(f, 2), step: one(f, 3, 0), maxError: one(f, 4, 0),
           data: one(f, 5, new Uint8Array(0)), boneTransforms: floats(f, 6) };
}

export function decodeGetMeshInfoResponse(b) {
  const f = fields(b);
  return { summary: decodeMeshSummary(one(f, 1, new Uint8Array(0))),
           restPositions: float32s(one(f, 2)), triangles: uint32s(one(f, 3)),
           predictionWeights: f.has(4) ? decodePredictionWeights(one(f, 4)) : null };
}
export function decodeLoadMeshResponse(b) {
  const f = fields(b);
  const mesh = one(f, 3);
  return { stage: one(f, 1, 0), elapsedMs: one(f, 2, 0), mesh: mesh ? decodeMeshSummary(mesh) : null };
}
export const STAGE_NAMES = ['UNSPECIFIED', 'RECEIVED', 'VALIDATED', 'WEIGHTS', 'FACTORISED', 'READY'];

// DeformResponse: {frame} or {notice}. A frame's positions are float32 (FRAME_ENCODING_FLOAT32) or
// `encoded` (frame_codec.js decodes both).
export function decodeDeformResponse(b) {
  const f = fields(b);
  if (f.has(1)) {
    const g = fields(one(f, 1));
    const t = g.has(7) ? fields(one(g, 7)) : new Map();
    return { frame: {
      sequence: one(g, 1, 0), clientTimestampNs: one(g, 2, 0), stiffnessVersion: one(g, 3, 0),
      skippedPoses: one(g, 4, 0), clampedAngles: one(g, 5, 0), meshUnloaded: one(g, 6, 0) === 1,
      timings: { queueMs: one(t, 1, 0), rhsMs: one(t, 2, 0), solveMs: one(t, 3, 0), encodeMs: one(t, 4, 0) },
      positions: float32s(one(g, 8)), encoded: g.has(9) ? decodeEncodedPositions(one(g, 9)) : null } };
  }
  if (f.has(2)) {
    const g = fields(one(f, 2));
    return { notice: { kind: one(g, 1, 0), sequence: one(g, 2, 0), stiffnessVersion: one(g, 3, 0),
                       message: text(one(g, 4)), factorMs: one(g, 5, 0) } };
  }
  return {};
}
export const NOTICE_KINDS = ['UNSPECIFIED', 'POSE_REJECTED', 'STIFFNESS_REJECTED', 'STIFFNESS_APPLIED'];
