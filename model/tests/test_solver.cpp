// Coordinate-descent solver and servo law: convergence to least squares (double), fixed point
// within a bound of double, limits never violated, singular Jacobians give bounded output.
#include <Eigen/Dense>
#include <random>

#include "check.hpp"
#include "tensor_servo/servo.hpp"

using namespace ts;

namespace {
std::mt19937_64 rng(777);
double urand(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); }

template <class Fmt, int NM>
void set_params(SolverParams<Fmt, NM>& P, int n, double L, double mu, int sweeps, Status& st) {
  P.L = from_double<typename Fmt::lchar_t>(L, st);
  for (int i = 0; i < n; ++i) {
    P.mu[i] = from_double<typename Fmt::mu_t>(mu, st);
    P.limited[i] = false;
    P.lo[i] = from_double<typename Fmt::angle_t>(-3, st);
    P.hi[i] = from_double<typename Fmt::angle_t>(3, st);
    P.vmax[i] = max_of<typename Fmt::qd_t>();
  }
  P.klim = from_double<typename Fmt::klim_t>(1000, st);
  P.sweeps = sweeps;
}

// A random Jacobian (columns like a 6-DOF arm's) in Fmt, also returned in double.
template <class Fmt, int NM>
void random_jacobian(Jacobian<Fmt, NM>& J, Eigen::MatrixXd& Jd, int n, double cond_kill, Status& st) {
  J.n = n;
  Jd.resize(6, n);
  for (int i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a) {
      J.w[i].c[a] = from_double<typename Fmt::jw_t>(urand(-1, 1), st);
      J.v[i].c[a] = from_double<typename Fmt::jv_t>(urand(-0.8, 0.8), st);
    }
  if (cond_kill > 0 && n > 1)  // make column 1 nearly parallel to column 0
    for (int a = 0; a < 3; ++a) {
      J.w[1].c[a] = from_double<typename Fmt::jw_t>(to_double(J.w[0].c[a]) * (1 + cond_kill), st);
      J.v[1].c[a] = from_double<typename Fmt::jv_t>(to_double(J.v[0].c[a]), st);
    }
  for (int i = 0; i < n; ++i)
    for (int a = 0; a < 3; ++a) { Jd(a, i) = to_double(J.w[i].c[a]); Jd(a + 3, i) = to_double(J.v[i].c[a]); }
}

double cond(const Eigen::MatrixXd& J, double L) {
  Eigen::MatrixXd Js = J;
  Js.topRows(3) *= L;
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(Js);
  const auto& s = svd.singularValues();
  return s(0) / s(s.size() - 1);
}

template <class Fmt, int NM>
Eigen::VectorXd solve(const SolverParams<Fmt, NM>& P, const Jacobian<Fmt, NM>& J, const Eigen::VectorXd& V, Status& st) {
  const int n = J.n;
  typename Fmt::angle_t q[NM];
  for (int i = 0; i < n; ++i) q[i] = from_double<typename Fmt::angle_t>(0.0, st);
  SolverColumns<Fmt, NM> C;
  solver_prepare(P, J, q, C, st);
  typename Fmt::tw_t vs[6], r[6];
  const double L = to_double(P.L);
  for (int a = 0; a < 6; ++a) vs[a] = from_double<typename Fmt::tw_t>(a < 3 ? L * V[a] : V[a], st);
  typename Fmt::qd_t qd[NM];
  for (int i = 0; i < n; ++i) qd[i] = from_double<typename Fmt::qd_t>(0.0, st);
  solver_run(P, C, n, vs, qd, r, st);
  Eigen::VectorXd out(n);
  for (int i = 0; i < n; ++i) out[i] = to_double(qd[i]);
  return out;
}

Eigen::VectorXd weighted_lstsq(const Eigen::MatrixXd& J, const Eigen::VectorXd& V, double L) {
  Eigen::MatrixXd Js = J;
  Eigen::VectorXd Vs = V;
  Js.topRows(3) *= L;
  Vs.head(3) *= L;
  return Js.completeOrthogonalDecomposition().solve(Vs);
}
}  // namespace

