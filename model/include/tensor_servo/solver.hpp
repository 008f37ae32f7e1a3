// tensor-servo: the division-free coordinate-descent solver of J q' = V with joint limits.
//
// Weighted least squares: minimise |V - J q'|_W^2 with W = diag(L^2 I3, I3) (L: characteristic
// length, m/rad), subject to a box on every joint rate q'_i (velocity limit and position-limit
// approach).  Scaling the omega rows by L turns W into the plain dot product, so the solver works
// on the scaled column Js_i = (L omega_i; v_i) and the scaled target Vs = (L V_omega; V_v).
//
// Per tick, once per column (reciprocal without a divider):
//     d_i   = |Js_i|^2 (exact),  k_i = floor(log2 d_i)            (leading-one detection)
//     m_i   = d_i 2^-k_i, truncated to mant_t, in [1, 2)
//     y0    = table[top RECIP_TABLE_BITS fraction bits of m_i]    ~ 1/m_i (interval midpoint)
//     e     = 1 - m_i y0  (rounded, |e| < 2^-(T+1)),  y = y0 + y0 e   (one Newton step)
//     c_i   = mu_i y                                              (per-joint multiplier folded in)
// so the exact step factor is mu_i / d_i up to a relative error below 2^-13 (2^-(2T+2) from the
// Newton step plus rounding), i.e. the effective relaxation of joint i is mu_i (1 + eps).
// Projected Gauss-Seidel on a convex quadratic decreases the objective at every coordinate step
// when the effective relaxation lies in (0, 2); mu_i <= 1.9 therefore always converges, and mu_i = 0
// freezes joint i (the seed's zeroed multiplier).
//
// Bounds of q'_i (per tick, from the measured q_i):
//     position:  [klim (lo_i - q_i), klim (hi_i - q_i)]   (klim <= 1/dt never commands past a limit)
//     velocity:  [-vmax_i, vmax_i]
// the position bound is clamped into the velocity interval, so it is never empty; a joint at its
// upper limit gets [.., 0]: an increment that would drive it further out is zeroed (the seed's
// rule), one that moves it back in is kept.
//
// Sweeps: warm start from the previous tick's q' (clamped), residual r = Vs - sum Js_i q'_i, then
//     for s in 1..sweeps, for i in 1..n:
//         g   = <Js_i, round(r)> (exact);  gk = g 2^-k_i (rounded);  q_new = clamp(q'_i + gk c_i)
//         dq  = q_new - q'_i;  r -= Js_i dq (exact: r never drifts);  q'_i = q_new
// Twist order (omega; v) everywhere.  Loops run to compile-time bounds (NMAX joints, ROWS rows,
// Fmt::SWEEPS_MAX sweeps) and skip the entries beyond the configured ones (the form HLS needs).
#pragma once
#include "kinematics.hpp"

