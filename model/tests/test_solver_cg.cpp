// The conjugate-direction refinement after the sweeps (solver.hpp solver_cg, the offline IK's
// polish): least squares on ill-conditioned problems where the sweeps alone crawl, in double and
// in fixed point; the box and frozen joints respected; singular problems bounded and finite.
#include <Eigen/Dense>
#include <random>

#include "check.hpp"
#include "tensor_servo/solver.hpp"

using namespace ts;

namespace {
std::mt19937_64 rng(2026);
double urand(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); }

// A 6 x n scaled problem (A, b) with singular values spread down to smin and a target with a
// large component along the weakest direction (what an IK target near a singularity looks like).
void ill_problem(int n, double smin, Eigen::MatrixXd& A, Eigen::VectorXd& b) {
  A.resize(6, n);
  for (int i = 0; i < n; ++i)
    for (int a = 0; a < 6; ++a) A(a, i) = urand(-0.8, 0.8);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullU | Eigen::ComputeThinV);
  Eigen::VectorXd s = svd.singularValues();
  s[5] = smin;
  s[4] = std::sqrt(smin * s[0]);
  A = svd.matrixU() * s.asDiagonal() * svd.matrixV().transpose();
  b = 1e-4 * svd.matrixU().col(5);
  for (int a = 0; a < 6; ++a) b[a] += urand(-1e-4, 1e-4);
}

struct Out {
  Eigen::VectorXd x;
  Eigen::VectorXd r;  // the solver's final residual
  uint32_t flags;
};

// The solver on (A, b) as its scaled columns and target (L = 1): sweeps, then cg steps.
template <class Fmt>
Out run(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, int sweeps, int cg, double vmax = -1,
        int frozen = -1) {
  constexpr int NM = 8;
  const int n = static_cast<int>(A.cols());
  Status st;
  SolverParams<Fmt, NM> P;
  P.L = from_double<typename Fmt::lchar_t>(1.0, st);
  for (int i = 0; i < n; ++i) {
    P.mu[i] = from_double<typename Fmt::mu_t>(i == frozen ? 0.0 : 1.5, st);
    P.limited[i] = false;
    P.vmax[i] = vmax > 0 ? from_double<typename Fmt::qd_t>(vmax, st) : max_of<typename Fmt::qd_t>();
  }
  P.klim = from_double<typename Fmt::klim_t>(100, st);
  P.sweeps = sweeps;
  P.cg = cg;
  SolverColumns<Fmt, NM> C;
  C.rows = 6;
  for (int i = 0; i < n; ++i)
    for (int a = 0; a < 6; ++a) C.js[i][a] = from_double<typename Fmt::jsc_t>(A(a, i), st);
  typename Fmt::angle_t q[NM];
  for (int i = 0; i < n; ++i) q[i] = from_double<typename Fmt::angle_t>(0.0, st);
  solver_steps(P, q, n, C, st);
  typename Fmt::tw_t vs[6], r[6];
  typename Fmt::qd_t qd[NM];
  for (int a = 0; a < 6; ++a) vs[a] = from_double<typename Fmt::tw_t>(b[a], st);
  for (int i = 0; i < n; ++i) qd[i] = from_double<typename Fmt::qd_t>(0.0, st);
  solver_run(P, C, n, vs, qd, r, st);
  Out o{Eigen::VectorXd(n), Eigen::VectorXd(6), st.flags};
  for (int i = 0; i < n; ++i) o.x[i] = to_double(qd[i]);
  for (int a = 0; a < 6; ++a) o.r[a] = to_double(r[a]);
  return o;
}

// (A, b) as the fixed-point solver sees them (jsc_t, tw_t)
void quantise(Eigen::MatrixXd& A, Eigen::VectorXd& b) {
  Status st;
  for (int i = 0; i < A.cols(); ++i)
    for (int a = 0; a < 6; ++a) A(a, i) = to_double(from_double<FmtDefault::jsc_t>(A(a, i), st));
  for (int a = 0; a < 6; ++a) b[a] = to_double(from_double<FmtDefault::tw_t>(b[a], st));
}

double ls_residual(const Eigen::MatrixXd& A, const Eigen::VectorXd& b) {
  return (b - A * A.completeOrthogonalDecomposition().solve(b)).norm();
}
}  // namespace

// Double: 2n refinement steps after 10 sweeps reach the least-squares solution (n = 6) or the
// least-squares residual (n = 7) to 1e-8 relative for condition numbers up to 10^5; the sweeps
// alone (the same 10, or 1000) do not: the comparison shows what the refinement adds.
TEST_CASE("solver cg: double reaches least squares on ill-conditioned problems") {
  double worst = 0, best_cd = 1e300, best_cd1000 = 1e300;
  for (int t = 0; t < 200; ++t) {
    const int n = 6 + (t % 2);
    Eigen::MatrixXd A;
    Eigen::VectorXd b;
    ill_problem(n, std::pow(10.0, urand(-5, -2)), A, b);
    const Eigen::VectorXd xl = A.completeOrthogonalDecomposition().solve(b);
    const double rl = (b - A * xl).norm();
    auto err = [&](const Out& o) {
      return n == 6 ? (o.x - xl).norm() / xl.norm() : std::fabs((b - A * o.x).norm() - rl) / b.norm();
    };
    const Out cg = run<FmtDouble>(A, b, 10, 2 * n);
    worst = std::max(worst, err(cg));
    CHECK(cg.flags == 0);
    if (n == 6) {
      best_cd = std::min(best_cd, err(run<FmtDouble>(A, b, 10, 0)));
      if (t < 20) best_cd1000 = std::min(best_cd1000, err(run<FmtDouble>(A, b, 1000, 0)));
    }
  }
  CHECK_MSG(worst < 1e-8, "refinement: worst relative error %.3g", worst);
  CHECK_MSG(best_cd > 1e-3, "sweeps alone: best relative error %.3g (expected no convergence)", best_cd);
  CHECK_MSG(best_cd1000 > 1e-4, "1000 sweeps alone: best relative error %.3g", best_cd1000);
  std::printf("    cg double: worst relative error %.3g; 10 sweeps alone: best %.3g, 1000 sweeps: best %.3g\n",
              worst, best_cd, best_cd1000);
}

