// Deform.cs: the C API (client/c/deform_c.h) for C# through P/Invoke: Unity (libdeform_c.so in
// Assets/Plugins), Mono or .NET on Linux. Every deform_* function of the header, under its own
// name, and every struct with the header's layout (LayoutKind.Sequential; the sizes are checked
// against the C compiler's by tests/client/csharp_binding_test.sh). The header states the
// contract (errors, ownership, threads, units); in short:
//   - Functions return a Deform.Status; after each call, Deform.LastError() is that call's message.
//   - Handles are IntPtr, freed exactly once by the matching deform_*_free.
//   - Strings the library returns (const char*) are IntPtr owned by the library: read them with
//     Deform.Text(ptr). Strings passed in are copied by the library before the call returns.
//   - size_t is UIntPtr; a C pointer that may be NULL is an array (null = NULL) or, for an
//     out-parameter that may be NULL, always given here.
using System;
using System.Runtime.InteropServices;

public static class Deform {
  // Finds libdeform_c.so (Mono and .NET add the "lib" prefix and ".so" suffix).
  public const string Library = "deform_c";

  // ---- Status -------------------------------------------------------------------------------

  public enum Status {
    Ok = 0,
    Cancelled = 1,
    Unknown = 2,
    InvalidArgument = 3,
    DeadlineExceeded = 4,
    NotFound = 5,
    AlreadyExists = 6,
    PermissionDenied = 7,
    ResourceExhausted = 8,
    FailedPrecondition = 9,
    Aborted = 10,
    OutOfRange = 11,
    Unimplemented = 12,
    Internal = 13,
    Unavailable = 14,
    DataLoss = 15,
    Unauthenticated = 16,
    NoData = 100,       // not a failure: nothing new yet
    StreamEnded = 101,  // not a failure: the stream ended normally, every frame handed out
  }

  [DllImport(Library)] public static extern IntPtr deform_last_error();
  [DllImport(Library)] public static extern IntPtr deform_status_name(int status);
  [DllImport(Library)] public static extern IntPtr deform_version();

  // A string the library owns (NULL: null), as UTF-8.
  public static string Text(IntPtr text) {
    if (text == IntPtr.Zero) return null;
    int length = 0;
    while (Marshal.ReadByte(text, length) != 0) ++length;
    var bytes = new byte[length];
    Marshal.Copy(text, bytes, 0, length);
    return System.Text.Encoding.UTF8.GetString(bytes);
  }
  public static string LastError() { return Text(deform_last_error()); }
  public static string StatusName(Status status) { return Text(deform_status_name((int)status)); }
  public static string Version() { return Text(deform_version()); }

  // ---- Client -------------------------------------------------------------------------------

  [StructLayout(LayoutKind.Sequential)]
  public struct ConnectOptions {
    [MarshalAs(UnmanagedType.LPStr)] public string target;  // required: "host:port"
    public int tls;
    [MarshalAs(UnmanagedType.LPStr)] public string caFile;
    [MarshalAs(UnmanagedType.LPStr)] public string certFile;
    [MarshalAs(UnmanagedType.LPStr)] public string keyFile;
    [MarshalAs(UnmanagedType.LPStr)] public string caPem;
    [MarshalAs(UnmanagedType.LPStr)] public string certPem;
    [MarshalAs(UnmanagedType.LPStr)] public string keyPem;
    [MarshalAs(UnmanagedType.LPStr)] public string serverName;
    [MarshalAs(UnmanagedType.LPStr)] public string token;
    public int unaryDeadlineMs;   // 0: 30000
    public int connectTimeoutMs;  // 0: connect lazily
  }

  [DllImport(Library)]
  public static extern Status deform_connect(ref ConnectOptions options, out IntPtr client);
  [DllImport(Library)] public static extern void deform_client_free(IntPtr client);

  // ---- Meshes -------------------------------------------------------------------------------

  [DllImport(Library)]
  public static extern Status deform_load_phantom(IntPtr client, int vertices, string name,
                                                  out IntPtr mesh);
  [DllImport(Library)]
  public static extern Status deform_load_files(IntPtr client, string meshPath,
                                                string skeletonPath, string weightsPath,
                                                out IntPtr mesh);
  [DllImport(Library)]
  public static extern Status deform_load_files_with_bones(
      IntPtr client, string meshPath, string skeletonPath, string weightsPath,
      [In, MarshalAs(UnmanagedType.LPArray, ArraySubType = UnmanagedType.LPStr)]
      string[] boneSurfaces,
      UIntPtr boneSurfaceCount, out IntPtr mesh);
  [DllImport(Library)]
  public static extern Status deform_mesh_open(IntPtr client, string meshId, out IntPtr mesh);
  [DllImport(Library)] public static extern void deform_mesh_free(IntPtr mesh);

