// Pseudo-inverse references (pinv.hpp): minimum-norm weighted least squares, the seed's coordinate
// exclusion vs the active set (KKT, brute-force enumeration of active sets), damped least squares
// with fixed and adaptive damping, degenerate Jacobians.
#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <random>

#include "check.hpp"
#include "tensor_servo/pinv.hpp"

using namespace ts;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {
std::mt19937_64 rng(20240603);
double urand(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); }
const double inf = std::numeric_limits<double>::infinity();

// Columns like an arm's: omega in [-1, 1]^3, v in [-0.8, 0.8]^3.
MatrixXd random_J(int n) {
  MatrixXd J(6, n);
  for (int i = 0; i < n; ++i)
    for (int a = 0; a < 6; ++a) J(a, i) = a < 3 ? urand(-1, 1) : urand(-0.8, 0.8);
  return J;
}
VectorXd random_V() {
  VectorXd V(6);
  for (int a = 0; a < 6; ++a) V[a] = urand(-1, 1);
  return V;
}
VectorXd scaled(const VectorXd& V, double L) { VectorXd b = V; b.head(3) *= L; return b; }
MatrixXd scaled(const MatrixXd& J, double L) { MatrixXd A = J; A.topRows(3) *= L; return A; }

// Minimum-norm pseudo-inverse built explicitly from the SVD: V diag(1/sigma, sigma > tol sigma_1) U^T.
MatrixXd svd_pinv(const MatrixXd& A, double rtol) {
  Eigen::JacobiSVD<MatrixXd> svd(A, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const VectorXd& s = svd.singularValues();
  MatrixXd Sp = MatrixXd::Zero(A.cols(), A.rows());
  for (Eigen::Index k = 0; k < s.size(); ++k)
    if (s[k] > rtol * s[0]) Sp(k, k) = 1.0 / s[k];
  return svd.matrixV() * Sp * svd.matrixU().transpose();
}

double objective(const MatrixXd& A, const VectorXd& b, const VectorXd& x) { return 0.5 * (b - A * x).squaredNorm(); }

bool in_box(const VectorXd& x, const VectorXd& lo, const VectorXd& hi) {
  for (Eigen::Index i = 0; i < x.size(); ++i)
    if (!(lo[i] <= x[i] && x[i] <= hi[i])) return false;  // exact: no tolerance
  return true;
}

// Brute force: every assignment free / at lower / at upper (3^n), free part by the SVD pseudo-inverse,
// keep the best feasible candidate.  Exact for finite boxes (an optimum with the most coordinates at
// bounds has a unique free-set solution, which the pseudo-inverse returns).
double brute_force(const MatrixXd& A, const VectorXd& b, const VectorXd& lo, const VectorXd& hi) {
  const int n = static_cast<int>(A.cols());
  int total = 1;
  for (int i = 0; i < n; ++i) total *= 3;
  double best = inf;
  for (int code = 0; code < total; ++code) {
    VectorXd x = VectorXd::Zero(n);
    std::vector<int> F;
    int c = code;
    for (int i = 0; i < n; ++i, c /= 3) {
      if (c % 3 == 0) F.push_back(i);
      else x[i] = c % 3 == 1 ? lo[i] : hi[i];
    }
    if (!F.empty()) {
      MatrixXd AF(A.rows(), static_cast<Eigen::Index>(F.size()));
      for (size_t k = 0; k < F.size(); ++k) AF.col(static_cast<Eigen::Index>(k)) = A.col(F[k]);
      const VectorXd z = svd_pinv(AF, 1e-12) * (b - A * x);
      bool feasible = true;
      for (size_t k = 0; k < F.size(); ++k) {
        const double zi = z[static_cast<Eigen::Index>(k)];
        const int i = F[k];
        if (zi < lo[i] - 1e-12 || zi > hi[i] + 1e-12) feasible = false;
        x[i] = std::min(std::max(zi, lo[i]), hi[i]);
      }
      if (!feasible) continue;
    }
    best = std::min(best, objective(A, b, x));
  }
  return best;
}

// A random box around the unconstrained solution's scale: some joints bind, some do not; one case
// in eight shifts a box off zero (a joint outside its position range must move back in).
void random_box(int n, double s, VectorXd& lo, VectorXd& hi) {
  lo.resize(n);
  hi.resize(n);
  for (int i = 0; i < n; ++i) {
    lo[i] = -urand(0.05, 1.0) * s;
    hi[i] = urand(0.05, 1.0) * s;
    if (urand(0, 1) < 0.125) { const double sh = urand(-1, 1) * s; lo[i] += sh; hi[i] += sh; }
  }
}

int count_fixed(const PinvResult& r) {
  int c = 0;
  for (auto s : r.active) c += s != BoundState::Free;
  return c;
}
}  // namespace

