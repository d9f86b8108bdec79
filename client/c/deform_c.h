/* deform_c.h: the C API of the deformd client, for game engines (Unity through P/Invoke, with
 * client/csharp/Deform.cs; Unreal through a plain C link) and any language with a C
 * foreign-function interface. One shared library, libdeform_c.so (SONAME libdeform_c.so.MAJOR),
 * built over the C++ client library (client/lib/deform_client.h); it exports the deform_*
 * functions below and nothing else. Installed, pkg-config's deform_c and CMake's
 * find_package(deform_c) give the flags (docs/clients/c-api.md).
 *
 * Error contract
 *   Every function that can fail returns a deform_status: DEFORM_OK (0), one of the gRPC status
 *   codes (the same numbers: DEFORM_NOT_FOUND = 5, DEFORM_UNAUTHENTICATED = 16, ...), or one of
 *   the two codes above them (DEFORM_NO_DATA, DEFORM_STREAM_ENDED), which are not failures. After
 *   every call, deform_last_error() holds that call's message on the calling thread: "" after
 *   DEFORM_OK, a one-line explanation otherwise (for server errors, the server's own message).
 *   No C++ exception ever crosses this boundary (an unexpected one becomes DEFORM_INTERNAL or,
 *   out of memory, DEFORM_RESOURCE_EXHAUSTED). A NULL handle or a NULL required pointer gives
 *   DEFORM_INVALID_ARGUMENT, never a crash. On failure, out-parameters are left unchanged unless
 *   stated otherwise.
 *
 * Ownership
 *   Handles (deform_client*, deform_mesh*, deform_stream*) are created by this library and freed
 *   by the matching deform_*_free, exactly once; freeing NULL does nothing. They may be freed in
 *   any order (a stream or mesh keeps what it needs of its client alive). Strings passed in are
 *   copied before the call returns. Strings returned (const char*) belong to the handle they came
 *   from and stay valid until it is freed; deform_last_error()'s string stays valid until the
 *   next deform_* call on the same thread. Buffers are the caller's: the library writes at most
 *   the capacity it is given, and reports the size needed when it is too small.
 *
 * Threads
 *   deform_client functions may be called from any thread, concurrently. A deform_mesh handle is
 *   immutable after creation except for its geometry cache, which is locked: any thread. A
 *   deform_stream's functions may be called from any thread (the stream locks itself); each frame
 *   is handed out once, so one reader per stream is the sensible design. No function calls back
 *   into the caller: frames and notices are polled. Calls that contact the server block (loads for
 *   as long as the server precomputes, which grows with the mesh); keep them off a render thread.
 *   deform_stream_next_frame with timeout 0 and the deform_stream_send_* functions never wait for
 *   the network. A handle must not be freed while another thread is inside a call on it.
 *
 * Units and layouts
 *   Positions are float x, y, z per vertex (3 floats per vertex) in the mesh's own units and
 *   vertex order (the file's order). Triangles are uint32 vertex indices, 3 per triangle. Angles
 *   are degrees; quaternions are (w, x, y, z). Times are milliseconds unless named _ns.
 */
#ifndef DEFORM_C_H_
#define DEFORM_C_H_

#include <stddef.h>
#include <stdint.h>

#if defined(_WIN32)
#if defined(DEFORM_C_BUILDING)
#define DEFORM_C_API __declspec(dllexport)
#else
#define DEFORM_C_API __declspec(dllimport)
#endif
#else
#define DEFORM_C_API __attribute__((visibility("default")))
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* ---- Status ------------------------------------------------------------------------------- */

typedef enum deform_status {
  DEFORM_OK = 0,
  DEFORM_CANCELLED = 1,
  DEFORM_UNKNOWN = 2,
  DEFORM_INVALID_ARGUMENT = 3,
  DEFORM_DEADLINE_EXCEEDED = 4,
  DEFORM_NOT_FOUND = 5,
  DEFORM_ALREADY_EXISTS = 6,
  DEFORM_PERMISSION_DENIED = 7,
  DEFORM_RESOURCE_EXHAUSTED = 8,
  DEFORM_FAILED_PRECONDITION = 9,
  DEFORM_ABORTED = 10,
  DEFORM_OUT_OF_RANGE = 11,
  DEFORM_UNIMPLEMENTED = 12,
  DEFORM_INTERNAL = 13,
  DEFORM_UNAVAILABLE = 14,
  DEFORM_DATA_LOSS = 15,
  DEFORM_UNAUTHENTICATED = 16,
  /* Not failures: nothing new to return yet (no frame within the timeout, no notice waiting). */
  DEFORM_NO_DATA = 100,
  /* Not a failure: the stream ended normally (after deform_stream_close) and every frame it
   * received has been handed out. A stream that ended with an error returns that error. */
  DEFORM_STREAM_ENDED = 101
} deform_status;

