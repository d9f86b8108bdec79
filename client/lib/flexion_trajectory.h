// The knee flexion the clients play (deform-vr's trajectory, every deform-loadtest pose): rest,
// bend to the peak, back to rest, once per cycle.
#pragma once

namespace deform::client {

// Flexion in degrees at `t_seconds`: peak * (1 - cos(2 pi t / cycle)) / 2, i.e. 0 at the start of
// each cycle, `peak_degrees` at its middle, and smooth (zero velocity) at both turning points.
// Precondition: cycle_seconds > 0.
double FlexionDegreesAt(double t_seconds, double cycle_seconds, double peak_degrees);

}  // namespace deform::client
