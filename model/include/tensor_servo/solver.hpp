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
  int cg = 0;                              // conjugate-direction steps after the sweeps (0..CG_MAX;
                                           // offline IK only: the core has none, see solver_cg)
};

constexpr int CG_MAX = 64;

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

// The value 1 of a storage type (double or a fixed-point format with an integer bit).
template <class T> inline T one_of() {
  if constexpr (std::is_same_v<T, double>) return 1.0;
  else return T::from_raw(int64_t(1) << T::F);
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

// Leading-one position of max |v[i]| over i < m; LEAD_NONE when every v[i] is zero.
constexpr int LEAD_NONE = -(1 << 20);
template <int M, class V>
inline int lead_exp(const V* v, int m) {
  int top = LEAD_NONE;
  for (int i = 0; i < M; ++i) {
    if (i >= m) continue;
    const int ki = v[i] < V{} ? ilog2(-v[i]) : ilog2(v[i]);
    top = ki > top ? ki : top;
  }
  return top;
}

// Block floating point: out[i] = v[i] 2^-k rounded to bfm_t with k = 1 + the leading-one position
// of max |v[i]|, so 1/2 <= max |out| <= 1 and rounding never saturates (bfm_t has 2 integer bits).
// Returns false (out zero, k = 0) when every v[i] (i < m) is zero.
template <class Fmt, int M, class V>
inline bool block_norm(const V* v, int m, typename Fmt::bfm_t* out, int& k, Status& st) {
  using bfm_t = typename Fmt::bfm_t;
  const int top = lead_exp<M>(v, m);
  k = top > LEAD_NONE ? top + 1 : 0;
  for (int i = 0; i < M; ++i) out[i] = i < m && top > LEAD_NONE ? cvt_shr<bfm_t>(v[i], k, st) : bfm_t{};
  return top > LEAD_NONE;
}

// Exact combination out[a] = sum_i js[i][a] x[i] of the scaled columns (rows a < rows, joints
// i < n): the accumulator has 7 more integer bits than one product (n <= 64), so it never rounds.
template <class Fmt, int NMAX, int ROWS, class X>
inline auto columns_times(const typename Fmt::jsc_t (*js)[ROWS], const X* x, int n, int a) {
  if constexpr (Fmt::is_float) {
    double acc = 0;
    for (int i = 0; i < NMAX; ++i)
      if (i < n) acc += js[i][a] * x[i];
    return acc;
  } else {
    using P = num_traits<decltype(js[0][0] * x[0])>;
    using Acc = typename Fmt::template num<P::W + 7, P::I + 7>;
    Acc acc = Acc::from_raw(0);
    for (int i = 0; i < NMAX; ++i)
      if (i < n) acc = wrap<Acc>(acc + js[i][a] * x[i]);  // |sum| < 2^(P::I + 6): never wraps
    return acc;
  }
}

// Conjugate-direction refinement after the sweeps (SolverParams::cg steps; the offline IK's polish,
// docs/ik.md): conjugate gradients on the normal equations of the scaled problem (CGLS) for the
// increment d of q', over the joints that are not frozen (mu_i = 0) and not held at a bound by the
// gradient, from the sweeps' q' and exact residual r0.  Division-free like the sweeps:
//   - vectors and scalars are held in block floating point: bfm_t mantissas, run-time exponents;
//   - the increment d and the residual r of the recurrence are fixed point relative to r0's
//     exponent k0 (cgx_t, cgr_t), so steps far below one LSB of qd_t still count;
//   - the two ratios of a step, the line search alpha = <A p, r> / |A p|^2 along the direction p
//     and the conjugacy coefficient beta = -<A s, A p> / |A p|^2 of the next direction
//     p' = s + beta p (s = A^T r), share one reciprocal of |A p|^2: the solver's table and Newton
//     step (step_factor with mu = 1, relative error < 2^-13), then one more Newton step in cgy_t
//     (relative error ~ 2^-24).  CG on an ill-conditioned problem needs the ratios to about that
//     precision: with the 2^-13 of the sweeps' reciprocal it stalls (measured, docs/ik.md).
// In exact arithmetic the refinement reaches the least-squares solution of the free joints in as
// many steps as there are free joints, whatever the condition number, where the sweeps crawl at
// about 1 - 1/cond^2 per sweep.  A step that would take a joint out of its box is not made and
// ends the refinement.  At the end q' += d (rounded to qd_t, clamped) and the solver's residual is
// updated exactly for what q' really moved.  The core has no such unit: cg = 0 there.
template <class Fmt, int NMAX, int ROWS>
inline void solver_cg(const SolverParams<Fmt, NMAX>& P, const SolverColumns<Fmt, NMAX, ROWS>& C, int n,
                      typename Fmt::qd_t* qd, typename Fmt::tacc_t* racc, Status& st) {
  using bfm_t = typename Fmt::bfm_t;
  using cgy_t = typename Fmt::cgy_t;
  using cgx_t = typename Fmt::cgx_t;
  using cgr_t = typename Fmt::cgr_t;
  using step_t = typename Fmt::step_t;
  using qd_t = typename Fmt::qd_t;
  using tacc_t = typename Fmt::tacc_t;
  using cge_t = typename Fmt::cge_t;
  using G = decltype(dot_exact<Fmt, ROWS>(C.js[0], static_cast<const bfm_t*>(nullptr), 0));
  using Y = decltype(columns_times<Fmt, NMAX, ROWS>(C.js, static_cast<const bfm_t*>(nullptr), 0, 0));
  using U = decltype(bfm_t{} + bfm_t{});
  const int rows = C.rows;
  const auto one = one_of<typename Fmt::mu_t>();
  bool use[NMAX];
  bfm_t rn[ROWS], s[NMAX], p[NMAX], w[ROWS], z[ROWS], sc;
  cgr_t rr[ROWS];                       // residual of the recurrence, times 2^-k0 (|rr| <= |rr_0| < sqrt(rows))
  cgx_t d[NMAX], dlo[NMAX], dhi[NMAX];  // increment and its box, times 2^-k0
  G g[NMAX];
  Y y[ROWS];
  U u[NMAX];
  int k0 = 0, kr = 0, kw = 0, kz = 0, kd = 0, kn = 0;
  int kdir = 0;                         // exponent of s and p: not needed (a direction's scale cancels)
  cgy_t yw{};                           // 2^(kd + 1) / |w|^2, in [1, 2]
  if (!block_norm<Fmt, ROWS>(racc, rows, rn, k0, st)) return;
  for (int a = 0; a < ROWS; ++a) rr[a] = a < rows ? cvt_shr<cgr_t>(racc[a], k0, st) : cgr_t{};
  for (int i = 0; i < NMAX; ++i) {
    d[i] = cgx_t{};
    if (i >= n) continue;
    // a bound beyond cgx_t's range is clipped to it: that can only end the refinement earlier,
    // so it raises no flag (scratch status)
    Status clip;
    dlo[i] = cvt_shr<cgx_t>(C.lo[i] - qd[i], k0, clip);
    dhi[i] = cvt_shr<cgx_t>(C.hi[i] - qd[i], k0, clip);
  }
  for (int it = 0; it < CG_MAX; ++it) {
    if (it >= P.cg) break;
    // residual and gradient g = A^T r over the joints in use, in block floating point
    if (!block_norm<Fmt, ROWS>(rr, rows, rn, kr, st)) break;
    kr += k0;
    for (int i = 0; i < NMAX; ++i) {
      if (i >= n) continue;
      g[i] = dot_exact<Fmt, ROWS>(C.js[i], rn, rows);
      if (it == 0)  // the free set: not frozen, and not pushed out of its box by the gradient
        use[i] = !(P.mu[i] == typename Fmt::mu_t{}) && !(!(C.lo[i] < qd[i]) && g[i] < G{}) &&
                 !(!(qd[i] < C.hi[i]) && G{} < g[i]);
      if (!use[i]) g[i] = G{};
    }
    if (!block_norm<Fmt, NMAX>(g, n, s, kdir, st)) break;
    // direction: p = s at the first step, then p = s + beta p, beta = -<A s, A p> / |A p|^2 = bt 2^eb
    if (it == 0) {
      for (int i = 0; i < NMAX; ++i) p[i] = s[i];
    } else {
      for (int a = 0; a < ROWS; ++a)
        if (a < rows) y[a] = columns_times<Fmt, NMAX, ROWS>(C.js, s, n, a);
      if (!block_norm<Fmt, ROWS>(y, rows, z, kz, st)) break;
      const auto bn = dot_exact<Fmt, ROWS>(z, w, rows);
      int eb = 0;
      bfm_t bt{};
      if (block_norm<Fmt, 1>(&bn, 1, &sc, kn, st)) {
        bt = cvt<bfm_t>(pow2<-1>(-(sc * yw)), st);   // in (-1, 1)
        eb = kn - kd + kz - kw;
      }
      // s + bt p 2^eb, both terms scaled by 2^-E (E: the larger term's exponent), renormalised
      decltype(bt * p[0]) t[NMAX];
      for (int i = 0; i < NMAX; ++i) t[i] = bt * p[i];
      const int kt = lead_exp<NMAX>(t, n);
      const int E = (kt > LEAD_NONE && kt + eb + 1 > 0) ? kt + eb + 1 : 0;
      for (int i = 0; i < NMAX; ++i)
        if (i < n) u[i] = cvt_shr<bfm_t>(s[i], E, st) + cvt_shr<bfm_t>(t[i], E - eb, st);
      if (!block_norm<Fmt, NMAX>(u, n, p, kdir, st)) break;
    }
    // w = A p, |w|^2 = m 2^(kd + 1) with m in [1/2, 1], yw = 1/m
    for (int a = 0; a < ROWS; ++a)
      if (a < rows) y[a] = columns_times<Fmt, NMAX, ROWS>(C.js, p, n, a);
    if (!block_norm<Fmt, ROWS>(y, rows, w, kw, st)) break;
    {
      const auto dd = dot_exact<Fmt, ROWS>(w, w, rows);
      step_t c{};
      step_factor<Fmt>(dd, one, c, kd, st);          // c ~ 1 / (dd 2^-kd), error < 2^-13
      const bfm_t m = cvt_shr<bfm_t>(dd, kd + 1, st);   // [1/2, 1]
      const auto y0 = pow2<1>(c);                       // ~ 1/m
      const cge_t e = cvt<cge_t>(one - m * y0, st);
      yw = cvt<cgy_t>(y0 + y0 * e, st);
    }
    // line search: alpha = <w, r> / |w|^2 2^(kr - kw) = at 2^ea
    const auto an = dot_exact<Fmt, ROWS>(w, rn, rows);
    if (!block_norm<Fmt, 1>(&an, 1, &sc, kn, st)) break;   // r orthogonal to A p: done
    const bfm_t at = cvt<bfm_t>(pow2<-1>(sc * yw), st);     // in (-1, 1)
    const int ea = kn - kd + kr - kw;
    bool inside = true;
    cgx_t dn[NMAX];
    for (int i = 0; i < NMAX; ++i) {
      dn[i] = d[i];
      if (i >= n || !use[i]) continue;
      dn[i] = cvt<cgx_t>(d[i] + cvt_shr<cgx_t>(at * p[i], k0 - ea, st), st);
      inside = inside && !(dn[i] < dlo[i]) && !(dhi[i] < dn[i]);
    }
    if (!inside) break;
    for (int i = 0; i < NMAX; ++i) d[i] = dn[i];
    // r -= alpha A p = at w 2^(ea + kw)
    for (int a = 0; a < ROWS; ++a)
      if (a < rows) rr[a] = cvt<cgr_t>(rr[a] - cvt_shr<cgr_t>(at * w[a], k0 - ea - kw, st), st);
  }
  // q' += d, and the exact residual of what q' really moved
  for (int i = 0; i < NMAX; ++i) {
    if (i >= n) continue;
    const qd_t qn = tmax(C.lo[i], tmin(cvt<qd_t>(qd[i] + cvt_shr<qd_t>(d[i], -k0, st), st), C.hi[i]));
    const qd_t dq = cvt<qd_t>(qn - qd[i], st);
    for (int a = 0; a < ROWS; ++a)
      if (a < rows) racc[a] = cvt<tacc_t>(racc[a] - C.js[i][a] * dq, st);
    qd[i] = qn;
  }
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
  if (P.cg > 0) solver_cg<Fmt, NMAX, ROWS>(P, C, n, qd, racc, st);
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
