// tensor-servo: the tracking servo law around the coordinate solver (one servo tick).
//
// Inputs per tick: measured joint values q, the setpoint pose U = (Q_U, p_U) and twist
// U' = (omega_U; v_U) of the controlled frame, gains.  Output: joint-rate commands q' (and, in
// virtual mode, the integrated model q + q' dt clamped to the limits).
//
// Error choice A (default; digest a.5 [FIX] 2A): root (or setpoint-frame) basis, geometric Jacobian
// at the controlled frame's origin:
//     e_p = p_U - p_P,   e_o = rotvec(Q_U (x) conj(Q_P)),   V = [omega_U + K_o e_o ; v_U + K_p e_p]
// Error choice B (digest a.5 [FIX] 2B): body basis of the controlled frame, body Jacobian:
//     E_b = P^-1 U:  e_o = rotvec(conj(Q_P) (x) Q_U),  e_p = R_P^T (p_U - p_P)
//     V = [R_P^T omega_U + K_o e_o ; R_P^T (v_U + omega_U x (p_P - p_U)) + K_p e_p]
//     (the feed-forward twist carried from U's origin to P's and into P's axes: Ad_{E_b} V_U^b)
// Error-only mode (the seed's alternative): U' is not fed forward.
// Moving local basis (seed section 11): the setpoint may be given relative to frame k of the chain.
// Then P is replaced by T_k^-1 P, the Jacobian is taken in frame k's axes and the columns of the
// joints that move frame k are zero (they move frame k and the controlled frame together).
// Trees of chains (seed section 12): several tasks (one per tip), each with its own setpoint, are
// stacked into one least-squares problem over the shared joints, each task's rows scaled by its
// weight w_t (so its squared error counts w_t^2).
//
// Rotation vector without a divider: for a unit quaternion (w, u) with w >= 0 (sign flipped
// otherwise), rotvec = 2 f(w) u with f(w) = acos(w) / sqrt(1 - w^2) = (phi/2) / sin(phi/2), taken
// from a table of 2^T + 1 values on w = j 2^-T with linear interpolation (T = ROTVEC_TABLE_BITS).
#pragma once
#include "solver.hpp"