// ---- unconstrained ---------------------------------------------------------------------------------

TEST_CASE("pinv: unconstrained full rank equals Eigen's weighted least squares") {
  double worst = 0, weight_effect = 0;  // weight_effect: distance to the unweighted answer
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 1 + trial % 7;  // 1..7: over-determined, square, redundant
    const MatrixXd J = random_J(n);
    const VectorXd V = random_V();
    const double L = urand(0.2, 2.0);
    const PinvResult r = pinv_solve(J, V, L);
    const MatrixXd A = scaled(J, L);
    const VectorXd b = scaled(V, L);
    // n <= 6: full column rank, the unique LS solution (Householder QR); n = 7: full row rank, the
    // minimum-norm exact solution A^T (A A^T)^-1 b.
    const VectorXd ref = n <= 6 ? VectorXd(A.householderQr().solve(b)) : VectorXd(A.transpose() * (A * A.transpose()).ldlt().solve(b));
    const double err = (r.qd - ref).norm() / std::max(1.0, ref.norm());
    worst = std::max(worst, err);
    CHECK(r.status == PinvStatus::Converged);
    CHECK(count_fixed(r) == 0);
    CHECK_MSG(std::abs(r.residual - (b - A * ref).norm()) < 1e-10, "residual %g vs %g", r.residual, (b - A * ref).norm());
    // The weighting must matter when the system cannot be met exactly (n < 6).
    if (n < 6 && std::abs(L - 1) > 0.3) weight_effect = std::max(weight_effect, (r.qd - VectorXd(J.householderQr().solve(V))).norm());
  }
  CHECK_MSG(worst < 1e-10, "worst relative error %g", worst);
  CHECK_MSG(weight_effect > 1e-3, "L has no effect on the solution (%g)", weight_effect);
}

TEST_CASE("pinv: rank-deficient Jacobians give the minimum-norm solution (SVD pseudo-inverse)") {
  double worst = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 2 + trial % 8;  // 2..9
    MatrixXd J = random_J(n);
    switch (trial % 4) {
      case 0: J.col(1) = J.col(0); break;                                    // duplicated joint
      case 1: J.col(n - 1).setZero(); break;                                 // zero column
      case 2: J = random_J(3).leftCols(std::min(n, 3)) * MatrixXd::Random(std::min(n, 3), n); break;  // rank <= 3
      case 3: J.col(1) = -2.0 * J.col(0); if (n > 2) J.col(2) = J.col(0) + J.col(1); break;
    }
    const VectorXd V = random_V();
    const double L = 0.5;
    const PinvResult r = pinv_solve(J, V, L);
    const MatrixXd A = scaled(J, L);
    const VectorXd ref = svd_pinv(A, 1e-10) * scaled(V, L);
    const double err = (r.qd - ref).norm() / std::max(1.0, ref.norm());
    worst = std::max(worst, err);
    // Minimum norm <=> orthogonal to the null space of A.
    Eigen::JacobiSVD<MatrixXd> svd(A, Eigen::ComputeFullV);
    const VectorXd& s = svd.singularValues();
    for (Eigen::Index k = 0; k < n; ++k)
      if (k >= s.size() || s[k] <= 1e-10 * s[0]) CHECK(std::abs(svd.matrixV().col(k).dot(r.qd)) < 1e-9 * (1 + r.qd.norm()));
    CHECK(r.qd.allFinite());
  }
  CHECK_MSG(worst < 1e-9, "worst relative error %g", worst);
}

