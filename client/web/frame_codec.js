// Decoders of deformd's frame encodings in the browser (proto/deform/v1/deform.proto is the
// specification; server/core/codec/ and client/python/deform_client/codec.py decode the same way).
// Every decoder returns the frame's positions as a Float32Array of 3 * V values (x, y, z per
// vertex, the mesh's own vertex order, model units):
//
// - FLOAT32: DeformFrame.positions, little-endian float32 x, y, z per vertex.
// - QUANTIZED: meshoptimizer's vertex codec over 8-byte records (uint16 a, b, c, 0) per vertex;
//   coordinate k = float32(origin[k] + a_k * step), computed in double (JavaScript's numbers).
// - PREDICTED: the same records holding zigzag-coded residuals r; coordinate k =
//   float32(p_k + r * step), computed in double, where p is the four-bone linear blend skinning
//   prediction computed in float32 operation by operation in the proto's order (predictPositions):
//   Math.fround after every product and sum, Float32Array storage. A product or sum of two float32
//   values computed in double and then rounded to float32 is the correctly rounded float32 result
//   (53 >= 2 * 24 + 2 bits), and JavaScript never fuses a multiply and an add, so the prediction
//   is bit for bit the server's, and each decoded coordinate is within the frame's max_error
//   (step / 2) of the server's solution plus the float32 rounding of the result.
//
// meshoptimizer's decoder is the npm package `meshoptimizer` (WebAssembly), served from the static
// root as vendor/meshopt_decoder.mjs; await frameCodecReady() before the first decode. Decoders
// throw an Error naming what is wrong for a frame that does not decode (wrong size, bad bytes, a
// non-positive step, the wrong number of bone transforms). A FrameDecoder keeps no state between
// frames (a skipped frame costs nothing); its arrays are read-only after construction.
import { MeshoptDecoder } from './vendor/meshopt_decoder.mjs';
import { FrameEncoding, FrameEncodingSchema } from './deform/v1/deform_pb.js';

// The FrameEncoding values decoded here (the proto's, from the generated code), each named by its
// enum value's name in lower case ('float32', 'quantized', 'predicted').
export const FLOAT32 = FrameEncoding.FLOAT32;
export const QUANTIZED = FrameEncoding.QUANTIZED;
export const PREDICTED = FrameEncoding.PREDICTED;
export const ENCODING_NAMES = Object.fromEntries(
  [FLOAT32, QUANTIZED, PREDICTED].map((value) => [value, FrameEncodingSchema.value[value].localName.toLowerCase()]));
export const BONES_PER_VERTEX = 4;
export const FLOATS_PER_BONE_TRANSFORM = 12;
const RECORD_BYTES = 8;  // uint16 a, b, c, 0

const littleEndian = new Uint8Array(new Uint16Array([1]).buffer)[0] === 1;

// Resolves once meshoptimizer's WebAssembly decoder is compiled.
export async function frameCodecReady() {
  if (!littleEndian) throw new Error('frame decoding needs a little-endian host');
  if (!MeshoptDecoder.supported) throw new Error('this browser cannot run meshoptimizer\'s WebAssembly decoder');
  await MeshoptDecoder.ready;
}

// 'float32' | 'quantized' | 'predicted' (or the enum value) -> the FrameEncoding value.
export function encodingFromName(encoding) {
  if (ENCODING_NAMES[encoding]) return Number(encoding);
  for (const [value, name] of Object.entries(ENCODING_NAMES)) {
    if (typeof encoding === 'string' && encoding.toLowerCase() === name) return Number(value);
  }
  throw new Error(`unknown frame encoding ${JSON.stringify(encoding)} (float32, quantized or predicted)`);
}

// Little-endian float32 x, y, z bytes (a Float32Array already read from them) -> a copy.
export function decodeFloat32(positions, vertexCount) {
  if (positions.length !== 3 * vertexCount) {
    throw new Error(`a float32 frame of ${4 * positions.length} bytes; ${vertexCount} vertices need ${12 * vertexCount}`);
  }
  return new Float32Array(positions);
}

// meshoptimizer's vertex codec -> 4 uint16 per vertex.
export function decodeRecords(data, vertexCount) {
  const records = new Uint16Array(4 * vertexCount);
  try {
    MeshoptDecoder.decodeVertexBuffer(new Uint8Array(records.buffer), vertexCount, RECORD_BYTES, data);
  } catch (error) {
    throw new Error(`encoded frame's bytes do not decode to ${vertexCount} vertices (${error.message})`);
  }
  return records;
}

