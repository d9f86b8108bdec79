// The volume a triangle mesh encloses and its gradient, with the mesh's boundary found once: what
// a per-frame volume constraint evaluates without allocating.
#pragma once

#include <vector>

#include "core/geometry/mesh.h"

namespace deform {

class VolumeClosure {
 public:
  // The closure of a mesh with these triangles: an open mesh is closed by a fan from each boundary
  // loop's centroid (the mean of its edges' ends, computed from the positions given to Volume, so
  // the cap moves with the mesh). `num_vertices` bounds the triangles' indices.
  VolumeClosure(const Triangles& triangles, int num_vertices);

  // The enclosed volume of the mesh with positions `xyz` (row i at xyz[3 i]; at least
  // num_vertices rows). No allocation.
  double Volume(const double* xyz) const;
  // gradient[3 i + c] = dV / dx_ic for the first num_vertices rows (overwritten). No allocation.
  void Gradient(const double* xyz, double* gradient) const;

  // The volume along a line, V(xyz + t * direction) = c[0] + c[1] t + c[2] t^2 + c[3] t^3 (a
  // cubic: the volume is a sum of triple products). No allocation.
  void VolumeAlong(const double* xyz, const double* direction, double c[4]) const;

  // The closure as a mesh at `positions` (num_vertices rows): the mesh's triangles, then each
  // boundary loop's fan, its centroid a vertex appended after the mesh's (one per loop, in loop
  // order). What a point-inside test on an open skin (a limb cut at its ends) asks.
  TriangleMesh ClosedMesh(const Positions& positions) const;

  int num_vertices() const { return num_vertices_; }
  bool closed() const { return loops_.empty(); }

 private:
  struct Loop {
    int first_edge = 0;  // its edges are boundary_[first_edge, first_edge + edges)
    int edges = 0;
  };
  // The centroid of loop l (the mean of its edges' ends).
  void Centroid(const double* xyz, const Loop& loop, double* c) const;

  int num_vertices_ = 0;
  Triangles triangles_;
  std::vector<int> boundary_;  // directed boundary edges (a, b), 2 ints each, grouped by loop
  std::vector<Loop> loops_;
};

}  // namespace deform
