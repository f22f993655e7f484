#include "rocklab/track/export.h"

#include <algorithm>
#include <cstdio>
#include <stdexcept>
#include <tuple>

#include "rocklab/track/plane.h"

namespace rocklab::track {

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

  std::filesystem::path temporary = path;
  temporary += ".tmp";
  std::FILE* f = std::fopen(temporary.c_str(), "w");
  if (!f) throw std::runtime_error("writeTracksCsv: cannot open " + temporary.string() + " for writing");
  bool ok = std::fprintf(f, "frame,time_s,id,u_px,v_px,x_m,y_m,z_m\n") > 0;
  for (const auto& [frame, id, p] : rows) {
    ok = ok && std::fprintf(f, "%d,%.9g,%d,%.4f,%.4f,", frame, p->time, id, p->pixel.x, p->pixel.y) > 0;
    if (const auto x = pointToWorld(camera, *p, plane_point, plane_normal))
      ok = ok && std::fprintf(f, "%.9g,%.9g,%.9g\n", x->x(), x->y(), x->z()) > 0;
    else
      ok = ok && std::fprintf(f, "nan,nan,nan\n") > 0;
  }
  ok = (std::fclose(f) == 0) && ok;
  std::error_code error;
  if (ok) std::filesystem::rename(temporary, path, error);
  if (!ok || error) {
    std::filesystem::remove(temporary, error);
    throw std::runtime_error("writeTracksCsv: cannot write " + path.string());
  }
}

}  // namespace rocklab::track
