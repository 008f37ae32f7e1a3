// Shared by the C++ benchmarks (bench_kin.cpp, bench_tick.cpp): the chain text file that
// scripts/bench.py writes, and the timing loop.
//
// CHAIN.txt: n; base quat(4) xyz(3); tool quat(4) xyz(3); then per joint: prismatic quat(4)
// xyz(3) axis(3) scale limited lower upper.
// timeit prints "<name> <ns_per_call_min> <ns_per_call_median> <checksum>" (7 repetitions).
#pragma once
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <vector>

#include "tensor_servo/kinematics.hpp"

namespace tsbench {
using ts::ChainSpec;
constexpr int K = 1024;  // inputs cycled through

inline ChainSpec read_spec(const char* path) {
  std::ifstream f(path);
  ChainSpec c;
  int n = 0;
  f >> n;
  for (double& v : c.base_quat) f >> v;
  for (double& v : c.base_xyz) f >> v;
  for (double& v : c.tool_quat) f >> v;
  for (double& v : c.tool_xyz) f >> v;
  c.joints.resize(n);
  for (auto& j : c.joints) {
    int pr = 0, lim = 0;
    f >> pr;
    for (double& v : j.origin_quat) f >> v;
    for (double& v : j.origin_xyz) f >> v;
    for (double& v : j.axis) f >> v;
    f >> j.scale >> lim >> j.lower >> j.upper;
    j.prismatic = pr != 0;
    j.limited = lim != 0;
  }
  if (!f) { std::fprintf(stderr, "bench_kin: cannot read %s\n", path); std::exit(2); }
  return c;
}

template <class F>
inline void timeit(const char* name, double seconds, F&& call) {
  double sink = 0;
  for (int k = 0; k < K; ++k) sink += call(k);  // warm-up
  std::vector<double> per;
  for (int rep = 0; rep < 7; ++rep) {
    long calls = 0;
    const auto t0 = std::chrono::steady_clock::now();
    double el = 0;
    do {
      for (int k = 0; k < K; ++k) sink += call(k);
      calls += K;
      el = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    } while (el < seconds / 7);
    per.push_back(el / calls * 1e9);
  }
  std::sort(per.begin(), per.end());
  std::printf("%s %.2f %.2f %.6g\n", name, per.front(), per[per.size() / 2], sink);
  std::fflush(stdout);
}

}  // namespace tsbench
