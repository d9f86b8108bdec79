// The viewer's protobuf layer against the proto, without a browser or a server: every message that
// client/web/proto_wire.js encodes is decoded by the code generated from deform.proto and compared
// with the message it should be, every message it decodes is built from its proto JSON form
// first, the frame encodings frame_codec.js names are the proto's values, and deform_api.js calls
// each RPC at the HTTP port's path with the right message.
// Expectations are written in the proto's JSON form and parsed by the generated code, which
// refuses a field name the proto does not have; a field the JavaScript names wrongly (or the
// proto no longer has) fails here by name.
//
//   node tests/web/proto_wire_test.mjs --web-root build/server/deformd/web
//
// The web root is the served directory the build assembles (the viewer's files, the generated
// deform/v1/deform_pb.js and its runtime in vendor/). Node's test runner reports each case.
import assert from 'node:assert/strict';
import path from 'node:path';
import { test } from 'node:test';
import { pathToFileURL } from 'node:url';

const argv = process.argv.slice(2);
const at = argv.indexOf('--web-root');
const root = path.resolve(at >= 0 ? argv[at + 1] : 'build/server/deformd/web');
async function load(file) {
  try {
    return await import(pathToFileURL(path.join(root, file)).href);
  } catch (error) {
    console.error(`proto_wire_test: ${file} does not load from ${root} (build deformd_web_files after ` +
                  `scripts/install-node-tools.sh): ${error.message}`);
    process.exit(1);
  }
}

const { equals, fromBinary, fromJson, toBinary, toJson } = await load('vendor/protobuf/index.js');
const pb = await load('deform/v1/deform_pb.js');
const wire = await load('proto_wire.js');
const codec = await load('frame_codec.js');

// bytes (as proto_wire.js produced them) decode to the message whose proto JSON form is `json`.
function assertEncodes(schema, bytes, json) {
  const actual = fromBinary(schema, bytes);
  const expected = fromJson(schema, json);
  assert.ok(equals(schema, actual, expected),
            `${schema.typeName}: encoded ${JSON.stringify(toJson(schema, actual))}, ` +
            `the proto's message is ${JSON.stringify(toJson(schema, expected))}`);
}
// The binary form of the message whose proto JSON form is `json`.
const binary = (schema, json) => toBinary(schema, fromJson(schema, json));
const base64 = (typed) => Buffer.from(typed.buffer, typed.byteOffset, typed.byteLength).toString('base64');

test('requests encode as the proto\'s messages', () => {
  assertEncodes(pb.GetMeshInfoRequestSchema, wire.encodeGetMeshInfoRequest('m1', true, true),
                { meshId: 'm1', includeGeometry: true, includePredictionWeights: true });
  assertEncodes(pb.GetMeshInfoRequestSchema, wire.encodeGetMeshInfoRequest('m1', false), { meshId: 'm1' });
  assertEncodes(pb.ListMeshesRequestSchema, wire.encodeListMeshesRequest(), {});
  assertEncodes(pb.LoadMeshRequestSchema, wire.encodeLoadPhantomHeader('phantom 2000', 2000),
                { header: { name: 'phantom 2000', phantom: { vertices: 2000 } } });
  assertEncodes(pb.DeformRequestSchema, wire.encodeDeformStart('m1', codec.QUANTIZED, 0.25),
                { start: { meshId: 'm1', encoding: 'FRAME_ENCODING_QUANTIZED', maxError: 0.25 } });
  assertEncodes(pb.DeformRequestSchema, wire.encodeDeformStart('m1'),
                { start: { meshId: 'm1', encoding: 'FRAME_ENCODING_FLOAT32' } });
  assertEncodes(pb.DeformRequestSchema,
                wire.encodeDeformPose(7, 1234567890123456, [{ joint: 'knee', axis: 'flex', degrees: -30.5 }]),
                { pose: { sequence: '7', clientTimestampNs: '1234567890123456',
                          angles: [{ joint: 'knee', axis: 'flex', degrees: -30.5 }] } });
  assertEncodes(pb.DeformRequestSchema, wire.encodeRegionWeights([{ joint: 'knee', weight: 2.5 }]),
                { stiffness: { regionWeights: [{ joint: 'knee', weight: 2.5 }] } });
});

