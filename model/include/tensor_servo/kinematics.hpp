// tensor-servo: forward kinematics of every frame and the Jacobian by screw transport.
//
// Frames: 0 = base (the first joint's parent frame), i = 1..n = the frame of joint i after its
// motion, n+1.. = tips (n+1 = the tool of a serial chain).  A joint's parent frame is the previous
// joint's (serial chain) or any earlier frame (a tree of chains, seed section 12).  All poses are in the root frame (the URDF's base link): quaternion Q_k and
// origin p_k.
//
// Per joint i (joint index j = i-1), from its parent frame P (serial: i-1):
//     QF  = Q_P (x) Qo_i                     joint frame before motion
//     pF  = p_P + R(Q_P) po_i
//     z_i = R(QF) a_i                        joint axis in the root basis (unit)
//   revolute:  u = wrap(q_j * s/(4 pi))  (half angle, turns);  (c, s) = sincos(u)
//              Q_i = QF (x) (c, s a_i),  p_i = pF
//   prismatic: d = s q_j;  Q_i = QF,  p_i = pF + d z_i
// Tip t on joint frame P: Q_{n+1+t} = Q_P (x) Qt_t, p_{n+1+t} = p_P + R(Q_P) pt_t.
//
// Jacobian column i for the reference point p_ref (origin of frame `ref`), twist order (omega; v),
// in the root basis -- the seed's W_i = (s a_i; 0) carried by screw transport:
//   revolute:  omega = s z_i,  v = omega x (p_ref - p_i)
//   prismatic: omega = 0,      v = s z_i
// and zero for joints that do not move frame `ref` (serial: joints after it).  In the basis of frame b both halves are rotated by conj(Q_b).
//
// No drift: the pose is recomputed from q every tick, so rounding errors never accumulate over
// time; their bound grows only with the number of joints (docs/numerics.md).
//
// Loops run to the compile-time bounds NMAX / TMAX and skip the entries beyond the configured n
// (the form HLS needs; hls/ instantiates these functions on ap_fixed).
#pragma once
#include "chain.hpp"

