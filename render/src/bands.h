#pragma once
// Work split into bands that share nothing (rows of the canvas, chunks of the sphere
// list), one thread a band: the CPU side of a frame runs while llvmpipe's rasteriser
// threads wait for it, so on a 2-core machine a second thread here is free.
#include <algorithm>
#include <thread>
#include <vector>

namespace rocklab::render::detail {

/// Bands to use: the machine's cores (at most 8), or `threads` when > 0.
inline int bandCount(int threads) {
  return threads > 0 ? threads : static_cast<int>(std::clamp(std::thread::hardware_concurrency(), 1u, 8u));
}

/// job(b) for b = 0 … count − 1: b = 0 on the calling thread, the others on their
/// own threads; returns when all are done. `job` must not throw.
template <typename Job>
void runBands(int count, Job&& job) {
  std::vector<std::jthread> helpers;
  helpers.reserve(static_cast<std::size_t>(std::max(0, count - 1)));
  for (int b = 1; b < count; ++b) helpers.emplace_back([&job, b] { job(b); });
  job(0);
}

}  // namespace rocklab::render::detail
