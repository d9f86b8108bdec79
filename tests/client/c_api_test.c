/* The C API (client/c/deform_c.h) from C11, against the real deformd executable (DEFORMD_PATH,
 * or $DEFORM_TEST_DEFORMD) started on 127.0.0.1 with a kernel-chosen port: connect, load the
 * phantom (and the shared leg from its files in ../shared/data), read its joints and
 * rest geometry, stream a 90-degree knee flexion in each encoding and check the shape, root motion,
 * latest wins, polling while another thread sends, notices, stiffness, the error paths (unknown
 * mesh, too small buffers, closed streams, malformed poses), a server with a token file and one
 * with mutual TLS. Prints the pose-to-frame latency of one stream measured through the C API.
 * Exits 0 when everything passed, 1 with the failed check, the last error and the server's log
 * otherwise. Every wait is bounded. */
#define _POSIX_C_SOURCE 200809L

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <threads.h>
#include <time.h>
#include <unistd.h>

#include "deform_c.h"

/* ---- A deformd child process ------------------------------------------------------------- */

typedef struct deformd_process {
  pid_t pid;
  char log_path[64];
  char target[64];
} deformd_process;

static deformd_process* g_servers[2];

static void sleep_ms(long ms) {
  struct timespec delay = {ms / 1000, (ms % 1000) * 1000000L};
  nanosleep(&delay, NULL);
}

static double now_ms(void) {
  struct timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return t.tv_sec * 1e3 + t.tv_nsec / 1e6;
}

static void print_log(const deformd_process* server) {
  FILE* log = fopen(server->log_path, "r");
  if (log == NULL) return;
  fprintf(stderr, "---- deformd log (%s) ----\n", server->target);
  char line[1024];
  while (fgets(line, sizeof line, log) != NULL) fputs(line, stderr);
  fclose(log);
}

/* SIGTERM, up to 10 s for the exit, then SIGKILL. Returns the exit code (-1: not a normal exit). */
static int stop_deformd(deformd_process* server) {
  if (server->pid <= 0) return -1;
  kill(server->pid, SIGTERM);
  int status = 0;
  for (int waited = 0; waited < 10000; waited += 10) {
    if (waitpid(server->pid, &status, WNOHANG) == server->pid) {
      server->pid = 0;
      unlink(server->log_path);
      return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    }
    sleep_ms(10);
  }
  kill(server->pid, SIGKILL);
  waitpid(server->pid, &status, 0);
  server->pid = 0;
  unlink(server->log_path);
  return -1;
}

static void kill_servers(void) {
  for (int k = 0; k < 2; ++k) {
    if (g_servers[k] != NULL && g_servers[k]->pid > 0) {
      kill(g_servers[k]->pid, SIGKILL);
      waitpid(g_servers[k]->pid, NULL, 0);
      unlink(g_servers[k]->log_path);
    }
  }
}