namespace ts {

enum ErrorMode : int { ERR_A = 0, ERR_B = 1 };

// f(j 2^-T) and its forward differences, read through f_at / df_at (a configuration may
// specialise the table with constant arrays, as TrigTable).
template <class Fmt>
struct RotvecTable {
  static constexpr int N = 1 << Fmt::ROTVEC_TABLE_BITS;
  typename Fmt::rvf_t f[N + 1];
  typename Fmt::rvf_t df[N + 1];
  static double fexact(double w) { return w >= 1.0 ? 1.0 : std::acos(w) / std::sqrt(1.0 - w * w); }
  RotvecTable() {
    Status st;
    for (int j = 0; j <= N; ++j) f[j] = from_double<typename Fmt::rvf_t>(fexact(double(j) / N), st);
    for (int j = 0; j <= N; ++j)
      df[j] = j < N ? cvt<typename Fmt::rvf_t>(f[j + 1] - f[j], st) : typename Fmt::rvf_t{};
  }
  static const RotvecTable& get() {
    static const RotvecTable t;
    return t;
  }
  static typename Fmt::rvf_t f_at(int j) { return get().f[j]; }
  static typename Fmt::rvf_t df_at(int j) { return get().df[j]; }
};

// Rotation vector (rad) of a unit quaternion, in rot_t.
template <class Fmt>
inline Vec3<typename Fmt::rot_t> rotvec(Quat<typename Fmt::quat_t> q, Status& st) {
  using quat_t = typename Fmt::quat_t;
  using rot_t = typename Fmt::rot_t;
  if (q.c[0] < quat_t{}) q = Quat<quat_t>{{cvt<quat_t>(-q.c[0], st), cvt<quat_t>(-q.c[1], st), cvt<quat_t>(-q.c[2], st), cvt<quat_t>(-q.c[3], st)}};
  Vec3<rot_t> r;
  if constexpr (Fmt::is_float) {
    const double f = RotvecTable<Fmt>::fexact(q.c[0]);
    for (int a = 0; a < 3; ++a) r.c[a] = 2.0 * f * q.c[a + 1];
  } else {
    using rvf_t = typename Fmt::rvf_t;
    constexpr int T = Fmt::ROTVEC_TABLE_BITS;
    constexpr int FB = quat_t::F - T;  // fraction bits of the interpolation weight
    const int64_t w = raw_of(q.c[0]);
    int idx = static_cast<int>(w >> FB);
    int64_t frac = w & ((int64_t(1) << FB) - 1);
    if (idx > (1 << T)) { idx = 1 << T; frac = 0; }  // w > 1 + 2^-T cannot come from a unit quaternion
    using tab = RotvecTable<Fmt>;
    const auto wgt = Fmt::template num<FB + 1, 1>::from_raw(frac);
    const rvf_t f = cvt<rvf_t>(tab::f_at(idx) + tab::df_at(idx) * wgt, st);
    for (int a = 0; a < 3; ++a) r.c[a] = cvt<rot_t>(pow2<1>(f * q.c[a + 1]), st);
  }
  return r;
}

template <class Fmt, int NMAX, int TMAX = 4>
struct ServoParams {
  SolverParams<Fmt, NMAX> solver;
  typename Fmt::gain_t kp, ko;      // position and orientation gains (1/s)
  typename Fmt::dt_t dt;            // tick period (s), used in virtual mode
  int mode = ERR_A;
  bool feedforward = true;          // false: the seed's error-only mode
  int ntasks = 1;                   // controlled frames stacked in one solve (trees: one per tip)
  int controlled[TMAX];             // frame of each task; -1: tip t (the tool for task 0)
  typename Fmt::weight_t weight[TMAX];  // row weight of each task (used when ntasks > 1)
  int setpoint_frame = -1;          // -1: U in the root frame; k: U relative to frame k
  int warm_leak = 0;                // warm start q'_warm - (q'_warm >> s); 0: none (docs/solver.md)
  ServoParams() { for (int t = 0; t < TMAX; ++t) controlled[t] = -1; }
};

template <class Fmt>
struct Setpoint {
  Quat<typename Fmt::quat_t> Q;
  Vec3<typename Fmt::pos_t> p;
  Vec3<typename Fmt::vel_t> w, v;   // twist (omega; v): v of the controlled point, axes as for e
};

template <class Fmt, int NMAX, int TMAX = 4>
struct TickResult {
  typename Fmt::qd_t qd[NMAX];      // joint-rate command
  typename Fmt::angle_t q_next[NMAX];  // q + q' dt, clamped to the limits (virtual mode)
  Vec3<typename Fmt::perr_t> ep[TMAX];  // position error of each task
  Vec3<typename Fmt::rot_t> eo[TMAX];   // orientation error (rotation vector) of each task
  typename Fmt::tw_t r[6 * TMAX];   // final scaled residual of the solver
  Frames<Fmt, NMAX, TMAX> frames;
  Jacobian<Fmt, NMAX> J[TMAX];      // each task's Jacobian, in the basis its error uses
  Vec3<typename Fmt::vel_t> V_w[TMAX], V_v[TMAX];  // each task's commanded twist (omega; v)
};

// Error and commanded twist of one task (controlled frame ctl, setpoint U); fills the task's
// Jacobian in the matching basis.
template <class Fmt, int NMAX, int TMAX>
inline void task_error(const ChainQ<Fmt, NMAX, TMAX>& ch, const ServoParams<Fmt, NMAX, TMAX>& P,
                       const Frames<Fmt, NMAX, TMAX>& f, int ctl, const Setpoint<Fmt>& U,
                       Vec3<typename Fmt::perr_t>& ep, Vec3<typename Fmt::rot_t>& eo,
                       Vec3<typename Fmt::vel_t>& V_w, Vec3<typename Fmt::vel_t>& V_v, Jacobian<Fmt, NMAX>& J,
                       Status& st) {
  using quat_t = typename Fmt::quat_t;
  using pos_t = typename Fmt::pos_t;
  using perr_t = typename Fmt::perr_t;
  using vel_t = typename Fmt::vel_t;
  const int k = P.setpoint_frame;
  // Pose of the controlled frame, relative to the setpoint frame when one is given.
  Quat<quat_t> QP = f.Q[ctl];
  Vec3<pos_t> pP = f.p[ctl];
  if (k >= 0) {
    QP = qmul<quat_t>(conj(f.Q[k], st), f.Q[ctl], st);
    const Vec3<typename Fmt::lever_t> d = vsub<typename Fmt::lever_t>(f.p[ctl], f.p[k], st);
    pP = rotate<pos_t, typename Fmt::len_tmp_t, true>(f.Q[k], d, st);
  }
  const Vec3<perr_t> dp = vsub<perr_t>(U.p, pP, st);  // p_U - p_P, setpoint axes
  if (P.mode == ERR_A) {
    ep = dp;
    eo = rotvec<Fmt>(qmul<quat_t>(U.Q, conj(QP, st), st), st);
    for (int a = 0; a < 3; ++a) {
      const auto fw = P.ko * eo.c[a];
      const auto fv = P.kp * ep.c[a];
      V_w.c[a] = P.feedforward ? cvt<vel_t>(U.w.c[a] + fw, st) : cvt<vel_t>(fw, st);
      V_v.c[a] = P.feedforward ? cvt<vel_t>(U.v.c[a] + fv, st) : cvt<vel_t>(fv, st);
    }
  } else {
    ep = rotate<perr_t, typename Fmt::len_tmp_t, true>(QP, dp, st);
    eo = rotvec<Fmt>(qmul<quat_t>(conj(QP, st), U.Q, st), st);
    Vec3<vel_t> ffw{}, ffv{};
    if (P.feedforward) {
      // omega_U x (p_P - p_U) = dp x omega_U
      const Vec3<vel_t> lev = cross<vel_t>(dp, U.w, st);
      const Vec3<vel_t> vP = vadd<vel_t>(U.v, lev, st);
      ffw = rotate<vel_t, typename Fmt::jv_tmp_t, true>(QP, U.w, st);
      ffv = rotate<vel_t, typename Fmt::jv_tmp_t, true>(QP, vP, st);
    }
    for (int a = 0; a < 3; ++a) {
      V_w.c[a] = cvt<vel_t>(ffw.c[a] + P.ko * eo.c[a], st);
      V_v.c[a] = cvt<vel_t>(ffv.c[a] + P.kp * ep.c[a], st);
    }
  }
  // Jacobian of the controlled frame's origin: root axes (A, no setpoint frame), frame k's axes
  // (A, moving local basis), or the controlled frame's own axes (B).  With a setpoint frame k,
  // the joints that move frame k move the controlled frame with it: their columns are zero.
  const int basis = P.mode == ERR_B ? ctl : k;
  jacobian(ch, f, ctl, basis, J, st);
  if (k >= 1) {
    bool moves_k[NMAX];
    joints_moving(ch, k, moves_k);
    for (int i = 0; i < NMAX; ++i)
      if (i < ch.n && moves_k[i])
        for (int a = 0; a < 3; ++a) { J.w[i].c[a] = typename Fmt::jw_t{}; J.v[i].c[a] = typename Fmt::jv_t{}; }
  }
}

// The warm start's leak: x - (x >> s) on the raw value (arithmetic shift, i.e. floor), one shifter
// and one subtractor; the double configuration uses x (1 - 2^-s).  s = 0: no leak.  Without it a
// joint rate in the null space of a redundant chain persists as self-motion (docs/solver.md).
template <class T>
inline T warm_leak(const T& x, int s) {
  if (s <= 0) return x;
  if constexpr (std::is_same_v<T, double>) return x - std::ldexp(x, -s);
  else return T::from_raw(raw_of(x) - (raw_of(x) >> s));
}

// The front half of a tick: FK, each task's error, Jacobian and commanded twist (into R).
template <class Fmt, int NMAX, int TMAX>
inline void servo_front(const ChainQ<Fmt, NMAX, TMAX>& ch, const ServoParams<Fmt, NMAX, TMAX>& P,
                        const typename Fmt::angle_t* q, const Setpoint<Fmt>* U, TickResult<Fmt, NMAX, TMAX>& R,
                        Status& st) {
  const int n = ch.n;
  forward_kinematics(ch, q, R.frames, st);
  for (int t = 0; t < TMAX; ++t) {
    if (t >= P.ntasks) continue;
    const int ctl = P.controlled[t] < 0 ? n + 1 + t : P.controlled[t];
    task_error(ch, P, R.frames, ctl, U[t], R.ep[t], R.eo[t], R.V_w[t], R.V_v[t], R.J[t], st);
  }
}

// The back half: the solve of the stacked tasks (R.J, R.V_w, R.V_v) and the virtual-mode
// integration; qd_warm: the previous tick's q' (warm start).
template <class Fmt, int NMAX, int TMAX>
inline void servo_back(const ServoParams<Fmt, NMAX, TMAX>& P, int n, const typename Fmt::angle_t* q,
                       const typename Fmt::qd_t* qd_warm, TickResult<Fmt, NMAX, TMAX>& R, Status& st) {
  using tw_t = typename Fmt::tw_t;
  const int T = P.ntasks;
  SolverColumns<Fmt, NMAX, 6 * TMAX> C;
  C.rows = 6 * T;
  tw_t vs[6 * TMAX];
  for (int t = 0; t < TMAX; ++t) {
    if (t >= T) continue;
    // Scaled (and, for several tasks, weighted) target and columns of this task.
    const typename Fmt::weight_t* w = T > 1 ? &P.weight[t] : nullptr;
    solver_target(P.solver, R.V_w[t], R.V_v[t], t, w, vs, st);
    solver_columns(P.solver, R.J[t], t, w, C, st);
  }
  solver_steps(P.solver, q, n, C, st);
  for (int i = 0; i < NMAX; ++i)
    if (i < n) R.qd[i] = warm_leak(qd_warm[i], P.warm_leak);
  solver_run(P.solver, C, n, vs, R.qd, R.r, st);

  // Virtual-mode integration, clamped to the position limits.
  using angle_t = typename Fmt::angle_t;
  for (int i = 0; i < NMAX; ++i) {
    if (i >= n) continue;
    angle_t qn = cvt<angle_t>(q[i] + R.qd[i] * P.dt, st);
    if (P.solver.limited[i]) qn = tmax(P.solver.lo[i], tmin(qn, P.solver.hi[i]));
    R.q_next[i] = qn;
  }
}

// One servo tick.  U: one setpoint per task; qd_warm: the previous tick's q' (warm start).
template <class Fmt, int NMAX, int TMAX>
inline void servo_tick(const ChainQ<Fmt, NMAX, TMAX>& ch, const ServoParams<Fmt, NMAX, TMAX>& P,
                       const typename Fmt::angle_t* q, const Setpoint<Fmt>* U, const typename Fmt::qd_t* qd_warm,
                       TickResult<Fmt, NMAX, TMAX>& R, Status& st) {
  servo_front(ch, P, q, U, R, st);
  servo_back(P, ch.n, q, qd_warm, R, st);
}

}  // namespace ts
