/* A program built outside the project against an installed libdeform_c (tests/client/
 * c_api_package_test.sh builds it twice: with pkg-config's flags alone, and as a CMake project
 * using find_package(deform_c)). Usage: c_api_consumer TARGET VERSION. Checks that
 * deform_version() is VERSION, then connects to the deformd at TARGET, loads the phantom, streams
 * a 90-degree knee flexion and checks that the frame answers that pose and moves the shin while
 * the hip stays. Exits 0 and prints one line when everything held, 1 with the failed check and
 * the last error otherwise. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "deform_c.h"

#define CHECK(condition)                                                                   \
  do {                                                                                     \
    if (!(condition)) {                                                                    \
      fprintf(stderr, "c_api_consumer: check failed: %s\n  deform_last_error(): \"%s\"\n", \
              #condition, deform_last_error());                                            \
      exit(1);                                                                             \
    }                                                                                      \
  } while (0)

int main(int argc, char** argv) {
  if (argc != 3) {
    fprintf(stderr, "usage: c_api_consumer TARGET VERSION\n");
    return 2;
  }
  CHECK(strcmp(deform_version(), argv[2]) == 0);

  deform_connect_options options;
  memset(&options, 0, sizeof options);
  options.target = argv[1];
  options.connect_timeout_ms = 10000;
  deform_client* client = NULL;
  CHECK(deform_connect(&options, &client) == DEFORM_OK);
  deform_mesh* mesh = NULL;
  CHECK(deform_load_phantom(client, 0, "consumer", &mesh) == DEFORM_OK);
  uint32_t vertices = 0;
  CHECK(deform_mesh_vertex_count(mesh, &vertices) == DEFORM_OK && vertices > 0);
  float* rest = malloc(3u * vertices * sizeof(float));
  float* frame = malloc(3u * vertices * sizeof(float));
  CHECK(rest != NULL && frame != NULL);
  CHECK(deform_mesh_rest_geometry(mesh, rest, 3u * vertices, NULL, 0) == DEFORM_OK);
  const char* mesh_id = NULL;
  CHECK(deform_mesh_id(mesh, &mesh_id) == DEFORM_OK);

  deform_stream* stream = NULL;
  CHECK(deform_stream_open(client, mesh_id, DEFORM_ENCODING_FLOAT32, 0.0, &stream) == DEFORM_OK);
  uint64_t sequence = 0;
  CHECK(deform_stream_send_pose_text(stream, "knee:flexion:90", &sequence) == DEFORM_OK);
  deform_frame_info info;
  memset(&info, 0, sizeof info);
  /* Frames answer the newest pose; wait (bounded) for the one answering ours. */
  for (int attempt = 0; attempt < 60 && info.sequence != sequence; ++attempt) {
    const deform_status status =
        deform_stream_next_frame(stream, frame, 3u * vertices, 1000, &info);
    CHECK(status == DEFORM_OK || status == DEFORM_NO_DATA);
  }
  CHECK(info.sequence == sequence && info.vertex_count == vertices);

  /* The phantom is Y up with the hip on top: the highest vertex (the hip's end) stays where it
   * was, and the lowest (the ankle's end) moves by a good part of the leg's length. */
  uint32_t top = 0, bottom = 0;
  for (uint32_t v = 1; v < vertices; ++v) {
    if (rest[3 * v + 1] > rest[3 * top + 1]) top = v;
    if (rest[3 * v + 1] < rest[3 * bottom + 1]) bottom = v;
  }
  /* Squared distances: no libm, so that the pkg-config build needs no flag of its own. */
  double top_moved2 = 0.0, bottom_moved2 = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    const double dt = frame[3 * top + axis] - rest[3 * top + axis];
    const double db = frame[3 * bottom + axis] - rest[3 * bottom + axis];
    top_moved2 += dt * dt;
    bottom_moved2 += db * db;
  }
  const double length = rest[3 * top + 1] - rest[3 * bottom + 1];
  CHECK(length > 0.0);
  CHECK(top_moved2 < 1e-6 * length * length);
  CHECK(bottom_moved2 > 0.04 * length * length);

  CHECK(deform_stream_close(stream, 10000) == DEFORM_OK);
  deform_stream_free(stream);
  CHECK(deform_unload_mesh(client, mesh_id) == DEFORM_OK);
  deform_mesh_free(mesh);
  deform_client_free(client);
  printf(
      "c_api_consumer: libdeform_c %s, %u vertices: pose %llu's frame kept the hip and moved the "
      "ankle end\n",
      deform_version(), vertices, (unsigned long long)sequence);
  free(rest);
  free(frame);
  return 0;
}