#define CHECK(condition)                                                                    \
  do {                                                                                      \
    if (!(condition)) {                                                                     \
      fprintf(stderr, "%s:%d: check failed: %s\n  deform_last_error(): \"%s\"\n", __FILE__, \
              __LINE__, #condition, deform_last_error());                                   \
      for (int server_ = 0; server_ < 2; ++server_) {                                       \
        if (g_servers[server_] != NULL && g_servers[server_]->pid > 0) {                    \
          print_log(g_servers[server_]);                                                    \
        }                                                                                   \
      }                                                                                     \
      kill_servers();                                                                       \
      exit(1);                                                                              \
    }                                                                                       \
  } while (0)

/* Starts deformd listening on 127.0.0.1:0 with `extra` arguments (NULL-terminated) and waits up
 * to 60 s for its "listening on HOST:PORT" line; server->target is then "127.0.0.1:PORT". */
static void start_deformd(deformd_process* server, const char* const* extra) {
  const char* program = getenv("DEFORM_TEST_DEFORMD");
  if (program == NULL) program = DEFORMD_PATH;
  strcpy(server->log_path, "/tmp/deformd-c-api-XXXXXX");
  const int log_fd = mkstemp(server->log_path);
  CHECK(log_fd >= 0);
  const char* argv[16] = {program, "--listen", "127.0.0.1:0", "--workers", "2"};
  int argc = 5;
  for (int k = 0; extra != NULL && extra[k] != NULL && argc < 15; ++k) argv[argc++] = extra[k];
  argv[argc] = NULL;
  server->pid = fork();
  CHECK(server->pid >= 0);
  if (server->pid == 0) {
    dup2(log_fd, STDOUT_FILENO);
    dup2(log_fd, STDERR_FILENO);
    execv(program, (char* const*)argv);
    _exit(127);
  }
  close(log_fd);
  const double deadline = now_ms() + 60000;
  while (now_ms() < deadline) {
    FILE* log = fopen(server->log_path, "r");
    CHECK(log != NULL);
    char line[1024];
    int port = 0;
    while (port == 0 && fgets(line, sizeof line, log) != NULL) {
      const char* at = strstr(line, "listening on ");
      if (at == NULL) continue;
      const char* end = strchr(at + 13, ' ');
      const char* colon = at + 13;
      for (const char* c = at + 13; *c != '\0' && c != end; ++c) {
        if (*c == ':') colon = c;
      }
      port = atoi(colon + 1);
    }
    fclose(log);
    if (port > 0) {
      snprintf(server->target, sizeof server->target, "127.0.0.1:%d", port);
      return;
    }
    int status = 0;
    if (waitpid(server->pid, &status, WNOHANG) == server->pid) {
      server->pid = 0;
      print_log(server);
      CHECK(!"deformd exited before listening");
    }
    sleep_ms(20);
  }
  CHECK(!"deformd did not print its listening line within 60 s");
}

/* ---- Helpers over the API ---------------------------------------------------------------- */

static deform_client* connect_to(const char* target, const char* token) {
  deform_connect_options options;
  memset(&options, 0, sizeof options);
  options.target = target;
  options.token = token;
  options.unary_deadline_ms = 10000;
  options.connect_timeout_ms = 10000;
  deform_client* client = NULL;
  CHECK(deform_connect(&options, &client) == DEFORM_OK);
  CHECK(client != NULL);
  CHECK(strcmp(deform_last_error(), "") == 0);
  return client;
}

/* Waits up to 10 s for the frame answering pose `sequence` (skipping older ones). */
static void frame_for(deform_stream* stream, uint64_t sequence, float* positions, size_t capacity,
                      deform_frame_info* info) {
  const double deadline = now_ms() + 10000;
  while (now_ms() < deadline) {
    const deform_status status = deform_stream_next_frame(stream, positions, capacity, 500, info);
    CHECK(status == DEFORM_OK || status == DEFORM_NO_DATA);
    if (status == DEFORM_OK && info->sequence >= sequence) {
      CHECK(info->sequence == sequence);
      return;
    }
  }
  CHECK(!"no frame answered the pose within 10 s");
}

static uint32_t joint_index(const deform_mesh* mesh, const char* name) {
  uint32_t count = 0;
  CHECK(deform_mesh_joint_count(mesh, &count) == DEFORM_OK);
  for (uint32_t j = 0; j < count; ++j) {
    deform_joint_info info;
    CHECK(deform_mesh_joint(mesh, j, &info) == DEFORM_OK);
    if (strcmp(info.name, name) == 0) return j;
  }
  CHECK(!"the phantom has no joint of that name");
  return 0;
}

static double distance(const float* a, const float* b) {
  const double dx = a[0] - b[0], dy = a[1] - b[1], dz = a[2] - b[2];
  return sqrt(dx * dx + dy * dy + dz * dz);
}

/* (p - origin) . unit(toward - origin), and |toward - origin| in *length. */
static double along(const float* p, const float* origin, const float* toward, double* length) {
  double axis[3], norm = 0, dot = 0;
  for (int a = 0; a < 3; ++a) {
    axis[a] = toward[a] - origin[a];
    norm += axis[a] * axis[a];
  }
  norm = sqrt(norm);
  for (int a = 0; a < 3; ++a) dot += (p[a] - origin[a]) * axis[a] / norm;
  *length = norm;
  return dot;
}

static int compare_doubles(const void* a, const void* b) {
  const double x = *(const double*)a, y = *(const double*)b;
  return (x > y) - (x < y);
}

/* A thread that sends `count` flexion poses on `stream`, 1 ms apart (C11 threads). */
typedef struct pose_sender {
  deform_stream* stream;
  int count;
  uint64_t last_sequence;
  int failures;
} pose_sender;

static int send_poses(void* argument) {
  pose_sender* sender = argument;
  for (int k = 0; k < sender->count; ++k) {
    const deform_joint_angle angle = {"knee", "flexion", 100.0 * k / sender->count};
    if (deform_stream_send_pose(sender->stream, &angle, 1, NULL, 0, NULL, &sender->last_sequence) !=
        DEFORM_OK) {
      ++sender->failures;
    }
    sleep_ms(1);
  }
  return 0;
}

/* ---- The tests ----------------------------------------------------------------------------- */

static void test_arguments_without_a_server(void) {
  deform_client* client = NULL;
  CHECK(deform_connect(NULL, &client) == DEFORM_INVALID_ARGUMENT);
  CHECK(strcmp(deform_last_error(), "deform_connect: options is NULL") == 0);
  deform_connect_options options;
  memset(&options, 0, sizeof options);
  CHECK(deform_connect(&options, &client) == DEFORM_INVALID_ARGUMENT);
  CHECK(strstr(deform_last_error(), "target") != NULL);
  options.target = "127.0.0.1:1";
  options.cert_file = "/nonexistent/client.crt";
  CHECK(deform_connect(&options, &client) == DEFORM_INVALID_ARGUMENT); /* no key_file */
  options.key_file = "/nonexistent/client.key";
  CHECK(deform_connect(&options, &client) == DEFORM_NOT_FOUND);
  CHECK(strstr(deform_last_error(), "/nonexistent/client.crt") != NULL);
  CHECK(client == NULL);
  CHECK(strcmp(deform_status_name(DEFORM_NOT_FOUND), "NOT_FOUND") == 0);
  CHECK(strcmp(deform_status_name(DEFORM_NO_DATA), "NO_DATA") == 0);
  CHECK(strcmp(deform_status_name(-3), "UNKNOWN_STATUS") == 0);
  /* The project's version (CMake's project()), leaving the last error as it was. */
  CHECK(strcmp(deform_version(), DEFORM_EXPECTED_VERSION) == 0);
  CHECK(strstr(deform_last_error(), "/nonexistent/client.crt") != NULL);
  CHECK(deform_stream_next_frame(NULL, NULL, 0, 0, NULL) == DEFORM_INVALID_ARGUMENT);
  CHECK(strcmp(deform_last_error(), "deform_stream_next_frame: stream is NULL") == 0);
  uint32_t count = 7;
  CHECK(deform_mesh_vertex_count(NULL, &count) == DEFORM_INVALID_ARGUMENT && count == 7);
  CHECK(strcmp(deform_last_error(), "deform_mesh_vertex_count: mesh is NULL") == 0);
  CHECK(deform_stream_vertex_count(NULL, &count) == DEFORM_INVALID_ARGUMENT && count == 7);
  CHECK(strcmp(deform_last_error(), "deform_stream_vertex_count: stream is NULL") == 0);
  deform_client_free(NULL);
  deform_mesh_free(NULL);
  deform_stream_free(NULL);
}

static void test_phantom_session(const char* target) {
  deform_client* client = connect_to(target, NULL);
  deform_mesh* mesh = NULL;
  CHECK(deform_load_phantom(client, 0, "c-api phantom", &mesh) == DEFORM_OK);
  const char* mesh_id = NULL;
  const char* name = NULL;
  CHECK(deform_mesh_id(mesh, &mesh_id) == DEFORM_OK && strncmp(mesh_id, "mesh-", 5) == 0);
  CHECK(deform_mesh_name(mesh, NULL) == DEFORM_INVALID_ARGUMENT);
  CHECK(strcmp(deform_last_error(), "deform_mesh_name: name is NULL") == 0);
  CHECK(deform_mesh_name(mesh, &name) == DEFORM_OK && strcmp(name, "c-api phantom") == 0);
  uint32_t n = 0, triangles = 0;
  CHECK(deform_mesh_vertex_count(mesh, &n) == DEFORM_OK && n > 1000);
  CHECK(deform_mesh_triangle_count(mesh, &triangles) == DEFORM_OK && triangles > 1000);

  /* Joints: hip, knee (flexion among its degrees of freedom), ankle. */
  const uint32_t hip = joint_index(mesh, "hip"), knee = joint_index(mesh, "knee"),
                 ankle = joint_index(mesh, "ankle");
  deform_joint_info hip_info, knee_info, ankle_info;
  CHECK(deform_mesh_joint(mesh, hip, &hip_info) == DEFORM_OK);
  CHECK(deform_mesh_joint(mesh, knee, &knee_info) == DEFORM_OK);
  CHECK(deform_mesh_joint(mesh, ankle, &ankle_info) == DEFORM_OK);
  CHECK(knee_info.has_region && knee_info.dof_count >= 1);
  int has_flexion = 0;
  for (uint32_t d = 0; d < knee_info.dof_count; ++d) {
    deform_dof_info dof;
    CHECK(deform_mesh_joint_dof(mesh, knee, d, &dof) == DEFORM_OK);
    if (strcmp(dof.name, "flexion") == 0) has_flexion = dof.max_degrees >= 90;
  }
  CHECK(has_flexion);
  deform_dof_info dof;
  CHECK(deform_mesh_joint_dof(mesh, knee, knee_info.dof_count, &dof) == DEFORM_OUT_OF_RANGE);
  CHECK(deform_mesh_joint(mesh, 99, &hip_info) == DEFORM_OUT_OF_RANGE);
  CHECK(strstr(deform_last_error(), "99") != NULL);

  /* Rest geometry, and a buffer one float short refused without a write. */
  const size_t floats = 3 * (size_t)n;
  float* rest = malloc(sizeof(float) * floats);
  uint32_t* indices = malloc(sizeof(uint32_t) * 3 * triangles);
  CHECK(rest != NULL && indices != NULL);
  CHECK(deform_mesh_rest_geometry(mesh, rest, floats - 1, NULL, 0) == DEFORM_INVALID_ARGUMENT);
  CHECK(strstr(deform_last_error(), "needs") != NULL);
  CHECK(deform_mesh_rest_geometry(mesh, rest, floats, indices, 3 * (size_t)triangles) == DEFORM_OK);
  for (size_t k = 0; k < 3 * (size_t)triangles; ++k) CHECK(indices[k] < n);

  /* The list holds the mesh; a buffer too small says how much is needed. */
  size_t needed = 0, count = 0;
  char small[4];
  CHECK(deform_list_meshes(client, small, sizeof small, &needed, &count) ==
        DEFORM_INVALID_ARGUMENT);
  CHECK(count == 1 && needed == strlen(mesh_id) + 2);
  char* list = malloc(needed);
  CHECK(list != NULL);
  CHECK(deform_list_meshes(client, list, needed, NULL, NULL) == DEFORM_OK);
  CHECK(strncmp(list, mesh_id, strlen(mesh_id)) == 0 && list[strlen(mesh_id)] == '\n');
  free(list);

  /* A 90-degree knee flexion over a float32 stream. */
  deform_stream* stream = NULL;
  CHECK(deform_stream_open(client, mesh_id, DEFORM_ENCODING_FLOAT32, 0, &stream) == DEFORM_OK);
  uint32_t stream_vertices = 0;
  CHECK(deform_stream_vertex_count(stream, &stream_vertices) == DEFORM_OK && stream_vertices == n);
  const deform_joint_angle flexion = {"knee", "flexion", 90};
  uint64_t sequence = 0;
  CHECK(deform_stream_send_pose(stream, &flexion, 1, NULL, 0, NULL, &sequence) == DEFORM_OK);
  CHECK(sequence == 1);
  float* bent = malloc(sizeof(float) * floats);
  float* frame = malloc(sizeof(float) * (floats + 16));
  CHECK(bent != NULL && frame != NULL);
  deform_frame_info info;
  deform_frame_constraints constraints;
  float bones[36];
  CHECK(deform_stream_frame_bones(stream, bones, 36, &constraints) == DEFORM_NO_DATA);
  frame_for(stream, sequence, bent, floats, &info);
  CHECK(info.vertex_count == n && info.clamped_angles == 0 && info.latency_ms > 0);
  CHECK(info.server_ms > 0 && info.server_ms <= info.latency_ms);
  /* The phantom's femur, tibia and patella: the femur stays, the tibia turns by 90 degrees (its
   * rotation's trace 1 + 2 cos 90 = 1); the skin stays out of them. */
  CHECK(deform_stream_frame_bones(stream, bones, 35, &constraints) == DEFORM_INVALID_ARGUMENT);
  CHECK(constraints.bone_surface_count == 3);
  CHECK(deform_stream_frame_bones(stream, bones, 36, &constraints) == DEFORM_OK);
  CHECK(constraints.constrained && constraints.penetrating_after == 0 && !constraints.unresolved);
  CHECK(fabs(bones[0] + bones[4] + bones[8] - 3.0) < 1e-5);
  CHECK(fabs(bones[12] + bones[16] + bones[20] - 1.0) < 1e-5);
  /* Their descriptions and rest geometry, as the frames' motions apply to them. */
  uint32_t surfaces = 0;
  CHECK(deform_mesh_bone_surface_count(mesh, &surfaces) == DEFORM_OK && surfaces == 3);
  deform_bone_surface_info surface;
  CHECK(deform_mesh_bone_surface(mesh, 3, &surface) == DEFORM_OUT_OF_RANGE);
  CHECK(deform_mesh_bone_surface(mesh, 0, &surface) == DEFORM_OK);
  CHECK(strcmp(surface.name, "femur") == 0 && surface.bone == 0 && surface.blend_bone == -1);
  CHECK(surface.vertex_count > 0 && surface.triangle_count > 0);
  CHECK(deform_mesh_bone_surface(mesh, 2, &surface) == DEFORM_OK);
  CHECK(strcmp(surface.name, "patella") == 0 && surface.blend_bone == 1 && surface.blend > 0);
  float* bone_rest = malloc(sizeof(float) * 3 * surface.vertex_count);
  uint32_t* bone_triangles = malloc(sizeof(uint32_t) * 3 * surface.triangle_count);
  CHECK(bone_rest != NULL && bone_triangles != NULL);
  CHECK(deform_mesh_bone_surface_geometry(mesh, 2, bone_rest, 3 * surface.vertex_count - 1, NULL,
                                          0) == DEFORM_INVALID_ARGUMENT);
  CHECK(deform_mesh_bone_surface_geometry(mesh, 2, bone_rest, 3 * surface.vertex_count,
                                          bone_triangles, 3 * surface.triangle_count) == DEFORM_OK);
  for (uint32_t k = 0; k < 3 * surface.triangle_count; ++k) {
    CHECK(bone_triangles[k] < surface.vertex_count);
  }
  CHECK(isfinite(bone_rest[0]) && isfinite(bone_rest[3 * surface.vertex_count - 1]));
  free(bone_rest);
  free(bone_triangles);

  /* The thigh's far part (beyond 60% of the way from the knee to the hip) does not move; the shin
   * below its middle swings: each vertex moves by more than its distance below the knee (a 90-
   * degree turn moves it by sqrt(2) times its distance from the knee's axis), keeping its distance
   * to the knee within 2%. */
  int thigh_vertices = 0, shin_vertices = 0;
  double thigh_worst = 0, shin_least_ratio = 1e9, shin_worst_stretch = 0, thigh_length = 0,
         shin_length = 0;
  for (uint32_t i = 0; i < n; ++i) {
    const float* p = rest + 3 * (size_t)i;
    const float* q = bent + 3 * (size_t)i;
    const double up = along(p, knee_info.rest_position, hip_info.rest_position, &thigh_length);
    const double down = along(p, knee_info.rest_position, ankle_info.rest_position, &shin_length);
    if (up > 0.6 * thigh_length) {
      ++thigh_vertices;
      if (distance(p, q) > thigh_worst) thigh_worst = distance(p, q);
    } else if (down > 0.5 * shin_length) {
      ++shin_vertices;
      const double ratio = distance(p, q) / down;
      if (ratio < shin_least_ratio) shin_least_ratio = ratio;
      const double stretch =
          fabs(distance(q, knee_info.rest_position) / distance(p, knee_info.rest_position) - 1);
      if (stretch > shin_worst_stretch) shin_worst_stretch = stretch;
    }
  }
  printf(
      "c_api_test: 90-degree flexion: %d thigh vertices moved at most %.2e, %d shin vertices "
      "moved at least %.3f x their depth below the knee, distance to the knee within %.2f%%\n",
      thigh_vertices, thigh_worst, shin_vertices, shin_least_ratio, 100 * shin_worst_stretch);
  CHECK(thigh_vertices > 50 && shin_vertices > 50);
  CHECK(thigh_worst < 1e-4 * thigh_length);
  CHECK(shin_least_ratio > 1.0 && shin_least_ratio < 1.5);
  CHECK(shin_worst_stretch < 0.02);

  /* A buffer one float short: refused, nothing written past it or into it, the frame kept. */
  CHECK(deform_stream_send_pose_text(stream, "knee:flexion:45", &sequence) == DEFORM_OK);
  CHECK(sequence == 2);
  for (size_t k = 0; k < floats + 16; ++k) frame[k] = -12345.0f;
  const double deadline = now_ms() + 10000;
  deform_status status = DEFORM_NO_DATA;
  while (status == DEFORM_NO_DATA && now_ms() < deadline) {
    status = deform_stream_next_frame(stream, frame, floats - 1, 500, &info);
  }
  CHECK(status == DEFORM_INVALID_ARGUMENT);
  CHECK(strstr(deform_last_error(), "needs") != NULL && strstr(deform_last_error(), "kept"));
  for (size_t k = 0; k < floats + 16; ++k) CHECK(frame[k] == -12345.0f);
  frame_for(stream, 2, frame, floats, &info);
  CHECK(frame[floats] == -12345.0f); /* wrote exactly 3n floats */
  double from_bent = 0;
  for (uint32_t i = 0; i < n; ++i) {
    const double d = distance(frame + 3 * (size_t)i, bent + 3 * (size_t)i);
    if (d > from_bent) from_bent = d;
  }
  CHECK(from_bent > 0.1 * shin_length); /* 45 degrees is not 90 */

  /* The other encodings decode to the float32 frame within their error bounds. */
  const deform_encoding encodings[2] = {DEFORM_ENCODING_QUANTIZED, DEFORM_ENCODING_PREDICTED};
  for (int e = 0; e < 2; ++e) {
    deform_stream* encoded = NULL;
    CHECK(deform_stream_open(client, mesh_id, encodings[e], 0, &encoded) == DEFORM_OK);
    CHECK(deform_stream_send_pose(encoded, &flexion, 1, NULL, 0, NULL, &sequence) == DEFORM_OK);
    frame_for(encoded, sequence, frame, floats, &info);
    double worst = 0;
    for (size_t k = 0; k < floats; ++k) {
      if (fabs(frame[k] - bent[k]) > worst) worst = fabs(frame[k] - bent[k]);
    }
    printf("c_api_test: encoding %d: largest difference from float32 %.2e\n", encodings[e], worst);
    CHECK(worst < 1e-3 * (thigh_length + shin_length));
    CHECK(deform_stream_close(encoded, 5000) == DEFORM_OK);
    deform_stream_free(encoded);
  }

  /* Root motion alone moves the rest mesh rigidly. */
  const deform_root_transform shift = {10, 0, 0, 1, 0, 0, 0};
  CHECK(deform_stream_send_pose(stream, NULL, 0, NULL, 0, &shift, &sequence) == DEFORM_OK);
  frame_for(stream, sequence, frame, floats, &info);
  for (uint32_t i = 0; i < n; ++i) {
    const float expected[3] = {rest[3 * i] + 10, rest[3 * i + 1], rest[3 * i + 2]};
    CHECK(distance(frame + 3 * (size_t)i, expected) < 1e-4);
  }

  /* A joint the skeleton does not have: a notice naming it, and the stream goes on. Malformed
   * text never leaves the library. */
  CHECK(deform_stream_send_pose_text(stream, "knee", NULL) == DEFORM_INVALID_ARGUMENT);
  CHECK(deform_stream_send_pose_text(stream, "elbow:x:10", &sequence) == DEFORM_OK);
  deform_notice_info notice;
  char message[256];
  status = DEFORM_NO_DATA;
  for (int tries = 0; status == DEFORM_NO_DATA && tries < 500; ++tries) {
    status = deform_stream_next_notice(stream, &notice, message, sizeof message);
    if (status == DEFORM_NO_DATA) sleep_ms(20);
  }
  CHECK(status == DEFORM_OK);
  CHECK(notice.kind == DEFORM_NOTICE_POSE_REJECTED && notice.sequence == sequence);
  CHECK(strstr(message, "elbow") != NULL);
  printf("c_api_test: rejected pose notice: %s\n", message);

  /* A stiffness update is applied (a notice) and later frames carry its version. */
  const deform_region_weight softer = {"knee", 0.5};
  CHECK(deform_stream_send_stiffness(stream, NULL, 0, &softer, 1, NULL, NULL, 0) == DEFORM_OK);
  status = DEFORM_NO_DATA;
  for (int tries = 0; tries < 500; ++tries) {
    status = deform_stream_next_notice(stream, &notice, message, sizeof message);
    if (status == DEFORM_OK && notice.kind == DEFORM_NOTICE_STIFFNESS_APPLIED) break;
    CHECK(status == DEFORM_NO_DATA);
    sleep_ms(20);
  }
  CHECK(status == DEFORM_OK && notice.kind == DEFORM_NOTICE_STIFFNESS_APPLIED);
  CHECK(notice.stiffness_version >= 1);
  CHECK(deform_stream_send_pose(stream, &flexion, 1, NULL, 0, NULL, &sequence) == DEFORM_OK);
  frame_for(stream, sequence, frame, floats, &info);
  CHECK(info.stiffness_version == notice.stiffness_version);

  /* Latest wins: pose A's frame waits untaken (a poll with a buffer one float short sees it
   * without taking it), pose B is sent, and a poll a second later gets B's frame with A's counted
   * as replaced (or, if B's frame were that late, A's frame with none replaced, then B's). */
  uint64_t pose_a = 0, pose_b = 0;
  CHECK(deform_stream_send_pose_text(stream, "knee:flexion:30", &pose_a) == DEFORM_OK);
  status = DEFORM_NO_DATA;
  for (int tries = 0; status == DEFORM_NO_DATA && tries < 20; ++tries) {
    status = deform_stream_next_frame(stream, frame, floats - 1, 500, &info);
  }
  CHECK(status == DEFORM_INVALID_ARGUMENT);
  CHECK(deform_stream_send_pose_text(stream, "knee:flexion:60", &pose_b) == DEFORM_OK);
  sleep_ms(1000);
  CHECK(deform_stream_next_frame(stream, frame, floats, 0, &info) == DEFORM_OK);
  CHECK((info.sequence == pose_b && info.frames_dropped == 1) ||
        (info.sequence == pose_a && info.frames_dropped == 0));
  printf("c_api_test: latest wins: the poll after two frames got pose %s's frame, %llu replaced\n",
         info.sequence == pose_b ? "B" : "A", (unsigned long long)info.frames_dropped);
  if (info.sequence == pose_a) frame_for(stream, pose_b, frame, floats, &info);
  CHECK(deform_stream_next_frame(stream, frame, floats, 0, &info) == DEFORM_NO_DATA);

  /* Latency of one stream through the C API: one pose at a time, each waiting for its frame. */
  enum { kPoses = 200 };
  double latencies[kPoses];
  for (int k = 0; k < kPoses; ++k) {
    const deform_joint_angle angle = {"knee", "flexion", 120.0 * k / kPoses};
    CHECK(deform_stream_send_pose(stream, &angle, 1, NULL, 0, NULL, &sequence) == DEFORM_OK);
    frame_for(stream, sequence, frame, floats, &info);
    latencies[k] = info.latency_ms;
  }
  qsort(latencies, kPoses, sizeof latencies[0], compare_doubles);
  printf(
      "c_api_test: pose-to-frame latency through the C API, %u-vertex phantom, %d poses one at "
      "a time: p50 %.2f ms, p90 %.2f ms, max %.2f ms\n",
      n, kPoses, latencies[kPoses / 2], latencies[kPoses * 9 / 10], latencies[kPoses - 1]);

  /* One thread sends while this one polls: every frame taken is whole and newer than the last,
   * and after the sender stops the last pose's frame arrives. */
  pose_sender sender = {stream, 300, 0, 0};
  thrd_t thread;
  CHECK(thrd_create(&thread, send_poses, &sender) == thrd_success);
  uint64_t previous = 0, taken = 0, dropped = 0;
  const double polling_ends = now_ms() + 200;
  while (now_ms() < polling_ends) {
    status = deform_stream_next_frame(stream, frame, floats, 20, &info);
    CHECK(status == DEFORM_OK || status == DEFORM_NO_DATA);
    if (status != DEFORM_OK) continue;
    CHECK(info.sequence > previous && info.vertex_count == n);
    previous = info.sequence;
    ++taken;
    dropped += info.frames_dropped;
  }
  CHECK(thrd_join(thread, NULL) == thrd_success);
  CHECK(sender.failures == 0 && sender.last_sequence > previous);
  frame_for(stream, sender.last_sequence, frame, floats, &info);
  printf(
      "c_api_test: polling while another thread sent 300 poses: %llu frames taken in 200 ms, "
      "%llu replaced before being taken\n",
      (unsigned long long)taken, (unsigned long long)dropped);
  CHECK(taken > 0);

  /* A sphere tool pressed into the outside of the bent knee: the skin it would enter slides on
   * its surface, and the same pose without it gives back the tool-free frame bit for bit. */
  CHECK(deform_stream_send_pose(stream, &flexion, 1, NULL, 0, NULL, &sequence) == DEFORM_OK);
  frame_for(stream, sequence, bent, floats, &info);
  uint32_t outermost = 0;
  for (uint32_t i = 1; i < n; ++i) {
    if (bent[3 * i] > bent[3 * outermost]) outermost = i;
  }
  deform_tool sphere = {DEFORM_TOOL_SPHERE, {0, 0, 0}, {0, 0, 0}, 0.3};
  for (int c = 0; c < 3; ++c) sphere.center[c] = bent[3 * outermost + c];
  sphere.center[0] += 0.15; /* half its radius inside the skin */
  CHECK(deform_stream_send_pose_with_tools(stream, &flexion, 1, NULL, 0, NULL, &sphere, 1,
                                           &sequence) == DEFORM_OK);
  frame_for(stream, sequence, frame, floats, &info);
  deform_frame_tools tool_report;
  CHECK(deform_stream_frame_tools(stream, &tool_report) == DEFORM_OK);
  CHECK(tool_report.penetrating_before > 0 && tool_report.contacts > 0);
  CHECK(tool_report.penetrating_after == 0 && !tool_report.unresolved);
  for (uint32_t i = 0; i < n; ++i) {
    double d2 = 0;
    for (int c = 0; c < 3; ++c) d2 += pow(frame[3 * i + c] - sphere.center[c], 2);
    CHECK(sqrt(d2) > 0.3 - 1e-3); /* every vertex outside the tool, within the margin */
  }
  deform_tool unknown_shape = sphere;
  unknown_shape.shape = 7;
  CHECK(deform_stream_send_pose_with_tools(stream, &flexion, 1, NULL, 0, NULL, &unknown_shape, 1,
                                           NULL) == DEFORM_INVALID_ARGUMENT);
  CHECK(deform_stream_send_pose_with_tools(stream, &flexion, 1, NULL, 0, NULL, NULL, 1, NULL) ==
        DEFORM_INVALID_ARGUMENT);
  CHECK(deform_stream_send_pose(stream, &flexion, 1, NULL, 0, NULL, &sequence) == DEFORM_OK);
  frame_for(stream, sequence, frame, floats, &info);
  CHECK(memcmp(frame, bent, sizeof(float) * floats) == 0);
  CHECK(deform_stream_frame_tools(stream, &tool_report) == DEFORM_OK);
  CHECK(tool_report.penetrating_before == 0 && tool_report.contacts == 0);

  /* The contact query against this stream's latest frame (the bent knee, no tool): the same sphere
   * is half its radius inside the skin there, pushed out along +x. */
  uint64_t stream_id = 0;
  CHECK(deform_stream_id(stream, &stream_id) == DEFORM_OK && stream_id > 0);
  deform_contact* contact = NULL;
  CHECK(deform_contact_open(client, mesh_id, stream_id, 0, &contact) == DEFORM_OK);
  double diagonal = 0;
  CHECK(deform_contact_diagonal(contact, &diagonal) == DEFORM_OK && diagonal > 1);
  deform_contact_result touch;
  CHECK(deform_contact_query(contact, &sphere, &touch) == DEFORM_OK);
  CHECK(touch.sequence == 1 && touch.frame_sequence == sequence && touch.frame_number > 0);
  CHECK(touch.depth > 0.1 && touch.depth <= 0.3 + 1e-9);
  CHECK(fabs(touch.depth - (0.3 - touch.signed_distance)) < 1e-9);
  CHECK(touch.normal[0] > 0.5 && touch.force[0] > 0);
  CHECK(fabs(sqrt(pow(touch.force[0], 2) + pow(touch.force[1], 2) + pow(touch.force[2], 2)) -
             100 * touch.material_weight * touch.depth / diagonal) < 1e-9);
  deform_tool away = sphere;
  away.center[0] += 1;
  deform_contact_result apart;
  CHECK(deform_contact_query(contact, &away, &apart) == DEFORM_OK);
  CHECK(apart.sequence == 2 && apart.depth == 0 && apart.force[0] == 0);
  CHECK(deform_contact_query(contact, &unknown_shape, &apart) == DEFORM_INVALID_ARGUMENT);
  CHECK(deform_contact_close(contact) == DEFORM_OK);
  printf("c_api_test: contact at the bent knee: depth %.4f, force %.4f along +x\n", touch.depth,
         touch.force[0]);
  CHECK(deform_contact_open(client, mesh_id, stream_id + 1000, 0, &contact) == DEFORM_NOT_FOUND);
  CHECK(strstr(deform_last_error(), "no open Deform stream") != NULL);
  CHECK(deform_contact_close(NULL) == DEFORM_OK);

  /* Closing ends the stream: no more poses, frames report the end. */
  CHECK(deform_stream_close(stream, 5000) == DEFORM_OK);
  CHECK(deform_stream_send_pose(stream, &flexion, 1, NULL, 0, NULL, NULL) == DEFORM_STREAM_ENDED);
  CHECK(deform_stream_next_frame(stream, frame, floats, 1000, &info) == DEFORM_STREAM_ENDED);
  deform_stream_free(stream);

  /* Unknown meshes: NOT_FOUND naming the id, at open and for streams. */
  const char* unknown = "mesh-00000000000000000000000000000000";
  deform_mesh* missing = NULL;
  CHECK(deform_mesh_open(client, unknown, &missing) == DEFORM_NOT_FOUND);
  CHECK(strstr(deform_last_error(), unknown) != NULL && missing == NULL);
  printf("c_api_test: unknown mesh: %s\n", deform_last_error());
  CHECK(deform_stream_open(client, unknown, DEFORM_ENCODING_FLOAT32, 0, &stream) ==
        DEFORM_NOT_FOUND);
  CHECK(strstr(deform_last_error(), unknown) != NULL);
  CHECK(deform_stream_open(client, mesh_id, (deform_encoding)7, 0, &stream) ==
        DEFORM_INVALID_ARGUMENT);

  /* The mesh by id, then unloaded (twice: NOT_FOUND). */
  deform_mesh* again = NULL;
  CHECK(deform_mesh_open(client, mesh_id, &again) == DEFORM_OK);
  uint32_t again_vertices = 0;
  CHECK(deform_mesh_vertex_count(again, &again_vertices) == DEFORM_OK && again_vertices == n);
  deform_mesh_free(again);
  CHECK(deform_unload_mesh(client, mesh_id) == DEFORM_OK);
  CHECK(deform_unload_mesh(client, mesh_id) == DEFORM_NOT_FOUND);

  /* The client is freed first: the mesh handle keeps working where it needs no server. */
  deform_client_free(client);
  CHECK(deform_mesh_vertex_count(mesh, &again_vertices) == DEFORM_OK && again_vertices == n);
  deform_mesh_free(mesh);
  free(rest);
  free(indices);
  free(bent);
  free(frame);
}

/* Uploads from files: missing and unknown files fail before the server is asked; the shared leg
 * (../shared/data) loads with its TGF skeleton and bends at its knee. Without the shared leg the
 * test fails, naming the path and DEFORM_SHARED_DATA_DIR, unless
 * DEFORM_ALLOW_MISSING_SHARED_DATA=1 (tests/shared_data.h: a developer without the data). */
static void test_files(const char* target) {
  deform_client* client = connect_to(target, NULL);
  deform_mesh* mesh = NULL;
  CHECK(deform_load_files(client, "/nonexistent/leg.obj", "/nonexistent/leg.tgf", NULL, &mesh) ==
        DEFORM_NOT_FOUND);
  CHECK(strstr(deform_last_error(), "/nonexistent/leg.obj") != NULL && mesh == NULL);
  CHECK(deform_load_files(client, "leg.xyz", "leg.tgf", NULL, &mesh) == DEFORM_INVALID_ARGUMENT);
  CHECK(strstr(deform_last_error(), "leg.xyz") != NULL);

  const char* data = getenv("DEFORM_SHARED_DATA");
  if (data == NULL) data = DEFORM_SHARED_DATA_DIR;
  char obj[512], tgf[512];
  snprintf(obj, sizeof obj, "%s/leg/leg_1633.obj", data);
  snprintf(tgf, sizeof tgf, "%s/leg/leg.tgf", data);
  if (access(obj, R_OK) != 0 || access(tgf, R_OK) != 0) {
    const char* allow = getenv("DEFORM_ALLOW_MISSING_SHARED_DATA");
    const int allowed = allow != NULL && strcmp(allow, "1") == 0;
    fprintf(allowed ? stdout : stderr,
            "c_api_test: shared data absent: %s or %s does not exist. Configure with "
            "-DDEFORM_SHARED_DATA_DIR=<the shared data folder> (CMake cache variable; now %s), "
            "or set DEFORM_SHARED_DATA; DEFORM_ALLOW_MISSING_SHARED_DATA=1 skips this part%s\n",
            obj, tgf, DEFORM_SHARED_DATA_DIR, allowed ? ": skipping the shared leg" : "");
    deform_client_free(client);
    if (!allowed) {
      kill_servers();
      exit(1);
    }
    return;
  }
  CHECK(deform_load_files(client, obj, tgf, NULL, &mesh) == DEFORM_OK);
  const char* name = NULL;
  const char* mesh_id = NULL;
  uint32_t n = 0;
  CHECK(deform_mesh_name(mesh, &name) == DEFORM_OK && strcmp(name, "leg_1633.obj") == 0);
  CHECK(deform_mesh_id(mesh, &mesh_id) == DEFORM_OK);
  CHECK(deform_mesh_vertex_count(mesh, &n) == DEFORM_OK && n == 1633);
  const size_t floats = 3 * (size_t)n;
  float* rest = malloc(sizeof(float) * floats);
  float* frame = malloc(sizeof(float) * floats);
  CHECK(rest != NULL && frame != NULL);
  CHECK(deform_mesh_rest_geometry(mesh, rest, floats, NULL, 0) == DEFORM_OK);
  deform_stream* stream = NULL;
  CHECK(deform_stream_open(client, mesh_id, DEFORM_ENCODING_FLOAT32, 0, &stream) == DEFORM_OK);
  uint64_t sequence = 0;
  CHECK(deform_stream_send_pose_text(stream, "1:x:90", &sequence) == DEFORM_OK);
  deform_frame_info info;
  frame_for(stream, sequence, frame, floats, &info);
  double moved = 0;
  for (uint32_t i = 0; i < n; ++i) {
    const double d = distance(frame + 3 * (size_t)i, rest + 3 * (size_t)i);
    if (d > moved) moved = d;
  }
  printf("c_api_test: leg_1633 bent 90 degrees at its knee: largest displacement %.3f\n", moved);
  CHECK(moved > 1.0);
  CHECK(deform_stream_close(stream, 5000) == DEFORM_OK);
  deform_stream_free(stream);

  /* The same leg with a bone surface: an octahedron around the middle of its first bone (a
   * twentieth of the bone's length in radius), uploaded from a file and carried by bone 0. */
  deform_joint_info head, tail;
  CHECK(deform_mesh_joint(mesh, 0, &head) == DEFORM_OK &&
        deform_mesh_joint(mesh, 1, &tail) == DEFORM_OK);
  const double radius = distance(head.rest_position, tail.rest_position) / 20;
  char bone_dir[] = "/tmp/deform-c-api-bone-XXXXXX";
  CHECK(mkdtemp(bone_dir) != NULL);
  char bone_path[600];
  snprintf(bone_path, sizeof bone_path, "%s/bone.obj", bone_dir);
  FILE* obj_file = fopen(bone_path, "w");
  CHECK(obj_file != NULL);
  static const int kAxes[6][3] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                  {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
  for (int v = 0; v < 6; ++v) {
    fprintf(obj_file, "v");
    for (int c = 0; c < 3; ++c) {
      fprintf(obj_file, " %.9g",
              (head.rest_position[c] + tail.rest_position[c]) / 2 + radius * kAxes[v][c]);
    }
    fprintf(obj_file, "\n");
  }
  /* Outward: each face's corners counter-clockwise seen from outside. */
  fputs("f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n", obj_file);
  CHECK(fclose(obj_file) == 0);
  char spec[700];
  snprintf(spec, sizeof spec, "%s:0", bone_path);
  const char* specs[1] = {spec};
  deform_mesh* with_bone = NULL;
  CHECK(deform_load_files_with_bones(client, obj, tgf, NULL, NULL, 1, &with_bone) ==
        DEFORM_INVALID_ARGUMENT);
  CHECK(deform_load_files_with_bones(client, obj, tgf, NULL, specs, 1, &with_bone) == DEFORM_OK);
  unlink(bone_path);
  rmdir(bone_dir);
  uint32_t surfaces = 0;
  CHECK(deform_mesh_bone_surface_count(with_bone, &surfaces) == DEFORM_OK && surfaces == 1);
  deform_bone_surface_info surface;
  CHECK(deform_mesh_bone_surface(with_bone, 0, &surface) == DEFORM_OK);
  CHECK(strcmp(surface.name, "bone") == 0 && surface.bone == 0);
  CHECK(surface.vertex_count == 6 && surface.triangle_count == 8);
  float octahedron[18];
  CHECK(deform_mesh_bone_surface_geometry(with_bone, 0, octahedron, 18, NULL, 0) == DEFORM_OK);
  CHECK(fabs(octahedron[0] - ((head.rest_position[0] + tail.rest_position[0]) / 2 + radius)) <
        1e-4 * (1 + radius));
  const char* with_bone_id = NULL;
  CHECK(deform_mesh_id(with_bone, &with_bone_id) == DEFORM_OK);
  CHECK(deform_stream_open(client, with_bone_id, DEFORM_ENCODING_FLOAT32, 0, &stream) == DEFORM_OK);
  CHECK(deform_stream_send_pose_text(stream, "1:x:90", &sequence) == DEFORM_OK);
  frame_for(stream, sequence, frame, floats, &info);
  float motion[12];
  deform_frame_constraints constraints;
  CHECK(deform_stream_frame_bones(stream, motion, 12, &constraints) == DEFORM_OK);
  CHECK(constraints.bone_surface_count == 1 && constraints.constrained);
  CHECK(deform_stream_close(stream, 5000) == DEFORM_OK);
  deform_stream_free(stream);
  CHECK(deform_unload_mesh(client, with_bone_id) == DEFORM_OK);
  deform_mesh_free(with_bone);

  CHECK(deform_unload_mesh(client, mesh_id) == DEFORM_OK);
  deform_mesh_free(mesh);
  deform_client_free(client);
  free(rest);
  free(frame);
}

/* A server with a token file: no token UNAUTHENTICATED, the right one gets in. */
static void test_token_server(void) {
  /* The token and its SHA-256 (printf '%s' TOKEN | sha256sum). */
  const char* token = "c-api-test-token-7d41f2";
  const char* token_hash = "c53c33fbc907f15028b9e1996be54c63b8367fbe1cbffe85e61699fbc395e8d5";
  char token_file[] = "/tmp/deformd-c-api-tokens-XXXXXX";
  const int fd = mkstemp(token_file);
  CHECK(fd >= 0);
  char line[160];
  const int length = snprintf(line, sizeof line, "%s  ward-c  tenant\n", token_hash);
  CHECK(write(fd, line, (size_t)length) == length);
  close(fd);
  deformd_process server;
  memset(&server, 0, sizeof server);
  g_servers[1] = &server;
  const char* const extra[] = {"--token-file", token_file, NULL};
  start_deformd(&server, extra);

  deform_client* anonymous = connect_to(server.target, NULL);
  size_t count = 0;
  CHECK(deform_list_meshes(anonymous, NULL, 0, NULL, &count) == DEFORM_UNAUTHENTICATED);
  printf("c_api_test: without a token: %s\n", deform_last_error());
  deform_mesh* mesh = NULL;
  CHECK(deform_load_phantom(anonymous, 400, NULL, &mesh) == DEFORM_UNAUTHENTICATED);
  deform_client_free(anonymous);

  deform_client* wrong = connect_to(server.target, "not-the-token");
  CHECK(deform_list_meshes(wrong, NULL, 0, NULL, &count) == DEFORM_UNAUTHENTICATED);
  deform_client_free(wrong);

  deform_client* client = connect_to(server.target, token);
  CHECK(deform_load_phantom(client, 400, NULL, &mesh) == DEFORM_OK);
  size_t needed = 0;
  CHECK(deform_list_meshes(client, NULL, 0, &needed, &count) == DEFORM_INVALID_ARGUMENT);
  CHECK(count == 1);
  deform_mesh_free(mesh);
  deform_client_free(client);

  CHECK(stop_deformd(&server) == 0);
  unlink(token_file);

  /* Nothing listens there any more: a bounded connect says so. */
  deform_connect_options options;
  memset(&options, 0, sizeof options);
  options.target = server.target;
  options.connect_timeout_ms = 300;
  deform_client* nobody = NULL;
  CHECK(deform_connect(&options, &nobody) == DEFORM_UNAVAILABLE && nobody == NULL);
}

/* The whole of a small text file, NUL-terminated (malloc'd). */
static char* read_text(const char* path) {
  FILE* file = fopen(path, "rb");
  CHECK(file != NULL);
  char* text = malloc(65536);
  CHECK(text != NULL);
  const size_t length = fread(text, 1, 65535, file);
  fclose(file);
  text[length] = '\0';
  return text;
}

/* A server with mutual TLS (certificates from scripts/make-test-certificates.sh): plaintext and a
 * client without a certificate, or with one from another CA, do not get in; the CA and client
 * certificate as files or as PEM text do, with the server name given. */
static void test_tls_server(void) {
  char dir[] = "/tmp/deform-c-api-certs-XXXXXX";
  CHECK(mkdtemp(dir) != NULL);
  const pid_t maker = fork();
  CHECK(maker >= 0);
  if (maker == 0) {
    const int null_fd = open("/dev/null", O_WRONLY);
    dup2(null_fd, STDOUT_FILENO);
    execl("/bin/bash", "bash", DEFORM_SOURCE_DIR "/scripts/make-test-certificates.sh", dir,
          (char*)NULL);
    _exit(127);
  }
  int made = 0;
  CHECK(waitpid(maker, &made, 0) == maker && WIFEXITED(made) && WEXITSTATUS(made) == 0);
  char ca[128], server_cert[128], server_key[128], client_cert[128], client_key[128],
      other_cert[128], other_key[128];
  snprintf(ca, sizeof ca, "%s/ca.pem", dir);
  snprintf(server_cert, sizeof server_cert, "%s/server.pem", dir);
  snprintf(server_key, sizeof server_key, "%s/server.key", dir);
  snprintf(client_cert, sizeof client_cert, "%s/client.pem", dir);
  snprintf(client_key, sizeof client_key, "%s/client.key", dir);
  snprintf(other_cert, sizeof other_cert, "%s/other-client.pem", dir);
  snprintf(other_key, sizeof other_key, "%s/other-client.key", dir);

  deformd_process server;
  memset(&server, 0, sizeof server);
  g_servers[1] = &server;
  const char* const extra[] = {"--tls-cert",      server_cert, "--tls-key", server_key,
                               "--tls-client-ca", ca,          NULL};
  start_deformd(&server, extra);

  deform_connect_options options;
  memset(&options, 0, sizeof options);
  options.target = server.target;
  options.connect_timeout_ms = 1500;
  deform_client* client = NULL;
  CHECK(deform_connect(&options, &client) == DEFORM_UNAVAILABLE); /* plaintext */
  options.ca_file = ca;
  CHECK(deform_connect(&options, &client) == DEFORM_UNAVAILABLE); /* no client certificate */
  options.cert_file = other_cert;
  options.key_file = other_key;
  CHECK(deform_connect(&options, &client) == DEFORM_UNAVAILABLE); /* another CA's client */
  CHECK(client == NULL);

  options.cert_file = client_cert;
  options.key_file = client_key;
  options.server_name = "not-the-server"; /* the certificate is for localhost and 127.0.0.1 */
  CHECK(deform_connect(&options, &client) == DEFORM_UNAVAILABLE);
  options.server_name = "localhost";
  options.connect_timeout_ms = 10000;
  CHECK(deform_connect(&options, &client) == DEFORM_OK);
  deform_mesh* mesh = NULL;
  CHECK(deform_load_phantom(client, 400, NULL, &mesh) == DEFORM_OK);
  deform_mesh_free(mesh);
  deform_client_free(client);

  deform_connect_options pem;
  memset(&pem, 0, sizeof pem);
  pem.target = server.target;
  pem.ca_pem = read_text(ca);
  pem.cert_pem = read_text(client_cert);
  pem.key_pem = read_text(client_key);
  pem.connect_timeout_ms = 10000;
  CHECK(deform_connect(&pem, &client) == DEFORM_OK);
  size_t count = 0;
  CHECK(deform_list_meshes(client, NULL, 0, NULL, &count) == DEFORM_INVALID_ARGUMENT);
  CHECK(count == 1);
  deform_client_free(client);
  free((char*)pem.ca_pem);
  free((char*)pem.cert_pem);
  free((char*)pem.key_pem);
  printf(
      "c_api_test: mutual TLS: refused plaintext, no certificate, another CA's and a wrong "
      "server name; files and PEM text got in\n");

  CHECK(stop_deformd(&server) == 0);
  const char* names[] = {"ca.pem",           "ca.key",           "server.pem",   "server.key",
                         "client.pem",       "client.key",       "other-ca.pem", "other-ca.key",
                         "other-client.pem", "other-client.key", "expired.pem",  "expired.key"};
  for (size_t k = 0; k < sizeof names / sizeof names[0]; ++k) {
    char path[160];
    snprintf(path, sizeof path, "%s/%s", dir, names[k]);
    unlink(path);
  }
  CHECK(rmdir(dir) == 0);
}

int main(void) {
  signal(SIGPIPE, SIG_IGN);
  test_arguments_without_a_server();
  deformd_process server;
  memset(&server, 0, sizeof server);
  g_servers[0] = &server;
  start_deformd(&server, NULL);
  test_phantom_session(server.target);
  test_files(server.target);
  CHECK(stop_deformd(&server) == 0);
  test_token_server();
  test_tls_server();
  printf("c_api_test: passed\n");
  return 0;
}