const summaryJson = {
  meshId: 'm1', name: 'phantom', vertexCount: 3, triangleCount: 1, factorBytes: '4096',
  joints: [{ name: 'knee', index: 1, restPosition: [0, 0.5, 0], hasRegion: true,
             dofs: [{ name: 'flex', axis: [1, 0, 0], minDegrees: -10, maxDegrees: 120 }] }],
};
const summary = {
  meshId: 'm1', name: 'phantom', vertexCount: 3, triangleCount: 1, factorBytes: 4096,
  joints: [{ name: 'knee', index: 1, restPosition: [0, 0.5, 0], hasRegion: true,
             dofs: [{ name: 'flex', axis: [1, 0, 0], minDegrees: -10, maxDegrees: 120 }] }],
};
// The decoded summary holds the fields above (and the proto's others at their defaults).
function assertSummary(actual) {
  for (const [key, value] of Object.entries(summary)) assert.deepEqual(actual[key], value, `MeshSummary.${key}`);
}

test('mesh listings and mesh info decode', () => {
  const list = wire.decodeListMeshesResponse(binary(pb.ListMeshesResponseSchema, { meshes: [summaryJson] }));
  assert.equal(list.length, 1);
  assertSummary(list[0]);
  assertSummary(wire.decodeMeshSummary(binary(pb.MeshSummarySchema, summaryJson)));

  const rest = new Float32Array([0, 1, 2, 3, 4, 5, 6, 7, 8]);
  const triangles = new Uint32Array([0, 1, 2]);
  const bones = new Uint16Array([0, 1, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0]);
  const weights = new Float32Array([0.75, 0.25, 0, 0, 1, 0, 0, 0, 0.5, 0.5, 0, 0]);
  const info = wire.decodeGetMeshInfoResponse(binary(pb.GetMeshInfoResponseSchema, {
    summary: summaryJson, restPositions: base64(rest), triangles: base64(triangles),
    predictionWeights: { bones: base64(bones), weights: base64(weights), numBones: 2 },
  }));
  assertSummary(info.summary);
  assert.deepEqual(info.restPositions, rest, 'GetMeshInfoResponse.rest_positions');
  assert.deepEqual(info.triangles, triangles, 'GetMeshInfoResponse.triangles');
  assert.deepEqual(info.predictionWeights, { bones, weights, numBones: 2 }, 'GetMeshInfoResponse.prediction_weights');
  const bare = wire.decodeGetMeshInfoResponse(binary(pb.GetMeshInfoResponseSchema, { summary: summaryJson }));
  assert.equal(bare.predictionWeights, null, 'GetMeshInfoResponse.prediction_weights unset');
  assert.equal(bare.restPositions.length, 0, 'GetMeshInfoResponse.rest_positions empty');
});

test('the LoadMesh stream\'s progress decodes and its stages are named', () => {
  const ready = wire.decodeLoadMeshResponse(binary(pb.LoadMeshResponseSchema,
                                                   { stage: 'STAGE_READY', elapsedMs: 12.5, mesh: summaryJson }));
  assert.equal(wire.STAGE_NAMES[ready.stage], 'READY', 'LoadMeshResponse.stage');
  assert.equal(ready.elapsedMs, 12.5, 'LoadMeshResponse.elapsed_ms');
  assertSummary(ready.mesh);
  const received = wire.decodeLoadMeshResponse(binary(pb.LoadMeshResponseSchema, { stage: 'STAGE_RECEIVED' }));
  assert.equal(wire.STAGE_NAMES[received.stage], 'RECEIVED', 'LoadMeshResponse.stage');
  assert.equal(received.mesh, null, 'LoadMeshResponse.mesh unset');
});