// Fixed point (default): 4n refinement steps (rounding costs conjugacy: 2n, enough in double, leave
// some of these problems short) bring the residual down to the resolution of q' itself:
// rounding the answer to qd_t (|dx_i| <= LSB/2) leaves at most |A|_2 sqrt(n) LSB(qd_t) / 2 of
// residual, plus the tw_t rounding of the residual the solver reports.  Checked against the least
// squares of the quantised problem, within 4 times that bound; the sweeps alone stay far above it.
TEST_CASE("solver cg: fixed point reaches the resolution of q'") {
  double worst = 0, cd_median_ratio = 0;
  std::vector<double> cd_ratios;
  uint32_t flags = 0;
  for (int t = 0; t < 200; ++t) {
    const int n = 6 + (t % 2);
    Eigen::MatrixXd A;
    Eigen::VectorXd b;
    ill_problem(n, std::pow(10.0, urand(-4, -2)), A, b);
    quantise(A, b);
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(A);
    const double floor = svd.singularValues()[0] * std::sqrt(n) * FmtDefault::qd_t::lsb() / 2 + 3 * FmtDefault::tw_t::lsb();
    const double rl = ls_residual(A, b);
    const Out cg = run<FmtDefault>(A, b, 10, 4 * n);
    const Out cd = run<FmtDefault>(A, b, 10, 0);
    flags |= cg.flags;
    worst = std::max(worst, (cg.r.norm() - rl) / floor);
    cd_ratios.push_back((cd.r.norm() - rl) / floor);
  }
  std::sort(cd_ratios.begin(), cd_ratios.end());
  cd_median_ratio = cd_ratios[cd_ratios.size() / 2];
  CHECK_MSG(worst < 4, "refinement: worst excess residual %.3g x the q' resolution bound", worst);
  CHECK_MSG(cd_median_ratio > 20, "sweeps alone: median excess residual %.3g x bound", cd_median_ratio);
  CHECK(flags == 0);
  std::printf("    cg fixed: worst excess residual %.3g x bound (sweeps alone: median %.3g x)\n", worst,
              cd_median_ratio);
}

// Box and frozen joints: a step that would leave the box is not taken (q' stays inside), a frozen
// joint (mu = 0) never moves, in both number types.
TEST_CASE("solver cg: box and frozen joints respected") {
  int outside = 0, moved = 0, stopped = 0;
  for (int t = 0; t < 100; ++t) {
    Eigen::MatrixXd A;
    Eigen::VectorXd b;
    ill_problem(6, 1e-3, A, b);
    const double vmax = 0.02;  // the least-squares step needs ~0.1: the box is active
    for (const Out& o : {run<FmtDouble>(A, b, 10, 12, vmax, t % 6), run<FmtDefault>(A, b, 10, 12, vmax, t % 6)}) {
      outside += (o.x.cwiseAbs().maxCoeff() > vmax + 1e-12);
      moved += o.x[t % 6] != 0.0;
      stopped += (b - A * o.x).norm() > 2 * ls_residual(A, b) + 1e-6;
    }
  }
  CHECK(outside == 0);
  CHECK(moved == 0);
  CHECK(stopped > 50);  // the box does bind (the test exercises it)
}

// Singular problems: an exactly zero column and two equal columns give finite output inside the
// box and raise no saturation.
TEST_CASE("solver cg: singular problems give bounded, finite output") {
  for (int t = 0; t < 50; ++t) {
    Eigen::MatrixXd A;
    Eigen::VectorXd b;
    ill_problem(6, 1e-3, A, b);
    A.col(5).setZero();
    A.col(3) = A.col(2);
    const Out d = run<FmtDouble>(A, b, 10, 12, 4.0), f = run<FmtDefault>(A, b, 10, 12, 4.0);
    CHECK(d.x.allFinite());
    CHECK(d.x.cwiseAbs().maxCoeff() <= 4.0);
    CHECK(f.x.cwiseAbs().maxCoeff() <= 4.0);
    CHECK(f.x[5] == 0.0);
    CHECK((f.flags & ~(ST_LIMIT_ACTIVE | ST_VLIMIT_ACTIVE)) == 0);
    // the minimum residual is still reached (the null-space directions carry no residual)
    CHECK((b - A * d.x).norm() <= ls_residual(A, b) + 1e-9);
  }
}