namespace ts {

template <class Fmt, int NMAX, int TMAX = 4>
struct Frames {
  static constexpr int nframes_max = NMAX + 1 + TMAX;
  int n = 0;
  int ntips = 1;
  Quat<typename Fmt::quat_t> Q[NMAX + 1 + TMAX];
  Vec3<typename Fmt::pos_t> p[NMAX + 1 + TMAX];
  Vec3<typename Fmt::quat_t> z[NMAX + 1];  // z[i]: axis of joint i (1..n), root basis
};

template <class Fmt, int NMAX>
struct Jacobian {
  int n = 0;
  Vec3<typename Fmt::jw_t> w[NMAX];  // omega part of column j
  Vec3<typename Fmt::jv_t> v[NMAX];  // v part of column j
};

// The joint quaternion (cos(theta/2), sin(theta/2) a) of a revolute joint, theta = s q.
template <class Fmt>
inline Quat<typename Fmt::quat_t> joint_quat(const JointQ<Fmt>& jq, typename Fmt::angle_t q, Status& st) {
  using quat_t = typename Fmt::quat_t;
  const auto u = wrap<typename Fmt::turn_t>(q * jq.k);
  quat_t sn, cs;
  sincos_turns<Fmt>(u, sn, cs, st);
  Quat<quat_t> r;
  r.c[0] = cs;
  for (int i = 0; i < 3; ++i) r.c[i + 1] = cvt<quat_t>(sn * jq.axis.c[i], st);
  return r;
}

template <class Fmt, int NMAX, int TMAX>
inline void forward_kinematics(const ChainQ<Fmt, NMAX, TMAX>& ch, const typename Fmt::angle_t* q,
                               Frames<Fmt, NMAX, TMAX>& f, Status& st) {
  using quat_t = typename Fmt::quat_t;
  using pos_t = typename Fmt::pos_t;
  using len_tmp_t = typename Fmt::len_tmp_t;
  using uvec_tmp_t = typename Fmt::uvec_tmp_t;
  using lever_t = typename Fmt::lever_t;
  const int n = ch.n;
  f.n = n;
  f.ntips = ch.ntips;
  f.Q[0] = ch.qb;
  f.p[0] = vec_cvt<pos_t>(ch.pb, st);  // exact widening
  for (int i = 1; i <= NMAX; ++i) {
    // Serial dependence through the parent frame: one joint after the other (docs/hls.md).
    if (i > n) continue;
    const JointQ<Fmt>& jq = ch.j[i - 1];
    const int pf = ch.parent[i - 1];  // serial chain: i - 1
    const Quat<quat_t> QF = qmul<quat_t>(f.Q[pf], jq.qo, st);
    const Vec3<pos_t> off = rotate<pos_t, len_tmp_t>(f.Q[pf], jq.po, st);
    const Vec3<pos_t> pF = vadd<pos_t>(f.p[pf], off, st);
    f.z[i] = rotate<quat_t, uvec_tmp_t>(QF, jq.axis, st);
    if (!jq.prismatic) {
      f.Q[i] = qmul<quat_t>(QF, joint_quat<Fmt>(jq, q[i - 1], st), st);
      f.p[i] = pF;
    } else {
      const lever_t d = cvt<lever_t>(jq.s * q[i - 1], st);
      f.Q[i] = QF;
      for (int a = 0; a < 3; ++a) f.p[i].c[a] = cvt<pos_t>(pF.c[a] + d * f.z[i].c[a], st);
    }
  }
  for (int t = 0; t < TMAX; ++t) {
    if (t >= ch.ntips) continue;
    const int pf = ch.tip_parent[t];  // serial chain: the tool on frame n
    f.Q[n + 1 + t] = qmul<quat_t>(f.Q[pf], ch.qt[t], st);
    const Vec3<pos_t> off = rotate<pos_t, len_tmp_t>(f.Q[pf], ch.pt[t], st);
    f.p[n + 1 + t] = vadd<pos_t>(f.p[pf], off, st);
  }
}

// Mark the joints that move frame f (its ancestors): on_path[j] for joint j (0-based).
// Every step goes to a lower frame index, so at most NMAX + 1 steps reach the base.
template <class Fmt, int NMAX, int TMAX>
inline void joints_moving(const ChainQ<Fmt, NMAX, TMAX>& ch, int f, bool* on_path) {
  for (int j = 0; j < NMAX; ++j) on_path[j] = false;
  for (int step = 0; step <= NMAX; ++step) {
    if (f < 1) continue;
    if (f <= ch.n) on_path[f - 1] = true;
    f = ch.parent_frame(f);
  }
}

// One Jacobian column by screw transport (root basis), reference point p_ref.
template <class Fmt>
inline void screw_column(bool prismatic, typename Fmt::scale_t s, const Vec3<typename Fmt::quat_t>& z,
                         const Vec3<typename Fmt::pos_t>& p_ref, const Vec3<typename Fmt::pos_t>& p_i,
                         Vec3<typename Fmt::jw_t>& w, Vec3<typename Fmt::jv_t>& v, Status& st) {
  using jw_t = typename Fmt::jw_t;
  using jv_t = typename Fmt::jv_t;
  if (!prismatic) {
    w = vscale<jw_t>(s, z, st);
    const Vec3<typename Fmt::lever_t> r = vsub<typename Fmt::lever_t>(p_ref, p_i, st);
    v = cross<jv_t>(w, r, st);
  } else {
    for (int a = 0; a < 3; ++a) w.c[a] = jw_t{};
    v = vscale<jv_t>(s, z, st);
  }
}

// Basis: -1 = root frame axes, otherwise a frame index 0..n+ntips.  ref: frame index 1..n+ntips.
// Columns of joints that do not move frame `ref` are zero (serial chain: joints after ref).
template <class Fmt, int NMAX, int TMAX>
inline void jacobian(const ChainQ<Fmt, NMAX, TMAX>& ch, const Frames<Fmt, NMAX, TMAX>& f, int ref, int basis,
                     Jacobian<Fmt, NMAX>& J, Status& st) {
  using jw_t = typename Fmt::jw_t;
  using jv_t = typename Fmt::jv_t;
  const int n = ch.n;
  J.n = n;
  bool moves[NMAX];
  joints_moving(ch, ref, moves);
  for (int i = 1; i <= NMAX; ++i) {
    // Independent columns: pipelined, II 4 shares the ~40 multipliers of a column by four
    // (latency ~ 20 cycles + 4 per column; docs/hls.md).
    TS_HLS(PIPELINE II=4)
    if (i > n) continue;
    Vec3<jw_t>& w = J.w[i - 1];
    Vec3<jv_t>& v = J.v[i - 1];
    if (!moves[i - 1]) {
      for (int a = 0; a < 3; ++a) { w.c[a] = jw_t{}; v.c[a] = jv_t{}; }
      continue;
    }
    const JointQ<Fmt>& jq = ch.j[i - 1];
    screw_column<Fmt>(jq.prismatic, jq.s, f.z[i], f.p[ref], f.p[i], w, v, st);
    if (basis >= 0) {
      w = rotate<jw_t, typename Fmt::jw_tmp_t, true>(f.Q[basis], w, st);
      v = rotate<jv_t, typename Fmt::jv_tmp_t, true>(f.Q[basis], v, st);
    }
  }
}

}  // namespace ts
