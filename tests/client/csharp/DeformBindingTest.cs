// client/csharp/Deform.cs under Mono against the real deformd (tests/client/csharp_binding_test.sh
// starts it and passes its address): the struct layouts against the C compiler's, then every
// function of the header once or more: the version, connect, the phantom's description, joints,
// degrees of freedom, bone surfaces and rest geometry, the mesh list, open by id, file loads'
// errors, a stream with angles, quaternions, root motion, a tool, pose text, stiffness, notices,
// the frame's bone and tool reports, close and the end of the stream.
// Usage: mono DeformBindingTest.exe TARGET VERSION LAYOUTS. LAYOUTS: lines "NAME SIZE FIELD OFFSET"
// printed by the C compiler. Exits 0 when everything held, 1 with the failed check otherwise.
using System;
using System.IO;
using System.Runtime.InteropServices;

static class DeformBindingTest {
  static void Check(bool condition, string what) {
    if (condition) return;
    Console.Error.WriteLine("csharp_binding_test: check failed: " + what +
                            "\n  deform_last_error(): \"" + Deform.LastError() + "\"");
    Environment.Exit(1);
  }
  static void Ok(Deform.Status status, string what) {
    Check(status == Deform.Status.Ok, what + " returned " + status);
  }
  static UIntPtr Size(long n) { return new UIntPtr((ulong)n); }

  // The frame answering pose `sequence`, waiting up to 60 s.
  static Deform.FrameInfo FrameFor(IntPtr stream, ulong sequence, float[] positions) {
    Deform.FrameInfo info = new Deform.FrameInfo();
    for (int attempt = 0; attempt < 60 && info.sequence != sequence; ++attempt) {
      Deform.Status status = Deform.deform_stream_next_frame(
          stream, positions, Size(positions.Length), 1000, out info);
      Check(status == Deform.Status.Ok || status == Deform.Status.NoData,
            "deform_stream_next_frame returned " + status);
    }
    Check(info.sequence == sequence, "a frame answering pose " + sequence);
    return info;
  }

  static Deform.NoticeInfo NoticeOf(IntPtr stream, Deform.NoticeKind kind, out string message) {
    var buffer = new byte[256];
    var notice = new Deform.NoticeInfo();
    for (int attempt = 0; attempt < 1000; ++attempt) {
      Deform.Status status =
          Deform.deform_stream_next_notice(stream, out notice, buffer, Size(buffer.Length));
      if (status == Deform.Status.Ok && notice.kind == (int)kind) {
        message = Deform.Text(buffer);
        return notice;
      }
      Check(status == Deform.Status.Ok || status == Deform.Status.NoData,
            "deform_stream_next_notice returned " + status);
      if (status == Deform.Status.NoData) System.Threading.Thread.Sleep(20);
    }
    Check(false, "a " + kind + " notice within 20 s");
    message = null;
    return notice;
  }

  static double Distance2(float[] a, int i, float[] b, int j) {
    double sum = 0;
    for (int c = 0; c < 3; ++c) {
      double d = a[3 * i + c] - b[3 * j + c];
      sum += d * d;
    }
    return sum;
  }