// The proto's prediction: rest (Float32Array 3V), bones (Uint16Array 4V), weights (Float32Array
// 4V), transforms (Float32Array 12B, rows [R | t] row-major) -> predicted (Float32Array 3V).
export function predictPositions(rest, bones, weights, transforms, predicted) {
  const f = Math.fround;
  const n = rest.length / 3;
  for (let i = 0; i < n; ++i) {
    const vx = rest[3 * i], vy = rest[3 * i + 1], vz = rest[3 * i + 2];
    let p0 = 0, p1 = 0, p2 = 0;
    for (let j = 0; j < BONES_PER_VERTEX; ++j) {
      const slot = BONES_PER_VERTEX * i + j;
      const w = weights[slot];
      const m = FLOATS_PER_BONE_TRANSFORM * bones[slot];
      let s = f(transforms[m] * vx);
      s = f(s + f(transforms[m + 1] * vy));
      s = f(s + f(transforms[m + 2] * vz));
      s = f(s + transforms[m + 3]);
      p0 = f(p0 + f(w * s));
      s = f(transforms[m + 4] * vx);
      s = f(s + f(transforms[m + 5] * vy));
      s = f(s + f(transforms[m + 6] * vz));
      s = f(s + transforms[m + 7]);
      p1 = f(p1 + f(w * s));
      s = f(transforms[m + 8] * vx);
      s = f(s + f(transforms[m + 9] * vy));
      s = f(s + f(transforms[m + 10] * vz));
      s = f(s + transforms[m + 11]);
      p2 = f(p2 + f(w * s));
    }
    predicted[3 * i] = p0;
    predicted[3 * i + 1] = p1;
    predicted[3 * i + 2] = p2;
  }
  return predicted;
}

// Decodes one mesh's frames, any encoding. vertexCount: MeshSummary.vertex_count. For PREDICTED
// frames also restPositions (GetMeshInfoResponse.rest_positions as a Float32Array) and
// predictionWeights ({bones: Uint16Array, weights: Float32Array, numBones}, from
// GetMeshInfoRequest.include_prediction_weights); throws when their sizes do not match vertexCount
// or a weight names a bone out of range or is negative or not finite.
export class FrameDecoder {
  constructor(vertexCount, restPositions = null, predictionWeights = null) {
    this.vertexCount = vertexCount;
    this.rest = null;
    if (!predictionWeights) return;
    const n = vertexCount, slots = BONES_PER_VERTEX * vertexCount;
    if (!restPositions || restPositions.length !== 3 * n || predictionWeights.bones.length !== slots
        || predictionWeights.weights.length !== slots) {
      throw new Error(`prediction weights or rest positions do not match ${n} vertices`);
    }
    const { bones, weights, numBones } = predictionWeights;
    for (let s = 0; s < slots; ++s) {
      if (bones[s] >= numBones || !Number.isFinite(weights[s]) || weights[s] < 0) {
        throw new Error('prediction weights name a bone out of range or are negative');
      }
    }
    this.rest = new Float32Array(restPositions);
    this.bones = new Uint16Array(bones);
    this.weights = new Float32Array(weights);
    this.numBones = numBones;
    this.predicted = new Float32Array(3 * n);
  }

  get canPredict() { return this.rest !== null; }

  // A decoded DeformFrame (proto_wire.js: {positions, encoded}) -> Float32Array positions.
  decode(frame) {
    if (!frame.encoded) return decodeFloat32(frame.positions, this.vertexCount);
    return this.decodeEncoded(frame.encoded);
  }

  // An EncodedPositions ({encoding, origin, step, maxError, data, boneTransforms}) -> positions.
  decodeEncoded(encoded) {
    const { step } = encoded;
    if (!Number.isFinite(step) || step <= 0) throw new Error('encoded frame\'s step must be positive and finite');
    const n = this.vertexCount;
    const f = Math.fround;
    if (encoded.encoding === QUANTIZED) {
      if (encoded.origin.length !== 3) throw new Error('a quantized frame without its box origin');
      const records = decodeRecords(encoded.data, n);
      const [ox, oy, oz] = encoded.origin;
      const positions = new Float32Array(3 * n);
      for (let c = 0; c < n; ++c) {
        positions[3 * c] = f(ox + records[4 * c] * step);
        positions[3 * c + 1] = f(oy + records[4 * c + 1] * step);
        positions[3 * c + 2] = f(oz + records[4 * c + 2] * step);
      }
      return positions;
    }
    if (encoded.encoding === PREDICTED) {
      if (!this.canPredict) throw new Error('a predicted frame needs the mesh\'s prediction weights');
      const expected = FLOATS_PER_BONE_TRANSFORM * this.numBones;
      if (encoded.boneTransforms.length !== expected) {
        throw new Error(`a predicted frame needs ${expected} transform floats, got ${encoded.boneTransforms.length}`);
      }
      const records = decodeRecords(encoded.data, n);
      const p = predictPositions(this.rest, this.bones, this.weights, encoded.boneTransforms, this.predicted);
      const positions = new Float32Array(3 * n);
      for (let k = 0; k < 3 * n; ++k) {
        const a = records[4 * (k / 3 | 0) + k % 3];
        positions[k] = f(p[k] + ((a >>> 1) ^ -(a & 1)) * step);
      }
      return positions;
    }
    throw new Error(`a frame in an unknown encoding (${encoded.encoding})`);
  }
}