/* The message of the last deform_* call on this thread: "" after DEFORM_OK. Never NULL. */
DEFORM_C_API const char* deform_last_error(void);

/* The name of a status, e.g. "NOT_FOUND", "NO_DATA"; "UNKNOWN_STATUS" for other values. A static
 * string. Does not change deform_last_error(). */
DEFORM_C_API const char* deform_status_name(int status);

/* The library's version, "MAJOR.MINOR.PATCH" (e.g. "0.1.0"): the project's version, the one
 * `deformd --version` prints. The library's file name carries MAJOR (its SONAME is
 * libdeform_c.so.MAJOR). A static string. Does not change deform_last_error(). */
DEFORM_C_API const char* deform_version(void);

/* ---- Client ------------------------------------------------------------------------------- */

typedef struct deform_client deform_client;

/* Connection options. Zero-initialize the struct and set what you need; NULL or "" means unset.
 * TLS is on when `tls` is non-zero or any of the CA / certificate / key fields is set. */
typedef struct deform_connect_options {
  const char* target;    /* required: "host:port", e.g. "127.0.0.1:50051" */
  int tls;               /* non-zero: TLS even without any file (the system's trusted roots) */
  const char* ca_file;   /* the CA that signed the server's certificate; unset: system roots */
  const char* cert_file; /* mutual TLS: the client's certificate chain, with key_file */
  const char* key_file;
  const char* ca_pem; /* the same as PEM text; a PEM field overrides its file field */
  const char* cert_pem;
  const char* key_pem;
  const char* server_name; /* the name the server's certificate must carry; unset: target host */
  const char* token;       /* bearer token sent with every call ("authorization: Bearer ...") */
  int unary_deadline_ms;   /* deadline of each short call (info, list, unload); 0: 30000 */
  int connect_timeout_ms;  /* > 0: wait this long for the connection, DEFORM_UNAVAILABLE if it
                            * is not up by then; 0: connect lazily at the first call */
} deform_connect_options;

/* Creates a client. *out receives the handle (free with deform_client_free). INVALID_ARGUMENT
 * without a target or with a certificate lacking its key (or the reverse); NOT_FOUND naming an
 * unreadable TLS file; UNAVAILABLE when connect_timeout_ms passed without a connection. */
DEFORM_C_API deform_status deform_connect(const deform_connect_options* options,
                                          deform_client** out);
/* Frees the client. Meshes and streams opened through it stay usable until freed. */
DEFORM_C_API void deform_client_free(deform_client* client);

/* ---- Meshes ------------------------------------------------------------------------------- */

/* A loaded mesh's description as the server reported it when the handle was made (load or
 * deform_mesh_open). Freeing the handle does not unload the mesh (deform_unload_mesh does). */
typedef struct deform_mesh deform_mesh;

/* Loads the built-in knee phantom (joints hip, knee, ankle; knee degrees of freedom "flexion",
 * "varus", "rotation"; decimetres, Y up). `vertices`: approximate vertex count, 0 = the default
 * (about 2,000). `name`: a label for lists, NULL = "phantom". Blocks until the server has
 * precomputed the mesh. */
DEFORM_C_API deform_status deform_load_phantom(deform_client* client, int vertices,
                                               const char* name, deform_mesh** out);
/* Uploads a mesh file (.obj .ply .stl .off) with its skeleton file (.tgf, or JSON) and
 * optionally its skinning weights (.dmat or .csv; NULL = none), or a .gltf/.glb rig alone
 * (skeleton_path and weights_path NULL). NOT_FOUND naming a file that cannot be read,
 * INVALID_ARGUMENT for an unknown extension; the server's own errors otherwise. Blocks. */