TEST_CASE("pinv: the rank tolerance decides what is singular") {
  // Column 1 = column 0 + 1e-12 * e: sigma_min / sigma_max ~ 1e-12.
  const MatrixXd J0 = random_J(4);
  MatrixXd J = J0;
  VectorXd e = VectorXd::Zero(6);
  e[4] = 1;
  J.col(1) = J.col(0) + 1e-12 * e;
  const VectorXd V = random_V();
  PinvOptions coarse, fine;
  coarse.rank_tol = 1e-10;  // (default) the tiny direction is dropped: bounded, minimum norm
  fine.rank_tol = 1e-15;    // kept: the exact least-squares solution, huge
  const PinvResult rc = pinv_solve(J, V, 1.0, coarse), rf = pinv_solve(J, V, 1.0, fine);
  CHECK_MSG(rc.qd.norm() < 1e3, "coarse |q'| = %g", rc.qd.norm());
  CHECK_MSG(rf.qd.norm() > 1e6, "fine |q'| = %g", rf.qd.norm());
  CHECK(rf.residual < rc.residual);
  const VectorXd ref = svd_pinv(J, 1e-10) * V;
  CHECK_MSG((rc.qd - ref).norm() < 1e-6 * (1 + ref.norm()), "coarse vs truncated SVD %g", (rc.qd - ref).norm());
}

// ---- box constraints ---------------------------------------------------------------------------

TEST_CASE("pinv: active set is a KKT point, matches enumeration of active sets, never leaves the box") {
  int cases = 0, with_fixed = 0, with_readmission = 0;
  double worst_obj = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const int n = 1 + trial % 7;  // enumeration: 3^7 = 2187 candidates at most
    MatrixXd J = random_J(n);
    if (trial % 5 == 0 && n >= 2) J.col(1) = J.col(0);          // rank-deficient
    if (trial % 11 == 0) J.col(n - 1).setZero();                // zero column
    const VectorXd V = random_V();
    const double L = urand(0.3, 1.5);
    const double s = std::max(0.1, pinv_solve(J, V, L).qd.lpNorm<Eigen::Infinity>());
    VectorXd lo, hi;
    random_box(n, s, lo, hi);
    const PinvResult r = pinv_solve(J, V, L, lo, hi);
    const MatrixXd A = scaled(J, L);
    const VectorXd b = scaled(V, L);
    ++cases;
    with_fixed += count_fixed(r) > 0;
    with_readmission += r.readmissions > 0;
    CHECK(r.status == PinvStatus::Converged);
    CHECK_MSG(in_box(r.qd, lo, hi), "trial %d leaves the box", trial);
    const KktReport k = kkt_check(J, V, L, r, lo, hi);
    CHECK_MSG(k.ok(1e-9), "trial %d: KKT stationarity %g multiplier %g feasibility %g (scale %g)", trial,
              k.stationarity, k.multiplier, k.feasibility, k.scale);
    const double fb = brute_force(A, b, lo, hi);
    const double d = std::abs(r.objective - fb) / std::max(1.0, fb);
    worst_obj = std::max(worst_obj, d);
    CHECK_MSG(d < 1e-9, "trial %d n=%d: objective %.15g vs enumeration %.15g", trial, n, r.objective, fb);
  }
  // The test means something only if limits actually bind (and re-admission happens).
  CHECK_MSG(with_fixed > cases / 2, "%d of %d cases had a fixed coordinate", with_fixed, cases);
  CHECK_MSG(with_readmission > cases / 20, "%d of %d cases re-admitted a coordinate", with_readmission, cases);
  std::printf("    active set: %d cases, %d with fixed joints, %d with re-admission, worst objective gap %.2g\n",
              cases, with_fixed, with_readmission, worst_obj);
}

TEST_CASE("pinv: the solver's box (velocity and position-limit approach) in double") {
  // Joint 0 at its upper limit, joint 1 near its lower limit, joint 2 beyond its upper limit,
  // joint 3 unlimited with a velocity limit.
  VectorXd q(4), lo(4), hi(4), vmax(4);
  q << 1.0, -0.995, 2.1, 0.0;
  lo << -1, -1, -2, -3;
  hi << 1, 1, 2, 3;
  vmax << 2, 2, 2, 0.5;
  const std::vector<bool> limited{true, true, true, false};
  const auto [bl, bu] = rate_box(q, lo, hi, limited, vmax, 10.0);
  CHECK(bl[0] == -2 && bu[0] == 0);                                   // at the limit: only inward
  CHECK(std::abs(bl[1] - (-0.05)) < 1e-12 && bu[1] == 2);             // klim (lo - q)
  CHECK(bl[2] == -2 && std::abs(bu[2] - (-1.0)) < 1e-12);             // beyond: must come back
  CHECK(bl[3] == -0.5 && bu[3] == 0.5);
  for (int trial = 0; trial < 50; ++trial) {
    const MatrixXd J = random_J(4);
    const VectorXd V = 3 * random_V();
    const PinvResult r = pinv_solve(J, V, 0.5, bl, bu);
    CHECK(in_box(r.qd, bl, bu));
    CHECK(r.qd[2] <= -1.0);  // the joint beyond its limit always moves back in
    CHECK(kkt_check(J, V, 0.5, r, bl, bu).ok());
  }
}