namespace ts {

template <class Fmt, int NMAX>
struct SolverParams {
  typename Fmt::lchar_t L;                 // characteristic length (m/rad)
  typename Fmt::mu_t mu[NMAX];             // per-joint multiplier (relaxation); 0 freezes the joint
  bool limited[NMAX];                      // position limits present
  typename Fmt::angle_t lo[NMAX], hi[NMAX];
  typename Fmt::qd_t vmax[NMAX];           // velocity limit (format max when none)
  typename Fmt::klim_t klim;               // limit-approach gain (1/s)
  int sweeps = 2;
};

// Per-column quantities computed once per tick.  ROWS = 6 x (number of stacked tasks); a serial
// chain with one controlled frame has 6.
template <class Fmt, int NMAX, int ROWS = 6>
struct SolverColumns {
  int rows = 6;                            // rows in use (6 per task)
  typename Fmt::jsc_t js[NMAX][ROWS];      // scaled columns (L omega; v) per task, stacked
  typename Fmt::step_t c[NMAX];            // mu_i / mant_i
  int k[NMAX];                             // normalisation exponent of d_i
  typename Fmt::qd_t lo[NMAX], hi[NMAX];   // bounds of q'_i this tick
  bool lo_pos[NMAX], hi_pos[NMAX];         // the bound comes from a position limit
};

// The reciprocal table: y0[j] = 1 / (1 + (j + 1/2) 2^-T), rounded to recip_t.  Read through at()
// (a configuration may specialise the table with a constant array, as TrigTable).
template <class Fmt>
struct RecipTable {
  static constexpr int N = 1 << Fmt::RECIP_TABLE_BITS;
  typename Fmt::recip_t y[N];
  RecipTable() {
    Status st;
    for (int j = 0; j < N; ++j) y[j] = from_double<typename Fmt::recip_t>(1.0 / (1.0 + (j + 0.5) / N), st);
  }
  static const RecipTable& get() {
    static const RecipTable t;
    return t;
  }
  static typename Fmt::recip_t at(int j) { return get().y[j]; }
};

// Exact sum of m <= M products a[i] b[i] (M <= 32): the accumulator has 5 more integer bits than
// one product, so no rounding and no overflow can occur (the RTL uses the same width).
template <class Fmt, int M, class A, class B>
inline auto dot_exact(const A* a, const B* b, int m) {
  static_assert(M <= 32, "dot_exact: accumulator sized for at most 32 products");
  if constexpr (std::is_same_v<A, double>) {
    double acc = 0;
    for (int i = 0; i < M; ++i)
      if (i < m) acc += a[i] * b[i];
    return acc;
  } else {
    using P = num_traits<decltype(a[0] * b[0])>;
    using Acc = typename Fmt::template num<P::W + 5, P::I + 5>;
    Acc acc = Acc::from_raw(0);
    // The sum has the accumulator's fraction bits and |sum| < 2^(P::I + 3): wrap never wraps.
    for (int i = 0; i < M; ++i)
      if (i < m) acc = wrap<Acc>(acc + a[i] * b[i]);
    return acc;
  }
}

// Step factor c = mu / d and the exponent k with d = m 2^k, m in [1, 2).  d <= 0 gives c = 0.
template <class Fmt, class D>
inline void step_factor(const D& d, typename Fmt::mu_t mu, typename Fmt::step_t& c, int& k, Status& st) {
  using step_t = typename Fmt::step_t;
  k = ilog2(d);
  if (k < -(1 << 19)) { c = step_t{}; k = 0; return; }
  if constexpr (Fmt::is_float) {
    (void)st;
    c = mu / std::ldexp(d, -k);
  } else {
    using mant_t = typename Fmt::mant_t;
    using recip_t = typename Fmt::recip_t;
    constexpr int T = Fmt::RECIP_TABLE_BITS;
    // m = d 2^-k truncated to mant_t (keep the leading bits; never rounds up to 2).
    const int s = num_traits<D>::F + k - mant_t::F;
    const int64_t dr = raw_of(d);
    const int64_t mr = s >= 0 ? (dr >> s) : detail::shl(dr, -s);
    const mant_t m = mant_t::from_raw(mr);
    const int idx = static_cast<int>((mr >> (mant_t::F - T)) & ((1 << T) - 1));
    const recip_t y0 = RecipTable<Fmt>::at(idx);
    using e_t = typename Fmt::template num<recip_t::W, recip_t::I - T, ST_OVF_SOLVER>;  // |1 - m y0| < 2^-(T+1)
    const auto one = Fmt::template num<2, 2>::from_raw(1);
    const e_t e = cvt<e_t>(one - m * y0, st);
    const recip_t y = cvt<recip_t>(y0 + y0 * e, st);
    c = cvt<step_t>(mu * y, st);
  }
}

template <class T> inline T tmin(const T& a, const T& b) { return b < a ? b : a; }
template <class T> inline T tmax(const T& a, const T& b) { return a < b ? b : a; }

// Scaled columns of one task into rows 6t..6t+5: (L w omega_i; w v_i).  weight == nullptr means
// w = 1 and no multiply (a single task: bit-identical to the unweighted solver).
template <class Fmt, int NMAX, int ROWS>
inline void solver_columns(const SolverParams<Fmt, NMAX>& P, const Jacobian<Fmt, NMAX>& J, int t,
                           const typename Fmt::weight_t* weight, SolverColumns<Fmt, NMAX, ROWS>& C, Status& st) {
  using jsc_t = typename Fmt::jsc_t;
  const int n = J.n;
  typename Fmt::lchar_t L = P.L;
  if (weight) L = cvt<typename Fmt::lchar_t>(P.L * *weight, st);
  for (int i = 0; i < NMAX; ++i) {
    TS_HLS(PIPELINE II=1)  // 3 (6 weighted) products per column; latency ~ 5 cycles + NMAX
    if (i >= n) continue;
    for (int a = 0; a < 3; ++a) {
      C.js[i][6 * t + a] = cvt<jsc_t>(L * J.w[i].c[a], st);
      C.js[i][6 * t + a + 3] = weight ? cvt<jsc_t>(*weight * J.v[i].c[a], st) : cvt<jsc_t>(J.v[i].c[a], st);
    }
  }
}

// Scaled target of one task into rows 6t..6t+5: (L w V_omega; w V_v), as the columns above.
template <class Fmt, int NMAX>
inline void solver_target(const SolverParams<Fmt, NMAX>& P, const Vec3<typename Fmt::vel_t>& V_w,
                          const Vec3<typename Fmt::vel_t>& V_v, int t, const typename Fmt::weight_t* weight,
                          typename Fmt::tw_t* vs, Status& st) {
  using tw_t = typename Fmt::tw_t;
  typename Fmt::lchar_t L = P.L;
  if (weight) L = cvt<typename Fmt::lchar_t>(P.L * *weight, st);
  for (int a = 0; a < 3; ++a) {
    vs[6 * t + a] = cvt<tw_t>(L * V_w.c[a], st);
    vs[6 * t + a + 3] = weight ? cvt<tw_t>(*weight * V_v.c[a], st) : cvt<tw_t>(V_v.c[a], st);
  }
}

// Step factors and the bounds of q' for this tick, from the scaled columns in C.
template <class Fmt, int NMAX, int ROWS>
inline void solver_steps(const SolverParams<Fmt, NMAX>& P, const typename Fmt::angle_t* q, int n,
                         SolverColumns<Fmt, NMAX, ROWS>& C, Status& st) {
  using qd_t = typename Fmt::qd_t;
  for (int i = 0; i < NMAX; ++i) {
    TS_HLS(PIPELINE II=2)  // |Js_i|^2, reciprocal and bounds per column; latency ~ 25 cycles + 2 NMAX
    if (i >= n) continue;
    const auto d = dot_exact<Fmt, ROWS>(C.js[i], C.js[i], C.rows);
    step_factor<Fmt>(d, P.mu[i], C.c[i], C.k[i], st);
    // Bounds: velocity interval, then the position-limit interval clamped into it.
    const qd_t vmax = P.vmax[i];
    const qd_t vmin = cvt<qd_t>(-vmax, st);
    C.lo[i] = vmin; C.hi[i] = vmax;
    C.lo_pos[i] = C.hi_pos[i] = false;
    if (P.limited[i]) {
      // Compared exactly before narrowing: a bound beyond the velocity interval is inactive and
      // never needs to be represented (no spurious saturation for wide ranges or large klim).
      using qdiff_t = typename Fmt::qdiff_t;  // default: exact; compact: rounded to 18 bits
      const auto plo = P.klim * cvt<qdiff_t>(P.lo[i] - q[i], st);
      const auto phi = P.klim * cvt<qdiff_t>(P.hi[i] - q[i], st);
      if (vmin < plo) { C.lo[i] = vmax < plo ? vmax : cvt<qd_t>(plo, st); C.lo_pos[i] = true; }
      if (phi < vmax) { C.hi[i] = phi < vmin ? vmin : cvt<qd_t>(phi, st); C.hi_pos[i] = true; }
    }
  }
}

// One task (serial chain): columns, step factors and bounds of one tick.
template <class Fmt, int NMAX>
inline void solver_prepare(const SolverParams<Fmt, NMAX>& P, const Jacobian<Fmt, NMAX>& J,
                           const typename Fmt::angle_t* q, SolverColumns<Fmt, NMAX>& C, Status& st) {
  C.rows = 6;
  solver_columns(P, J, 0, nullptr, C, st);
  solver_steps(P, q, J.n, C, st);
}

// Solve: qd holds the warm start on entry and q' on return; r receives the final scaled residual
// (C.rows entries).
template <class Fmt, int NMAX, int ROWS>
inline void solver_run(const SolverParams<Fmt, NMAX>& P, const SolverColumns<Fmt, NMAX, ROWS>& C, int n,
                       const typename Fmt::tw_t* vs, typename Fmt::qd_t* qd, typename Fmt::tw_t* r, Status& st) {
  using tw_t = typename Fmt::tw_t;
  using qd_t = typename Fmt::qd_t;
  using gk_t = typename Fmt::gk_t;
  const int rows = C.rows;
  // Warm start, clamped into this tick's box, and the initial residual.  The residual is kept
  // exact (tacc_t: |Js_i q'_i| < 2^9, n <= 64, so |r| < 2^16 and no rounding ever happens), so it
  // never drifts from Vs - Js q' however many sweeps run; only its rounded copy (tw_t) is a
  // multiplier operand.
  using tacc_t = typename Fmt::tacc_t;
  for (int i = 0; i < NMAX; ++i)
    if (i < n) qd[i] = tmax(C.lo[i], tmin(qd[i], C.hi[i]));
  tacc_t racc[ROWS];
  TS_HLS(ARRAY_PARTITION variable=racc type=complete)  // all rows updated in parallel
  for (int a = 0; a < ROWS; ++a) {
    if (a >= rows) continue;
    racc[a] = cvt<tacc_t>(vs[a], st);
    for (int i = 0; i < NMAX; ++i)
      if (i < n) racc[a] = cvt<tacc_t>(racc[a] - C.js[i][a] * qd[i], st);
  }
  for (int sweep = 0; sweep < Fmt::SWEEPS_MAX; ++sweep) {
    if (sweep >= P.sweeps) break;
    for (int i = 0; i < NMAX; ++i) {
      // Gauss-Seidel: each coordinate step needs the residual of the previous one, so the
      // steps are sequential (latency ~ 20 cycles each); the row loops inside are unrolled.
      if (i >= n) continue;
      const auto* js = C.js[i];
      tw_t ro[ROWS];
      for (int a = 0; a < ROWS; ++a)
        if (a < rows) ro[a] = cvt<tw_t>(racc[a], st);
      const auto g = dot_exact<Fmt, ROWS>(js, ro, rows);
      const gk_t gk = cvt_shr<gk_t>(g, C.k[i], st);
      qd_t qn = cvt<qd_t>(qd[i] + gk * C.c[i], st);
      qn = tmax(C.lo[i], tmin(qn, C.hi[i]));
      const qd_t dq = cvt<qd_t>(qn - qd[i], st);
      for (int a = 0; a < ROWS; ++a)
        if (a < rows) racc[a] = cvt<tacc_t>(racc[a] - js[a] * dq, st);
      qd[i] = qn;
    }
  }
  for (int a = 0; a < ROWS; ++a)
    if (a < rows) r[a] = cvt<tw_t>(racc[a], st);
  for (int i = 0; i < NMAX; ++i) {
    if (i >= n) continue;
    if ((C.lo_pos[i] && !(C.lo[i] < qd[i])) || (C.hi_pos[i] && !(qd[i] < C.hi[i]))) st.raise(ST_LIMIT_ACTIVE);
    if ((!C.lo_pos[i] && !(C.lo[i] < qd[i])) || (!C.hi_pos[i] && !(qd[i] < C.hi[i]))) {
      if (P.vmax[i] < max_of<qd_t>()) st.raise(ST_VLIMIT_ACTIVE);
    }
  }
}

}  // namespace ts