  [DllImport(Library)] public static extern Status deform_mesh_id(IntPtr mesh, out IntPtr id);
  [DllImport(Library)] public static extern Status deform_mesh_name(IntPtr mesh, out IntPtr name);
  [DllImport(Library)]
  public static extern Status deform_mesh_vertex_count(IntPtr mesh, out uint count);
  [DllImport(Library)]
  public static extern Status deform_mesh_triangle_count(IntPtr mesh, out uint count);
  [DllImport(Library)]
  public static extern Status deform_mesh_rest_geometry(IntPtr mesh, [Out] float[] positions,
                                                        UIntPtr capacityFloats,
                                                        [Out] uint[] triangles,
                                                        UIntPtr capacityIndices);

  [StructLayout(LayoutKind.Sequential)]
  public struct JointInfo {
    public IntPtr name;  // owned by the mesh handle: Deform.Text(name)
    [MarshalAs(UnmanagedType.ByValArray, SizeConst = 3)] public float[] restPosition;
    public uint dofCount;
    public int hasRegion;
  }
  [StructLayout(LayoutKind.Sequential)]
  public struct DofInfo {
    public IntPtr name;  // owned by the mesh handle
    [MarshalAs(UnmanagedType.ByValArray, SizeConst = 3)] public float[] axis;
    public float minDegrees;
    public float maxDegrees;
  }
  [DllImport(Library)]
  public static extern Status deform_mesh_joint_count(IntPtr mesh, out uint count);
  [DllImport(Library)]
  public static extern Status deform_mesh_joint(IntPtr mesh, uint joint, out JointInfo info);
  [DllImport(Library)]
  public static extern Status deform_mesh_joint_dof(IntPtr mesh, uint joint, uint dof,
                                                    out DofInfo info);

  [StructLayout(LayoutKind.Sequential)]
  public struct BoneSurfaceInfo {
    public IntPtr name;  // owned by the mesh handle
    public uint bone;
    public int blendBone;  // -1: none
    public float blend;
    public uint vertexCount;
    public uint triangleCount;
  }
  [DllImport(Library)]
  public static extern Status deform_mesh_bone_surface_count(IntPtr mesh, out uint count);
  [DllImport(Library)]
  public static extern Status deform_mesh_bone_surface(IntPtr mesh, uint surface,
                                                       out BoneSurfaceInfo info);
  [DllImport(Library)]
  public static extern Status deform_mesh_bone_surface_geometry(IntPtr mesh, uint surface,
                                                                [Out] float[] positions,
                                                                UIntPtr capacityFloats,
                                                                [Out] uint[] triangles,
                                                                UIntPtr capacityIndices);

  // `buffer` receives the ids, each followed by '\n', NUL-terminated (bytes; null with capacity 0
  // to size it).
  [DllImport(Library)]
  public static extern Status deform_list_meshes(IntPtr client, [Out] byte[] buffer,
                                                 UIntPtr capacity, out UIntPtr needed,
                                                 out UIntPtr count);
  [DllImport(Library)]
  public static extern Status deform_unload_mesh(IntPtr client, string meshId);

  // ---- Streams ------------------------------------------------------------------------------

  public enum Encoding { Float32 = 1, Quantized = 2, Predicted = 3 }

  [DllImport(Library)]
  public static extern Status deform_stream_open(IntPtr client, string meshId, Encoding encoding,
                                                 double maxError, out IntPtr stream);
  [DllImport(Library)]
  public static extern Status deform_stream_vertex_count(IntPtr stream, out uint count);

  [StructLayout(LayoutKind.Sequential)]
  public struct JointAngle {
    [MarshalAs(UnmanagedType.LPStr)] public string joint;  // name or decimal index
    [MarshalAs(UnmanagedType.LPStr)] public string axis;   // a degree of freedom, or "x" "y" "z"
    public double degrees;
  }
  [StructLayout(LayoutKind.Sequential)]
  public struct JointRotation {
    [MarshalAs(UnmanagedType.LPStr)] public string joint;
    public double w, x, y, z;
  }
  [StructLayout(LayoutKind.Sequential)]
  public struct RootTransform {
    public double tx, ty, tz;
    public double qw, qx, qy, qz;
  }

  public enum ToolShape { Sphere = 1, Capsule = 2 }
  [StructLayout(LayoutKind.Sequential)]
  public struct Tool {
    public int shape;  // (int)ToolShape
    [MarshalAs(UnmanagedType.ByValArray, SizeConst = 3)] public double[] center;
    [MarshalAs(UnmanagedType.ByValArray, SizeConst = 3)] public double[] end;
    public double radius;
  }

  // `root`: null = the rest placement, else an array of one.
  [DllImport(Library)]
  public static extern Status deform_stream_send_pose(IntPtr stream, [In] JointAngle[] angles,
                                                      UIntPtr angleCount,
                                                      [In] JointRotation[] rotations,
                                                      UIntPtr rotationCount,
                                                      [In] RootTransform[] root,
                                                      out ulong sequence);
  [DllImport(Library)]
  public static extern Status deform_stream_send_pose_with_tools(
      IntPtr stream, [In] JointAngle[] angles, UIntPtr angleCount, [In] JointRotation[] rotations,
      UIntPtr rotationCount, [In] RootTransform[] root, [In] Tool[] tools, UIntPtr toolCount,
      out ulong sequence);
  [DllImport(Library)]
  public static extern Status deform_stream_send_pose_text(IntPtr stream, string pose,
                                                           out ulong sequence);

