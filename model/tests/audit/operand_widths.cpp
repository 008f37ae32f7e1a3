// Audit of multiplier operand widths (built with -DTS_AUDIT_MUL as its own program, see Makefile):
// runs FK, every Jacobian form, the servo tick in both error modes (with the IK's conjugate-direction
// refinement) and the configuration step,
// and checks the widest multiplier operand: <= 18 bits in the compact configuration (one
// MULT18X18D / DSP48E1 per product) and <= 36 in the default one (4 MULT18X18D).
#include <cstdio>
#include <random>

#include "tensor_servo/core_config.hpp"

using namespace ts;

template <class Fmt>
int run() {
  constexpr int NM = 8;
  std::mt19937_64 g(3);
  std::uniform_real_distribution<double> U(-1, 1);
  ChainSpec c;
  c.joints.resize(7);
  for (size_t i = 0; i < c.joints.size(); ++i) {
    auto& j = c.joints[i];
    double n = 0;
    for (double& v : j.origin_quat) { v = U(g); n += v * v; }
    for (double& v : j.origin_quat) v /= std::sqrt(n);
    n = 0;
    for (double& v : j.axis) { v = U(g); n += v * v; }
    for (double& v : j.axis) v /= std::sqrt(n);
    for (double& v : j.origin_xyz) v = 0.1 * U(g);
    j.prismatic = i == 3;
    j.lower = j.prismatic ? -0.2 : -3.0;
    j.upper = -j.lower;
  }
  audit::max_operand_width = 0;
  ChainQ<Fmt, NM> ch;
  if (!configure_chain(c, ch).ok()) { std::printf("%s: configuration refused\n", Fmt::name); return 1; }
  for (int mode : {ERR_A, ERR_B}) {
    for (int spf : {-1, 2}) {
      ServoParams<Fmt, NM> P;
      Status st;
      P.solver.L = Fmt::lchar_t::from_double(0.5, st);
      P.solver.klim = Fmt::klim_t::from_double(500, st);
      P.solver.sweeps = 3;
      P.solver.cg = 2 * ch.n;  // the offline IK's refinement too (model only, same operand rule)
      for (int i = 0; i < ch.n; ++i) {
        P.solver.mu[i] = Fmt::mu_t::from_double(1.5, st);
        P.solver.limited[i] = true;
        P.solver.lo[i] = Fmt::angle_t::from_double(c.joints[i].lower, st);
        P.solver.hi[i] = Fmt::angle_t::from_double(c.joints[i].upper, st);
        P.solver.vmax[i] = Fmt::qd_t::from_double(2.0, st);
      }
      P.kp = P.ko = Fmt::gain_t::from_double(300, st);
      P.dt = Fmt::dt_t::from_double(1e-3, st);
      P.mode = mode;
      P.setpoint_frame = spf;
      P.warm_leak = 5;
      typename Fmt::angle_t q[NM];
      typename Fmt::qd_t w[NM];
      for (int i = 0; i < ch.n; ++i) { q[i] = Fmt::angle_t::from_double(0.5 * U(g), st); w[i] = Fmt::qd_t::from_double(0.1 * U(g), st); }
      Setpoint<Fmt> sp;
      sp.Q = ch.qb;
      for (int a = 0; a < 3; ++a) {
        sp.p.c[a] = Fmt::pos_t::from_double(0.1 * U(g), st);
        sp.w.c[a] = Fmt::vel_t::from_double(0.1 * U(g), st);
        sp.v.c[a] = Fmt::vel_t::from_double(0.1 * U(g), st);
      }
      TickResult<Fmt, NM> R;
      servo_tick(ch, P, q, &sp, w, R, st);
      Jacobian<Fmt, NM> J;
      jacobian(ch, R.frames, ch.n + 1, 3, J, st);  // a basis change too
    }
  }
  const int limit = Fmt::name[0] == 'c' ? 18 : 36;
  std::printf("%s: widest multiplier operand %d bits (limit %d)\n", Fmt::name, audit::max_operand_width, limit);
  return audit::max_operand_width <= limit && audit::max_operand_width > 0 ? 0 : 1;
}

int main() { return run<FmtCompact>() | run<FmtDefault>(); }
