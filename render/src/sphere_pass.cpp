#include "sphere_pass.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <tuple>

#include "bands.h"

namespace rocklab::render::detail {

namespace {

struct Box {  // canvas pixels
  double u0, v0, u1, v1;
};

std::uint8_t toByte(float v) { return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); }

// Normalised image extent of a sphere along one axis (Mara & McGuire 2013): in the
// plane of that axis and the optical axis the centre is (a, z); the tangents from
// the eye have slopes (a T ∓ z r) / (z T ± a r) with T = sqrt(a² + z² − r²).
// Needs z > r (the near-plane test guarantees it).
std::pair<double, double> extent(double a, double z, double r) {
  const double t = std::sqrt(a * a + z * z - r * r);
  return {(a * t - z * r) / (z * t + a * r), (a * t + z * r) / (z * t - a * r)};
}

// llvmpipe shades a primitive in blocks of 4 × 4 pixels (aligned to the canvas, whose
// sides are multiples of 4), a partly covered block at the cost of a whole one.
constexpr int kShadingBlock = 4;

// A point sprite is a square: the fewest pixels n on a side that hold `box` (the
// pixel centres within it), placed where it touches the fewest shading blocks, then
// where it reaches least beyond the sphere's whole image (its pixels there shade to
// nothing), and within the canvas where it can (points are clipped by their centre).
// Its edges lie halfway between pixel centres, so which pixels it holds is exact.
Box pointSquare(const Box& box, const Box& image, int canvasWidth, int canvasHeight) {
  const auto first = [](double edge) { return static_cast<int>(std::ceil(edge)); };
  const auto last = [](double edge) { return static_cast<int>(std::floor(edge)); };
  const int n = std::max(last(box.u1) - first(box.u0), last(box.v1) - first(box.v0)) + 1;
  const auto blockOf = [](int pixel) {  // floor(pixel / 4)
    return (pixel >= 0 ? pixel : pixel - kShadingBlock + 1) / kShadingBlock;
  };
  // Pixels a … a + n − 1 along one axis, holding lo … hi.
  const auto place = [&](double lo, double hi, double imageLo, double imageHi, int size) {
    const int i0 = first(imageLo), i1 = last(imageHi);
    const auto cost = [&](int a) {
      const bool outsideCanvas = a - 0.5 < 0.0 || a + n - 0.5 > size - 1.0;  // as `inside` in upload()
      const int beyondImage = std::max(0, i0 - a) + std::max(0, a + n - 1 - i1);
      return std::tuple{outsideCanvas, blockOf(a + n - 1) - blockOf(a), beyondImage};
    };
    int best = last(hi) - n + 1;
    auto bestCost = cost(best);
    for (int a = best + 1; a <= first(lo); ++a)
      if (const auto c = cost(a); c < bestCost) best = a, bestCost = c;
    return std::pair{best - 0.5, best + n - 0.5};
  };
  const auto [u0, u1] = place(box.u0, box.u1, image.u0, image.u1, canvasWidth);
  const auto [v0, v1] = place(box.v0, box.v1, image.v0, image.v1, canvasHeight);
  return {u0, v0, u1, v1};
}

}  // namespace

SpherePass::SpherePass(const GlApi& gl)
    : gl_(gl),
      program_(gl, kSphereVertexShader, kSphereFragmentShader, "sphere"),
      uCanvasSize_(program_.uniform("canvasSize")),
      uAsQuads_(program_.uniform("asQuads")),
      uPixelToRay_(program_.uniform("pixelToRay")),
      uWindowDepth_(program_.uniform("windowDepth")),
      uLighting_(program_.uniform("lighting")),
      uGain_(program_.uniform("gain")) {
  float range[2] = {1.0f, 1.0f};
  gl.GetFloatv(GL_POINT_SIZE_RANGE, range);
  maxPointSize_ = range[1];
  gl.GenVertexArrays(1, &pointVao_);
  gl.GenVertexArrays(1, &quadVao_);
  gl.GenBuffers(1, &vbo_);
  setAttributes(pointVao_, 0, 0);
  gl.check("sphere pass setup");
}

SpherePass::~SpherePass() {
  gl_.DeleteBuffers(1, &vbo_);
  gl_.DeleteVertexArrays(1, &pointVao_);
  gl_.DeleteVertexArrays(1, &quadVao_);
}