TEST_CASE("pinv: the seed's exclusion stops a joint that the active set keeps moving") {
  // Two joints, L = 1: column 0 = e_0, column 1 = e_0 + e_1, V = 3 c0 - 2 c1 = (1, -2, 0, 0, 0, 0).
  // Unconstrained q' = (3, -2); box q'_0 in [-1, 1], q'_1 in [-1.5, 1.5]: both leave it.
  MatrixXd J = MatrixXd::Zero(6, 2);
  J(0, 0) = 1;
  J(0, 1) = 1;
  J(1, 1) = 1;
  VectorXd V = VectorXd::Zero(6);
  V[0] = 1;
  V[1] = -2;
  VectorXd lo(2), hi(2);
  lo << -1, -1.5;
  hi << 1, 1.5;
  PinvOptions seed;
  seed.exclusion = Exclusion::Seed;
  const PinvResult rs = pinv_solve(J, V, 1.0, lo, hi, seed);
  const PinvResult ra = pinv_solve(J, V, 1.0, lo, hi);
  // Seed: both excluded and zeroed -> the arm stops; objective 1/2 |V|^2 = 2.5.
  CHECK(rs.qd.norm() == 0);
  CHECK(rs.active[0] == BoundState::Zeroed && rs.active[1] == BoundState::Zeroed);
  CHECK(std::abs(rs.objective - 2.5) < 1e-12);
  // Active set: joint 0 saturates at 1; joint 1 is fixed at -1.5 in phase 1, then re-admitted
  // (multiplier: moving it inward reduces the residual) and ends inside, at -1; objective 1.
  CHECK_MSG(std::abs(ra.qd[0] - 1) < 1e-12 && std::abs(ra.qd[1] + 1) < 1e-12, "q' = (%g, %g)", ra.qd[0], ra.qd[1]);
  CHECK(ra.active[0] == BoundState::Upper && ra.active[1] == BoundState::Free);
  CHECK(ra.readmissions == 1);
  CHECK(std::abs(ra.objective - 1.0) < 1e-12);
  // The seed's answer is not a KKT point; the active set's is.
  CHECK(!kkt_check(J, V, 1.0, rs, lo, hi).ok());
  CHECK(kkt_check(J, V, 1.0, ra, lo, hi).ok());
}

TEST_CASE("pinv: seed exclusion is discontinuous in V (abrupt stops), the active set is continuous") {
  // Sweep V = t V0 across the point where joint 0 reaches its velocity limit (well-conditioned J).
  MatrixXd J = random_J(6);
  while (Eigen::JacobiSVD<MatrixXd>(J).singularValues()[5] < 0.2) J = random_J(6);
  VectorXd x0 = VectorXd::Zero(6);
  x0[0] = 1.0;
  x0[1] = 0.3;
  x0[2] = -0.2;
  const VectorXd V0 = J * x0;  // unconstrained q' = t x0: joint 0 reaches 0.8 at t = 0.8
  const VectorXd lo = VectorXd::Constant(6, -0.8), hi = VectorXd::Constant(6, 0.8);
  PinvOptions seed;
  seed.exclusion = Exclusion::Seed;
  double jump_seed = 0, jump_as = 0;
  VectorXd ps, pa;
  const int N = 1000;
  for (int k = 0; k <= N; ++k) {
    const double t = 0.5 + 0.5 * k / N;  // Delta t = 5e-4
    const VectorXd xs = pinv_solve(J, t * V0, 1.0, lo, hi, seed).qd;
    const VectorXd xa = pinv_solve(J, t * V0, 1.0, lo, hi).qd;
    if (k > 0) {
      jump_seed = std::max(jump_seed, (xs - ps).lpNorm<Eigen::Infinity>());
      jump_as = std::max(jump_as, (xa - pa).lpNorm<Eigen::Infinity>());
    }
    ps = xs;
    pa = xa;
  }
  CHECK_MSG(jump_seed > 0.5, "seed: largest step between neighbours %g", jump_seed);
  CHECK_MSG(jump_as < 0.05, "active set: largest step between neighbours %g", jump_as);
}

