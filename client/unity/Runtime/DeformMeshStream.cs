// DeformMeshStream: one stream from a deformd, with everything of the package that does not need
// UnityEngine (DeformMeshStreamer is a thin MonoBehaviour over it). It connects, loads the
// built-in phantom or opens a loaded mesh by id, reads the rest geometry in Unity's frame
// (DeformAxes), opens the stream and starts a receiver thread.
//
// Threads: Open blocks while the server precomputes (call it off the main thread). The receiver
// thread polls deform_stream_next_frame, converts each frame in place to Unity's frame and
// publishes it; the main thread takes the newest published frame with TryTakeFrame and reads
// Positions until its next TryTakeFrame. Three buffers allocated once: the receiver writes one,
// one holds the newest published frame, the main thread reads the third, so neither thread waits
// for the other beyond a swap under a lock, and nothing is allocated per frame. A frame published
// before the main thread took the previous one replaces it (latest wins, counted in
// FramesReplaced), as the C API's own polling does (FrameInfo.framesDropped).
// SetJointAngle and SendPose may be called from any one thread (the main thread in Unity): the
// C API's stream locks itself, and sending never waits for the network.
// Plain C#, no UnityEngine: compiled and run under Mono by tests/client/unity_stream_test.sh.
using System;
using System.Threading;

namespace Deformd {

// A failed deform_* call: its status and deform_last_error()'s message.
public sealed class DeformException : Exception {
  public readonly Deform.Status Status;
  public DeformException(string call, Deform.Status status, string message)
      : base(call + ": " + status + ": " + message) {
    Status = status;
  }
}

public sealed class DeformStreamOptions {
  public string Target = "127.0.0.1:50051";
  public string Token;       // bearer token, or null
  public string CaFile;      // TLS: the CA's PEM file; null with Tls = false: plaintext
  public string ServerName;  // TLS: the name the certificate holds, when not the target's host
  public bool Tls;
  // The mesh to stream: a loaded mesh's id, or null / "" for a new built-in knee phantom.
  public string MeshId;
  public int PhantomVertices;  // 0: the server's default resolution
  public Deform.Encoding Encoding = Deform.Encoding.Predicted;
  public double MaxError;  // predicted frames' bound; 0: the server's default
  // Meters per mesh unit (the phantom is in decimeters: 0.1) and the mesh's up axis.
  public float MetersPerUnit = 1;
  public SourceUp Up = SourceUp.Y;
  // How long the receiver waits in one poll: bounds how long Dispose waits for it.
  public int PollTimeoutMs = 50;
}

public sealed class DeformMeshStream : IDisposable {
  // At most this many joint angles in one pose (the server's own limit is larger).
  public const int MaxJointAngles = 32;

  public readonly DeformAxes Axes;
  public readonly string MeshId;
  public readonly int VertexCount;
  // The rest geometry in Unity's frame: 3 floats per vertex, and triangles wound for Unity.
  public readonly float[] RestPositions;
  public readonly int[] Triangles;

  // The C API's handles, for calls this class does not wrap (tools, stiffness, notices).
  public IntPtr Client { get { return client; } }
  public IntPtr Mesh { get { return mesh; } }
  public IntPtr Stream { get { return stream; } }

  // The frame last taken: 3 floats per vertex in Unity's frame, valid until the next
  // TryTakeFrame (the array is one of three reused buffers). Before the first frame: the rest.
  public float[] Positions { get { return front; } }
  public Deform.FrameInfo FrameInfo { get { return frontInfo; } }
  // Frames received, and frames published that a newer one replaced before TryTakeFrame.
  public long FramesReceived { get { return Interlocked.Read(ref framesReceived); } }
  public long FramesReplaced { get { return Interlocked.Read(ref framesReplaced); } }
  // The receiver's end: Ended after the server ended the stream; Error after a failed poll.
  public bool Ended { get { return Volatile.Read(ref ended); } }
  public string Error { get { return Volatile.Read(ref error); } }

  IntPtr client, mesh, stream;
  readonly int pollTimeoutMs;
  readonly object frameLock = new object();
  float[] back, ready, front;  // receiver's, newest published, main thread's
  Deform.FrameInfo readyInfo, frontInfo;
  bool hasReady;
  long framesReceived, framesReplaced;
  bool ended;
  string error;
  volatile bool stopping;
  Thread receiver;

  readonly Deform.JointAngle[] angles = new Deform.JointAngle[MaxJointAngles];
  int angleCount;
  bool poseChanged;

  static void Check(string call, Deform.Status status) {
    if (status != Deform.Status.Ok) throw new DeformException(call, status, Deform.LastError());
  }