DEFORM_C_API deform_status deform_load_files(deform_client* client, const char* mesh_path,
                                             const char* skeleton_path, const char* weights_path,
                                             deform_mesh** out);
/* deform_load_files with bone surfaces: `bone_surfaces` holds `bone_surface_count` specs
 * "FILE:BONE", FILE a closed mesh (.obj .ply .stl .off) in the skin's units and frame, BONE the
 * bone that carries it (a bone index, "HEAD-TAIL", or the joint it starts at; the first ':'
 * splits, so BONE may hold colons). A glTF rig's own bone surfaces (unskinned mesh nodes under its
 * joints) come first and need no spec. `bone_surfaces` may be NULL when the count is 0. */
DEFORM_C_API deform_status deform_load_files_with_bones(
    deform_client* client, const char* mesh_path, const char* skeleton_path,
    const char* weights_path, const char* const* bone_surfaces, size_t bone_surface_count,
    deform_mesh** out);
/* A handle for a mesh already on the server (e.g. from deform_list_meshes). NOT_FOUND when the
 * server has no mesh with that id (or none this client's token may see). */
DEFORM_C_API deform_status deform_mesh_open(deform_client* client, const char* mesh_id,
                                            deform_mesh** out);
DEFORM_C_API void deform_mesh_free(deform_mesh* mesh);

/* The mesh id (the handle's string), the label, and the counts. */
DEFORM_C_API deform_status deform_mesh_id(const deform_mesh* mesh, const char** id);
DEFORM_C_API deform_status deform_mesh_name(const deform_mesh* mesh, const char** name);
DEFORM_C_API deform_status deform_mesh_vertex_count(const deform_mesh* mesh, uint32_t* count);
DEFORM_C_API deform_status deform_mesh_triangle_count(const deform_mesh* mesh, uint32_t* count);

/* The rest geometry, fetched from the server at the first call and kept in the handle.
 * `positions`: 3 * vertex_count floats; `triangles`: 3 * triangle_count indices. Either may be
 * NULL (not wanted). INVALID_ARGUMENT, nothing written, when a capacity is smaller than needed. */
DEFORM_C_API deform_status deform_mesh_rest_geometry(deform_mesh* mesh, float* positions,
                                                     size_t capacity_floats, uint32_t* triangles,
                                                     size_t capacity_indices);

typedef struct deform_joint_info {
  const char* name;       /* owned by the mesh handle */
  float rest_position[3]; /* model units */
  uint32_t dof_count;     /* named degrees of freedom (e.g. the knee's "flexion") */
  int has_region;         /* non-zero: an inner joint, whose stiffness updates can change */
} deform_joint_info;

typedef struct deform_dof_info {
  const char* name;  /* owned by the mesh handle; the `axis` of deform_joint_angle */
  float axis[3];     /* unit axis, rest frame */
  float min_degrees; /* the range of motion angles are clamped to */
  float max_degrees;
} deform_dof_info;

/* Joints are numbered 0 .. joint_count - 1 (the skeleton's order; a joint's number in decimal is
 * also accepted wherever a joint name is). OUT_OF_RANGE for an index past the end. */
DEFORM_C_API deform_status deform_mesh_joint_count(const deform_mesh* mesh, uint32_t* count);
DEFORM_C_API deform_status deform_mesh_joint(const deform_mesh* mesh, uint32_t joint,
                                             deform_joint_info* info);
DEFORM_C_API deform_status deform_mesh_joint_dof(const deform_mesh* mesh, uint32_t joint,
                                                 uint32_t dof, deform_dof_info* info);

/* The mesh's bone surfaces (the skin is kept outside them; frames carry their motion, see
 * deform_stream_frame_bones), in the server's order. */
typedef struct deform_bone_surface_info {
  const char* name;      /* owned by the mesh handle */
  uint32_t bone;         /* the bone that carries it */
  int32_t blend_bone;    /* a child bone whose rotation it partly follows (a patella); -1: none */
  float blend;           /* the fraction it follows, with blend_bone */
  uint32_t vertex_count; /* of its rest geometry */
  uint32_t triangle_count;
} deform_bone_surface_info;
DEFORM_C_API deform_status deform_mesh_bone_surface_count(const deform_mesh* mesh, uint32_t* count);
/* OUT_OF_RANGE for an index past the end. */
DEFORM_C_API deform_status deform_mesh_bone_surface(const deform_mesh* mesh, uint32_t surface,
                                                    deform_bone_surface_info* info);
