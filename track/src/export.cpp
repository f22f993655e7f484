#include "rocklab/track/export.h"

#include <algorithm>
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>

#include "rocklab/track/plane.h"

namespace rocklab::track {

namespace {

// `rows` prints the rows into the temporary file beside `path` (false on a failed
// write); the file then replaces `path` whole, or is removed.
template <typename Rows>
void writeAtomically(const std::filesystem::path& path, const char* what, const char* header, Rows&& rows) {
  std::filesystem::path temporary = path;
  temporary += ".tmp";
  std::FILE* f = std::fopen(temporary.c_str(), "w");
  if (!f) throw std::runtime_error(std::string(what) + ": cannot open " + temporary.string() + " for writing");
  bool ok = std::fputs(header, f) >= 0;
  ok = ok && rows(f);
  ok = (std::fclose(f) == 0) && ok;
  std::error_code error;
  if (ok) std::filesystem::rename(temporary, path, error);
  if (!ok || error) {
    std::filesystem::remove(temporary, error);
    throw std::runtime_error(std::string(what) + ": cannot write " + path.string());
  }
}

bool printWorld(std::FILE* f, const std::optional<geometry::Vec3>& x, const char* end) {
  return x ? std::fprintf(f, "%.9g,%.9g,%.9g%s", x->x(), x->y(), x->z(), end) > 0
           : std::fprintf(f, "nan,nan,nan%s", end) > 0;
}

}  // namespace

void writeTracksCsv(const std::filesystem::path& path, const std::vector<Track>& tracks,
                    const geometry::Camera& camera, const geometry::Vec3& plane_point,
                    const geometry::Vec3& plane_normal) {
  // Rows: (frame, id, point), sorted by frame then id.
  std::vector<std::tuple<int, int, const TrackPoint*>> rows;
  for (const Track& t : tracks)
    for (const TrackPoint& p : t.points) rows.emplace_back(p.frame, t.id, &p);
  std::sort(rows.begin(), rows.end(), [](const auto& a, const auto& b) {
    return std::tie(std::get<0>(a), std::get<1>(a)) < std::tie(std::get<0>(b), std::get<1>(b));
  });
  writeAtomically(path, "writeTracksCsv", "frame,time_s,id,u_px,v_px,x_m,y_m,z_m\n", [&](std::FILE* f) {
    bool ok = true;
    for (const auto& [frame, id, p] : rows) {
      ok = ok && std::fprintf(f, "%d,%.9g,%d,%.4f,%.4f,", frame, p->time, id, p->pixel.x, p->pixel.y) > 0;
      ok = ok && printWorld(f, pointToWorld(camera, *p, plane_point, plane_normal), "\n");
    }
    return ok;
  });
}

void writePairedCsv(const std::filesystem::path& path, const TrackingEvaluation& evaluation,
                    const std::vector<TruthMarker>& truth) {
  writeAtomically(path, "writePairedCsv",
                  "frame,marker,track_id,truth_u_px,truth_v_px,tracked_u_px,tracked_v_px,truth_x_m,truth_y_m,"
                  "truth_z_m,tracked_x_m,tracked_y_m,tracked_z_m\n",
                  [&](std::FILE* f) {
                    bool ok = true;
                    for (const PairedPoint& p : evaluation.paired) {
                      const int id = p.marker < truth.size() ? truth[p.marker].id : -1;
                      ok = ok && std::fprintf(f, "%d,%d,%d,%.4f,%.4f,%.4f,%.4f,", p.frame, id, p.track_id,
                                              p.truth_pixel.x, p.truth_pixel.y, p.tracked_pixel.x,
                                              p.tracked_pixel.y) > 0;
                      ok = ok && printWorld(f, p.truth_world, ",");
                      ok = ok && printWorld(f, p.tracked_world, "\n");
                    }
                    return ok;
                  });
}

}  // namespace rocklab::track
