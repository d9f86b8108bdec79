// The sample of the package: bends the built-in knee phantom's knee from 0 to 120 degrees and
// back, over and over, through a DeformMeshStreamer on the same GameObject. Add both to an empty
// GameObject with a MeshRenderer and a material, start a deformd on 127.0.0.1:50051
// (build/server/deformd/deformd), and press Play.
using UnityEngine;

namespace Deformd.Samples {

[RequireComponent(typeof(DeformMeshStreamer))]
public sealed class KneeFlexionSample : MonoBehaviour {
  [Tooltip("Seconds for 0 -> 120 -> 0 degrees")]
  public float period = 4;
  public float maxDegrees = 120;

  DeformMeshStreamer streamer;

  // The streamer's defaults fit the phantom: no mesh id (a new phantom), 0.1 m per unit
  // (decimeters), Y up.
  void Awake() { streamer = GetComponent<DeformMeshStreamer>(); }

  void Update() {
    float phase = Mathf.PingPong(2 * Time.time / period, 1);
    streamer.SetJointAngle("knee", "flexion", phase * maxDegrees);
  }

  void OnGUI() {
    Deform.FrameInfo frame = streamer.LastFrame;
    GUI.Label(new Rect(10, 10, 600, 20),
              string.Format("pose {0}: {1:F1} ms pose to frame, {2:F1} ms on the server",
                            frame.sequence, frame.latencyMs, frame.serverMs));
  }
}

}  // namespace Deformd.Samples
