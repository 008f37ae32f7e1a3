// tensor-servo: the servo core's configuration at register level, and its commit step.
//
// The core is configured over AXI4-Lite with raw fixed-point words (rtl/ts_servo_regs.rdl,
// docs/registers.md).  Writing CTRL.COMMIT runs the commit step defined here: the words are taken
// as the chain's and the servo's constants, checked, and the derived constant of every revolute
// joint (k = s/(4 pi), the turn constant) is computed.  A failed check sets CFG_ERROR (code and
// joint) and the core refuses to run.  The same check is applied to every chain the model loads
// from a file (configure_chain), so the CLI refuses exactly what the core refuses.
//
// Checks, in this order (the first failure is reported):
//   1. joint count 1..NMAX                                        CFG_JOINT_COUNT
//   2. base and tool quaternions of unit norm (|norm^2 - 1| <= 2^-10)    CFG_QUAT
//   3. per joint, in order: origin quaternion unit norm            CFG_QUAT
//                            axis unit norm                        CFG_AXIS
//                            scale != 0; revolute: k fits kturn_t  CFG_SCALE
//                            prismatic needs limits; lower <= upper; velocity limit > 0   CFG_LIMITS
//                            multiplier mu >= 0                    CFG_PARAM
//   4. reach (exact L1 bound, conservative):                       CFG_REACH
//        R = sum_i |po_i|_1 + |pt|_1 + sum_prismatic |s| max(|lower|, |upper|)
//        R < max(lever_t),  |pb|_1 + R < max(pos_t),  max|s| R < max(jv_t)
//   5. servo parameters: L > 0, dt > 0, kp, ko, klim >= 0, sweeps 1..SWEEPS_MAX,
//      warm leak 0..20                                             CFG_PARAM
#pragma once
#include <vector>

#include "servo.hpp"