// Gauss-Seidel needs O(cond^2) sweeps (docs/solver.md); these tests use Jacobians with
// cond(Js) <= 30 and enough sweeps to converge, with plain (mu = 1) and over-relaxed (mu = 1.6) steps.
TEST_CASE("solver: double converges to the weighted least-squares solution") {
  constexpr int NM = 8;
  double worst = 0;
  int cases = 0;
  for (int t = 0; cases < 200; ++t) {
    const int n = 6 + (t % 2);
    Status st;
    SolverParams<FmtDouble, NM> P;
    set_params(P, n, 0.5, t % 4 < 2 ? 1.0 : 1.6, 6000, st);
    Jacobian<FmtDouble, NM> J;
    Eigen::MatrixXd Jd;
    random_jacobian(J, Jd, n, 0.0, st);
    if (cond(Jd, 0.5) > 30) continue;
    ++cases;
    Eigen::VectorXd V = Eigen::VectorXd::Random(6);
    const Eigen::VectorXd x = solve(P, J, V, st);
    const Eigen::VectorXd xr = weighted_lstsq(Jd, V, 0.5);
    // n = 7: compare the residual (the minimum-norm solution is not unique); n = 6: the solution.
    Eigen::MatrixXd W = Eigen::MatrixXd::Identity(6, 6);
    W.topLeftCorner(3, 3) *= 0.25;
    const double e = n == 6 ? (x - xr).cwiseAbs().maxCoeff()
                            : std::fabs(((V - Jd * x).transpose() * W * (V - Jd * x))(0) -
                                        ((V - Jd * xr).transpose() * W * (V - Jd * xr))(0));
    worst = std::max(worst, e / (1 + xr.norm()));
  }
  CHECK_MSG(worst < 1e-9, "worst relative deviation %.3g", worst);
}

TEST_CASE("solver: converged fixed point stays within a bound of the least-squares solution") {
  constexpr int NM = 8;
  double worst = 0;
  uint32_t flags = 0;
  int cases = 0;
  for (int t = 0; cases < 200; ++t) {
    const int n = 6;
    Status st;
    SolverParams<FmtDefault, NM> P;
    set_params(P, n, 0.5, t % 2 ? 1.0 : 1.6, 6000, st);
    Jacobian<FmtDefault, NM> J;
    Eigen::MatrixXd Jd;
    random_jacobian(J, Jd, n, 0.0, st);
    const double c = cond(Jd, 0.5);
    if (c > 30) continue;
    ++cases;
    Eigen::VectorXd V = 0.2 * Eigen::VectorXd::Random(6);
    // the target as the solver sees it (quantised to tw_t)
    for (int a = 0; a < 6; ++a) {
      const double s = a < 3 ? to_double(P.L) : 1.0;
      V[a] = FmtDefault::tw_t::from_double(s * V[a], st).to_double() / s;
    }
    const Eigen::VectorXd x = solve(P, J, V, st);
    const Eigen::VectorXd xr = weighted_lstsq(Jd, V, to_double(P.L));
    // Bound (docs/solver.md): the fixed point leaves a residual of a few LSB of tw_t; the solution
    // error is at most cond * |r| / sigma_max-ish -> normalised by cond here.
    worst = std::max(worst, (x - xr).cwiseAbs().maxCoeff() / (c * FmtDefault::tw_t::lsb()));
    flags |= st.flags;
  }
  CHECK_MSG(worst < 16, "worst error %.3g x cond x LSB(tw_t)", worst);
  std::printf("    converged fixed point: worst |x - x_ls| = %.3g x cond x LSB(tw_t)\n", worst);
  CHECK(flags == 0);
}