void SpherePass::setAttributes(GLuint vao, std::size_t firstInstance, GLuint divisor) const {
  const auto at = [&](std::size_t member) {
    return reinterpret_cast<const void*>(firstInstance * sizeof(Instance) + member);
  };
  gl_.BindVertexArray(vao);
  gl_.BindBuffer(GL_ARRAY_BUFFER, vbo_);
  gl_.EnableVertexAttribArray(0);
  gl_.VertexAttribPointer(0, 4, GL_FLOAT, GL_FALSE, sizeof(Instance), at(offsetof(Instance, sphere)));
  gl_.VertexAttribDivisor(0, divisor);
  gl_.EnableVertexAttribArray(1);
  gl_.VertexAttribPointer(1, 4, GL_FLOAT, GL_FALSE, sizeof(Instance), at(offsetof(Instance, box)));
  gl_.VertexAttribDivisor(1, divisor);
  gl_.EnableVertexAttribArray(2);
  gl_.VertexAttribPointer(2, 4, GL_UNSIGNED_BYTE, GL_TRUE, sizeof(Instance), at(offsetof(Instance, rgba)));
  gl_.VertexAttribDivisor(2, divisor);
  gl_.BindVertexArray(0);
}

void SpherePass::upload(const std::vector<SphereInstance>& spheres, const geometry::Mat3& rotation,
                        const geometry::Vec3& translation, const Canvas& canvas, double nearClip, double farClip,
                        double dt, const std::optional<CutPlane>& cut, const std::vector<Screen>& screens) {
  // Side planes of the canvas frustum (through the eye, two pixels outside the
  // canvas edges), inward unit normals: a sphere with n·c < −r is invisible.
  const double xl = (-2.5 - canvas.cx) / canvas.fx, xr = (canvas.width + 1.5 - canvas.cx) / canvas.fx;
  const double yt = (-2.5 - canvas.cy) / canvas.fy, yb = (canvas.height + 1.5 - canvas.cy) / canvas.fy;
  const std::array<geometry::Vec3, 4> planes{geometry::Vec3(1, 0, -xl).normalized(), geometry::Vec3(-1, 0, xr).normalized(),
                                             geometry::Vec3(0, 1, -yt).normalized(), geometry::Vec3(0, -1, yb).normalized()};
  // Near to far for the occlusion test (then drawn far to near); ties by list index, so
  // the order is total and sorting the chunks, then merging them, gives the one order.
  const auto nearFirst = [](const Key& a, const Key& b) {
    return a.power != b.power ? a.power < b.power : a.index < b.index;
  };
  // Chunks of the list on their own threads, joined in list order: the same staging as one pass.
  const std::size_t n = spheres.size();
  const int chunks = n >= 2000 ? bandCount(0) : 1;
  chunks_.resize(static_cast<std::size_t>(chunks));
  runBands(chunks, [&](int b) {
    Staging& out = chunks_[static_cast<std::size_t>(b)];
    out.keys.clear();
    out.staged.clear();
    out.colours.clear();
    out.behindScreens = true;
    for (std::size_t i = n * b / chunks; i < n * (b + 1) / chunks; ++i) {
      const SphereInstance& s = spheres[i];
      const geometry::Vec3 centre = s.centre + dt * s.velocity;
      // Cut away: a sphere goes whole when its centre is in the removed part.
      if (cut && cut->removes(centre)) continue;
      const geometry::Vec3 c = rotation * centre + translation;
      const double r = s.radius;
      // Not drawn: crossing the near plane (the impostor needs the eye outside), wholly beyond far, outside the sides.
      if (c.z() - r < nearClip || c.z() - r > farClip) continue;
      bool outside = false;
      for (const auto& plane : planes) outside = outside || plane.dot(c) < -r;
      if (outside) continue;
      for (const Screen& screen : screens)
        out.behindScreens = out.behindScreens && screen.normal.dot(c) + screen.offset >= (1.0 - kScreenOverlap) * r;
      out.keys.push_back({c.squaredNorm() - r * r, static_cast<std::uint32_t>(out.staged.size())});
      out.staged.push_back({static_cast<float>(c.x()), static_cast<float>(c.y()), static_cast<float>(c.z()),
                            static_cast<float>(r)});
      out.colours.push_back({toByte(s.colour.r), toByte(s.colour.g), toByte(s.colour.b), 255});
    }
    std::sort(out.keys.begin(), out.keys.end(), nearFirst);
  });
  keys_.clear();
  staged_.clear();
  colours_.clear();
  behindScreens_ = true;
  for (const Staging& chunk : chunks_) {
    behindScreens_ = behindScreens_ && chunk.behindScreens;
    const auto offset = static_cast<std::uint32_t>(staged_.size());
    const auto sorted = static_cast<std::ptrdiff_t>(keys_.size());  // the keys so far, in order
    for (const Key& k : chunk.keys) keys_.push_back({k.power, k.index + offset});
    std::inplace_merge(keys_.begin(), keys_.begin() + sorted, keys_.end(), nearFirst);
    staged_.insert(staged_.end(), chunk.staged.begin(), chunk.staged.end());
    colours_.insert(colours_.end(), chunk.colours.begin(), chunk.colours.end());
  }
  order_.resize(keys_.size());
  for (std::size_t k = 0; k < keys_.size(); ++k) order_[k] = keys_[k].index;
  const std::vector<PixelRect>& shows = culler_.cull(staged_, order_, canvas);

  // Far to near, in chunks of that order on their own threads, joined in order.
  const double margin = 0.6;  // pixels: the soft edge reaches half a pixel beyond the silhouette
  const std::size_t kept = order_.size();
  runBands(chunks, [&](int b) {
    Staging& out = chunks_[static_cast<std::size_t>(b)];
    out.points.clear();
    out.quads.clear();
    for (std::size_t m = kept * b / chunks; m < kept * (b + 1) / chunks; ++m) {
      const std::uint32_t k = order_[kept - 1 - m];
      const PixelRect& rect = shows[k];
      if (rect.empty()) continue;
      const CameraSphere& s = staged_[k];
      const auto [x0, x1] = extent(s.x, s.z, s.radius);
      const auto [y0, y1] = extent(s.y, s.z, s.radius);
      const Box image{canvas.fx * x0 + canvas.cx - margin, canvas.fy * y0 + canvas.cy - margin,
                      canvas.fx * x1 + canvas.cx + margin, canvas.fy * y1 + canvas.cy + margin};
      // Only the pixels where it can still show (the others are covered by nearer spheres).
      const Box box{std::max(image.u0, rect.u0 - 0.5), std::max(image.v0, rect.v0 - 0.5),
                    std::min(image.u1, rect.u1 + 0.5), std::min(image.v1, rect.v1 + 0.5)};
      // No pixel centre inside: what shows lies beyond its soft edge.
      if (std::ceil(box.u0) > std::floor(box.u1) || std::ceil(box.v0) > std::floor(box.v1)) continue;
      const Box square = pointSquare(box, image, canvas.width, canvas.height);
      const auto instance = [&](const Box& q) {
        return Instance{{s.x, s.y, s.z, s.radius},
                        {static_cast<float>(q.u0), static_cast<float>(q.v0), static_cast<float>(q.u1),
                         static_cast<float>(q.v1)},
                        {colours_[k][0], colours_[k][1], colours_[k][2], colours_[k][3]}};
      };
      // Points are clipped by their centre, so only squares inside the canvas are points.
      const bool inside = square.u0 >= 0 && square.v0 >= 0 && square.u1 <= canvas.width - 1 &&
                          square.v1 <= canvas.height - 1;
      const bool fits = square.u1 - square.u0 + 1.0 <= maxPointSize_;
      if (inside && fits)
        out.points.push_back(instance(square));
      else
        out.quads.push_back(instance(box));
    }
  });
  instances_.clear();
  for (const Staging& chunk : chunks_) instances_.insert(instances_.end(), chunk.points.begin(), chunk.points.end());
  points_ = instances_.size();
  for (const Staging& chunk : chunks_) instances_.insert(instances_.end(), chunk.quads.begin(), chunk.quads.end());
  quads_ = instances_.size() - points_;
  gl_.BindBuffer(GL_ARRAY_BUFFER, vbo_);
  gl_.BufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(instances_.size() * sizeof(Instance)), instances_.data(),
                 GL_STREAM_DRAW);
  if (quads_ > 0) setAttributes(quadVao_, points_, 1);
}

