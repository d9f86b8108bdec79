// DeformMeshStreamer: streams a deformd mesh into this GameObject's MeshFilter. A thin
// MonoBehaviour over DeformMeshStream (which holds the stream, the receiver thread, the frame
// buffers and the axis convention): it opens the stream off the main thread, builds the Mesh from
// the rest geometry, sends the inspector's joint angles when they change, and writes each new
// frame's vertices into the Mesh in Update (the main thread), into a Vector3[] allocated once.
// Needs UnityEngine: compiled by Unity only (the tests compile and run DeformMeshStream).
using System;
using System.Threading.Tasks;
using UnityEngine;
using UnityEngine.Rendering;

namespace Deformd {

[RequireComponent(typeof(MeshFilter))]
[AddComponentMenu("Deformd/Deform Mesh Streamer")]
public sealed class DeformMeshStreamer : MonoBehaviour {
  [Serializable]
  public sealed class JointAngleSetting {
    public string joint = "knee";
    public string axis = "flexion";
    [Range(-180, 180)] public float degrees;
  }

  [Header("Server")]
  public string target = "127.0.0.1:50051";
  [Tooltip("Bearer token (deformd --token-file); empty: none")]
  public string token = "";
  [Tooltip("TLS: the CA's PEM file; empty: plaintext (loopback servers only)")]
  public string caFile = "";
  public string serverName = "";

  [Header("Mesh")]
  [Tooltip("A loaded mesh's id; empty: a new built-in knee phantom")]
  public string meshId = "";
  public int phantomVertices = 0;
  public Deform.Encoding encoding = Deform.Encoding.Predicted;
  [Tooltip("Meters per mesh unit: 0.1 for the phantom (decimeters), 0.001 for millimeters")]
  public float metersPerUnit = 0.1f;
  public SourceUp sourceUp = SourceUp.Y;

  [Header("Pose")]
  public JointAngleSetting[] jointAngles = { new JointAngleSetting() };

  // The stream once open (null before and after), and its last frame's report.
  public DeformMeshStream Stream { get { return stream; } }
  public Deform.FrameInfo LastFrame { get; private set; }

  Task<DeformMeshStream> opening;
  DeformMeshStream stream;
  Mesh mesh;
  Vector3[] vertices;

  // Sets a joint angle from code (an inspector entry for it is added if missing).
  public void SetJointAngle(string joint, string axis, float degrees) {
    foreach (var setting in jointAngles) {
      if (setting.joint == joint && setting.axis == axis) {
        setting.degrees = degrees;
        return;
      }
    }
    var grown = new JointAngleSetting[jointAngles.Length + 1];
    Array.Copy(jointAngles, grown, jointAngles.Length);
    grown[jointAngles.Length] =
        new JointAngleSetting { joint = joint, axis = axis, degrees = degrees };
    jointAngles = grown;
  }

  void OnEnable() {
    var options = new DeformStreamOptions {
      Target = target,
      Token = string.IsNullOrEmpty(token) ? null : token,
      Tls = !string.IsNullOrEmpty(caFile),
      CaFile = string.IsNullOrEmpty(caFile) ? null : caFile,
      ServerName = string.IsNullOrEmpty(serverName) ? null : serverName,
      MeshId = meshId,
      PhantomVertices = phantomVertices,
      Encoding = encoding,
      MetersPerUnit = metersPerUnit,
      Up = sourceUp,
    };
    // Loading blocks while the server precomputes: never on the main thread.
    opening = Task.Run(() => DeformMeshStream.Open(options));
  }

  void Update() {
    if (stream == null && !FinishOpening()) return;
    foreach (var setting in jointAngles) {
      stream.SetJointAngle(setting.joint, setting.axis, setting.degrees);
    }
    stream.SendPose();
    Deform.FrameInfo info;
    if (!stream.TryTakeFrame(out info)) {
      if (stream.Error != null) {
        Debug.LogError("DeformMeshStreamer: " + stream.Error, this);
        enabled = false;
      }
      return;
    }
    LastFrame = info;
    float[] positions = stream.Positions;
    for (int v = 0; v < vertices.Length; ++v) {
      vertices[v].Set(positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]);
    }
    mesh.SetVertices(vertices);
    mesh.RecalculateNormals();
    mesh.RecalculateBounds();
  }

  // True once the stream is open and the Mesh built from its rest geometry.
  bool FinishOpening() {
    if (opening == null || !opening.IsCompleted) return false;
    Task<DeformMeshStream> done = opening;
    opening = null;
    if (done.IsFaulted) {
      Debug.LogError("DeformMeshStreamer: " + done.Exception.GetBaseException().Message, this);
      enabled = false;
      return false;
    }
    stream = done.Result;
    vertices = new Vector3[stream.VertexCount];
    float[] rest = stream.RestPositions;
    for (int v = 0; v < vertices.Length; ++v) {
      vertices[v] = new Vector3(rest[3 * v], rest[3 * v + 1], rest[3 * v + 2]);
    }
    mesh = new Mesh { name = "deformd " + stream.MeshId };
    mesh.indexFormat = vertices.Length > 65535 ? IndexFormat.UInt32 : IndexFormat.UInt16;
    mesh.MarkDynamic();
    mesh.SetVertices(vertices);
    mesh.SetTriangles(stream.Triangles, 0);
    mesh.RecalculateNormals();
    GetComponent<MeshFilter>().sharedMesh = mesh;
    return true;
  }

  void OnDisable() {
    if (opening != null) {
      // Still loading: close the stream when it opens.
      opening.ContinueWith(t => {
        if (t.Status == TaskStatus.RanToCompletion) t.Result.Dispose();
      });
      opening = null;
    }
    if (stream != null) {
      stream.Dispose();
      stream = null;
    }
    if (mesh != null) {
      Destroy(mesh);
      mesh = null;
    }
  }
}

}  // namespace Deformd