TEST_CASE("pinv: iteration cap is reported and the output stays feasible") {
  int capped = 0;
  for (int trial = 0; trial < 100; ++trial) {
    const int n = 7;
    const MatrixXd J = random_J(n);
    const VectorXd V = random_V();
    const double s = std::max(0.1, pinv_solve(J, V, 1.0).qd.lpNorm<Eigen::Infinity>());
    VectorXd lo, hi;
    random_box(n, s, lo, hi);
    PinvOptions opt;
    const PinvResult full = pinv_solve(J, V, 1.0, lo, hi, opt);
    CHECK(full.status == PinvStatus::Converged);
    opt.max_iter = 1;
    const PinvResult r = pinv_solve(J, V, 1.0, lo, hi, opt);
    CHECK(in_box(r.qd, lo, hi));
    if (full.readmissions > 0) {  // needed phase 2: must report the cap
      ++capped;
      CHECK(r.status == PinvStatus::IterationCap);
    }
    CHECK(r.status != PinvStatus::Converged || kkt_check(J, V, 1.0, r, lo, hi).ok());
  }
  CHECK_MSG(capped > 0, "no case needed re-admission");
}

TEST_CASE("pinv: kkt_check detects violations") {
  // A problem whose solution has both free and fixed coordinates.
  MatrixXd J;
  VectorXd V;
  const VectorXd lo = VectorXd::Constant(5, -0.3), hi = VectorXd::Constant(5, 0.3);
  PinvResult r;
  int fi = -1, bi = -1;
  for (int trial = 0; trial < 100 && (fi < 0 || bi < 0); ++trial) {
    J = random_J(5);
    V = 0.5 * random_V();
    r = pinv_solve(J, V, 1.0, lo, hi);
    fi = bi = -1;
    for (int i = 0; i < 5; ++i) (r.active[i] == BoundState::Free ? fi : bi) = i;
  }
  CHECK(fi >= 0 && bi >= 0);
  CHECK(kkt_check(J, V, 1.0, r, lo, hi).ok());
  if (fi >= 0) {  // move a free coordinate: not stationary
    PinvResult p = r;
    p.qd[fi] += 1e-3 * (p.qd[fi] > 0 ? -1 : 1);
    CHECK(kkt_check(J, V, 1.0, p, lo, hi).stationarity > 1e-6 * kkt_check(J, V, 1.0, p, lo, hi).scale);
    CHECK(!kkt_check(J, V, 1.0, p, lo, hi).ok());
  }
  if (bi >= 0) {  // claim the opposite bound: wrong multiplier sign and not on the claimed bound
    PinvResult p = r;
    p.active[bi] = p.active[bi] == BoundState::Upper ? BoundState::Lower : BoundState::Upper;
    CHECK(!kkt_check(J, V, 1.0, p, lo, hi).ok());
    PinvResult f = r;  // push a fixed coordinate out of the box
    f.qd[bi] *= 1.01;
    CHECK(kkt_check(J, V, 1.0, f, lo, hi).feasibility > 0);
  }
  // Sign alone: one joint held at its lower bound 0 while the target pulls it up (multiplier of
  // the wrong sign); feasible, nothing free.
  const MatrixXd c = random_J(1);
  const VectorXd lo1 = VectorXd::Zero(1), hi1 = VectorXd::Ones(1);
  PinvResult p;
  p.qd = VectorXd::Zero(1);
  p.active = {BoundState::Lower};
  const KktReport k = kkt_check(c, 0.5 * c.col(0), 1.0, p, lo1, hi1);
  CHECK(k.feasibility == 0 && k.stationarity == 0);
  CHECK_MSG(std::abs(k.multiplier - 0.5 * c.squaredNorm()) < 1e-12, "multiplier %g", k.multiplier);
  CHECK(!k.ok());
  CHECK(pinv_solve(c, 0.5 * c.col(0), 1.0, lo1, hi1).active[0] == BoundState::Free);
}

