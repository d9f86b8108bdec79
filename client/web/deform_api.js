// deformd's HTTP port from the browser (server/service/rpc/web_server.h): the unary calls as POSTs of
// protobuf bodies, the streaming calls as WebSockets carrying one protobuf message per binary
// message, ended by the server's "status CODE MESSAGE" text message. The bearer token (optional)
// goes in the Authorization header of POSTs and as the "bearer.<base64url>" subprotocol of
// WebSockets (browsers cannot set headers on an upgrade). The paths name the RPCs as the proto's
// DeformService does (/api/ListMeshes, /ws/Deform), the names taken from the generated code.
// Clusters (docs/cluster.md): the POSTs that name a mesh send its id in the deform-mesh-key header
// and the Deform WebSocket's URL carries it as ?mesh=<id> (an upgrade cannot carry the header), so
// that a balancer in front of several servers sends all of a mesh's calls to the one holding it;
// the server ignores the query string.
import { DeformService, FrameEncoding } from './deform/v1/deform_pb.js';
import * as wire from './proto_wire.js';

const rpc = DeformService.method;

// The header the C++ and Python clients send too (client/lib/deform_client.h, kMeshKeyHeader):
// only for an id of printable ASCII without spaces, at most 128 bytes (no server has another).
export const MESH_KEY_HEADER = 'deform-mesh-key';

export function isMeshKey(meshId) {
  return typeof meshId === 'string' && meshId.length > 0 && meshId.length <= 128 && /^[\x21-\x7e]+$/.test(meshId);
}

function base64url(text) {
  const bytes = new TextEncoder().encode(text);
  let s = '';
  for (const b of bytes) s += String.fromCharCode(b);
  return btoa(s).replace(/\+/g, '-').replace(/\//g, '_').replace(/=+$/, '');
}

export class DeformApi {
  constructor(token = '') { this.token = token; }

  // POSTs one unary call's request message (bytes) to /api/<method name>, with the mesh it names
  // (if any) as MESH_KEY_HEADER; resolves with the response message's bytes.
  async call(method, body, meshId = '') {
    const headers = { 'Content-Type': 'application/x-protobuf' };
    if (this.token) headers.Authorization = `Bearer ${this.token}`;
    if (isMeshKey(meshId)) headers[MESH_KEY_HEADER] = meshId;
    const response = await fetch(`/api/${method}`, { method: 'POST', headers, body });
    const bytes = new Uint8Array(await response.arrayBuffer());
    if (!response.ok) {
      throw new Error(`${method}: ${response.status} ${new TextDecoder().decode(bytes).trim()}`);
    }
    return bytes;
  }

  async listMeshes() {
    return wire.decodeListMeshesResponse(await this.call(rpc.listMeshes.name, wire.encodeListMeshesRequest()));
  }

  // The summary, rest positions and triangles, and (by default) the prediction weights that
  // FRAME_ENCODING_PREDICTED frames are decoded with.
  async meshInfo(meshId, includePredictionWeights = true) {
    return wire.decodeGetMeshInfoResponse(
      await this.call(rpc.getMeshInfo.name, wire.encodeGetMeshInfoRequest(meshId, true, includePredictionWeights),
                      meshId));
  }

  // A WebSocket to /ws/<method> with the protocol's subprotocols; ?mesh=<id> for a call that
  // names a mesh.
  openSocket(method, meshId = '') {
    const protocols = ['deform.v1'];
    if (this.token) protocols.push(`bearer.${base64url(this.token)}`);
    const query = isMeshKey(meshId) ? `?mesh=${encodeURIComponent(meshId)}` : '';
    const socket = new WebSocket(`${location.origin.replace(/^http/, 'ws')}/ws/${method}${query}`, protocols);
    socket.binaryType = 'arraybuffer';
    return socket;
  }

  // Loads the phantom; onProgress(stage name, elapsed ms). Resolves with the mesh summary.
  loadPhantom(vertices, onProgress) {
    return new Promise((resolve, reject) => {
      const socket = this.openSocket(rpc.loadMesh.name);
      let mesh = null;
      socket.onopen = () => {
        socket.send(wire.encodeLoadPhantomHeader(`phantom ${vertices}`, vertices));
        socket.send('end');
      };
      socket.onmessage = (event) => {
        if (typeof event.data === 'string') {
          const [, code, message] = event.data.match(/^status (\d+) ?(.*)$/s) || [];
          if (code === '0' && mesh) resolve(mesh);
          else reject(new Error(`LoadMesh: status ${code}: ${message}`));
          return;
        }
        const progress = wire.decodeLoadMeshResponse(new Uint8Array(event.data));
        onProgress(wire.STAGE_NAMES[progress.stage] || String(progress.stage), progress.elapsedMs);
        if (progress.mesh) mesh = progress.mesh;
      };
      socket.onerror = () => reject(new Error('LoadMesh: the WebSocket failed'));
    });
  }
}

// One Deform stream over a WebSocket, its frames in `encoding` (a FrameEncoding value; FLOAT32 by
// default) with `maxError` (PREDICTED: a fraction of the diagonal; 0 = the server's default).
// Callbacks: onFrame(frame, byte length, the DeformResponse message's bytes), onNotice(notice),
// onEnd(code, message).
export class DeformStream {
  constructor(api, meshId, { onFrame, onNotice, onEnd, onOpen, encoding = FrameEncoding.FLOAT32, maxError = 0 }) {
    this.socket = api.openSocket(rpc.deform.name, meshId);
    this.sequence = 0;
    this.open = false;
    this.socket.onopen = () => {
      this.open = true;
      this.socket.send(wire.encodeDeformStart(meshId, encoding, maxError));
      if (onOpen) onOpen();
    };
    this.socket.onmessage = (event) => {
      if (typeof event.data === 'string') {
        const [, code, message] = event.data.match(/^status (\d+) ?(.*)$/s) || [];
        onEnd(Number(code), message);
        return;
      }
      const bytes = new Uint8Array(event.data);
      const response = wire.decodeDeformResponse(bytes);
      if (response.frame) onFrame(response.frame, event.data.byteLength, bytes);
      else if (response.notice) onNotice(response.notice);
    };
    this.socket.onclose = () => { if (this.open) { this.open = false; } };
  }

  // Sends a pose: [{joint, axis, degrees}]. Returns its sequence.
  sendPose(angles) {
    if (!this.open) return 0;
    this.sequence += 1;
    const nowNs = Math.round(performance.now() * 1e6);
    this.socket.send(wire.encodeDeformPose(this.sequence, nowNs, angles));
    return this.sequence;
  }

  sendRegionWeights(weights) { if (this.open) this.socket.send(wire.encodeRegionWeights(weights)); }

  close() { this.open = false; this.socket.close(); }
}
