#include <algorithm>
#include <cmath>

#include "contact_kernel.h"

namespace rocklab::sim::detail {

namespace {
double series(double a, double b) { return (a > 0 && b > 0) ? a * b / (a + b) : 0.0; }

double mixFriction(double a, double b, FrictionRule rule) {
  switch (rule) {
    case FrictionRule::Max: return std::max(a, b);
    case FrictionRule::Mean: return 0.5 * (a + b);
    case FrictionRule::Min: break;
  }
  return std::min(a, b);  // Eq 2-39
}

void setHertz(PairProps& p, double g, double nu) {
  if (g <= 0.0) return;
  p.hertz_cn = 2.0 * g * std::sqrt(2.0) / (3.0 * (1.0 - nu));            // Eq 2-22
  p.hertz_ks = 2.0 * std::cbrt(3.0 * g * g * (1.0 - nu)) / (2.0 - nu);    // Eq 2-23
  p.hertz_ks_per_secant = p.hertz_ks / std::cbrt(p.hertz_cn * p.hertz_cn);  // HertzMindlinLaw::shear
}
}  // namespace

PairProps ballBallProps(const Material& a, const Material& b, FrictionRule rule) {
  PairProps p;
  p.kn = series(a.kn, b.kn);
  p.ks = series(a.ks, b.ks);
  p.friction = mixFriction(a.friction, b.friction, rule);
  setHertz(p, 0.5 * (a.shear_modulus + b.shear_modulus), 0.5 * (a.poisson + b.poisson));  // Eq 2-25, 2-26
  return p;
}

PairProps ballWallProps(const Material& ball, const Material& wall, FrictionRule rule) {
  PairProps p;
  p.kn = series(ball.kn, wall.kn);
  p.ks = series(ball.ks, wall.ks);
  p.friction = mixFriction(ball.friction, wall.friction, rule);
  setHertz(p, ball.shear_modulus, ball.poisson);  // mirror-image ball (ref §4.2)
  return p;
}

}  // namespace rocklab::sim::detail