test('frames and notices decode', () => {
  const positions = new Float32Array([1.5, -2, 3, 4, 5, 6, 7, 8, 9]);
  const float32 = wire.decodeDeformResponse(binary(pb.DeformResponseSchema, { frame: {
    sequence: '9', clientTimestampNs: '1234567890123456', stiffnessVersion: '2', skippedPoses: '1',
    clampedAngles: 3, meshUnloaded: true, positions: base64(positions),
    timings: { queueMs: 0.5, rhsMs: 0.25, solveMs: 1.5, encodeMs: 0.125 },
  } })).frame;
  assert.deepEqual(
    { sequence: float32.sequence, clientTimestampNs: float32.clientTimestampNs, stiffnessVersion: float32.stiffnessVersion,
      skippedPoses: float32.skippedPoses, clampedAngles: float32.clampedAngles, meshUnloaded: float32.meshUnloaded },
    { sequence: 9, clientTimestampNs: 1234567890123456, stiffnessVersion: 2, skippedPoses: 1, clampedAngles: 3, meshUnloaded: true },
    'DeformFrame');
  assert.deepEqual(float32.positions, positions, 'DeformFrame.positions');
  assert.equal(float32.encoded, null, 'DeformFrame.encoded unset');
  for (const [key, value] of Object.entries({ queueMs: 0.5, rhsMs: 0.25, solveMs: 1.5, encodeMs: 0.125 })) {
    assert.equal(float32.timings[key], value, `FrameTimings.${key}`);
  }

  const data = new Uint8Array([1, 2, 3]);
  const predicted = wire.decodeDeformResponse(binary(pb.DeformResponseSchema, { frame: {
    sequence: '10', encoded: { encoding: 'FRAME_ENCODING_PREDICTED', origin: [1, 2, 3], step: 0.5, maxError: 0.25,
                               data: base64(data), boneTransforms: [1, 0, 0, 0.5, 0, 1, 0, 0, 0, 0, 1, 0] } } })).frame;
  const { encoded } = predicted;
  assert.equal(encoded.encoding, codec.PREDICTED, 'EncodedPositions.encoding');
  assert.deepEqual({ origin: encoded.origin, step: encoded.step, maxError: encoded.maxError, data: encoded.data },
                   { origin: [1, 2, 3], step: 0.5, maxError: 0.25, data }, 'EncodedPositions');
  assert.deepEqual(encoded.boneTransforms, new Float32Array([1, 0, 0, 0.5, 0, 1, 0, 0, 0, 0, 1, 0]),
                   'EncodedPositions.bone_transforms');
  assert.equal(predicted.timings.solveMs, 0, 'DeformFrame.timings unset: zeros');

  const { notice } = wire.decodeDeformResponse(binary(pb.DeformResponseSchema, { notice: {
    kind: 'KIND_STIFFNESS_APPLIED', sequence: '4', stiffnessVersion: '5', message: 'applied', factorMs: 3.5 } }));
  assert.deepEqual({ ...notice, kind: wire.NOTICE_KINDS[notice.kind] },
                   { kind: 'STIFFNESS_APPLIED', sequence: 4, stiffnessVersion: 5, message: 'applied', factorMs: 3.5 }, 'Notice');
  assert.deepEqual(wire.decodeDeformResponse(new Uint8Array(0)), {});
});

test('the frame encodings the viewer names are the proto\'s', () => {
  const named = Object.fromEntries(pb.FrameEncodingSchema.values.map((v) => [v.name, v.number]));
  assert.deepEqual({ FRAME_ENCODING_FLOAT32: codec.FLOAT32, FRAME_ENCODING_QUANTIZED: codec.QUANTIZED,
                     FRAME_ENCODING_PREDICTED: codec.PREDICTED },
                   { FRAME_ENCODING_FLOAT32: named.FRAME_ENCODING_FLOAT32,
                     FRAME_ENCODING_QUANTIZED: named.FRAME_ENCODING_QUANTIZED,
                     FRAME_ENCODING_PREDICTED: named.FRAME_ENCODING_PREDICTED });
  assert.deepEqual(codec.ENCODING_NAMES, { [codec.FLOAT32]: 'float32', [codec.QUANTIZED]: 'quantized', [codec.PREDICTED]: 'predicted' });
  for (const name of ['float32', 'quantized', 'predicted']) assert.equal(codec.ENCODING_NAMES[codec.encodingFromName(name)], name);
});

