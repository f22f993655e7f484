// The crusher product's statistics (crusher/product_statistics.h) and Whiten's
// model (crusher/whiten_model.h) against hand-computed cases: P50/P80 on the
// product's own curve, residence through breakage, the power meter's energy,
// Eq 3-20 on three classes.
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "crusher/product_statistics.h"
#include "crusher/whiten_model.h"

using namespace rocklab::experiments::crusher;

TEST_CASE("product sizes: P50 and P80 read off the cumulative mass curve, linear between balls", "[crusher]") {
  // Four balls, 4/8/12/16 mm, masses 1/1/1/1 kg: the curve passes (4, 0.25),
  // (8, 0.5), (12, 0.75), (16, 1). P50 = 8 mm, P80 = 12 + 0.05/0.25 x 4 = 12.8 mm;
  // the order of the balls does not matter.
  const std::vector<ProductBall> balls{
      {1, 0.1, 0.016, 1.0, 0}, {2, 0.2, 0.004, 1.0, 0}, {3, 0.3, 0.012, 1.0, 0}, {4, 0.4, 0.008, 1.0, 0}};
  CHECK(*sizeAtPassing(balls, 0.5) == Approx(0.008).epsilon(1e-12));
  CHECK(*sizeAtPassing(balls, 0.8) == Approx(0.0128).epsilon(1e-12));
  CHECK(*sizeAtPassing(balls, 0.1) == Approx(0.004));  // below the finest ball's own fraction
  CHECK(*sizeAtPassing(balls, 1.0) == Approx(0.016));
  CHECK_FALSE(sizeAtPassing(std::vector<ProductBall>{}, 0.5).has_value());
  // Mass weighted: a heavy coarse ball pulls P50 up. 4 mm 1 kg, 16 mm 3 kg:
  // (4, 0.25), (16, 1) -> P50 = 4 + (0.25 / 0.75) x 12 = 8 mm.
  const std::vector<ProductBall> two{{1, 0.1, 0.004, 1.0, 0}, {2, 0.2, 0.016, 3.0, 0}};
  CHECK(*sizeAtPassing(two, 0.5) == Approx(0.008).epsilon(1e-12));
}

TEST_CASE("product statistics: throughput over the discharge period, residence from entry through breakage",
          "[crusher]") {
  ChamberEntries entries(0.15);  // the chamber's top at 150 mm
  entries.record(std::vector<std::uint64_t>{1, 2}, std::vector<double>{0.14, 0.20}, 1.0);  // 1 entered at 1 s
  entries.record(std::vector<std::uint64_t>{1, 2}, std::vector<double>{0.10, 0.12}, 1.5);  // 2 at 1.5 s, 1 kept
  entries.inherit(1, std::vector<std::uint64_t>{10, 11});  // 1 broke: its fragments entered at 1 s
  entries.inherit(99, std::vector<std::uint64_t>{12});     // a ball never seen: no entry for its fragment
  CHECK(entries.residence(1, 2.0) == Approx(1.0));
  CHECK(entries.residence(2, 2.0) == Approx(0.5));
  CHECK(entries.residence(11, 3.0) == Approx(2.0));
  CHECK(std::isnan(entries.residence(12, 3.0)));
  // 3 kg discharged between 2 s and 3 s: 3e-3 t per 1/3600 h = 10.8 t/h.
  const std::vector<ProductBall> product{{10, 2.0, 0.01, 1.0, entries.residence(10, 2.0)},
                                         {2, 2.5, 0.01, 1.0, entries.residence(2, 2.5)},
                                         {12, 3.0, 0.01, 1.0, entries.residence(12, 3.0)}};
  const nlohmann::json s = productStatistics(product);
  CHECK(s["throughput_tph"].get<double>() == Approx(10.8));
  CHECK(s["residence_s"]["balls"] == 2);  // the ball without an entry is left out
  CHECK(s["residence_s"]["mean"].get<double>() == Approx(1.0));  // (1 + 1) / 2
  CHECK(s["residence_s"]["max"].get<double>() == Approx(1.0));
  CHECK(productStatistics(std::vector<ProductBall>{})["p50_mm"].is_null());
}

TEST_CASE("power meter: energy is the sum of power x span, power_W its mean over the loaded time", "[crusher]") {
  PowerMeter meter(0.01);
  for (int k = 0; k < 100; ++k) meter.add(1e-3 * k, k >= 20 && k < 60 ? 50.0 : 0.0, 1e-3);
  CHECK(meter.energy() == Approx(40 * 1e-3 * 50.0));  // 2 J
  CHECK(meter.loadedTime() == Approx(0.040));          // from the first loaded sample (20 ms) to 60 ms
  const nlohmann::json r = meter.report();
  CHECK(r["power_W"].get<double>() == Approx(50.0));
  CHECK(r["samples"] == 100);
  REQUIRE(meter.series().size() == 10);  // 10 ms bins
  CHECK(meter.series()[2].second == Approx(50.0));
  CHECK(meter.series()[0].second == Approx(0.0));
}