/* Surface `surface`'s rest geometry (fetched with the skin's, once per handle), as
 * deform_mesh_rest_geometry gives the skin's: 3 * vertex_count floats, 3 * triangle_count
 * indices; either may be NULL. INVALID_ARGUMENT, nothing written, for a capacity too small;
 * OUT_OF_RANGE for an index past the end. */
DEFORM_C_API deform_status deform_mesh_bone_surface_geometry(deform_mesh* mesh, uint32_t surface,
                                                             float* positions,
                                                             size_t capacity_floats,
                                                             uint32_t* triangles,
                                                             size_t capacity_indices);

/* The ids of the meshes on the server (those this client's token may see), one per line, each
 * followed by '\n', the whole NUL-terminated, into `buffer`. *needed (may be NULL) receives the
 * bytes needed including the NUL, also when the buffer is too small (then INVALID_ARGUMENT and
 * nothing written): call with capacity 0 to size the buffer. *count (may be NULL): the number of
 * meshes. */
DEFORM_C_API deform_status deform_list_meshes(deform_client* client, char* buffer, size_t capacity,
                                              size_t* needed, size_t* count);
/* Unloads a mesh (streams open on it keep their copy until they end). NOT_FOUND if unknown. */
DEFORM_C_API deform_status deform_unload_mesh(deform_client* client, const char* mesh_id);

/* ---- Streams ------------------------------------------------------------------------------ */

typedef struct deform_stream deform_stream;

/* How frames travel; the library decodes all of them into float positions. */
typedef enum deform_encoding {
  DEFORM_ENCODING_FLOAT32 = 1,   /* 12 bytes per vertex, exact */
  DEFORM_ENCODING_QUANTIZED = 2, /* 16-bit in the frame's box, meshoptimizer-coded */
  DEFORM_ENCODING_PREDICTED = 3  /* skinning prediction + residual within max_error */
} deform_encoding;

/* Opens a Deform stream on `mesh_id`. `max_error`: for DEFORM_ENCODING_PREDICTED, the largest
 * error per coordinate as a fraction of the mesh's bounding-box diagonal, (0, 0.01]; 0 = the
 * default, 5e-5 (kDefaultPredictedMaxError, defined in server/core/codec/frame_codec.h); ignored
 * otherwise. Checks the mesh first: NOT_FOUND for an unknown id. Free with
 * deform_stream_free. */
DEFORM_C_API deform_status deform_stream_open(deform_client* client, const char* mesh_id,
                                              deform_encoding encoding, double max_error,
                                              deform_stream** out);
/* The vertex count of this stream's frames (3 floats each). */
DEFORM_C_API deform_status deform_stream_vertex_count(const deform_stream* stream, uint32_t* count);

/* A rotation of `joint` (name or decimal index) by `degrees` about `axis`: a degree of freedom's
 * name ("flexion", clamped to its range) or a rest-frame axis "x", "y", "z". */
typedef struct deform_joint_angle {
  const char* joint;
  const char* axis;
  double degrees;
} deform_joint_angle;

/* A joint's whole local rotation as a quaternion (normalized by the server); applied before the
 * angles of the same joint. */
typedef struct deform_joint_rotation {
  const char* joint;
  double w, x, y, z;
} deform_joint_rotation;

/* The whole body's placement: rotate about the rest frame's origin by (qw, qx, qy, qz), then
 * translate by (tx, ty, tz) model units. */
typedef struct deform_root_transform {
  double tx, ty, tz;
  double qw, qx, qy, qz;
} deform_root_transform;

/* Sends a pose: the joints named turn, the others keep their rest rotation (a pose is whole, not
 * an increment). `angles` / `rotations` may be NULL when their count is 0; `root` NULL = the rest
 * placement. *sequence (may be NULL) receives the pose's sequence number (1, 2, ... per stream),
 * which the frame answering it reports. Never waits: the newest unsent pose replaces an older one
 * still waiting (latest wins). STREAM_ENDED (or the stream's error) once the stream is over. The
 * server checks joint and axis names: a bad one comes back as a notice (deform_stream_next_notice),
 * and the stream goes on. */