TEST_CASE("pinv: solutions on a bound stay exactly inside the box") {
  // Targets made from rates exactly on a bound, just beyond it and far beyond it: rounding must
  // never leak past the bound, re-admission must not cycle on rounding-level multipliers.
  int outside = 0, cases = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const int n = 3 + trial % 5;
    const MatrixXd J = random_J(n);
    VectorXd lo(n), hi(n), x0(n);
    for (int i = 0; i < n; ++i) {
      lo[i] = -urand(0.1, 1);
      hi[i] = urand(0.1, 1);
      const double u = urand(0, 1);
      x0[i] = u < 0.3 ? hi[i] : u < 0.5 ? lo[i] : u < 0.6 ? hi[i] + 1e-4 : u < 0.8 ? urand(lo[i], hi[i]) : 2 * hi[i];
    }
    const VectorXd V = J * x0;
    for (double L : {1.0, 0.37}) {
      const PinvResult r = pinv_solve(J, V, L, lo, hi);
      ++cases;
      outside += !in_box(r.qd, lo, hi);
      CHECK(r.status == PinvStatus::Converged);
      CHECK(kkt_check(J, V, L, r, lo, hi).ok(1e-9));
    }
  }
  CHECK_MSG(outside == 0, "%d of %d solutions leave the box", outside, cases);
}

// ---- damped least squares ----------------------------------------------------------------------

TEST_CASE("pinv/dls: unconstrained equals J^T (J J^T + lambda^2 I)^-1 V in the weighted metric") {
  for (int trial = 0; trial < 100; ++trial) {
    const int n = 2 + trial % 7;
    const MatrixXd J = random_J(n);
    const VectorXd V = random_V();
    const double L = urand(0.3, 1.5), lambda = urand(0.01, 0.5);
    const MatrixXd A = scaled(J, L);
    const VectorXd ref = A.transpose() * (A * A.transpose() + lambda * lambda * MatrixXd::Identity(6, 6)).ldlt().solve(scaled(V, L));
    const PinvResult r = dls_solve(J, V, L, lambda);
    CHECK_MSG((r.qd - ref).norm() < 1e-10 * (1 + ref.norm()), "n=%d err %g", n, (r.qd - ref).norm());
    CHECK(r.lambda == lambda);
  }
}

TEST_CASE("pinv/dls: converges to the least-squares solution as lambda -> 0 (well conditioned)") {
  for (int n : {4, 6, 7}) {
    const MatrixXd J = random_J(n);
    const VectorXd V = random_V();
    const VectorXd ls = pinv_solve(J, V, 0.7).qd;
    // x_lambda - x = -lambda^2 (A^T A + lambda^2)^-1 x on the row space: |.| <= lambda^2 / sigma_min^2 |x|.
    const double smin = dls_solve(J, V, 0.7, 0.0).sigma_min;
    CHECK(smin > 1e-3);
    double prev = inf;
    for (double lambda = 1e-1; lambda > 1e-7; lambda /= 10) {
      const double err = (dls_solve(J, V, 0.7, lambda).qd - ls).norm();
      CHECK_MSG(err < prev, "n=%d lambda=%g: error %g not below %g", n, lambda, err, prev);
      CHECK_MSG(err <= lambda * lambda / (smin * smin) * ls.norm() * (1 + 1e-6) + 1e-12, "n=%d lambda=%g: error %g above the bound", n, lambda, err);
      prev = err;
    }
    CHECK(prev < 1e-8);
  }
}