  static void CheckLayouts(string path) {
    var types = new System.Collections.Generic.Dictionary<string, Type> {
      {"deform_connect_options", typeof(Deform.ConnectOptions)},
      {"deform_joint_info", typeof(Deform.JointInfo)},
      {"deform_dof_info", typeof(Deform.DofInfo)},
      {"deform_bone_surface_info", typeof(Deform.BoneSurfaceInfo)},
      {"deform_joint_angle", typeof(Deform.JointAngle)},
      {"deform_joint_rotation", typeof(Deform.JointRotation)},
      {"deform_root_transform", typeof(Deform.RootTransform)},
      {"deform_tool", typeof(Deform.Tool)},
      {"deform_joint_material", typeof(Deform.JointMaterial)},
      {"deform_region_weight", typeof(Deform.RegionWeight)},
      {"deform_frame_info", typeof(Deform.FrameInfo)},
      {"deform_frame_constraints", typeof(Deform.FrameConstraints)},
      {"deform_frame_tools", typeof(Deform.FrameTools)},
      {"deform_contact_result", typeof(Deform.ContactResult)},
      {"deform_notice_info", typeof(Deform.NoticeInfo)},
    };
    int fields = 0;
    var seen = new System.Collections.Generic.Dictionary<string, int>();
    foreach (string line in File.ReadAllLines(path)) {
      string[] parts = line.Split(' ');
      Check(parts.Length == 4 && types.ContainsKey(parts[0]), "a layout line: " + line);
      Type type = types[parts[0]];
      Check(Marshal.SizeOf(type) == int.Parse(parts[1]),
            parts[0] + ": C# " + Marshal.SizeOf(type) + " bytes, C " + parts[1]);
      // The C field's index in the struct is the C# field's (same order, other names).
      var csFields = type.GetFields();
      int index = int.Parse(parts[2]);
      Check(index < csFields.Length, parts[0] + " has a field " + index);
      long offset = Marshal.OffsetOf(type, csFields[index].Name).ToInt64();
      Check(offset == long.Parse(parts[3]),
            parts[0] + "." + csFields[index].Name + " at " + offset + ", C at " + parts[3]);
      ++fields;
      seen[parts[0]] = seen.ContainsKey(parts[0]) ? seen[parts[0]] + 1 : 1;
    }
    foreach (var entry in types) {
      int cFields = seen.ContainsKey(entry.Key) ? seen[entry.Key] : 0;
      Check(cFields == entry.Value.GetFields().Length,
            entry.Key + ": " + cFields + " C fields, " + entry.Value.GetFields().Length + " in C#");
    }
    Console.WriteLine("csharp_binding_test: " + types.Count + " structs, " + fields +
                      " field offsets equal to the C compiler's");
  }