DEFORM_C_API deform_status
deform_stream_send_pose(deform_stream* stream, const deform_joint_angle* angles, size_t angle_count,
                        const deform_joint_rotation* rotations, size_t rotation_count,
                        const deform_root_transform* root, uint64_t* sequence);
/* A surgical tool pressed on the skin (docs/instruments.md): a sphere, or a capsule (the points
 * within `radius` of the segment from `center` to `end`), in model units and the posed skin's
 * frame. Skin it would enter slides on its surface; the rest follows the method. */
typedef enum deform_tool_shape {
  DEFORM_TOOL_SPHERE = 1,
  DEFORM_TOOL_CAPSULE = 2
} deform_tool_shape;
typedef struct deform_tool {
  int shape;        /* deform_tool_shape */
  double center[3]; /* a sphere's centre, a capsule's first end */
  double end[3];    /* a capsule's second end; unused for a sphere */
  double radius;
} deform_tool;

/* deform_stream_send_pose with up to 4 tools (`tools` may be NULL when tool_count is 0). The tools
 * are part of the pose: latest wins for both, and a pose without tools lifts them (its frame is
 * the tool-free frame). INVALID_ARGUMENT for an unknown shape; the server checks the rest (a
 * radius in (0, half the mesh's diagonal], finite values, at most 4) and refuses a bad tool with
 * a DEFORM_NOTICE_POSE_REJECTED notice, the stream going on. */
DEFORM_C_API deform_status
deform_stream_send_pose_with_tools(deform_stream* stream, const deform_joint_angle* angles,
                                   size_t angle_count, const deform_joint_rotation* rotations,
                                   size_t rotation_count, const deform_root_transform* root,
                                   const deform_tool* tools, size_t tool_count, uint64_t* sequence);
/* The same pose written as text, "JOINT:AXIS:DEGREES[,JOINT:AXIS:DEGREES...]" (deformctl's
 * syntax, e.g. "knee:flexion:90,knee:varus:5"); INVALID_ARGUMENT for malformed text. */
DEFORM_C_API deform_status deform_stream_send_pose_text(deform_stream* stream, const char* pose,
                                                        uint64_t* sequence);

/* The material of a joint's region: rigid (outside every region, default 2), soft (inside,
 * default 1), seam (the region's border, default 4). */
typedef struct deform_joint_material {
  const char* joint;
  double rigid, soft, seam;
} deform_joint_material;

typedef struct deform_region_weight {
  const char* joint;
  double weight;
} deform_region_weight;

/* Replaces the stream's stiffness (not cumulative: the model's defaults, then these). Any array
 * may be NULL when its count is 0; `vertex_indices` and `vertex_weights` both have vertex_count
 * entries. Never waits; updates are applied in order, each with a refactorization on the server
 * (a notice says when it is applied or why it was rejected). */
DEFORM_C_API deform_status deform_stream_send_stiffness(
    deform_stream* stream, const deform_joint_material* materials, size_t material_count,
    const deform_region_weight* regions, size_t region_count, const uint32_t* vertex_indices,
    const double* vertex_weights, size_t vertex_count);

typedef struct deform_frame_info {
  uint64_t sequence;           /* the pose this frame answers (0: none yet) */
  int64_t client_timestamp_ns; /* when that pose was sent (this library's monotonic clock) */
  double latency_ms;           /* pose sent -> frame received by this library */
  double age_ms;               /* frame received -> handed out by this call */
  uint64_t frames_dropped;     /* frames received but never handed out (a newer one replaced
                                * them) since the previous frame handed out */
  uint64_t skipped_poses;      /* poses the server superseded before solving, since its last
                                * frame */
  uint32_t clamped_angles;     /* angles clamped to their range of motion in this pose */
  uint64_t stiffness_version;  /* 0 = the model's default stiffness */
  double server_ms;            /* the server's share: queue + kinematics + solve + constraints
                                * + encode */
  uint32_t vertex_count;       /* the frame's vertices: 3 * vertex_count floats were written */
  int mesh_unloaded;           /* non-zero: the mesh was unloaded; this stream keeps its copy */
} deform_frame_info;

