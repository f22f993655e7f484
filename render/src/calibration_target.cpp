#include "rocklab/render/calibration_target.h"

namespace rocklab::render {

FrameDescription checkerboardFrame(const Checkerboard& board, const BoardPlacement& placement) {
  FrameDescription f;
  const Rgb black{0.04f, 0.04f, 0.04f}, white{0.92f, 0.92f, 0.92f};
  auto quad = [&](double x0, double y0, double x1, double y1, Rgb colour) {
    f.polygons.push_back({{placement.toWorld(Vec3(x0, y0, 0)), placement.toWorld(Vec3(x1, y0, 0)),
                           placement.toWorld(Vec3(x1, y1, 0)), placement.toWorld(Vec3(x0, y1, 0))},
                          colour,
                          1.0f});
  };
  const double s = board.square;
  const double x0 = -s, y0 = -s;  // outer corner of the squares
  const double x1 = x0 + (board.inner_cols + 1) * s, y1 = y0 + (board.inner_rows + 1) * s;
  for (int i = 0; i <= board.inner_rows; ++i)
    for (int j = 0; j <= board.inner_cols; ++j)
      quad(x0 + j * s, y0 + i * s, x0 + (j + 1) * s, y0 + (i + 1) * s, (i + j) % 2 ? white : black);
  quad(x0 - s, y0 - s, x1 + s, y0, white);  // border, one square wide
  quad(x0 - s, y1, x1 + s, y1 + s, white);
  quad(x0 - s, y0, x0, y1, white);
  quad(x1, y0, x1 + s, y1, white);
  return f;
}

}  // namespace rocklab::render
