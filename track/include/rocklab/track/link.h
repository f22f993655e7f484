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
#include <limits>
#include <vector>

#include <opencv2/core.hpp>

#include "rocklab/geometry/vec.h"
#include "rocklab/track/detect.h"

namespace rocklab::track {

struct TrackPoint {
  int frame = 0;
  double time = 0.0;    // s
  cv::Point2d pixel;    // px, the marker's position: the detection's centroid, or the shape fit's centre
  cv::Point2d detected = {std::numeric_limits<double>::quiet_NaN(), 0.0};  // px, the detection's centroid
                        // (the linker predicts from these; NaN = the same as pixel)
  // m, world: the marker's centre when the shape fit gave it (its depth from the
  // clump touching the wall); NaN = not fitted (pixel → world on the marker plane).
  geometry::Vec3 centre = geometry::Vec3::Constant(std::numeric_limits<double>::quiet_NaN());
  bool merged = false;  // the detection held two or more markers (Detection::merged)
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
  /// The track of each of predictions(frame, ...), in the same order.
  std::vector<int> predictedTracks(int frame) const;

  /// Every track so far (ended or not; withdrawn ones with no point left are left
  /// out), by id.
  std::vector<Track> tracks() const;
  /// The track each detection of the last add() went to (extended or started), by
  /// detection index.
  const std::vector<int>& lastTrackIds() const { return last_track_ids_; }
  /// The model-based position of a track's point in the last add() (shape_fit.h):
  /// `pixel` replaces the reported position (the centroid stays for prediction),
  /// `centre` is the fitted world centre. Throws std::invalid_argument when the
  /// track has no point in the last frame.
  void refineLastPoint(int id, cv::Point2d pixel, const geometry::Vec3& centre);
  /// A track whose point in the last add() repeats another track's marker (the
  /// shape fit found both on one clump): that point is removed and the track ends;
  /// a track left without points is gone from tracks(). Throws std::invalid_argument
  /// when the track has no point in the last frame.
  void withdraw(int id);
  /// Points of a track so far.
  std::size_t pointCount(int id) const { return tracks_.at(static_cast<std::size_t>(id)).points.size(); }
  /// Ids of the tracks that ended at an ambiguous match (step 5), ascending.
  const std::vector<int>& ambiguousEnds() const { return ambiguous_ends_; }

 private:
  bool retired(int id, int frame) const;

  LinkSettings settings_;
  std::vector<Track> tracks_;  // index = id
  std::vector<int> active_;    // ids of tracks that may still be found
  std::vector<int> ambiguous_ends_;
  std::vector<int> last_track_ids_;  // per detection of the last frame
  int last_frame_ = 0;
  double last_time_ = 0.0;
  bool started_ = false;
};

}  // namespace rocklab::track