/* Copies the newest frame not yet handed out into `positions` (3 * vertex_count floats) and
 * describes it in *info (may be NULL). Waits up to timeout_ms (0: just look; < 0: until a frame
 * or the end) for one. Returns
 *   DEFORM_OK                a frame was written;
 *   DEFORM_NO_DATA           none arrived within the timeout (nothing written);
 *   DEFORM_INVALID_ARGUMENT  capacity_floats < 3 * vertex_count: nothing written, and the frame
 *                            stays available for a call with a large enough buffer;
 *   DEFORM_STREAM_ENDED      the stream ended normally and every frame was handed out;
 *   the stream's error       it ended with one (e.g. UNAVAILABLE when the server went away,
 *                            NOT_FOUND if the mesh vanished before the stream started).
 * Frames that arrive between calls replace each other (latest wins; info->frames_dropped counts
 * them), so polling once per rendered frame always gets the newest shape. */
DEFORM_C_API deform_status deform_stream_next_frame(deform_stream* stream, float* positions,
                                                    size_t capacity_floats, int timeout_ms,
                                                    deform_frame_info* info);

/* The server's id of this stream (DeformFrame.stream_id), which deform_contact_open names to query
 * against its latest frame. DEFORM_NO_DATA until the stream's first frame has arrived. */
DEFORM_C_API deform_status deform_stream_id(deform_stream* stream, uint64_t* id);

/* What a frame's constraints did (the server's FrameConstraints), on a mesh with bone surfaces or
 * its volume kept. Vertices are the solved mesh's. */
typedef struct deform_frame_constraints {
  int constrained;             /* non-zero: the frame carried a report (the fields below) */
  uint32_t penetrating_before; /* skin vertices inside a bone surface as the model solved them */
  uint32_t penetrating_after;  /* ... in the frame handed out */
  double max_depth_after;      /* the deepest of those, model units (0 when none) */
  int unresolved;              /* non-zero: skin was left inside a bone */
  uint32_t contacts;           /* contact constraints in the frame's last solve */
  double volume_change;        /* (V - V_rest) / V_rest */
  double constraint_ms;        /* the server's time for them */
  uint32_t bone_surface_count; /* bone surfaces: 12 floats each in `transforms` */
} deform_frame_constraints;

/* The bone surfaces and constraint report of the frame the last deform_stream_next_frame handed
 * out: each surface's rigid motion as 12 floats, the row-major 3 x 3 rotation then the
 * translation (a rest point v is posed at R v + t), into `transforms` (may be NULL when
 * capacity_floats is 0), and the report into *constraints. Never waits. DEFORM_NO_DATA before
 * any frame was handed out; DEFORM_INVALID_ARGUMENT (nothing written but
 * constraints->bone_surface_count) when capacity_floats < 12 * bone_surface_count. */
DEFORM_C_API deform_status deform_stream_frame_bones(deform_stream* stream, float* transforms,
                                                     size_t capacity_floats,
                                                     deform_frame_constraints* constraints);

/* What the tools did to the frame the last deform_stream_next_frame handed out (the server's
 * FrameConstraints.tool_*; all zero for a frame without tools). Never waits. DEFORM_NO_DATA
 * before any frame was handed out. */
typedef struct deform_frame_tools {
  uint32_t penetrating_before; /* skin vertices inside a tool as the model solved them */
  uint32_t penetrating_after;  /* ... in the frame handed out */
  double max_depth_after;      /* the deepest of those, model units */
  uint32_t contacts;           /* tool contacts in the frame's last solve */
  int unresolved;              /* non-zero: skin was left inside a tool */
} deform_frame_tools;
DEFORM_C_API deform_status deform_stream_frame_tools(deform_stream* stream,
                                                     deform_frame_tools* tools);

typedef enum deform_notice_kind {
  DEFORM_NOTICE_POSE_REJECTED = 1,      /* `sequence` names the pose; the message says why */
  DEFORM_NOTICE_STIFFNESS_REJECTED = 2, /* `stiffness_version` names the update */
  DEFORM_NOTICE_STIFFNESS_APPLIED = 3,  /* frames from now on use `stiffness_version` */
  DEFORM_NOTICE_CREDENTIALS_REVOKED = 4 /* the token was revoked: the stream ends next */
} deform_notice_kind;

