// tensor-servo: double-precision pseudo-inverse references for the inverse velocity problem.
//
// Not part of the core: this is the offline / reference tool for the problem the coordinate-descent
// solver (solver.hpp) solves in fixed point, with the same problem statement and the same box:
//
//     minimise  |V - J q'|_W^2,   W = diag(L^2 I3, I3)     (twist order (omega; v), L in m/rad)
//     subject to lower <= q' <= upper                      (rate_box(): velocity limit and the
//                                                           position-limit approach, as solver.hpp)
//
// Scaling the omega rows by L turns W into the plain dot product: A = S J, b = S V with
// S = diag(L, L, L, 1, 1, 1), and the problem is the bounded least-squares problem
// min 1/2 |b - A x|^2, lower <= x <= upper.  Everything below works on (A, b).
//
// pinv_solve()  -- the seed's "pseudo-inverse (linear system) method" with its coordinate-exclusion
//                  rule for the joint-limit constraint (24) (seed 000, §9; digest a.7):
//   Exclusion::Seed       literally the seed: solve over the remaining coordinates, remove every
//                         coordinate whose rate leaves its range, set its rate to 0 (clamped into the
//                         box when the box excludes 0) and re-solve; repeat until no remaining
//                         coordinate violates.  No re-admission.  Not a KKT point in general and
//                         discontinuous in V ("abrupt stops", as the seed warns).
//   Exclusion::ActiveSet  the digest's [FIX]: the same exclusion is phase 1 of an active-set method,
//                         with an excluded coordinate fixed at the bound it violated (not at 0), and
//                         phase 2 re-admits a fixed coordinate when its multiplier (the gradient of
//                         the objective w.r.t. it) shows that moving it inward reduces the objective.
//                         Phase 2 is the primal active-set method for bounded least squares
//                         (Lawson & Hanson 1974 ch. 23, Stark & Parker 1995 "BVLS"): from a feasible
//                         point, step towards the re-solved free-set solution as far as the box
//                         allows and fix the coordinate that blocks.  The objective never increases
//                         in phase 2 (block exclusion and re-admission alone can cycle); the method
//                         is finite in exact arithmetic for full column rank, and degenerate cases
//                         (rounding-level multipliers) are guarded by a noise floor, by blocking a
//                         coordinate that bounces straight back, and by the iteration cap.
//                         Ends at a KKT point, or with status IterationCap (output still feasible).
//   Free-set subproblems are solved for the minimum-norm solution by a complete orthogonal
//   decomposition (Eigen::CompleteOrthogonalDecomposition) with a relative rank tolerance:
//   a pivot |R_kk| <= rank_tol * |R_11| of the column-pivoted QR is treated as zero (|R_11| is the
//   largest column norm, within sqrt(n) of sigma_max; the pivots track the singular values for the
//   small matrices here).  With a box, each subproblem is minimum-norm; the constrained solution
//   set may still contain points of smaller norm (the fitted twist A x is unique, x need not be).
//
// dls_solve()   -- damped least squares q' = J^T (J J^T + lambda^2 I)^-1 V in the weighted metric,
//                  i.e. min |b - A x|^2 + lambda^2 |x|^2 = the least-squares problem of
//                  [A; lambda I] x = [b; 0], so the same box and active set apply unchanged.
//                  Damping::Adaptive (in the style of Nakamura & Hanafusa 1986, Maciejewski &
//                  Klein 1988; `lambda` is then lambda_max):
//                  lambda^2 = lambda_max^2 (1 - (sigma_min / eps)^2) when sigma_min < eps, else 0,
//                  sigma_min = the min(6, n)-th singular value of A.
//
// kkt_check()   -- stationarity of the free coordinates, signs of the multipliers of the fixed
//                  ones, feasibility (used by the tests; works for any (A, b)).
//
// Only Eigen and the standard library; nothing here is synthesised.
#pragma once
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>
#include <vector>

