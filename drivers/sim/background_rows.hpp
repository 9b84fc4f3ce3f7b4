#pragma once
// Where the virtual rig renders inside procamd. On a rig the cameras and projectors do
// their own work; under `procamd --sim` the renderer does it for them on the daemon's
// cores, and at the daemon's priority it delays the daemon's own pipeline on a small
// machine. The mock drivers therefore ask for background rendering: the rows run on
// threads of their own at nice +10, which the daemon's threads preempt (a per-thread
// attribute on Linux, see setpriority(2)), and which have the cores whenever the
// daemon leaves them idle.
#include <functional>

namespace procam::sim {

// Process-wide; off (OpenCV's pool) until the mock drivers turn it on.
void setBackgroundRendering(bool on);
bool backgroundRendering();

// body(row) for rows [0, rows) on one thread per core at nice +10; the caller waits.
// An exception from body stops the rows not yet started and is rethrown here after
// every thread has ended.
void forEachRowInBackground(int rows, const std::function<void(int)>& body);

}  // namespace procam::sim
