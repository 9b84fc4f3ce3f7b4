#pragma once
// Display-to-capture latency (projector–camera synchronisation, [Raskar02] §4.1.1:
// every structured-light capture must see the pattern shown before it). An
// output switches a test region between two levels at a known time; a camera
// keeps capturing it; the latency is when the new level first appears in the
// captures, less the time the switch was shown. Pure: times in seconds on one
// clock, brightness in any unit (camera DN).
#include <vector>

#include "core/error.hpp"

namespace procam::sl {

struct BrightnessSample {
  double time = 0;        // capture timestamp (s), the exposure's start
  double brightness = 0;  // mean level of the test region
};

struct TransitionOptions {
  // Smallest |new - old| level difference accepted, in brightness units.
  double min_contrast = 8.0;
  // The level difference must also exceed this many noise sigmas (estimated from
  // the samples on either side of the switch).
  double min_snr = 6.0;
  // Samples at the end of the sequence that give the new level (at least 1).
  int settled_samples = 3;
};

struct Transition {
  double appeared = 0;   // time the new level appears (s), on the samples' clock
  double latency = 0;    // appeared - shown (s), >= 0
  double old_level = 0;  // median of the samples taken before the switch was shown
  double new_level = 0;  // median of the last `settled_samples` samples
  double noise = 0;      // robust sigma of the two levels' samples
  int first_new = -1;    // index of the first sample past the midpoint for good
};

// `samples` in time order; `shown` is when the switch was handed to the output.
// Samples with time < shown give the old level (at least one is needed), the
// last `settled_samples` the new one. The crossing is the first sample past the
// midpoint of the two levels after which every sample stays past it (a noise
// spike before the change does not count). The time is interpolated linearly to
// the midpoint between that sample and the one before, so it stays inside the
// interval that holds the change: its middle for instantaneous samples (error at
// most half a frame period), moved towards the sample whose exposure straddled
// the switch when one caught part of it. For a camera that integrates over an
// exposure e with timestamps at its start the half-level crossing is e/2 before
// the change, so the estimate comes up to 0.6 e early (the settle margin covers it).
// Levels are measured, never assumed, so ambient light (an offset on both) and
// the camera's gain cancel.
// kInvalidInput: no sample before `shown`, fewer than `settled_samples` after
// it, non-finite values, times not increasing; kIllConditioned: no sample after
// `shown` differs from the old level by `min_contrast` and `min_snr` noise
// sigmas (the camera does not see the region change, the contrast is too low, or
// the change comes after the last sample); kNotFound: a change is seen but the
// sequence does not end settled past the midpoint (it had not finished, or it
// went back).
Result<Transition> findTransition(const std::vector<BrightnessSample>& samples, double shown,
                                  const TransitionOptions& options = {});

// True once the last `options.settled_samples` samples after `shown` agree with
// one another (spread within a quarter of their distance from the old level)
// and differ from the old level by the contrast findTransition needs: the
// capture loop may stop.
bool transitionSettled(const std::vector<BrightnessSample>& samples, double shown,
                       const TransitionOptions& options = {});

struct LatencyStats {
  double median = 0;  // s
  double spread = 0;  // max - min (s)
  double min = 0, max = 0;
  int count = 0;
};

// kInvalidInput when `latencies` is empty or holds a non-finite value.
Result<LatencyStats> latencyStats(std::vector<double> latencies);

// Output frames to wait after showing a pattern: ceil(latency * refresh_hz) +
// margin_frames (a latency within 1e-9 frames of a whole frame count rounds down).
int settleFrames(double latency_s, double refresh_hz, int margin_frames);

}  // namespace procam::sl
