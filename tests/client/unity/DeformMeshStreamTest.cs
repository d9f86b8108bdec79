// The Unity package's Unity-independent part (client/unity/Runtime: DeformAxes, DeformMeshStream)
// under Mono against the real deformd (tests/client/unity_stream_test.sh starts it and passes its
// address): the axis convention on points and on the phantom's triangles (a closed mesh keeps a
// positive signed volume, scaled by the cube of the unit), the rest geometry in Unity's frame, a
// knee flexion's frame taken on this thread from the receiver thread, root motion along deformd's
// +z arriving as Unity's -z in meters, the main thread allocating nothing while it takes frames
// and only three position buffers ever handed out, an unknown mesh refused, and Dispose.
// Usage: mono DeformMeshStreamTest.exe TARGET. Exits 0 when everything held, 1 otherwise.
using System;
using Deformd;

static class DeformMeshStreamTest {
  static void Check(bool condition, string what) {
    if (condition) return;
    Console.Error.WriteLine("unity_stream_test: check failed: " + what);
    Environment.Exit(1);
  }
  static bool Near(double a, double b, double tolerance) { return Math.Abs(a - b) <= tolerance; }

  // The signed volume of a triangle mesh (positive when its triangles wind counter-clockwise
  // seen from outside, with the right-handed cross product), 3 floats per vertex.
  static double SignedVolume(float[] p, long[] triangles) {
    double volume = 0;
    for (int t = 0; t + 2 < triangles.Length; t += 3) {
      long a = 3 * triangles[t], b = 3 * triangles[t + 1], c = 3 * triangles[t + 2];
      double cx = p[b + 1] * p[c + 2] - p[b + 2] * p[c + 1];
      double cy = p[b + 2] * p[c] - p[b] * p[c + 2];
      double cz = p[b] * p[c + 1] - p[b + 1] * p[c];
      volume += p[a] * cx + p[a + 1] * cy + p[a + 2] * cz;
    }
    return volume / 6;
  }
  static long[] Widen(uint[] t) { return Array.ConvertAll(t, i => (long)i); }
  static long[] Widen(int[] t) { return Array.ConvertAll(t, i => (long)i); }

  // Takes frames on this thread until one answers `sequence` (60 s at most).
  static Deform.FrameInfo FrameFor(DeformMeshStream stream, ulong sequence) {
    Deform.FrameInfo info = new Deform.FrameInfo();
    for (int attempt = 0; attempt < 6000; ++attempt) {
      if (stream.TryTakeFrame(out info) && info.sequence == sequence) return info;
      Check(stream.Error == null, "the receiver's poll: " + stream.Error);
      System.Threading.Thread.Sleep(10);
    }
    Check(false, "a frame answering pose " + sequence + " within 60 s");
    return info;
  }

  static void CheckAxes() {
    var y = new DeformAxes(0.1f, SourceUp.Y);
    var z = new DeformAxes(0.1f, SourceUp.Z);
    var p = new float[] {1, 2, 3, -4, 5, -6};
    var q = new float[6];
    y.ConvertPositions(p, q, 6);
    Check(Near(q[0], 0.1, 1e-6) && Near(q[1], 0.2, 1e-6) && Near(q[2], -0.3, 1e-6) &&
              Near(q[3], -0.4, 1e-6) && Near(q[4], 0.5, 1e-6) && Near(q[5], 0.6, 1e-6),
          "Y up: Unity (x, y, z) = 0.1 (x, y, -z)");
    z.ConvertPositions(p, q, 6);
    Check(Near(q[0], 0.1, 1e-6) && Near(q[1], 0.3, 1e-6) && Near(q[2], 0.2, 1e-6),
          "Z up: Unity (x, y, z) = 0.1 (x, z, y)");
    foreach (var axes in new[] {y, z}) {
      float ux, uy, uz;
      double x, yy, zz;
      axes.ToUnity(1, 2, 3, out ux, out uy, out uz);
      axes.FromUnity(ux, uy, uz, out x, out yy, out zz);
      Check(Near(x, 1, 1e-5) && Near(yy, 2, 1e-5) && Near(zz, 3, 1e-5),
            "FromUnity undoes ToUnity (" + axes.Up + " up)");
    }
    int[] flipped = DeformAxes.ConvertTriangles(new uint[] {0, 1, 2, 3, 4, 5});
    Check(flipped[0] == 0 && flipped[1] == 2 && flipped[2] == 1 && flipped[3] == 3 &&
              flipped[4] == 5 && flipped[5] == 4,
          "the winding reversed");
    bool refused = false;
    try {
      new DeformAxes(0, SourceUp.Y);
    } catch (ArgumentOutOfRangeException) {
      refused = true;
    }
    Check(refused, "0 meters per unit refused");
  }