namespace ts {

constexpr int CFG_PARAM = 10;  // a servo parameter out of range (extends ConfigError)
constexpr int kCoreSweepsMax = 255;  // MODE.SWEEPS is 8 bits

// Joint-configuration word (register JCFG).
enum JointCfgBits : uint32_t { JCFG_PRISMATIC = 1u << 0, JCFG_LIMITED = 1u << 1, JCFG_VLIMITED = 1u << 2 };
// Mode word (register MODE).
enum ModeBits : uint32_t { MODE_ERR_B = 1u << 0, MODE_ERROR_ONLY = 1u << 1 };

struct RawJoint {
  uint32_t jcfg = 0;
  int64_t qo[4] = {}, po[3] = {}, axis[3] = {};
  int64_t scale = 0, lower = 0, upper = 0, vmax = 0, mu = 0;
};

// The register file as raw integers (sign-extended register words).
struct RawConfig {
  int n = 0;
  uint32_t mode = 0;  // ERR_B, ERROR_ONLY
  int sweeps = 1, warm_leak = 0;
  int64_t kp = 0, ko = 0, lchar = 0, klim = 0, dt = 0;
  int64_t base_q[4] = {}, base_p[3] = {}, tool_q[4] = {}, tool_p[3] = {};
  std::vector<RawJoint> joints;
};

namespace detail {
// |sum v_i^2 - 1| <= 2^-10 for a vector of unit-norm format values (exact in fixed point).
template <class Fmt, class T>
inline bool unit_norm(const T* v, int m) {
  if constexpr (std::is_same_v<T, double>) {
    double s = 0;
    for (int i = 0; i < m; ++i) s += v[i] * v[i];
    return std::fabs(s - 1.0) <= std::ldexp(1.0, -10);
  } else {
    const auto s = dot_exact<Fmt, 4>(v, v, m);
    using S = num_traits<decltype(s)>;
    const int64_t one = int64_t(1) << S::F, tol = int64_t(1) << (S::F - 10);
    const int64_t d = raw_of(s) - one;
    return d <= tol && d >= -tol;
  }
}
}  // namespace detail

// Steps 2-4 on a quantised chain (limits, velocity limits and multipliers from the solver
// parameters when given).
template <class Fmt, int NMAX, int TMAX>
inline ConfigResult check_chain(const ChainQ<Fmt, NMAX, TMAX>& ch, const SolverParams<Fmt, NMAX>* S) {
  auto fail = [](int e, int j, const std::string& f, const std::string& m) {
    ConfigResult r;
    r.code = static_cast<ConfigError>(e); r.joint = j; r.field = f; r.message = m;
    return r;
  };
  const int n = ch.n;
  if (n < 1 || n > NMAX) return fail(CFG_JOINT_COUNT, -1, "joints", "joint count outside 1.." + std::to_string(NMAX));
  if (!detail::unit_norm<Fmt>(ch.qb.c, 4)) return fail(CFG_QUAT, -1, "base.quat_wxyz", "quaternion is not of unit norm");
  for (int t = 0; t < ch.ntips; ++t)
    if (!detail::unit_norm<Fmt>(ch.qt[t].c, 4)) return fail(CFG_QUAT, -1, "tool.quat_wxyz", "quaternion is not of unit norm");
  using scale_t = typename Fmt::scale_t;
  for (int i = 0; i < n; ++i) {
    const JointQ<Fmt>& j = ch.j[i];
    const std::string pre = "joints[" + std::to_string(i) + "].";
    if (!detail::unit_norm<Fmt>(j.qo.c, 4)) return fail(CFG_QUAT, i, pre + "origin.quat_wxyz", "quaternion is not of unit norm");
    if (!detail::unit_norm<Fmt>(j.axis.c, 3)) return fail(CFG_AXIS, i, pre + "axis", "axis is not a unit vector");
    if (j.s == scale_t{}) return fail(CFG_SCALE, i, pre + "scale", "scale is zero");
    if (!j.prismatic) {
      Status st;
      derive_kturn<Fmt>(j.s, st);
      if (st.overflow()) return fail(CFG_SCALE, i, pre + "scale", "scale outside the range of the turn constant");
    }
    if (S) {
      if (j.prismatic && !S->limited[i]) return fail(CFG_LIMITS, i, pre + "limits", "a prismatic joint needs position limits");
      if (S->limited[i] && S->hi[i] < S->lo[i]) return fail(CFG_LIMITS, i, pre + "limits", "lower > upper");
      if (!(typename Fmt::qd_t{} < S->vmax[i])) return fail(CFG_LIMITS, i, pre + "limits.velocity", "velocity limit must be positive");
      if (S->mu[i] < typename Fmt::mu_t{}) return fail(CFG_PARAM, i, pre + "mu", "multiplier must be >= 0");
    }
  }
  // Reach, exact on the raw integers: L1 norms of the offsets (an upper bound of every lever-arm
  // component), prismatic strokes rounded up to the offset format.
  if constexpr (Fmt::is_float) {
    auto l1 = [](const Vec3<double>& p) { return std::fabs(p.c[0]) + std::fabs(p.c[1]) + std::fabs(p.c[2]); };
    double reach = 0, smax = 0;
    for (int t = 0; t < ch.ntips; ++t) reach = std::max(reach, l1(ch.pt[t]));
    for (int i = 0; i < n; ++i) {
      reach += l1(ch.j[i].po);
      smax = std::max(smax, std::fabs(ch.j[i].s));
      if (ch.j[i].prismatic && S) reach += std::fabs(ch.j[i].s) * std::max(std::fabs(S->lo[i]), std::fabs(S->hi[i]));
    }
    (void)reach; (void)smax;  // the double configuration has no format range to exceed
  } else {
    using len_t = typename Fmt::len_t;
    using angle_t = typename Fmt::angle_t;
    constexpr int FL = len_t::F, FS = scale_t::F, FA = angle_t::F;
    auto a = [](int64_t x) { return x < 0 ? -x : x; };
    auto l1 = [&](const Vec3<len_t>& p) { return a(raw_of(p.c[0])) + a(raw_of(p.c[1])) + a(raw_of(p.c[2])); };
    int64_t reach = 0, smax = 0;  // reach: len_t raw units
    for (int t = 0; t < ch.ntips; ++t) reach = std::max(reach, l1(ch.pt[t]));
    for (int i = 0; i < n; ++i) {
      reach += l1(ch.j[i].po);
      smax = std::max(smax, a(raw_of(ch.j[i].s)));
      if (ch.j[i].prismatic && S) {
        const __int128 prod = static_cast<__int128>(a(raw_of(ch.j[i].s))) * std::max(a(raw_of(S->lo[i])), a(raw_of(S->hi[i])));
        const int sh = FS + FA - FL;  // to len_t units, rounded up
        reach += static_cast<int64_t>(sh > 0 ? (prod + ((static_cast<__int128>(1) << sh) - 1)) >> sh : prod << -sh);
      }
    }
    // x 2^-Fx < y 2^-Fy, exactly
    auto less = [](__int128 x, int fx_, __int128 y, int fy) { return fx_ >= fy ? x < (y << (fx_ - fy)) : (x << (fy - fx_)) < y; };
    using lever_t = typename Fmt::lever_t;
    using pos_t = typename Fmt::pos_t;
    using jv_t = typename Fmt::jv_t;
    if (!less(reach, FL, lever_t::RAW_MAX, lever_t::F))
      return fail(CFG_REACH, -1, "joints", "chain reach exceeds the lever-arm format");
    if (!less(reach + l1(ch.pb), FL, pos_t::RAW_MAX, pos_t::F))
      return fail(CFG_REACH, -1, "joints", "base offset + reach exceeds the position format");
    if (!less(static_cast<__int128>(smax) * reach, FS + FL, jv_t::RAW_MAX, jv_t::F))
      return fail(CFG_REACH, -1, "joints", "scale x reach exceeds the Jacobian format");
  }
  return ConfigResult{};
}

// quantize + the core's checks: the one rule for every chain the model accepts.
template <class Fmt, int NMAX, int TMAX>
inline ConfigResult configure_chain(const ChainSpec& c, ChainQ<Fmt, NMAX, TMAX>& out) {
  ConfigResult r = quantize<Fmt, NMAX, TMAX>(c, out);
  if (!r.ok()) return r;
  // Limits as the servo will hold them (inward-rounded) for the prismatic stroke and the checks.
  SolverParams<Fmt, NMAX> S;
  Status st;
  for (int i = 0; i < out.n; ++i) {
    const JointSpec& j = c.joints[i];
    S.limited[i] = j.limited;
    S.lo[i] = from_double_dir<typename Fmt::angle_t>(j.limited ? j.lower : 0.0, true, st);
    S.hi[i] = from_double_dir<typename Fmt::angle_t>(j.limited ? j.upper : 0.0, false, st);
    S.vmax[i] = max_of<typename Fmt::qd_t>();
    S.mu[i] = typename Fmt::mu_t{};
  }
  return check_chain(out, &S);
}

// The commit step of the core: register words -> chain constants and servo parameters, checked.
// Serial chain, one task (the tool), setpoint in the root frame.
template <class Fmt, int NMAX>
inline ConfigResult commit_config(const RawConfig& rc, ChainQ<Fmt, NMAX, 1>& ch, ServoParams<Fmt, NMAX, 1>& P) {
  auto fail = [](int e, int j, const std::string& f, const std::string& m) {
    ConfigResult r;
    r.code = static_cast<ConfigError>(e); r.joint = j; r.field = f; r.message = m;
    return r;
  };
  if (rc.n < 1 || rc.n > NMAX || static_cast<int>(rc.joints.size()) < rc.n)
    return fail(CFG_JOINT_COUNT, -1, "NJOINTS", "joint count outside 1.." + std::to_string(NMAX));
  using quat_t = typename Fmt::quat_t;
  using len_t = typename Fmt::len_t;
  auto q = [](int64_t r) { return of_raw_storage<quat_t>(r); };
  auto l = [](int64_t r) { return of_raw_storage<len_t>(r); };
  ch.n = rc.n;
  ch.ntips = 1;
  ch.tip_parent[0] = rc.n;
  for (int a = 0; a < 4; ++a) { ch.qb.c[a] = q(rc.base_q[a]); ch.qt[0].c[a] = q(rc.tool_q[a]); }
  for (int a = 0; a < 3; ++a) { ch.pb.c[a] = l(rc.base_p[a]); ch.pt[0].c[a] = l(rc.tool_p[a]); }
  auto& S = P.solver;
  Status st;
  for (int i = 0; i < rc.n; ++i) {
    const RawJoint& rj = rc.joints[i];
    JointQ<Fmt>& j = ch.j[i];
    ch.parent[i] = i;
    j.prismatic = (rj.jcfg & JCFG_PRISMATIC) != 0;
    for (int a = 0; a < 4; ++a) j.qo.c[a] = q(rj.qo[a]);
    for (int a = 0; a < 3; ++a) { j.po.c[a] = l(rj.po[a]); j.axis.c[a] = q(rj.axis[a]); }
    j.s = of_raw_storage<typename Fmt::scale_t>(rj.scale);
    j.k = j.prismatic ? typename Fmt::kturn_t{} : derive_kturn<Fmt>(j.s, st);
    S.limited[i] = (rj.jcfg & JCFG_LIMITED) != 0;
    S.lo[i] = of_raw_storage<typename Fmt::angle_t>(rj.lower);
    S.hi[i] = of_raw_storage<typename Fmt::angle_t>(rj.upper);
    S.vmax[i] = (rj.jcfg & JCFG_VLIMITED) ? of_raw_storage<typename Fmt::qd_t>(rj.vmax) : max_of<typename Fmt::qd_t>();
    S.mu[i] = of_raw_storage<typename Fmt::mu_t>(rj.mu);
  }
  if (ConfigResult r = check_chain(ch, &S); !r.ok()) return r;
  S.L = of_raw_storage<typename Fmt::lchar_t>(rc.lchar);
  S.klim = of_raw_storage<typename Fmt::klim_t>(rc.klim);
  S.sweeps = rc.sweeps;
  P.kp = of_raw_storage<typename Fmt::gain_t>(rc.kp);
  P.ko = of_raw_storage<typename Fmt::gain_t>(rc.ko);
  P.dt = of_raw_storage<typename Fmt::dt_t>(rc.dt);
  P.mode = (rc.mode & MODE_ERR_B) ? ERR_B : ERR_A;
  P.feedforward = (rc.mode & MODE_ERROR_ONLY) == 0;
  P.ntasks = 1;
  P.controlled[0] = -1;
  P.setpoint_frame = -1;
  P.warm_leak = rc.warm_leak;
  if (!(typename Fmt::lchar_t{} < S.L)) return fail(CFG_PARAM, -1, "LCHAR", "characteristic length must be positive");
  if (!(typename Fmt::dt_t{} < P.dt)) return fail(CFG_PARAM, -1, "DT", "tick period must be positive");
  if (P.kp < typename Fmt::gain_t{} || P.ko < typename Fmt::gain_t{}) return fail(CFG_PARAM, -1, "KP/KO", "gains must be >= 0");
  if (S.klim < typename Fmt::klim_t{}) return fail(CFG_PARAM, -1, "KLIM", "limit gain must be >= 0");
  if (rc.sweeps < 1 || rc.sweeps > kCoreSweepsMax) return fail(CFG_PARAM, -1, "MODE.SWEEPS", "sweeps must be 1..255");
  if (rc.warm_leak < 0 || rc.warm_leak > 20) return fail(CFG_PARAM, -1, "MODE.WARM_LEAK", "warm leak must be 0..20");
  return ConfigResult{};
}

}  // namespace ts