namespace ts {

enum class Exclusion { ActiveSet, Seed };
enum class PinvStatus { Converged, IterationCap, InvalidInput };
// State of one coordinate in the result.  Zeroed: excluded by the seed's rule (rate set to 0).
enum class BoundState : signed char { Free = 0, Lower = -1, Upper = 1, Zeroed = 2 };

struct PinvOptions {
  Exclusion exclusion = Exclusion::ActiveSet;
  double rank_tol = 1e-10;    // relative rank tolerance of the COD (see the header comment)
  double readmit_tol = 1e-9;  // re-admit when the inward descent rate exceeds readmit_tol |A_i| |r|
                              // (and the rounding floor 1e-12 |A_i| (|b| + |A x|))
  int max_iter = 0;           // cap on least-squares solves; 0: 20 + 10 n
};

struct PinvResult {
  Eigen::VectorXd qd;               // joint rates q'
  std::vector<BoundState> active;   // per coordinate: free, fixed at a bound, or zeroed (seed)
  int iterations = 0;               // least-squares (sub)problem solves
  int readmissions = 0;             // coordinates re-admitted in phase 2 (active set only)
  PinvStatus status = PinvStatus::Converged;
  double objective = 0;             // 1/2 |b - A q'|^2 of the problem solved (DLS: + 1/2 lambda^2 |q'|^2)
  double residual = 0;              // |V - J q'|_W (never includes the damping term)
  double lambda = 0;                // damping used (dls_solve)
  double sigma_min = std::numeric_limits<double>::quiet_NaN();  // dls_solve: min(6,n)-th sigma of A
};

// ---- problem set-up ------------------------------------------------------------------------------

// (A, b) = (S J, S V), S = diag(L, L, L, 1, 1, 1): |V - J q'|_W = |b - A q'|.
inline std::pair<Eigen::MatrixXd, Eigen::VectorXd> weighted_system(const Eigen::MatrixXd& J,
                                                                   const Eigen::VectorXd& V, double L) {
  if (J.rows() != 6 || V.size() != 6) throw std::invalid_argument("pinv: J must be 6 x n and V a 6-vector");
  Eigen::MatrixXd A = J;
  Eigen::VectorXd b = V;
  A.topRows(3) *= L;
  b.head(3) *= L;
  return {A, b};
}

// The damped system [A; lambda I] x = [b; 0].
inline std::pair<Eigen::MatrixXd, Eigen::VectorXd> damped_system(const Eigen::MatrixXd& J, const Eigen::VectorXd& V,
                                                                 double L, double lambda) {
  auto [A, b] = weighted_system(J, V, L);
  const Eigen::Index n = A.cols();
  Eigen::MatrixXd Ad(6 + n, n);
  Ad << A, lambda * Eigen::MatrixXd::Identity(n, n);
  Eigen::VectorXd bd = Eigen::VectorXd::Zero(6 + n);
  bd.head(6) = b;
  return {Ad, bd};
}

// The box of solver.hpp (solver_prepare) in double: [-vmax, vmax], and for a limited joint the
// position-limit approach [klim (lo - q), klim (hi - q)] clamped into it (never empty).
inline std::pair<Eigen::VectorXd, Eigen::VectorXd> rate_box(const Eigen::VectorXd& q, const Eigen::VectorXd& lo,
                                                            const Eigen::VectorXd& hi, const std::vector<bool>& limited,
                                                            const Eigen::VectorXd& vmax, double klim) {
  const Eigen::Index n = q.size();
  Eigen::VectorXd lower(n), upper(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double vhi = vmax[i], vlo = -vmax[i];
    lower[i] = vlo;
    upper[i] = vhi;
    if (limited[i]) {
      const double plo = klim * (lo[i] - q[i]), phi = klim * (hi[i] - q[i]);
      if (vlo < plo) lower[i] = std::min(plo, vhi);
      if (phi < vhi) upper[i] = std::max(phi, vlo);
    }
  }
  return {lower, upper};
}

// ---- bounded least squares -----------------------------------------------------------------------

namespace pinv_detail {

inline double clampd(double x, double lo, double hi) { return std::min(std::max(x, lo), hi); }
// Slack before a free coordinate counts as out of the box (rounding of the subproblem solve).
inline double slack(double bound) { return 1e-12 * (1.0 + (std::isfinite(bound) ? std::abs(bound) : 0.0)); }

// Minimum-norm solution over the free coordinates with the others held at x:
// z = argmin |(b - A_B x_B) - A_F z|, smallest |z|.  F receives the free indices.
inline Eigen::VectorXd solve_free(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const Eigen::VectorXd& x,
                                  const std::vector<BoundState>& st, double rank_tol, std::vector<int>& F) {
  F.clear();
  Eigen::VectorXd r = b;
  for (int i = 0; i < static_cast<int>(st.size()); ++i) {
    if (st[i] == BoundState::Free) F.push_back(i);
    else r -= A.col(i) * x[i];
  }
  if (F.empty()) return Eigen::VectorXd();
  Eigen::MatrixXd AF(A.rows(), static_cast<Eigen::Index>(F.size()));
  double cmax = 0;
  for (size_t k = 0; k < F.size(); ++k) {
    AF.col(static_cast<Eigen::Index>(k)) = A.col(F[k]);
    cmax = std::max(cmax, A.col(F[k]).stableNorm());
  }
  if (cmax == 0) return Eigen::VectorXd::Zero(AF.cols());
  // Scale by a power of two (exact; the minimum-norm solution just scales back): Householder
  // vectors of columns far from unit size would underflow or overflow.
  const int e = std::ilogb(cmax);
  AF *= std::ldexp(1.0, -e);
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod;
  cod.setThreshold(rank_tol);  // before compute(): the rank is fixed when the decomposition is made
  cod.compute(AF);
  return cod.solve(r) * std::ldexp(1.0, -e);
}

inline bool finite(const Eigen::MatrixXd& M) { return M.allFinite(); }

}  // namespace pinv_detail

// min 1/2 |b - A x|^2 subject to lower <= x <= upper (A: m x n, any m).  See the header comment.
inline PinvResult box_lsq(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const Eigen::VectorXd& lower,
                          const Eigen::VectorXd& upper, const PinvOptions& opt = {}) {
  using namespace pinv_detail;
  const int n = static_cast<int>(A.cols());
  if (b.size() != A.rows() || lower.size() != n || upper.size() != n)
    throw std::invalid_argument("pinv: inconsistent sizes of A, b, lower, upper");
  PinvResult res;
  res.qd = Eigen::VectorXd::Zero(n);
  res.active.assign(n, BoundState::Free);

  // Invalid input: non-finite A or b, NaN bounds, an empty box.  Output stays finite (zero).
  bool ok = finite(A) && b.allFinite();
  for (int i = 0; i < n; ++i)
    ok = ok && !std::isnan(lower[i]) && !std::isnan(upper[i]) && lower[i] <= upper[i] &&
         lower[i] < std::numeric_limits<double>::infinity() && upper[i] > -std::numeric_limits<double>::infinity();
  if (!ok) {
    res.status = PinvStatus::InvalidInput;
    res.objective = res.residual = std::numeric_limits<double>::quiet_NaN();
    return res;
  }

  const int max_iter = opt.max_iter > 0 ? opt.max_iter : 20 + 10 * n;
  Eigen::VectorXd& x = res.qd;
  std::vector<BoundState>& st = res.active;
  std::vector<int> F;
  // A point box pins its coordinate from the start (it can never be re-admitted).
  for (int i = 0; i < n; ++i)
    if (lower[i] == upper[i]) { st[i] = BoundState::Lower; x[i] = lower[i]; }

  // Phase 1, the seed's coordinate exclusion: solve over the remaining coordinates and exclude every
  // one whose rate leaves the box; repeat until none does (at most n + 1 solves).  The seed zeroes an
  // excluded rate; the active set fixes it at the bound it violated.
  for (;;) {
    const Eigen::VectorXd z = solve_free(A, b, x, st, opt.rank_tol, F);
    ++res.iterations;
    bool excluded = false;
    for (size_t k = 0; k < F.size(); ++k) {
      const int i = F[k];
      const double zi = z[static_cast<Eigen::Index>(k)];
      const bool above = zi > upper[i] + slack(upper[i]), below = zi < lower[i] - slack(lower[i]);
      if (above || below) {
        excluded = true;
        if (opt.exclusion == Exclusion::Seed) { st[i] = BoundState::Zeroed; x[i] = clampd(0.0, lower[i], upper[i]); }
        else if (above) { st[i] = BoundState::Upper; x[i] = upper[i]; }
        else { st[i] = BoundState::Lower; x[i] = lower[i]; }
      } else {
        x[i] = clampd(zi, lower[i], upper[i]);
      }
    }
    if (!excluded) break;
  }

  // Phase 2 (active set only): re-admission.  Invariant: x feasible, fixed coordinates at their
  // bound, x_F the minimum-norm optimum of the free subproblem.
  if (opt.exclusion == Exclusion::ActiveSet) {
    // A coordinate re-admitted on a multiplier that is numerically zero may bounce straight back
    // (step 0): it is then blocked until the objective decreases again.
    std::vector<bool> blocked(n, false);
    double f_blocked = 0;  // objective when the blocks were set
    const double fb = 0.5 * b.squaredNorm();
    auto progress = [&]() {  // a decrease above the rounding level of the objective
      const double f = 0.5 * (b - A * x).squaredNorm();
      if (f < f_blocked - 1e-13 * (f_blocked + fb)) std::fill(blocked.begin(), blocked.end(), false);
    };
    bool capped = false;
    while (!capped) {
      // Multipliers: g = dF/dx = -A^T (b - A x).  At a lower bound moving inward (up) helps when
      // g_i < 0; at an upper bound when g_i > 0.  Re-admit the largest such rate per unit column,
      // if it exceeds readmit_tol |A_i| |r| and the rounding level of g, 1e-12 |A_i| (|b| + |A x|)
      // (at an exact fit every multiplier is rounding noise).
      const Eigen::VectorXd Ax = A * x;
      const Eigen::VectorXd r = b - Ax;
      const Eigen::VectorXd g = -(A.transpose() * r);
      const double floor = std::max(opt.readmit_tol * r.stableNorm(), 1e-12 * (b.stableNorm() + Ax.stableNorm()));
      int best = -1;
      double best_rate = 0;
      for (int i = 0; i < n; ++i) {
        if (st[i] == BoundState::Free || lower[i] == upper[i] || blocked[i]) continue;
        const double inward = st[i] == BoundState::Lower ? -g[i] : g[i];
        const double cn = A.col(i).stableNorm();  // stable: tiny columns must not underflow to 0
        if (cn == 0 || !(inward > cn * floor)) continue;
        if (inward / cn > best_rate) { best_rate = inward / cn; best = i; }
      }
      if (best < 0) break;  // KKT point
      if (res.iterations >= max_iter) { capped = true; break; }
      const BoundState was = st[best];
      st[best] = BoundState::Free;
      ++res.readmissions;
      // Re-solve; when the solution leaves the box, step towards it as far as the box allows, fix
      // the coordinate(s) that block, and re-solve with the smaller free set.
      for (;;) {
        const Eigen::VectorXd z = solve_free(A, b, x, st, opt.rank_tol, F);
        ++res.iterations;
        // Each violating coordinate's own step fraction to its bound; alpha = the smallest.
        std::vector<double> ai(F.size(), 2.0);
        double alpha = 1.0;
        for (size_t k = 0; k < F.size(); ++k) {
          const int i = F[k];
          const double zi = z[static_cast<Eigen::Index>(k)];
          if (zi > upper[i] + slack(upper[i])) ai[k] = (upper[i] - x[i]) / (zi - x[i]);
          else if (zi < lower[i] - slack(lower[i])) ai[k] = (lower[i] - x[i]) / (zi - x[i]);
          ai[k] = std::max(ai[k], 0.0);
          alpha = std::min(alpha, ai[k]);
        }
        if (alpha >= 1.0) {  // the free-set optimum is feasible: accept it
          for (size_t k = 0; k < F.size(); ++k) x[F[k]] = clampd(z[static_cast<Eigen::Index>(k)], lower[F[k]], upper[F[k]]);
          progress();
          break;
        }
        bool bounced = false;
        for (size_t k = 0; k < F.size(); ++k) {
          const int i = F[k];
          const double zi = z[static_cast<Eigen::Index>(k)];
          if (ai[k] <= alpha * (1 + 1e-9)) {  // blocks (ties: fixed together)
            const bool up = zi > upper[i];
            st[i] = up ? BoundState::Upper : BoundState::Lower;
            x[i] = up ? upper[i] : lower[i];
            if (i == best && st[i] == was) bounced = blocked[i] = true;  // straight back: no progress
          } else {
            x[i] = clampd(x[i] + alpha * (zi - x[i]), lower[i], upper[i]);
          }
        }
        if (bounced) f_blocked = 0.5 * (b - A * x).squaredNorm();
        else progress();
        if (res.iterations >= max_iter) { capped = true; break; }
      }
    }
    if (capped) res.status = PinvStatus::IterationCap;
  }

  const Eigen::VectorXd r = b - A * x;
  res.objective = 0.5 * r.squaredNorm();
  res.residual = r.norm();  // pinv_solve / dls_solve replace it by |V - J q'|_W
  return res;
}

// ---- public entry points -------------------------------------------------------------------------

// Weighted (minimum-norm) least squares with the box, by coordinate exclusion (seed) or active set.
inline PinvResult pinv_solve(const Eigen::MatrixXd& J, const Eigen::VectorXd& V, double L, const Eigen::VectorXd& lower,
                             const Eigen::VectorXd& upper, const PinvOptions& opt = {}) {
  const auto [A, b] = weighted_system(J, V, L);
  PinvResult res = box_lsq(A, b, lower, upper, opt);
  if (res.status != PinvStatus::InvalidInput) res.residual = (b - A * res.qd).norm();
  return res;
}

// Without a box.
inline PinvResult pinv_solve(const Eigen::MatrixXd& J, const Eigen::VectorXd& V, double L, const PinvOptions& opt = {}) {
  const double inf = std::numeric_limits<double>::infinity();
  const Eigen::Index n = J.cols();
  return pinv_solve(J, V, L, Eigen::VectorXd::Constant(n, -inf), Eigen::VectorXd::Constant(n, inf), opt);
}

enum class Damping { Fixed, Adaptive };

struct DlsOptions {
  Damping damping = Damping::Fixed;  // Fixed: lambda as given.  Adaptive: lambda is lambda_max.
  double eps = 0.05;                 // Adaptive: singular region sigma_min < eps (units of A = S J)
  PinvOptions box;                   // active set / seed exclusion for the box
};

// min_{lower <= x <= upper} |b - A x|^2 + lambda^2 |x|^2; unconstrained it is
// x = A^T (A A^T + lambda^2 I)^-1 b, i.e. q' = J^T (J J^T + lambda^2 I)^-1 V in the W metric.
inline PinvResult dls_solve(const Eigen::MatrixXd& J, const Eigen::VectorXd& V, double L, double lambda,
                            const Eigen::VectorXd& lower, const Eigen::VectorXd& upper, const DlsOptions& opt = {}) {
  const auto [A, b] = weighted_system(J, V, L);
  const Eigen::Index n = A.cols();
  double sigma_min = std::numeric_limits<double>::quiet_NaN();
  double lam = std::abs(lambda);
  if (n > 0 && A.allFinite()) {
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A);
    sigma_min = svd.singularValues()[std::min<Eigen::Index>(6, n) - 1];
  }
  if (opt.damping == Damping::Adaptive) {
    if (!(sigma_min < opt.eps)) lam = 0;  // also for n = 0
    else lam = std::abs(lambda) * std::sqrt(std::max(0.0, 1.0 - (sigma_min / opt.eps) * (sigma_min / opt.eps)));
  }
  PinvResult res;
  if (lam == 0 || n == 0) {
    res = box_lsq(A, b, lower, upper, opt.box);
  } else {
    const auto [Ad, bd] = damped_system(J, V, L, lam);
    res = box_lsq(Ad, bd, lower, upper, opt.box);
  }
  if (res.status != PinvStatus::InvalidInput) res.residual = (b - A * res.qd).norm();
  res.lambda = lam;
  res.sigma_min = sigma_min;
  return res;
}