typedef struct deform_notice_info {
  int kind; /* a deform_notice_kind */
  uint64_t sequence;
  uint64_t stiffness_version;
  double factor_ms; /* STIFFNESS_APPLIED: the refactorization's time */
} deform_notice_info;

/* Takes the oldest notice not yet taken (the stream keeps the last 64) into *info; its message,
 * NUL-terminated and truncated to fit, into `message` (may be NULL when capacity is 0). Never
 * waits. DEFORM_NO_DATA when none is waiting. */
DEFORM_C_API deform_status deform_stream_next_notice(deform_stream* stream,
                                                     deform_notice_info* info, char* message,
                                                     size_t message_capacity);

/* Finishes the stream: sends what is pending, half-closes, and waits up to timeout_ms (< 0:
 * without limit) for the server to end it. DEFORM_OK once ended normally, the stream's error if
 * it ended with one, DEFORM_DEADLINE_EXCEEDED if it had not ended in time (it is then
 * cancelled). Frames already received can still be taken with deform_stream_next_frame. */
DEFORM_C_API deform_status deform_stream_close(deform_stream* stream, int timeout_ms);
/* Cancels the stream if it is still open and frees it. */
DEFORM_C_API void deform_stream_free(deform_stream* stream);

/* ---- Contact queries ---------------------------------------------------------------------- */

/* A QueryContact stream (docs/instruments.md): a tool's contact with the skin, one blocking round
 * trip a query, for a haptic loop. One thread at a time per handle. */
typedef struct deform_contact deform_contact;

/* Opens a contact query on `mesh_id` against the latest frame of the Deform stream
 * `deform_stream_id` (deform_stream_id(); the same tenant's) or, with 0, the rest pose.
 * `stiffness`: the force of a press one bounding-box diagonal deep into material of weight 1, in
 * the caller's force unit; 0 = 100. Waits for the server's answer: NOT_FOUND for an unknown mesh
 * or stream, INVALID_ARGUMENT for a bad stiffness, RESOURCE_EXHAUSTED beyond the stream limits.
 * End with deform_contact_close. */
DEFORM_C_API deform_status deform_contact_open(deform_client* client, const char* mesh_id,
                                               uint64_t deform_stream_id, double stiffness,
                                               deform_contact** out);

typedef struct deform_contact_result {
  uint64_t sequence;      /* this query's, 1, 2, ... per handle */
  double point[3];        /* the skin point closest to the tool's axis */
  double normal[3];       /* the skin's outward unit normal there */
  double depth;           /* radius - signed_distance, at least 0: > 0 inside the skin */
  double force[3];        /* on the tool: stiffness * material_weight * depth / diagonal * normal */
  double signed_distance; /* the axis's distance from the skin, negative inside */
  double material_weight; /* at `point` */
  uint64_t frame_number;  /* the Deform stream's frame queried (1 = its first); 0 = rest pose */
  uint64_t frame_sequence; /* the pose that frame answered; 0 at rest */
} deform_contact_result;

/* The contact of `tool` (deform_tool, as in a pose) with the skin as it stands now. Blocks for one
 * round trip. A bad tool ends the query stream with INVALID_ARGUMENT (every later call returns
 * it); INVALID_ARGUMENT without contacting the server for an unknown shape. */
DEFORM_C_API deform_status deform_contact_query(deform_contact* contact, const deform_tool* tool,
                                                deform_contact_result* result);

/* The bounding-box diagonal of the rest skin (the force model's length), model units. */
DEFORM_C_API deform_status deform_contact_diagonal(const deform_contact* contact, double* diagonal);

/* Ends the query stream, returns its final status (DEFORM_OK after a clean end, or the error that
 * ended it) and frees the handle; NULL does nothing (DEFORM_OK). */
DEFORM_C_API deform_status deform_contact_close(deform_contact* contact);

#ifdef __cplusplus
} /* extern "C" */
#endif

#endif /* DEFORM_C_H_ */
