#pragma once
// Frame-to-frame linking of detections into tracks.
//
// Each frame (Linker::add), in order:
//   1. retire   — a track not found for more than max_missed_frames frames ends;
//   2. predict  — constant velocity: p = p_last + v (t − t_last), v from the last two
//                 points of the track (a one-point track stands still);
//   3. cost     — squared pixel distance prediction → detection; pairs farther than
//                 max_distance_px are forbidden (the gate);
//   4. assign   — optimal (Hungarian) on the augmented matrix
//                     [ D      | miss ]      D: n tracks × m detections
//                     [ birth  |  0   ]      miss, birth: diagonal, cost gate²
//                 so a track may stay unmatched (cost gate²) and a detection may
//                 start a track (cost gate²): every allowed link (≤ gate²) beats
//                 leaving both of its ends unmatched (2 gate²);
//   5. update   — matched tracks grow; unmatched detections start new tracks. A
//                 track whose detection is not clearly its own (another detection,
//                 or another track's prediction, within the gate is less than
//                 1 / ambiguity_ratio times as far: e.g. a blob it followed came
//                 apart and its prediction lies between the pieces, or a neighbour
//                 vanished and its prediction lies next to this marker) ends there
//                 instead of guessing: it is listed in ambiguousEnds() and its
//                 detection starts a new track (stitching may join them, stitch.h).
// A track that missed some frames is re-found like any other (its prediction spans the gap).
#include <vector>

#include <opencv2/core.hpp>

#include "rocklab/track/detect.h"

namespace rocklab::track {

struct TrackPoint {
  int frame = 0;
  double time = 0.0;    // s
  cv::Point2d pixel;    // px
};

struct Track {
  int id = 0;                      // 0, 1, 2... in order of birth
  std::vector<TrackPoint> points;  // by increasing frame; missed frames have no point
};

struct LinkSettings {
  enum class Assignment {
    Hungarian,  // optimal: least total squared distance
    Greedy,     // cheapest pair first; only to show what Hungarian avoids
  };
  double max_distance_px = 20.0;  // gate: farthest detection from a prediction [px]
  int max_missed_frames = 3;      // frames a track may go unseen and still be re-found
  Assignment assignment = Assignment::Hungarian;
  // [-] in (0, 1]: a match must be nearer than ratio × the next detection in the
  // gate, else the track ends (ambiguous); 1 = never.
  double ambiguity_ratio = 1.0;

  /// Throws std::invalid_argument naming the first invalid field ("link.max_distance_px ...").
  void validate() const;
};

class Linker {
 public:
  explicit Linker(LinkSettings settings = {});

  /// Adds one frame. Frames and times must increase from call to call (else
  /// std::invalid_argument); frames may be skipped. An empty list is a frame
  /// where nothing was seen.
  void add(int frame, double time, const std::vector<Detection>& detections);

  /// Where each track that add(frame, time, ...) could still extend expects its
  /// marker (step 2), for the detector's prediction-seeded split (detect.h, 4a).
  /// Does not change the linker.
  std::vector<cv::Point2d> predictions(int frame, double time) const;

  /// Every track so far (ended or not), by id.
  std::vector<Track> tracks() const;
  /// Ids of the tracks that ended at an ambiguous match (step 5), ascending.
  const std::vector<int>& ambiguousEnds() const { return ambiguous_ends_; }

 private:
  bool retired(int id, int frame) const;

  LinkSettings settings_;
  std::vector<Track> tracks_;  // index = id
  std::vector<int> active_;    // ids of tracks that may still be found
  std::vector<int> ambiguous_ends_;
  int last_frame_ = 0;
  double last_time_ = 0.0;
  bool started_ = false;
};

}  // namespace rocklab::track