TEST_CASE("pinv/dls: bounded output at and near singularities, fixed and adaptive damping") {
  const double lmax = 0.05, eps = 0.1;
  // sup over sigma of the adaptive gain sigma / (sigma^2 + lambda(sigma)^2) (see pinv.hpp):
  // lambda_max <= eps / sqrt 2 -> 1 / (2 lambda_max sqrt(1 - lambda_max^2 / eps^2)), else 1 / eps.
  const double G = std::max(1 / eps, lmax <= eps / std::sqrt(2.0) ? 1 / (2 * lmax * std::sqrt(1 - lmax * lmax / (eps * eps))) : 1 / eps);
  DlsOptions adaptive;
  adaptive.damping = Damping::Adaptive;
  adaptive.eps = eps;
  double worst_pinv = 0;
  int damped = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 2 + trial % 5;  // 2..6 (for n = 7 the 6th singular value need not be small)
    MatrixXd J = random_J(n);
    const double kill = trial % 4 == 0 ? 0.0 : std::pow(10.0, -urand(2, 12));  // 0: exactly singular
    VectorXd d = VectorXd::Zero(6);
    d[trial % 6] = 1;
    J.col(1) = J.col(0) + kill * d;
    const VectorXd V = random_V();
    const double L = 0.5;
    const double bn = scaled(V, L).norm();
    const PinvResult rf = dls_solve(J, V, L, lmax);
    const PinvResult ra = dls_solve(J, V, L, lmax, adaptive);
    CHECK(rf.qd.allFinite() && ra.qd.allFinite());
    CHECK_MSG(rf.qd.norm() <= bn / (2 * lmax) * (1 + 1e-12), "fixed: |q'| %g > %g", rf.qd.norm(), bn / (2 * lmax));
    CHECK_MSG(ra.qd.norm() <= G * bn * (1 + 1e-12), "adaptive: |q'| %g > %g", ra.qd.norm(), G * bn);
    CHECK(ra.lambda > 0 && ra.lambda <= lmax);
    if (kill == 0) CHECK_MSG(std::abs(ra.lambda - lmax) < 1e-6 * lmax, "at the singularity lambda %g", ra.lambda);
    damped += ra.lambda > 0;
    // With a box containing 0: |q'| <= |b| / lambda (the objective at q' is at most its value at 0).
    const VectorXd lo = VectorXd::Constant(n, -100), hi = VectorXd::Constant(n, 100);
    const PinvResult rb = dls_solve(J, V, L, lmax, lo, hi);
    CHECK(rb.qd.norm() <= bn / lmax * (1 + 1e-12) && in_box(rb.qd, lo, hi));
    if (kill > 0 && kill < 1e-6) worst_pinv = std::max(worst_pinv, pinv_solve(J, V, L).qd.norm() / bn);
  }
  CHECK(damped == 200);
  // Near-singular problems are hard for the undamped pseudo-inverse (so the bound above is a real test).
  CHECK_MSG(worst_pinv > 10 * G, "pinv gain near singularities only %g", worst_pinv);
}

TEST_CASE("pinv/dls: adaptive damping is zero away from singularities") {
  DlsOptions adaptive;
  adaptive.damping = Damping::Adaptive;
  adaptive.eps = 0.02;
  int checked = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 6 + trial % 2;
    const MatrixXd J = random_J(n);
    const VectorXd V = random_V();
    const PinvResult r = dls_solve(J, V, 1.0, 0.1, adaptive);
    if (!(r.sigma_min >= adaptive.eps)) continue;  // random J may be near-singular: skip those
    ++checked;
    CHECK(r.lambda == 0);
    CHECK((r.qd - pinv_solve(J, V, 1.0).qd).norm() == 0);
  }
  CHECK_MSG(checked > 100, "only %d well-conditioned samples", checked);
  // And just inside the singular region the damping switches on continuously from 0.
  MatrixXd J = random_J(6);
  Eigen::JacobiSVD<MatrixXd> svd(J, Eigen::ComputeFullU | Eigen::ComputeFullV);
  VectorXd s = svd.singularValues();
  s[5] = 0.999 * adaptive.eps;
  J = svd.matrixU() * s.asDiagonal() * svd.matrixV().transpose();
  const PinvResult r = dls_solve(J, random_V(), 1.0, 0.1, adaptive);
  const double expect = 0.1 * std::sqrt(1 - 0.999 * 0.999);  // lambda_max sqrt(1 - (sigma_min / eps)^2)
  CHECK_MSG(std::abs(r.lambda - expect) < 1e-9, "lambda %g at sigma_min = 0.999 eps, expected %g", r.lambda, expect);
}

TEST_CASE("pinv/dls: box-constrained damped problem is a KKT point and matches enumeration") {
  int with_fixed = 0;
  for (int trial = 0; trial < 100; ++trial) {
    const int n = 2 + trial % 5;
    MatrixXd J = random_J(n);
    if (trial % 3 == 0) J.col(1) = J.col(0);  // singular
    const VectorXd V = random_V();
    const double L = 0.8, lambda = 0.05;
    const double s = std::max(0.1, dls_solve(J, V, L, lambda).qd.lpNorm<Eigen::Infinity>());
    VectorXd lo, hi;
    random_box(n, s, lo, hi);
    const PinvResult r = dls_solve(J, V, L, lambda, lo, hi);
    const auto [Ad, bd] = damped_system(J, V, L, lambda);
    CHECK(r.status == PinvStatus::Converged && in_box(r.qd, lo, hi));
    CHECK(kkt_check(Ad, bd, r.qd, lo, hi, r.active).ok(1e-9));
    const double fb = brute_force(Ad, bd, lo, hi);
    CHECK_MSG(std::abs(r.objective - fb) < 1e-9 * std::max(1.0, fb), "objective %.15g vs %.15g", r.objective, fb);
    with_fixed += count_fixed(r) > 0;
  }
  CHECK(with_fixed > 50);
}