  // Connects and opens the stream; throws DeformException (everything opened is freed).
  public static DeformMeshStream Open(DeformStreamOptions options) {
    var axes = new DeformAxes(options.MetersPerUnit, options.Up);
    var connect = new Deform.ConnectOptions {
      target = options.Target,   tls = options.Tls ? 1 : 0, caFile = options.CaFile,
      serverName = options.ServerName, token = options.Token,
    };
    IntPtr client = IntPtr.Zero, mesh = IntPtr.Zero, stream = IntPtr.Zero;
    try {
      Check("deform_connect", Deform.deform_connect(ref connect, out client));
      if (string.IsNullOrEmpty(options.MeshId)) {
        Check("deform_load_phantom",
              Deform.deform_load_phantom(client, options.PhantomVertices, "unity", out mesh));
      } else {
        Check("deform_mesh_open", Deform.deform_mesh_open(client, options.MeshId, out mesh));
      }
      IntPtr id;
      Check("deform_mesh_id", Deform.deform_mesh_id(mesh, out id));
      string meshId = Deform.Text(id);
      uint vertices, triangles;
      Check("deform_mesh_vertex_count", Deform.deform_mesh_vertex_count(mesh, out vertices));
      Check("deform_mesh_triangle_count", Deform.deform_mesh_triangle_count(mesh, out triangles));
      var rest = new float[3 * (long)vertices];
      var indices = new uint[3 * (long)triangles];
      Check("deform_mesh_rest_geometry",
            Deform.deform_mesh_rest_geometry(mesh, rest, new UIntPtr((ulong)rest.Length), indices,
                                             new UIntPtr((ulong)indices.Length)));
      axes.ConvertPositions(rest, rest, rest.Length);
      Check("deform_stream_open", Deform.deform_stream_open(client, meshId, options.Encoding,
                                                            options.MaxError, out stream));
      return new DeformMeshStream(axes, client, mesh, stream, meshId, rest,
                                  DeformAxes.ConvertTriangles(indices), options.PollTimeoutMs);
    } catch {
      if (stream != IntPtr.Zero) Deform.deform_stream_free(stream);
      if (mesh != IntPtr.Zero) Deform.deform_mesh_free(mesh);
      if (client != IntPtr.Zero) Deform.deform_client_free(client);
      throw;
    }
  }

  DeformMeshStream(DeformAxes axes, IntPtr client, IntPtr mesh, IntPtr stream, string meshId,
                   float[] rest, int[] triangles, int pollTimeoutMs) {
    Axes = axes;
    this.client = client;
    this.mesh = mesh;
    this.stream = stream;
    MeshId = meshId;
    VertexCount = rest.Length / 3;
    RestPositions = rest;
    Triangles = triangles;
    this.pollTimeoutMs = pollTimeoutMs > 0 ? pollTimeoutMs : 50;
    back = new float[rest.Length];
    ready = new float[rest.Length];
    front = (float[])rest.Clone();
    receiver = new Thread(Receive) { IsBackground = true, Name = "deformd frames" };
    receiver.Start();
  }

  // Sets one degree of freedom of the next pose ("knee", "flexion", 90): a joint's name (or its
  // index in decimal) and one of its degrees of freedom (or "x", "y", "z", rest-frame axes).
  // Joints set once stay in the pose until ClearPose. Allocates nothing for a joint already set.
  public void SetJointAngle(string joint, string axis, double degrees) {
    for (int i = 0; i < angleCount; ++i) {
      if (angles[i].joint == joint && angles[i].axis == axis) {
        if (angles[i].degrees != degrees) {
          angles[i].degrees = degrees;
          poseChanged = true;
        }
        return;
      }
    }
    if (angleCount == MaxJointAngles)
      throw new InvalidOperationException("at most " + MaxJointAngles + " joint angles");
    angles[angleCount++] = new Deform.JointAngle { joint = joint, axis = axis, degrees = degrees };
    poseChanged = true;
  }

  // Every joint back to its rest angle at the next SendPose.
  public void ClearPose() {
    angleCount = 0;
    poseChanged = true;
  }

  // Sends the pose if it changed since the last send: returns its sequence (FrameInfo.sequence
  // of the frame that answers it), or 0 when nothing changed. Throws DeformException.
  public ulong SendPose() {
    if (!poseChanged) return 0;
    ulong sequence;
    Check("deform_stream_send_pose",
          Deform.deform_stream_send_pose(stream, angles, new UIntPtr((uint)angleCount), null,
                                         UIntPtr.Zero, null, out sequence));
    poseChanged = false;
    return sequence;
  }

  // Takes the newest frame published since the last call: true and Positions / FrameInfo are
  // it, or false and they stay the previous one. Allocates nothing.
  public bool TryTakeFrame(out Deform.FrameInfo info) {
    lock (frameLock) {
      if (!hasReady) {
        info = frontInfo;
        return false;
      }
      float[] taken = ready;
      ready = front;
      front = taken;
      frontInfo = readyInfo;
      hasReady = false;
    }
    info = frontInfo;
    return true;
  }

  void Receive() {
    var capacity = new UIntPtr((ulong)back.Length);
    while (!stopping) {
      Deform.FrameInfo info;
      Deform.Status status =
          Deform.deform_stream_next_frame(stream, back, capacity, pollTimeoutMs, out info);
      if (status == Deform.Status.NoData) continue;
      if (status == Deform.Status.StreamEnded) {
        Volatile.Write(ref ended, true);
        return;
      }
      if (status != Deform.Status.Ok) {
        Volatile.Write(ref error,
                       "deform_stream_next_frame: " + status + ": " + Deform.LastError());
        return;
      }
      Axes.ConvertPositions(back, back, back.Length);
      lock (frameLock) {
        float[] published = back;
        back = ready;
        ready = published;
        readyInfo = info;
        if (hasReady) Interlocked.Increment(ref framesReplaced);
        hasReady = true;
      }
      Interlocked.Increment(ref framesReceived);
    }
  }

  // Stops the receiver, ends the stream (waiting up to closeTimeoutMs for the server) and frees
  // the handles. Safe to call twice.
  public void Dispose() { Close(1000); }

  public void Close(int closeTimeoutMs) {
    if (stream == IntPtr.Zero) return;
    stopping = true;
    receiver.Join();
    Deform.deform_stream_close(stream, closeTimeoutMs);
    Deform.deform_stream_free(stream);
    Deform.deform_mesh_free(mesh);
    Deform.deform_client_free(client);
    stream = mesh = client = IntPtr.Zero;
  }
}

}  // namespace Deformd
