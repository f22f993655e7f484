#pragma once
// Stitching: a track that ends is joined to one that starts a little later near
// where the ended one was heading (a marker hidden for a while behind a
// neighbour, or turned away, comes back as a new track of the Linker).
//
// For an ended track A and a track B that starts after it:
//   gap       = B's first frame − A's last frame − 1 (frames with neither), at most
//               max_gap_frames;
//   miss      = |B's first pixel − A extrapolated to B's first time| (px): A's last
//               velocity_points points fitted by a straight line in time (least
//               squares, per axis; one point stands still), at most max_distance_px.
// A pair within both gates is a candidate. A is joined to B only when each is the
// other's nearest candidate and that candidate is clearly the nearer one: the
// runner-up (on either side) misses by more than its miss / ambiguity_ratio.
// A track that had a candidate on a side (after its end, before its start) and was
// not joined there is *unresolved*: it is reported and left apart, never merged by
// a guess. Joins chain (A → B → C); the joined track
// keeps the id of its first piece.
#include <vector>

#include "rocklab/track/link.h"

namespace rocklab::track {

struct StitchSettings {
  int max_gap_frames = 25;        // frames: longest gap bridged (0 = stitching off)
  double max_distance_px = 10.0;  // px: farthest start from the extrapolation
  int velocity_points = 8;        // points of the ended track fitted for its velocity (>= 2)
  double ambiguity_ratio = 0.5;   // [-] in (0, 1]: best miss <= ratio × the runner-up's

  /// Throws std::invalid_argument naming the first invalid field ("stitch.max_gap_frames ...").
  void validate() const;
};

struct StitchJoin {
  int from_id = 0, to_id = 0;  // the ended track and the one it continues as
  int gap_frames = 0;          // frames without either
  double miss_px = 0.0;        // distance from the extrapolation
};

struct StitchResult {
  std::vector<Track> tracks;   // joined, by id (ids of the continuing pieces are gone)
  std::vector<StitchJoin> joins;
  std::vector<int> unresolved;  // ids (before joining) of tracks with an ambiguous candidate, ascending
};

/// Tracks as Linker::tracks() gives them (points by increasing frame, none empty).
/// `ended_ambiguous` (Linker::ambiguousEnds): tracks that ended at an ambiguous
/// match; they are joined only as above (the least-squares extrapolation and the
/// ratio test decide what the linker's 2-point prediction could not), and one not
/// continued is listed unresolved.
StitchResult stitchTracks(const std::vector<Track>& tracks, const StitchSettings& settings,
                          const std::vector<int>& ended_ambiguous = {});

}  // namespace rocklab::track
