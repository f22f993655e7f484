#pragma once
// Smoothing a track in time. The model-based position jitters by a few tenths of
// a pixel from frame to frame (the visible outline changes as neighbours pass), and
// the velocity's onset (2 mm of travel, reached while the marker is still slow)
// turns that jitter into timing: 0.4 mm at 0.1 m/s is 4 ms, 1 % of the velocity.
#include <vector>

#include "rocklab/track/link.h"

namespace rocklab::track {

/// Each point's pixel and fitted centre (when it has one) replaced by the value at
/// its time of a least-squares quadratic in time through the track's points within
/// ±half_window frames (a constant acceleration passes unbiased; a point with fewer
/// than 5 such neighbours, itself included, is left alone). `detected` is kept.
void smoothTrack(Track& track, int half_window);

}  // namespace rocklab::track
