// Host wall time in milliseconds, for the timings every stage reports beside its GPU times.
#pragma once
#include <chrono>

namespace sffd {

inline double msSince(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace sffd