void SpherePass::draw(const ViewUniforms& view, const Canvas& canvas) const {
  if (points_ + quads_ == 0) return;
  gl_.UseProgram(program_.id());
  gl_.Uniform2f(uCanvasSize_, static_cast<float>(canvas.width), static_cast<float>(canvas.height));
  // Window point (u + 0.5, v + 0.5) is pixel (u, v), whose ray is ((u − cx)/fx, (v − cy)/fy, 1).
  const double fx = canvas.fx, fy = canvas.fy, cx = canvas.cx, cy = canvas.cy;
  gl_.Uniform4f(uPixelToRay_, static_cast<float>(1.0 / fx), static_cast<float>(1.0 / fy),
                static_cast<float>(-(cx + 0.5) / fx), static_cast<float>(-(cy + 0.5) / fy));
  // Window depth = (z_ndc + 1) / 2 with z_ndc = depthMap.x + depthMap.y / z.
  gl_.Uniform2f(uWindowDepth_, 0.5f * view.depthMap[0] + 0.5f, 0.5f * view.depthMap[1]);
  gl_.Uniform4f(uLighting_, view.lighting[0], view.lighting[1], view.lighting[2], view.lighting[3]);
  gl_.Uniform1f(uGain_, view.gain);
  if (points_ > 0) {
    gl_.Enable(GL_PROGRAM_POINT_SIZE);
    gl_.Uniform1i(uAsQuads_, 0);
    gl_.BindVertexArray(pointVao_);
    gl_.DrawArrays(GL_POINTS, 0, static_cast<GLsizei>(points_));
  }
  if (quads_ > 0) {
    gl_.Uniform1i(uAsQuads_, 1);
    gl_.BindVertexArray(quadVao_);
    gl_.DrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, static_cast<GLsizei>(quads_));
  }
  gl_.BindVertexArray(0);
}

}  // namespace rocklab::render::detail