TEST_CASE("Whiten's model: a hand-solved three-class case, mass kept, p = f when k1 is above every size, a trapping "
          "class refused",
          "[crusher]") {
  // Classes coarse to fine; 1 kg fed into the top class, all of it selected; its
  // broken mass goes half to class 1, half to class 2; class 1 is half selected and
  // keeps a fifth of its broken mass. By hand: x0 = 1, x1 = 0.5 / (1 - 0.2 x 0.5) =
  // 5/9, x2 = 0.5 + 0.8 x 0.5 x 5/9 = 13/18; P = (I - C) x = (0, 5/18, 13/18).
  Eigen::MatrixXd B(3, 3);
  B << 0, 0, 0, 0.5, 0.2, 0, 0.5, 0.8, 0;
  const Eigen::Vector3d c(1.0, 0.5, 0.0), f(1.0, 0.0, 0.0);
  const Eigen::VectorXd P = whitenProduct(B, c, f);
  CHECK(P[0] == Approx(0.0).margin(1e-15));
  CHECK(P[1] == Approx(5.0 / 18.0).epsilon(1e-14));
  CHECK(P[2] == Approx(13.0 / 18.0).epsilon(1e-14));
  CHECK(std::abs(P.sum() - f.sum()) < 1e-15);  // columns of B sum to 1: mass kept
  // k1 above every class's size: nothing is selected, the product is the feed.
  const SizeClasses classes({0.004, 0.008, 0.016});
  Eigen::VectorXd none(4), feed(4);
  feed << 0.3, 0.5, 0.2, 0.0;
  for (Eigen::Index k = 0; k < 4; ++k)
    none[k] = whitenClassification(classes.representative(static_cast<std::size_t>(k)), 0.05, 0.06, 2.0);
  const Eigen::MatrixXd split = splitBreakageMatrix(classes, std::vector<double>{0.843, 0.669, 0.464},
                                                    std::vector<double>{0.6, 0.3, 0.1});
  CHECK((whitenProduct(split, none, feed) - feed).norm() == 0.0);
  // Every column of the split's matrix sums to 1 and stays on or below the diagonal.
  for (Eigen::Index j = 0; j < 4; ++j) {
    CHECK(split.col(j).sum() == Approx(1.0).epsilon(1e-15));
    for (Eigen::Index i = 0; i < j; ++i) CHECK(split(i, j) == 0.0);
  }
  // A class that keeps all of its broken mass and selects all of it: refused by name.
  Eigen::MatrixXd trap = Eigen::MatrixXd::Zero(3, 3);
  trap(0, 0) = 1.0;
  CHECK_THROWS_WITH(whitenProduct(trap, c, f), Catch::Matchers::Contains("class 0") &&
                                                    Catch::Matchers::Contains("never leaves"));
  Eigen::MatrixXd upper = B;
  upper(0, 1) = 0.1;
  CHECK_THROWS_WITH(whitenProduct(upper, c, f), Catch::Matchers::Contains("lower triangular"));
}

TEST_CASE("Whiten's classification (Eq 3-21 to 3-23) and the size classes", "[crusher]") {
  CHECK(whitenClassification(0.010, 0.012, 0.025, 2.0) == 0.0);
  CHECK(whitenClassification(0.030, 0.012, 0.025, 2.0) == 1.0);
  // Half way: 1 - 0.5^2 = 0.75.
  CHECK(whitenClassification(0.0185, 0.012, 0.025, 2.0) == Approx(0.75));
  CHECK_THROWS(whitenClassification(0.01, 0.02, 0.02, 2.0));
  const SizeClasses classes({0.004, 0.008, 0.016});  // classes [16, inf), [8, 16), [4, 8), [0, 4) mm
  CHECK(classes.size() == 4);
  CHECK(classes.classOf(0.020) == 0);
  CHECK(classes.classOf(0.016) == 0);
  CHECK(classes.classOf(0.010) == 1);
  CHECK(classes.classOf(0.004) == 2);
  CHECK(classes.classOf(0.001) == 3);
  CHECK(classes.representative(1) == Approx(std::sqrt(0.008 * 0.016)));
  CHECK(classes.lower(3) == 0.0);
  Eigen::VectorXd mass(4);
  mass << 1, 1, 1, 1;  // finer than 4 mm: the pan; than 8: pan + [4, 8); than 16: three classes
  CHECK(passingOfClasses(classes, mass) == std::vector<double>{0.25, 0.5, 0.75});
}