inline PinvResult dls_solve(const Eigen::MatrixXd& J, const Eigen::VectorXd& V, double L, double lambda,
                            const DlsOptions& opt = {}) {
  const double inf = std::numeric_limits<double>::infinity();
  const Eigen::Index n = J.cols();
  return dls_solve(J, V, L, lambda, Eigen::VectorXd::Constant(n, -inf), Eigen::VectorXd::Constant(n, inf), opt);
}

// ---- KKT check -----------------------------------------------------------------------------------

// For min 1/2 |b - A x|^2 on the box, with g = A^T (A x - b):
//   free coordinate (strictly inside, or claimed free):  g_i = 0           -> stationarity = max |g_i|
//   fixed at lower:  g_i >= 0;  fixed at upper:  g_i <= 0                  -> multiplier = max wrong-sign |g_i|
//   lower <= x <= upper, fixed coordinates exactly at their bound          -> feasibility
// (a point box imposes no sign).  A zeroed coordinate (seed) counts as fixed if it sits on a bound,
// else as free.  scale = max_i |A_i| (|b| + |A x|): the natural size of g.
struct KktReport {
  double stationarity = 0, multiplier = 0, feasibility = 0, scale = 0;
  bool ok(double grad_rtol = 1e-9, double x_atol = 0.0) const {
    return stationarity <= grad_rtol * scale && multiplier <= grad_rtol * scale && feasibility <= x_atol;
  }
};

