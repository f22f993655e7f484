#include <algorithm>
#include <cstdint>

#include "detect_internal.h"

namespace rocklab::track::detail {

namespace {

struct Run {
  int row, start, end;  // mask row, columns [start, end)
  int parent;           // union-find over run indices
};

int nextZero(const std::uint8_t* row, int from, int width) {
  int u = from;
  while (u < width && row[u] != 0) ++u;
  return u;
}

int root(std::vector<Run>& runs, int k) {
  while (runs[static_cast<std::size_t>(k)].parent != k) {
    Run& r = runs[static_cast<std::size_t>(k)];
    r.parent = runs[static_cast<std::size_t>(r.parent)].parent;  // path halving
    k = r.parent;
  }
  return k;
}

}  // namespace

Components labelComponents(const cv::Mat& mask) {
  CV_Assert(mask.type() == CV_8U);
  // 1. Runs of set pixels, row by row; each joined to the runs of the row above that
  // it touches (8-connected: they overlap once widened by one column).
  std::vector<Run> runs;
  std::size_t above_begin = 0, above_end = 0;  // runs of the row above
  for (int v = 0; v < mask.rows; ++v) {
    const std::uint8_t* row = mask.ptr<std::uint8_t>(v);
    const std::size_t row_begin = runs.size();
    std::size_t a = above_begin;
    for (int u = nextNonzero(row, 0, mask.cols); u < mask.cols; u = nextNonzero(row, u, mask.cols)) {
      const int end = nextZero(row, u, mask.cols);
      const int self = static_cast<int>(runs.size());
      runs.push_back({v, u, end, self});
      while (a < above_end && runs[a].end < u) ++a;  // ends left of this run's widened start
      for (std::size_t b = a; b < above_end && runs[b].start <= end; ++b) {
        const int x = root(runs, self), y = root(runs, static_cast<int>(b));
        runs[static_cast<std::size_t>(std::max(x, y))].parent = std::min(x, y);
      }
      u = end;
    }
    above_begin = row_begin;
    above_end = runs.size();
  }
  // 2. Labels 1, 2... in order of the components' first runs (raster order), areas,
  // boxes, and the label image.
  Components out;
  out.mask = mask;
  out.labels.create(mask.size(), CV_32S);
  out.areas.push_back(0);
  out.boxes.emplace_back();
  std::vector<int> label_of(runs.size(), 0);
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const Run& r = runs[k];
    const std::size_t top = static_cast<std::size_t>(root(runs, static_cast<int>(k)));
    if (label_of[top] == 0) {
      label_of[top] = static_cast<int>(out.areas.size());
      out.areas.push_back(0);
      out.boxes.emplace_back(r.start, r.row, 0, 0);
    }
    const int label = label_of[top];
    out.areas[static_cast<std::size_t>(label)] += r.end - r.start;
    cv::Rect& box = out.boxes[static_cast<std::size_t>(label)];
    const int x0 = std::min(box.x, r.start), x1 = std::max(box.x + box.width, r.end);
    box = cv::Rect(x0, box.y, x1 - x0, r.row + 1 - box.y);
    int* labels = out.labels.ptr<int>(r.row);
    std::fill(labels + r.start, labels + r.end, label);
  }
  return out;
}

}  // namespace rocklab::track::detail
