// The deform.v1 messages the viewer sends and reads, encoded and decoded by the code that
// protoc-gen-es generates from proto/deform/v1/deform.proto at build time (deform/v1/deform_pb.js
// beside this file; its runtime, @bufbuild/protobuf, in vendor/protobuf/): field numbers, wire
// types and enum values have the proto as their one home, and none is written here.
//
// Decoded messages become plain objects with the proto's field names in lowerCamelCase and no
// bigint: 64-bit integers become JavaScript numbers, exact up to 2^53, which sequences and the
// page's nanosecond timestamps stay far below; bytes fields that carry little-endian arrays
// become typed arrays (copied: the field need not be aligned). Unknown fields are skipped, so
// newer servers' fields do no harm. tests/web/proto_wire_test.mjs checks every function here
// against the proto's messages.
import { create, fromBinary, toBinary } from './vendor/protobuf/index.js';
import * as pb from './deform/v1/deform_pb.js';

const encode = (schema, init) => toBinary(schema, create(schema, init));

// A generated message (or any value in it) -> the same without $typeName and bigint.
function plain(value) {
  if (typeof value === 'bigint') return Number(value);
  if (Array.isArray(value)) return value.map(plain);
  if (value === null || typeof value !== 'object' || ArrayBuffer.isView(value)) return value;
  const result = {};
  for (const [key, v] of Object.entries(value)) if (key !== '$typeName') result[key] = plain(v);
  return result;
}

// An enum's values -> their names without the enum's prefix ({4: 'FACTORISED', ...}).
const valueNames = (schema) => Object.fromEntries(schema.values.map((v) => [v.number, v.localName]));

// Little-endian arrays out of a bytes field.
const float32s = (b) => new Float32Array(b.slice().buffer);
const uint32s = (b) => new Uint32Array(b.slice().buffer);
const uint16s = (b) => new Uint16Array(b.slice().buffer);

// ---- requests ----
export function encodeGetMeshInfoRequest(meshId, includeGeometry, includePredictionWeights = false) {
  return encode(pb.GetMeshInfoRequestSchema, { meshId, includeGeometry, includePredictionWeights });
}
export function encodeListMeshesRequest() { return encode(pb.ListMeshesRequestSchema, {}); }

// LoadMeshRequest{header: LoadMeshHeader{name, phantom: PhantomSource{vertices}}}
export function encodeLoadPhantomHeader(name, vertices) {
  const header = { name, source: { case: 'phantom', value: { vertices } } };
  return encode(pb.LoadMeshRequestSchema, { part: { case: 'header', value: header } });
}

// DeformRequest{start: DeformStart{mesh_id, encoding, max_error}}; encoding: a FrameEncoding
// value; maxError 0 = the server's default.
export function encodeDeformStart(meshId, encoding = pb.FrameEncoding.FLOAT32, maxError = 0) {
  return encode(pb.DeformRequestSchema, { action: { case: 'start', value: { meshId, encoding, maxError } } });
}

// DeformRequest{pose: PoseUpdate{sequence, client_timestamp_ns, angles: [{joint, axis, degrees}]}}
export function encodeDeformPose(sequence, timestampNs, angles) {
  const pose = { sequence: BigInt(sequence), clientTimestampNs: BigInt(timestampNs), angles };
  return encode(pb.DeformRequestSchema, { action: { case: 'pose', value: pose } });
}

// DeformRequest{stiffness: StiffnessUpdate{region_weights: [{joint, weight}]}}
export function encodeRegionWeights(weights) {
  return encode(pb.DeformRequestSchema, { action: { case: 'stiffness', value: { regionWeights: weights } } });
}

// ---- responses ----
// MeshSummary: {meshId, name, vertexCount, triangleCount, joints: [{name, index, restPosition,
// dofs: [{name, axis, minDegrees, maxDegrees}], hasRegion}], ...}.
export function decodeMeshSummary(bytes) { return plain(fromBinary(pb.MeshSummarySchema, bytes)); }
export function decodeListMeshesResponse(bytes) {
  return plain(fromBinary(pb.ListMeshesResponseSchema, bytes).meshes);
}

// {summary, restPositions: Float32Array, triangles: Uint32Array, predictionWeights: {bones:
// Uint16Array (4 per vertex), weights: Float32Array (4 per vertex), numBones} or null}.
export function decodeGetMeshInfoResponse(bytes) {
  const m = fromBinary(pb.GetMeshInfoResponseSchema, bytes);
  const w = m.predictionWeights;
  return { summary: plain(m.summary ?? create(pb.MeshSummarySchema)),
           restPositions: float32s(m.restPositions), triangles: uint32s(m.triangles),
           predictionWeights: w ? { bones: uint16s(w.bones), weights: float32s(w.weights), numBones: w.numBones } : null };
}

// {stage (a LoadMeshResponse.Stage value; STAGE_NAMES names it), elapsedMs, mesh: summary or null}.
export function decodeLoadMeshResponse(bytes) {
  const m = fromBinary(pb.LoadMeshResponseSchema, bytes);
  return { stage: m.stage, elapsedMs: m.elapsedMs, mesh: m.mesh ? plain(m.mesh) : null };
}
export const STAGE_NAMES = valueNames(pb.LoadMeshResponse_StageSchema);

// EncodedPositions (FrameEncoding QUANTIZED or PREDICTED): {encoding, origin (3 numbers,
// QUANTIZED), step, maxError (model units), data (meshoptimizer's vertex codec), boneTransforms
// (Float32Array, 12 per bone, PREDICTED)}.
function encodedPositions(m) {
  return { ...plain(m), boneTransforms: new Float32Array(m.boneTransforms) };
}

// DeformResponse: {frame} or {notice}. A frame's positions are float32 (FRAME_ENCODING_FLOAT32, a
// Float32Array) or `encoded` (or null; frame_codec.js decodes both); its timings are
// {queueMs, rhsMs, solveMs, encodeMs, ...}.
export function decodeDeformResponse(bytes) {
  const { event } = fromBinary(pb.DeformResponseSchema, bytes);
  if (event.case === 'frame') {
    const f = event.value;
    return { frame: { ...plain(f), timings: plain(f.timings ?? create(pb.FrameTimingsSchema)),
                      positions: float32s(f.positions), encoded: f.encoded ? encodedPositions(f.encoded) : null } };
  }
  if (event.case === 'notice') return { notice: plain(event.value) };
  return {};
}
export const NOTICE_KINDS = valueNames(pb.Notice_KindSchema);