  static int Main(string[] args) {
    Check(args.Length == 3, "usage: DeformBindingTest.exe TARGET VERSION LAYOUTS");
    CheckLayouts(args[2]);
    Check(Deform.Version() == args[1], "deform_version() is " + args[1]);
    Check(Deform.StatusName(Deform.Status.NotFound) == "NOT_FOUND", "deform_status_name");

    var options = new Deform.ConnectOptions { target = args[0], connectTimeoutMs = 10000 };
    IntPtr client;
    Ok(Deform.deform_connect(ref options, out client), "deform_connect");
    Check(Deform.LastError() == "", "no error after DEFORM_OK");

    // Loads that fail on a missing file name it.
    IntPtr none;
    Check(Deform.deform_load_files(client, "/nonexistent/leg.obj", "/nonexistent/leg.tgf", null,
                                   out none) == Deform.Status.NotFound &&
              Deform.LastError().Contains("/nonexistent/leg.obj"),
          "deform_load_files: NOT_FOUND naming the file");
    Check(Deform.deform_load_files_with_bones(client, "/nonexistent/leg.obj",
                                              "/nonexistent/leg.tgf", null,
                                              new[] {"/nonexistent/femur.obj:0"}, Size(1),
                                              out none) == Deform.Status.NotFound,
          "deform_load_files_with_bones: NOT_FOUND");

    IntPtr mesh;
    Ok(Deform.deform_load_phantom(client, 0, "csharp", out mesh), "deform_load_phantom");
    IntPtr text;
    Ok(Deform.deform_mesh_id(mesh, out text), "deform_mesh_id");
    string meshId = Deform.Text(text);
    Ok(Deform.deform_mesh_name(mesh, out text), "deform_mesh_name");
    Check(Deform.Text(text) == "csharp", "the mesh's name");
    uint vertices, triangles;
    Ok(Deform.deform_mesh_vertex_count(mesh, out vertices), "deform_mesh_vertex_count");
    Ok(Deform.deform_mesh_triangle_count(mesh, out triangles), "deform_mesh_triangle_count");
    Check(vertices > 1000 && triangles > 1000, "the phantom's counts");
    var rest = new float[3 * vertices];
    var indices = new uint[3 * triangles];
    Check(Deform.deform_mesh_rest_geometry(mesh, rest, Size(rest.Length - 1), indices,
                                           Size(indices.Length)) ==
              Deform.Status.InvalidArgument,
          "a buffer one float short is refused");
    Ok(Deform.deform_mesh_rest_geometry(mesh, rest, Size(rest.Length), indices,
                                        Size(indices.Length)),
       "deform_mesh_rest_geometry");
    foreach (uint index in indices) Check(index < vertices, "triangle indices within the mesh");

    // Joints hip, knee, ankle; the knee's "flexion" with its range.
    uint joints;
    Ok(Deform.deform_mesh_joint_count(mesh, out joints), "deform_mesh_joint_count");
    Check(joints == 3, "3 joints");
    Deform.JointInfo knee;
    Ok(Deform.deform_mesh_joint(mesh, 1, out knee), "deform_mesh_joint");
    Check(Deform.Text(knee.name) == "knee" && knee.dofCount > 0 && knee.restPosition.Length == 3,
          "joint 1 is the knee, with degrees of freedom");
    bool flexion = false;
    for (uint dof = 0; dof < knee.dofCount; ++dof) {
      Deform.DofInfo info;
      Ok(Deform.deform_mesh_joint_dof(mesh, 1, dof, out info), "deform_mesh_joint_dof");
      double norm = Math.Sqrt(info.axis[0] * info.axis[0] + info.axis[1] * info.axis[1] +
                              info.axis[2] * info.axis[2]);
      Check(Math.Abs(norm - 1) < 1e-4 && info.minDegrees < info.maxDegrees, "a unit axis, a range");
      if (Deform.Text(info.name) == "flexion") flexion = true;
    }
    Check(flexion, "the knee's flexion");
    Deform.JointInfo past;
    Check(Deform.deform_mesh_joint(mesh, joints, out past) == Deform.Status.OutOfRange,
          "OUT_OF_RANGE past the last joint");
    uint surfaces;
    Ok(Deform.deform_mesh_bone_surface_count(mesh, out surfaces),
       "deform_mesh_bone_surface_count");
    for (uint surface = 0; surface < surfaces; ++surface) {
      Deform.BoneSurfaceInfo info;
      Ok(Deform.deform_mesh_bone_surface(mesh, surface, out info), "deform_mesh_bone_surface");
      var positions = new float[3 * info.vertexCount];
      Ok(Deform.deform_mesh_bone_surface_geometry(mesh, surface, positions,
                                                  Size(positions.Length), null, Size(0)),
         "deform_mesh_bone_surface_geometry");
    }
    Deform.BoneSurfaceInfo pastSurface;
    Check(Deform.deform_mesh_bone_surface(mesh, surfaces, out pastSurface) ==
              Deform.Status.OutOfRange,
          "OUT_OF_RANGE past the last bone surface");
    Check(Deform.deform_mesh_bone_surface_geometry(mesh, surfaces, null, Size(0), null,
                                                   Size(0)) == Deform.Status.OutOfRange,
          "OUT_OF_RANGE geometry past the last bone surface");

    // The list holds the mesh; a handle opened by id describes the same mesh.
    UIntPtr needed, count;
    Check(Deform.deform_list_meshes(client, null, Size(0), out needed, out count) ==
              Deform.Status.InvalidArgument,
          "deform_list_meshes sizes its buffer");
    var list = new byte[needed.ToUInt64()];
    Ok(Deform.deform_list_meshes(client, list, Size(list.Length), out needed, out count),
       "deform_list_meshes");
    Check(Array.IndexOf(Deform.Text(list).Split('\n'), meshId) >= 0 && count.ToUInt64() >= 1,
          "the list holds " + meshId);
    IntPtr opened;
    Ok(Deform.deform_mesh_open(client, meshId, out opened), "deform_mesh_open");
    uint openedVertices;
    Ok(Deform.deform_mesh_vertex_count(opened, out openedVertices), "the opened handle's count");
    Check(openedVertices == vertices, "the same mesh");
    Deform.deform_mesh_free(opened);
    Check(Deform.deform_mesh_open(client, "mesh-none", out none) == Deform.Status.NotFound,
          "deform_mesh_open: NOT_FOUND");

    IntPtr stream;
    Ok(Deform.deform_stream_open(client, meshId, Deform.Encoding.Float32, 0, out stream),
       "deform_stream_open");
    uint streamVertices;
    Ok(Deform.deform_stream_vertex_count(stream, out streamVertices), "deform_stream_vertex_count");
    Check(streamVertices == vertices, "the stream's vertex count");
    var frame = new float[3 * vertices];
    var bent = new float[3 * vertices];

    // A 90-degree knee flexion: the hip's end stays, the ankle's end swings.
    int top = 0, bottom = 0;
    for (int v = 1; v < vertices; ++v) {
      if (rest[3 * v + 1] > rest[3 * top + 1]) top = v;
      if (rest[3 * v + 1] < rest[3 * bottom + 1]) bottom = v;
    }
    double length = rest[3 * top + 1] - rest[3 * bottom + 1];
    var flex = new[] {new Deform.JointAngle {joint = "knee", axis = "flexion", degrees = 90}};
    ulong sequence;
    Ok(Deform.deform_stream_send_pose(stream, flex, Size(1), null, Size(0), null, out sequence),
       "deform_stream_send_pose");
    Deform.FrameInfo frameInfo = FrameFor(stream, sequence, bent);
    Check(frameInfo.vertexCount == vertices && frameInfo.latencyMs > 0, "the frame's info");
    Check(Distance2(bent, top, rest, top) < 1e-6 * length * length, "the hip's end stays");
    Check(Distance2(bent, bottom, rest, bottom) > 0.04 * length * length, "the ankle's end moves");

    // Root motion with the hip's rotation the identity quaternion moves the rest mesh rigidly.
    var shift = new[] {new Deform.RootTransform {tx = 10, qw = 1}};
    var identity = new[] {new Deform.JointRotation {joint = "hip", w = 1}};
    Ok(Deform.deform_stream_send_pose(stream, null, Size(0), identity, Size(1), shift,
                                      out sequence),
       "deform_stream_send_pose with a rotation and root motion");
    FrameFor(stream, sequence, frame);
    for (int v = 0; v < vertices; ++v) {
      Check(Math.Abs(frame[3 * v] - rest[3 * v] - 10) < 1e-4 &&
                Math.Abs(frame[3 * v + 1] - rest[3 * v + 1]) < 1e-4 &&
                Math.Abs(frame[3 * v + 2] - rest[3 * v + 2]) < 1e-4,
            "root motion moves vertex " + v + " by (10, 0, 0)");
    }

    // A sphere pressed half its radius into the outside of the bent knee.
    int outermost = 0;
    for (int v = 1; v < vertices; ++v) {
      if (bent[3 * v] > bent[3 * outermost]) outermost = v;
    }
    var sphere = new[] {new Deform.Tool {
      shape = (int)Deform.ToolShape.Sphere,
      center = new double[] {bent[3 * outermost] + 0.15, bent[3 * outermost + 1],
                             bent[3 * outermost + 2]},
      end = new double[3], radius = 0.3}};
    Ok(Deform.deform_stream_send_pose_with_tools(stream, flex, Size(1), null, Size(0), null,
                                                 sphere, Size(1), out sequence),
       "deform_stream_send_pose_with_tools");
    FrameFor(stream, sequence, frame);
    Deform.FrameTools tools;
    Ok(Deform.deform_stream_frame_tools(stream, out tools), "deform_stream_frame_tools");
    Check(tools.penetratingBefore > 0 && tools.contacts > 0 && tools.penetratingAfter == 0 &&
              tools.unresolved == 0,
          "the tool's report: skin it entered, moved out");
    // A larger sphere at the same centre through a contact query against this stream's latest
    // frame (the dented one: the skin sits on the first sphere, inside the larger).
    ulong streamId;
    Ok(Deform.deform_stream_id(stream, out streamId), "deform_stream_id");
    IntPtr contact;
    Ok(Deform.deform_contact_open(client, meshId, streamId, 0, out contact),
       "deform_contact_open");
    double diagonal;
    Ok(Deform.deform_contact_diagonal(contact, out diagonal), "deform_contact_diagonal");
    Deform.Tool larger = sphere[0];
    larger.radius = 0.5;
    Deform.ContactResult result;
    Ok(Deform.deform_contact_query(contact, ref larger, out result), "deform_contact_query");
    Check(diagonal > 0 && result.sequence == 1 && result.frameNumber > 0 && result.depth > 0 &&
              result.force.Length == 3 &&
              result.force[0] * result.normal[0] + result.force[1] * result.normal[1] +
                      result.force[2] * result.normal[2] > 0,
          "the contact query: the pressed sphere is in the skin, pushed out along the normal");
    Ok(Deform.deform_contact_close(contact), "deform_contact_close");
    var bones = new float[12 * (surfaces + 1)];
    Deform.FrameConstraints constraints;
    Ok(Deform.deform_stream_frame_bones(stream, bones, Size(bones.Length), out constraints),
       "deform_stream_frame_bones");
    Check(constraints.boneSurfaceCount == surfaces, "the frame's bone surfaces");

    // Pose text, a rejected pose's notice, a stiffness update's notice and its version in frames.
    Check(Deform.deform_stream_send_pose_text(stream, "knee", out sequence) ==
              Deform.Status.InvalidArgument,
          "malformed pose text");
    Ok(Deform.deform_stream_send_pose_text(stream, "elbow:x:10", out sequence),
       "deform_stream_send_pose_text");
    string message;
    Deform.NoticeInfo notice = NoticeOf(stream, Deform.NoticeKind.PoseRejected, out message);
    Check(notice.sequence == sequence && message.Contains("elbow"), "the notice names the joint");
    var softer = new[] {new Deform.RegionWeight {joint = "knee", weight = 0.5}};
    var materials = new[] {new Deform.JointMaterial {joint = "knee", rigid = 2, soft = 1, seam = 4}};
    Ok(Deform.deform_stream_send_stiffness(stream, materials, Size(1), softer, Size(1), null, null,
                                           Size(0)),
       "deform_stream_send_stiffness");
    notice = NoticeOf(stream, Deform.NoticeKind.StiffnessApplied, out message);
    Check(notice.stiffnessVersion >= 1, "a stiffness version");
    Ok(Deform.deform_stream_send_pose(stream, flex, Size(1), null, Size(0), null, out sequence),
       "a pose after the update");
    frameInfo = FrameFor(stream, sequence, frame);
    Check(frameInfo.stiffnessVersion == notice.stiffnessVersion, "frames carry the new version");

    Ok(Deform.deform_stream_close(stream, 10000), "deform_stream_close");
    Deform.Status end = Deform.Status.Ok;
    for (int k = 0; k < 10 && end == Deform.Status.Ok; ++k) {
      end = Deform.deform_stream_next_frame(stream, frame, Size(frame.Length), 1000, out frameInfo);
    }
    Check(end == Deform.Status.StreamEnded, "STREAM_ENDED after close, not " + end);
    Deform.deform_stream_free(stream);
    Ok(Deform.deform_unload_mesh(client, meshId), "deform_unload_mesh");
    Check(Deform.deform_unload_mesh(client, meshId) == Deform.Status.NotFound,
          "a second unload: NOT_FOUND");
    Deform.deform_mesh_free(mesh);
    Deform.deform_client_free(client);
    Console.WriteLine("csharp_binding_test: libdeform_c " + Deform.Version() + " under Mono: " +
                      vertices + " vertices streamed, the flexion's frame latency " +
                      frameInfo.latencyMs.ToString("F2") + " ms");
    return 0;
  }
}