  [StructLayout(LayoutKind.Sequential)]
  public struct JointMaterial {
    [MarshalAs(UnmanagedType.LPStr)] public string joint;
    public double rigid, soft, seam;
  }
  [StructLayout(LayoutKind.Sequential)]
  public struct RegionWeight {
    [MarshalAs(UnmanagedType.LPStr)] public string joint;
    public double weight;
  }
  [DllImport(Library)]
  public static extern Status deform_stream_send_stiffness(
      IntPtr stream, [In] JointMaterial[] materials, UIntPtr materialCount,
      [In] RegionWeight[] regions, UIntPtr regionCount, [In] uint[] vertexIndices,
      [In] double[] vertexWeights, UIntPtr vertexCount);

  [StructLayout(LayoutKind.Sequential)]
  public struct FrameInfo {
    public ulong sequence;
    public long clientTimestampNs;
    public double latencyMs;
    public double ageMs;
    public ulong framesDropped;
    public ulong skippedPoses;
    public uint clampedAngles;
    public ulong stiffnessVersion;
    public double serverMs;
    public uint vertexCount;
    public int meshUnloaded;
  }
  [DllImport(Library)]
  public static extern Status deform_stream_next_frame(IntPtr stream, [Out] float[] positions,
                                                       UIntPtr capacityFloats, int timeoutMs,
                                                       out FrameInfo info);

  [StructLayout(LayoutKind.Sequential)]
  public struct FrameConstraints {
    public int constrained;
    public uint penetratingBefore;
    public uint penetratingAfter;
    public double maxDepthAfter;
    public int unresolved;
    public uint contacts;
    public double volumeChange;
    public double constraintMs;
    public uint boneSurfaceCount;  // 12 floats each in `transforms`
  }
  [DllImport(Library)]
  public static extern Status deform_stream_frame_bones(IntPtr stream, [Out] float[] transforms,
                                                        UIntPtr capacityFloats,
                                                        out FrameConstraints constraints);

  [StructLayout(LayoutKind.Sequential)]
  public struct FrameTools {
    public uint penetratingBefore;
    public uint penetratingAfter;
    public double maxDepthAfter;
    public uint contacts;
    public int unresolved;
  }
  [DllImport(Library)]
  public static extern Status deform_stream_frame_tools(IntPtr stream, out FrameTools tools);

  // The server's id of this stream, for deform_contact_open; NoData before its first frame.
  [DllImport(Library)] public static extern Status deform_stream_id(IntPtr stream, out ulong id);

  // A QueryContact stream: a tool's contact with the skin, one blocking round trip a query.
  [DllImport(Library)]
  public static extern Status deform_contact_open(IntPtr client, string meshId,
                                                  ulong deformStreamId, double stiffness,
                                                  out IntPtr contact);
  [StructLayout(LayoutKind.Sequential)]
  public struct ContactResult {
    public ulong sequence;
    [MarshalAs(UnmanagedType.ByValArray, SizeConst = 3)] public double[] point;
    [MarshalAs(UnmanagedType.ByValArray, SizeConst = 3)] public double[] normal;
    public double depth;
    [MarshalAs(UnmanagedType.ByValArray, SizeConst = 3)] public double[] force;
    public double signedDistance;
    public double materialWeight;
    public ulong frameNumber;
    public ulong frameSequence;
  }
  [DllImport(Library)]
  public static extern Status deform_contact_query(IntPtr contact, ref Tool tool,
                                                   out ContactResult result);
  [DllImport(Library)]
  public static extern Status deform_contact_diagonal(IntPtr contact, out double diagonal);
  // Ends the query stream, returns its final status and frees the handle.
  [DllImport(Library)] public static extern Status deform_contact_close(IntPtr contact);

  public enum NoticeKind {
    PoseRejected = 1,
    StiffnessRejected = 2,
    StiffnessApplied = 3,
    CredentialsRevoked = 4,
  }
  [StructLayout(LayoutKind.Sequential)]
  public struct NoticeInfo {
    public int kind;  // (int)NoticeKind
    public ulong sequence;
    public ulong stiffnessVersion;
    public double factorMs;
  }
  // `message` receives the notice's text as NUL-terminated UTF-8 bytes, truncated to fit.
  [DllImport(Library)]
  public static extern Status deform_stream_next_notice(IntPtr stream, out NoticeInfo info,
                                                        [Out] byte[] message,
                                                        UIntPtr messageCapacity);

  [DllImport(Library)]
  public static extern Status deform_stream_close(IntPtr stream, int timeoutMs);
  [DllImport(Library)] public static extern void deform_stream_free(IntPtr stream);

  // The text of a NUL-terminated UTF-8 buffer (deform_list_meshes, deform_stream_next_notice).
  public static string Text(byte[] buffer) {
    int length = Array.IndexOf(buffer, (byte)0);
    if (length < 0) length = buffer.Length;
    return System.Text.Encoding.UTF8.GetString(buffer, 0, length);
  }
}
