// DeformAxes: deformd's coordinates in Unity's. deformd streams positions in the mesh's own
// units, vertex order and right-handed frame (the built-in phantom: decimeters, Y up). Unity is
// left-handed, Y up, in meters. Both conversions below are a reflection, so they also reverse
// every triangle's winding (Unity culls clockwise-wound back faces as seen from the camera):
//   Y up (the phantom, glTF, most rigs):  Unity (x, y, z) = metersPerUnit * ( x, y, -z)
//   Z up (many scanners, CAD, DICOM-derived meshes): Unity (x, y, z) = metersPerUnit * ( x, z,  y)
// Joint angles need no conversion: a pose names a joint's own degree of freedom ("knee",
// "flexion"), which the server resolves in the mesh's frame.
// Plain C#, no UnityEngine: compiled and run under Mono by tests/client/unity_stream_test.sh.
using System;

namespace Deformd {

// The up axis of the mesh as the server holds it (right-handed in both cases).
public enum SourceUp { Y = 0, Z = 1 }

public struct DeformAxes {
  public readonly float MetersPerUnit;
  public readonly SourceUp Up;

  public DeformAxes(float metersPerUnit, SourceUp up) {
    if (!(metersPerUnit > 0))
      throw new ArgumentOutOfRangeException("metersPerUnit", "must be positive");
    MetersPerUnit = metersPerUnit;
    Up = up;
  }

  // `floats` floats of `source` (x, y, z per vertex, deformd's frame) into `destination` (Unity's
  // frame); the two may be the same array. Allocates nothing.
  public void ConvertPositions(float[] source, float[] destination, int floats) {
    float s = MetersPerUnit;
    if (Up == SourceUp.Y) {
      for (int i = 0; i + 2 < floats; i += 3) {
        float x = source[i], y = source[i + 1], z = source[i + 2];
        destination[i] = s * x;
        destination[i + 1] = s * y;
        destination[i + 2] = -s * z;
      }
    } else {
      for (int i = 0; i + 2 < floats; i += 3) {
        float x = source[i], y = source[i + 1], z = source[i + 2];
        destination[i] = s * x;
        destination[i + 1] = s * z;
        destination[i + 2] = s * y;
      }
    }
  }

  // One point, deformd's frame to Unity's.
  public void ToUnity(double x, double y, double z, out float ux, out float uy, out float uz) {
    float s = MetersPerUnit;
    ux = (float)(s * x);
    if (Up == SourceUp.Y) {
      uy = (float)(s * y);
      uz = (float)(-s * z);
    } else {
      uy = (float)(s * z);
      uz = (float)(s * y);
    }
  }

  // One point, Unity's frame back to deformd's (tool centers, root motion).
  public void FromUnity(float ux, float uy, float uz, out double x, out double y, out double z) {
    double inverse = 1.0 / MetersPerUnit;
    x = inverse * ux;
    if (Up == SourceUp.Y) {
      y = inverse * uy;
      z = -inverse * uz;
    } else {
      y = inverse * uz;
      z = inverse * uy;
    }
  }

  // The server's triangles (3 indices each) as Unity's: the same vertices, winding reversed.
  public static int[] ConvertTriangles(uint[] source) {
    var triangles = new int[source.Length];
    for (int i = 0; i + 2 < source.Length; i += 3) {
      triangles[i] = checked((int)source[i]);
      triangles[i + 1] = checked((int)source[i + 2]);
      triangles[i + 2] = checked((int)source[i + 1]);
    }
    return triangles;
  }
}

}  // namespace Deformd