  static int Main(string[] args) {
    string target = args[0];
    CheckAxes();

    var options = new DeformStreamOptions {
      Target = target, MetersPerUnit = 0.1f, Up = SourceUp.Y, Encoding = Deform.Encoding.Float32,
    };
    DeformMeshStream stream = DeformMeshStream.Open(options);
    int vertices = stream.VertexCount;
    Check(vertices > 1000 && stream.Triangles.Length > 3000, "the phantom's counts");

    // The rest geometry as the C API gives it, converted: the same numbers as the stream's.
    uint triangleCount;
    Check(Deform.deform_mesh_triangle_count(stream.Mesh, out triangleCount) == Deform.Status.Ok,
          "deform_mesh_triangle_count");
    var raw = new float[3 * vertices];
    var rawTriangles = new uint[3 * triangleCount];
    Check(Deform.deform_mesh_rest_geometry(stream.Mesh, raw, new UIntPtr((uint)raw.Length),
                                           rawTriangles, new UIntPtr((uint)rawTriangles.Length)) ==
              Deform.Status.Ok,
          "deform_mesh_rest_geometry");
    for (int v = 0; v < vertices; ++v) {
      Check(stream.RestPositions[3 * v] == 0.1f * raw[3 * v] &&
                stream.RestPositions[3 * v + 1] == 0.1f * raw[3 * v + 1] &&
                stream.RestPositions[3 * v + 2] == -0.1f * raw[3 * v + 2],
            "rest vertex " + v + " in Unity's frame");
      Check(stream.Positions[3 * v + 1] == stream.RestPositions[3 * v + 1],
            "Positions is the rest before the first frame");
    }
    // The phantom is closed and wound outward: converting positions and winding together keeps
    // its signed volume positive (the positions alone would turn it inside out), scaled by 0.1^3.
    double volume = SignedVolume(raw, Widen(rawTriangles));
    double unityVolume = SignedVolume(stream.RestPositions, Widen(stream.Triangles));
    Check(volume > 0, "the phantom's signed volume is positive: " + volume);
    Check(Near(unityVolume, 1e-3 * volume, 1e-6 * volume),
          "its volume in Unity's frame is 1e-3 of it: " + unityVolume + " vs " + volume);
    double reflectedOnly =
        SignedVolume(stream.RestPositions, Widen(Array.ConvertAll(rawTriangles, i => (int)i)));
    Check(reflectedOnly < 0, "without the winding's reversal the mesh would be inside out");

    // A 90-degree knee flexion, the frame taken on this thread: the hip's end stays, the
    // ankle's end swings.
    int top = 0, bottom = 0;
    float[] rest = stream.RestPositions;
    for (int v = 1; v < vertices; ++v) {
      if (rest[3 * v + 1] > rest[3 * top + 1]) top = v;
      if (rest[3 * v + 1] < rest[3 * bottom + 1]) bottom = v;
    }
    double length = rest[3 * top + 1] - rest[3 * bottom + 1];
    stream.SetJointAngle("knee", "flexion", 90);
    ulong sequence = stream.SendPose();
    Check(sequence > 0, "the pose was sent");
    Check(stream.SendPose() == 0, "an unchanged pose is not sent again");
    Deform.FrameInfo info = FrameFor(stream, sequence);
    Check(info.vertexCount == vertices, "the frame's vertex count");
    float[] bent = stream.Positions;
    Func<float[], int, double> moved = (p, v) => {
      double sum = 0;
      for (int c = 0; c < 3; ++c) {
        double d = p[3 * v + c] - rest[3 * v + c];
        sum += d * d;
      }
      return Math.Sqrt(sum);
    };
    Check(moved(bent, top) < 1e-3 * length, "the hip's end stays: " + moved(bent, top));
    Check(moved(bent, bottom) > 0.2 * length, "the ankle's end moves: " + moved(bent, bottom));

    // Root motion 10 units along deformd's +z (rest angles, the hip's rotation the identity): in
    // Unity's frame every vertex moves 1 m along -z.
    var identity = new[] {new Deform.JointRotation {joint = "hip", w = 1}};
    var shift = new[] {new Deform.RootTransform {tz = 10, qw = 1}};
    Check(Deform.deform_stream_send_pose(stream.Stream, null, UIntPtr.Zero, identity,
                                         new UIntPtr(1u), shift, out sequence) == Deform.Status.Ok,
          "root motion sent");
    FrameFor(stream, sequence);
    float[] shifted = stream.Positions;
    for (int v = 0; v < vertices; ++v) {
      Check(Near(shifted[3 * v], rest[3 * v], 1e-4) &&
                Near(shifted[3 * v + 1], rest[3 * v + 1], 1e-4) &&
                Near(shifted[3 * v + 2], rest[3 * v + 2] - 1, 1e-4),
            "root motion +10 dm along deformd's z moves vertex " + v + " 1 m along Unity's -z");
    }

    // Many frames: taking them allocates nothing on this thread, and only the three buffers are
    // ever handed out.
    var seen = new float[4][];
    int distinct = 0;
    long allocated = 0;
    int taken = 0;
    for (int step = 0; step < 200 && taken < 100; ++step) {
      stream.SetJointAngle("knee", "flexion", step % 120);
      stream.SendPose();
      for (int poll = 0; poll < 20; ++poll) {
        long before = GC.GetAllocatedBytesForCurrentThread();
        bool got = stream.TryTakeFrame(out info);
        float[] positions = stream.Positions;
        float sum = positions[0] + positions[3 * vertices - 1];
        allocated += GC.GetAllocatedBytesForCurrentThread() - before;
        if (!got) {
          System.Threading.Thread.Sleep(2);
          continue;
        }
        ++taken;
        Check(!float.IsNaN(sum), "a frame's positions");
        bool known = false;
        for (int i = 0; i < distinct; ++i) known |= ReferenceEquals(seen[i], positions);
        if (!known) {
          Check(distinct < 3, "at most three position buffers are handed out");
          seen[distinct++] = positions;
        }
        break;
      }
    }
    Check(taken >= 50, "frames taken while posing: " + taken);
    Check(allocated == 0, "taking " + taken + " frames allocated " + allocated + " bytes");
    Check(stream.Error == null && !stream.Ended, "the receiver still runs");
    long received = stream.FramesReceived;
    stream.Dispose();
    stream.Dispose();  // a second Dispose does nothing

    bool notFound = false;
    try {
      DeformMeshStream.Open(new DeformStreamOptions {Target = target, MeshId = "mesh-none"});
    } catch (DeformException e) {
      notFound = e.Status == Deform.Status.NotFound;
    }
    Check(notFound, "an unknown mesh id refused with NOT_FOUND");

    Console.WriteLine("unity_stream_test: " + vertices + " vertices, " + received +
                      " frames received, " + taken + " taken on the main thread with " +
                      allocated + " bytes allocated, " + distinct + " buffers handed out");
    return 0;
  }
}