// ---- degenerate input ----------------------------------------------------------------------------

TEST_CASE("pinv: singular, rank-deficient and zero-column Jacobians give finite output") {
  const VectorXd V = random_V();
  std::vector<MatrixXd> Js;
  Js.push_back(MatrixXd::Zero(6, 6));                           // all zero
  { MatrixXd J = random_J(6); J.col(2).setZero(); J.col(4).setZero(); Js.push_back(J); }
  { const VectorXd c = random_J(1).col(0); MatrixXd J(6, 7); for (int i = 0; i < 7; ++i) J.col(i) = (i + 1) * c; Js.push_back(J); }  // rank 1
  { MatrixXd J = random_J(6); J.row(5).setZero(); J.row(2).setZero(); Js.push_back(J); }  // two lost task directions
  Js.push_back(random_J(1));
  Js.push_back(MatrixXd(6, 0));                                 // no joints
  { MatrixXd J = random_J(5); J *= 1e-200; Js.push_back(J); }   // vanishing scale
  for (size_t t = 0; t < Js.size(); ++t) {
    const MatrixXd& J = Js[t];
    const Eigen::Index n = J.cols();
    const VectorXd lo = VectorXd::Constant(n, -1), hi = VectorXd::Constant(n, 1);
    PinvOptions seed;
    seed.exclusion = Exclusion::Seed;
    DlsOptions adaptive;
    adaptive.damping = Damping::Adaptive;
    const PinvResult rs[] = {pinv_solve(J, V, 0.5), pinv_solve(J, V, 0.5, lo, hi), pinv_solve(J, V, 0.5, lo, hi, seed),
                             dls_solve(J, V, 0.5, 0.05), dls_solve(J, V, 0.5, 0.05, adaptive),
                             dls_solve(J, V, 0.5, 0.05, lo, hi, adaptive)};
    for (const auto& r : rs) {
      CHECK_MSG(r.qd.allFinite() && r.qd.size() == n, "case %zu", t);
      CHECK(r.status == PinvStatus::Converged);
      CHECK(std::isfinite(r.objective));
    }
    CHECK(in_box(rs[1].qd, lo, hi) && in_box(rs[5].qd, lo, hi));
    { const KktReport k = kkt_check(J, V, 0.5, rs[1], lo, hi);
      CHECK_MSG(k.ok(), "case %zu: %g %g %g scale %g", t, k.stationarity, k.multiplier, k.feasibility, k.scale); }
    // A zero column never moves (minimum norm), whatever the box.
    for (Eigen::Index i = 0; i < n; ++i)
      if (J.col(i).isZero(0.0)) CHECK_MSG(std::abs(rs[0].qd[i]) <= 1e-12 * (1 + rs[0].qd.norm()) && std::abs(rs[1].qd[i]) <= 1e-12, "case %zu joint %ld: %g %g", t, (long)i, rs[0].qd[i], rs[1].qd[i]);
  }
  // Non-finite input or an empty box: status InvalidInput, output zero (finite).
  MatrixXd Jn = random_J(3);
  Jn(2, 1) = std::numeric_limits<double>::quiet_NaN();
  const PinvResult rn = pinv_solve(Jn, V, 1.0);
  CHECK(rn.status == PinvStatus::InvalidInput && rn.qd.allFinite());
  const PinvResult rd = dls_solve(Jn, V, 1.0, 0.1);
  CHECK(rd.status == PinvStatus::InvalidInput && rd.qd.allFinite());
  VectorXd lo(3), hi(3);
  lo << -1, 1, -1;
  hi << 1, 0, 1;
  const PinvResult re = pinv_solve(random_J(3), V, 1.0, lo, hi);
  CHECK(re.status == PinvStatus::InvalidInput && re.qd.allFinite());
}