// deform_api.js with fetch and WebSocket stubbed: each call goes to the HTTP port's path for the
// proto's RPC (server/service/rpc/web_server.h) with the request message proto_wire.js encodes.
test('the page calls the proto\'s RPCs at the HTTP port\'s paths', async () => {
  const posts = [], sockets = [];
  globalThis.location = { origin: 'http://127.0.0.1:8080' };
  globalThis.fetch = async (url, init) => {
    posts.push({ url, body: init.body, headers: init.headers });
    const body = url === '/api/ListMeshes' ? binary(pb.ListMeshesResponseSchema, { meshes: [summaryJson] })
      : binary(pb.GetMeshInfoResponseSchema, { summary: summaryJson });
    return { ok: true, arrayBuffer: async () => body.slice().buffer };
  };
  globalThis.WebSocket = class {
    constructor(url, protocols) { this.url = url; this.protocols = protocols; this.sent = []; sockets.push(this); }
    send(message) { this.sent.push(message); }
    close() {}
  };
  const { DeformApi, DeformStream, MESH_KEY_HEADER, isMeshKey } = await load('deform_api.js');
  const api = new DeformApi();
  assertSummary((await api.listMeshes())[0]);
  assertSummary((await api.meshInfo('m1')).summary);
  assert.deepEqual(posts.map((p) => p.url), ['/api/ListMeshes', '/api/GetMeshInfo']);
  // The mesh's key for a balancer (docs/cluster.md): on the POST naming it, not on the listing.
  assert.equal(MESH_KEY_HEADER, 'deform-mesh-key');
  assert.equal(posts[0].headers[MESH_KEY_HEADER], undefined);
  assert.equal(posts[1].headers[MESH_KEY_HEADER], 'm1');
  assertEncodes(pb.GetMeshInfoRequestSchema, posts[1].body,
                { meshId: 'm1', includeGeometry: true, includePredictionWeights: true });

  api.loadPhantom(2000, () => {}).catch(() => {});
  const stream = new DeformStream(api, 'm1', { encoding: codec.PREDICTED, onFrame() {}, onNotice() {}, onEnd() {} });
  assert.deepEqual(sockets.map((s) => s.url), ['ws://127.0.0.1:8080/ws/LoadMesh', 'ws://127.0.0.1:8080/ws/Deform?mesh=m1']);
  sockets[0].onopen();
  assertEncodes(pb.LoadMeshRequestSchema, sockets[0].sent[0], { header: { name: 'phantom 2000', phantom: { vertices: 2000 } } });
  sockets[1].onopen();
  assertEncodes(pb.DeformRequestSchema, sockets[1].sent[0], { start: { meshId: 'm1', encoding: 'FRAME_ENCODING_PREDICTED' } });
  stream.close();

  // The id in the URL is encoded as a query value; an id no server has (not printable ASCII, or
  // over 128 bytes) is sent neither in the URL nor as the header, as the other clients do.
  new DeformStream(api, 'a&b=c/d#e+f', { onFrame() {}, onNotice() {}, onEnd() {} }).close();
  assert.equal(sockets[2].url, 'ws://127.0.0.1:8080/ws/Deform?mesh=a%26b%3Dc%2Fd%23e%2Bf');
  for (const id of ['two words', 'é', 'x'.repeat(129), '']) {
    assert.equal(isMeshKey(id), false, id);
    new DeformStream(api, id, { onFrame() {}, onNotice() {}, onEnd() {} }).close();
    assert.equal(sockets.at(-1).url, 'ws://127.0.0.1:8080/ws/Deform');
    await api.meshInfo(id);
    assert.equal(posts.at(-1).headers[MESH_KEY_HEADER], undefined);
  }
  assert.equal(isMeshKey('x'.repeat(128)), true);
});
