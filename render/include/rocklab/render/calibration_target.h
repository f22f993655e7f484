#pragma once
// A planar checkerboard calibration target, as a lab prints one, for rendering
// the calibration photographs (cv::findChessboardCorners reads them back).
#include "rocklab/geometry/vec.h"
#include "rocklab/render/frame.h"

namespace rocklab::render {

struct Checkerboard {
  int inner_cols = 9;    // inner corners along the board's x axis
  int inner_rows = 6;    // inner corners along its y axis (≠ inner_cols: no 90° ambiguity)
  double square = 0.02;  // m, side of one square
};

/// Board frame → world: corner (row i, column j) of the inner-corner grid lies at
/// board (j · square, i · square, 0), i.e. at origin + rotation · (j s, i s, 0).
struct BoardPlacement {
  Mat3 rotation = Mat3::Identity();  // columns: the board's x, y, z axes in the world
  Vec3 origin = Vec3::Zero();        // m, world position of the first inner corner
  Vec3 toWorld(const Vec3& board) const { return rotation * board + origin; }
};

/// The board's squares and a white border one square wide, as separate coplanar
/// polygons that never overlap (no depth fighting).
FrameDescription checkerboardFrame(const Checkerboard& board, const BoardPlacement& placement = {});

}  // namespace rocklab::render
