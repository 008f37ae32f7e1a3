// Benchmark: one whole servo tick (FK, Jacobian by screw transport, servo law in error choice A
// with feed-forward, coordinate descent with a given number of sweeps) of the C++ model, per call,
// in double and in the two fixed-point configurations: the software peer of the servo core's
// tick (scripts/bench.py compares it with the core's cycles per tick at its post-route Fmax).
//
// usage: bench_tick CHAIN.txt SWEEPS [seconds_per_case]
// Setpoints: the tool pose at a joint vector near each measured q (0.02 rad away), zero twist;
// warm start zero; safe-default gains (0.3/dt, dt = 1 ms), L = 0.5 m, mu = 1.5.
// Output: one line per configuration: "tick-<cfg> <ns_min> <ns_median> <checksum>".
#include <memory>
#include <random>
#include <string>

#include "bench_common.hpp"
#include "tensor_servo/servo.hpp"

using namespace ts;
using namespace tsbench;
constexpr int NM = 32;

template <class Fmt>
static void bench(const char* name, const ChainSpec& c, int sweeps, const std::vector<std::vector<double>>& qs,
                  const std::vector<std::vector<double>>& qt, double sec) {
  using angle_t = typename Fmt::angle_t;
  static ChainQ<Fmt, NM> ch;
  if (!quantize(c, ch).ok()) { std::printf("%s skipped-config\n", name); return; }
  const int n = c.joints.size();
  static ServoParams<Fmt, NM> P;
  Status st;
  const double dt = 1e-3;
  P.solver.L = from_double<typename Fmt::lchar_t>(0.5, st);
  P.solver.klim = from_double<typename Fmt::klim_t>(0.5 / dt, st);
  P.solver.sweeps = sweeps;
  for (int i = 0; i < n; ++i) {
    const auto& j = c.joints[i];
    P.solver.mu[i] = from_double<typename Fmt::mu_t>(1.5, st);
    P.solver.limited[i] = j.limited;
    P.solver.lo[i] = from_double<angle_t>(j.limited ? j.lower : 0.0, st);
    P.solver.hi[i] = from_double<angle_t>(j.limited ? j.upper : 0.0, st);
    P.solver.vmax[i] = max_of<typename Fmt::qd_t>();
  }
  P.kp = P.ko = from_double<typename Fmt::gain_t>(0.3 / dt, st);
  P.dt = from_double<typename Fmt::dt_t>(dt, st);
  std::vector<std::vector<angle_t>> q(K);
  std::vector<Setpoint<Fmt>> U(K);
  Frames<Fmt, NM> f;
  for (int k = 0; k < K; ++k) {
    std::vector<angle_t> tq;
    for (int i = 0; i < n; ++i) {
      q[k].push_back(from_double<angle_t>(qs[k][i], st));
      tq.push_back(from_double<angle_t>(qt[k][i], st));
    }
    forward_kinematics(ch, tq.data(), f, st);
    U[k].Q = f.Q[n + 1];
    for (int a = 0; a < 3; ++a) U[k].p.c[a] = cvt<typename Fmt::pos_t>(f.p[n + 1].c[a], st);
  }
  typename Fmt::qd_t warm[NM] = {};
  auto R = std::make_unique<TickResult<Fmt, NM>>();
  timeit(name, sec, [&](int k) {
    Status s;
    servo_tick(ch, P, q[k].data(), &U[k], warm, *R, s);
    return to_double(R->qd[0]) + to_double(R->qd[n - 1]);
  });
}

int main(int argc, char** argv) {
  if (argc < 3) { std::fprintf(stderr, "usage: bench_tick CHAIN.txt SWEEPS [seconds]\n"); return 2; }
  const ChainSpec c = read_spec(argv[1]);
  const int sweeps = std::atoi(argv[2]);
  const double sec = argc > 3 ? std::atof(argv[3]) : 1.0;
  std::mt19937_64 g(42);
  std::vector<std::vector<double>> qs(K), qt(K);
  for (int k = 0; k < K; ++k)
    for (const auto& j : c.joints) {
      const double lo = j.limited ? j.lower : -3.0, hi = j.limited ? j.upper : 3.0, m = 0.25 * (hi - lo);
      const double v = std::uniform_real_distribution<double>(lo + m, hi - m)(g);
      qs[k].push_back(v);
      qt[k].push_back(v + std::uniform_real_distribution<double>(-0.02, 0.02)(g));
    }
  bench<FmtDouble>("tick-double", c, sweeps, qs, qt, sec);
  bench<FmtDefault>("tick-default", c, sweeps, qs, qt, sec);
  bench<FmtCompact>("tick-compact", c, sweeps, qs, qt, sec);
  return 0;
}