TEST_CASE("solver: rates stay inside the velocity and position-limit box") {
  constexpr int NM = 8;
  using F = FmtDefault;
  int violations = 0, active = 0;
  for (int t = 0; t < 500; ++t) {
    Status st;
    SolverParams<F, NM> P;
    set_params(P, 6, 0.5, 1.0, 3, st);
    F::angle_t q[NM];
    for (int i = 0; i < 6; ++i) {
      P.limited[i] = true;
      P.lo[i] = F::angle_t::from_double(-1.0, st);
      P.hi[i] = F::angle_t::from_double(1.0, st);
      P.vmax[i] = F::qd_t::from_double(urand(0.2, 2.0), st);
      q[i] = F::angle_t::from_double(urand(-1.05, 1.05), st);  // some beyond the limits
    }
    P.klim = F::klim_t::from_double(10.0, st);
    Jacobian<F, NM> J;
    Eigen::MatrixXd Jd;
    random_jacobian(J, Jd, 6, 0.0, st);
    SolverColumns<F, NM> C;
    solver_prepare(P, J, q, C, st);
    F::tw_t vs[6], r[6];
    for (auto& v : vs) v = F::tw_t::from_double(urand(-5, 5), st);
    F::qd_t qd[NM];
    for (int i = 0; i < 6; ++i) qd[i] = F::qd_t::from_double(urand(-3, 3), st);
    solver_run(P, C, 6, vs, qd, r, st);
    for (int i = 0; i < 6; ++i) {
      const double v = qd[i].to_double(), qq = q[i].to_double();
      const double vm = P.vmax[i].to_double();
      const double lo = std::max(-vm, std::min(vm, 10 * (-1 - qq))), hi = std::min(vm, std::max(-vm, 10 * (1 - qq)));
      if (v < lo - 2 * F::qd_t::lsb() || v > hi + 2 * F::qd_t::lsb()) ++violations;
    }
    active += (st.flags & (ST_LIMIT_ACTIVE | ST_VLIMIT_ACTIVE)) != 0;
  }
  CHECK(violations == 0);
  CHECK(active > 100);  // the test does exercise the limits
}

TEST_CASE("solver: singular and rank-deficient Jacobians give bounded, finite output") {
  constexpr int NM = 8;
  for (double kill : {0.0, 1e-9, 1e-4}) {
    Status st, sd;
    SolverParams<FmtDefault, NM> P;
    SolverParams<FmtDouble, NM> Pd;
    set_params(P, 6, 0.5, 1.0, 50, st);
    set_params(Pd, 6, 0.5, 1.0, 50, sd);
    for (int i = 0; i < 6; ++i) { P.vmax[i] = FmtDefault::qd_t::from_double(4, st); Pd.vmax[i] = 4; }
    Jacobian<FmtDefault, NM> J;
    Eigen::MatrixXd Jd;
    random_jacobian(J, Jd, 6, kill < 1e-12 ? 1e-12 : kill, st);
    Jacobian<FmtDouble, NM> JD;
    JD.n = 6;
    for (int i = 0; i < 6; ++i)
      for (int a = 0; a < 3; ++a) { JD.w[i].c[a] = Jd(a, i); JD.v[i].c[a] = Jd(a + 3, i); }
    // a zero column too
    for (int a = 0; a < 3; ++a) { J.w[5].c[a] = FmtDefault::jw_t{}; J.v[5].c[a] = FmtDefault::jv_t{}; JD.w[5].c[a] = 0; JD.v[5].c[a] = 0; }
    Eigen::VectorXd V = Eigen::VectorXd::Random(6);
    const Eigen::VectorXd x = solve(P, J, V, st), xd = solve(Pd, JD, V, sd);
    CHECK(x.allFinite());
    CHECK(xd.allFinite());
    CHECK(x.cwiseAbs().maxCoeff() <= 4.0);
    CHECK(xd.cwiseAbs().maxCoeff() <= 4.0);
    CHECK(x[5] == 0.0);
    CHECK(st.overflow() == false);
  }
}

TEST_CASE("rotvec: division-free rotation vector within 1e-4 relative + 2 LSB") {
  using F = FmtDefault;
  Status st;
  double worst = 0;
  for (int t = 0; t < 100000; ++t) {
    double ax[3], s = 0;
    for (double& a : ax) { a = urand(-1, 1); s += a * a; }
    const double phi = urand(0, kPi);
    Quat<F::quat_t> q;
    q.c[0] = F::quat_t::from_double(std::cos(phi / 2), st);
    for (int a = 0; a < 3; ++a) q.c[a + 1] = F::quat_t::from_double(std::sin(phi / 2) * ax[a] / std::sqrt(s), st);
    if (t % 2) for (auto& c : q.c) c = cvt<F::quat_t>(-c, st);  // double cover
    const auto rv = rotvec<F>(q, st);
    for (int a = 0; a < 3; ++a) {
      const double want = phi * ax[a] / std::sqrt(s);
      worst = std::max(worst, std::fabs(rv.c[a].to_double() - want) / (1e-4 * std::fabs(want) + 2 * F::rot_t::lsb() + 4 * F::quat_t::lsb()));
    }
  }
  CHECK_MSG(worst <= 1.0, "worst normalised error %.3g", worst);
  CHECK(st.flags == 0);
}