inline KktReport kkt_check(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const Eigen::VectorXd& x,
                           const Eigen::VectorXd& lower, const Eigen::VectorXd& upper,
                           const std::vector<BoundState>& active) {
  KktReport rep;
  const Eigen::Index n = A.cols();
  const Eigen::VectorXd Ax = A * x;
  const Eigen::VectorXd g = A.transpose() * (Ax - b);
  double colmax = 0;
  for (Eigen::Index i = 0; i < n; ++i) colmax = std::max(colmax, A.col(i).stableNorm());
  rep.scale = colmax * (b.stableNorm() + Ax.stableNorm()) + std::numeric_limits<double>::min();
  for (Eigen::Index i = 0; i < n; ++i) {
    rep.feasibility = std::max({rep.feasibility, lower[i] - x[i], x[i] - upper[i]});
    BoundState s = active[static_cast<size_t>(i)];
    if (s == BoundState::Zeroed) s = x[i] == lower[i] ? BoundState::Lower : x[i] == upper[i] ? BoundState::Upper : BoundState::Free;
    if (s == BoundState::Free) {
      rep.stationarity = std::max(rep.stationarity, std::abs(g[i]));
    } else {
      const double bound = s == BoundState::Lower ? lower[i] : upper[i];
      rep.feasibility = std::max(rep.feasibility, std::abs(x[i] - bound));
      if (lower[i] < upper[i]) rep.multiplier = std::max(rep.multiplier, s == BoundState::Lower ? -g[i] : g[i]);
    }
  }
  return rep;
}

// Classification from x alone: on a bound -> fixed there (lower first), else free.
inline std::vector<BoundState> classify(const Eigen::VectorXd& x, const Eigen::VectorXd& lower, const Eigen::VectorXd& upper) {
  std::vector<BoundState> s(static_cast<size_t>(x.size()), BoundState::Free);
  for (Eigen::Index i = 0; i < x.size(); ++i)
    s[static_cast<size_t>(i)] = x[i] == lower[i] ? BoundState::Lower : x[i] == upper[i] ? BoundState::Upper : BoundState::Free;
  return s;
}

// The weighted problem of pinv_solve.
inline KktReport kkt_check(const Eigen::MatrixXd& J, const Eigen::VectorXd& V, double L, const PinvResult& res,
                           const Eigen::VectorXd& lower, const Eigen::VectorXd& upper) {
  const auto [A, b] = weighted_system(J, V, L);
  return kkt_check(A, b, res.qd, lower, upper, res.active);
}

}  // namespace ts
