// Quaternion primitives, FK and Jacobian in fixed point against the same algorithm in double.
#include <random>

#include "check.hpp"
#include "tensor_servo/core_config.hpp"

using namespace ts;

namespace {
std::mt19937_64 rng(12345);
double urand(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); }

void random_unit(double* v, int n) {
  double s = 0;
  for (int i = 0; i < n; ++i) { v[i] = urand(-1, 1); s += v[i] * v[i]; }
  for (int i = 0; i < n; ++i) v[i] /= std::sqrt(s);
}

template <class T> Quat<T> rquat(Status& st) {
  double v[4]; random_unit(v, 4);
  Quat<T> q; for (int i = 0; i < 4; ++i) q.c[i] = T::from_double(v[i], st);
  return q;
}
template <class T> Quat<double> dbl(const Quat<T>& q) { Quat<double> r; for (int i = 0; i < 4; ++i) r.c[i] = q.c[i].to_double(); return r; }
template <class T> Vec3<double> dbl(const Vec3<T>& v) { Vec3<double> r; for (int i = 0; i < 3; ++i) r.c[i] = v.c[i].to_double(); return r; }

ChainSpec random_chain(int n, double off, double prismatic_prob) {
  ChainSpec c;
  random_unit(c.base_quat, 4); random_unit(c.tool_quat, 4);
  for (int a = 0; a < 3; ++a) { c.base_xyz[a] = urand(-off, off); c.tool_xyz[a] = urand(-off, off); }
  c.joints.resize(n);
  for (auto& j : c.joints) {
    random_unit(j.origin_quat, 4); random_unit(j.axis, 3);
    for (int a = 0; a < 3; ++a) j.origin_xyz[a] = urand(-off, off);
    j.prismatic = urand(0, 1) < prismatic_prob;
    j.lower = j.prismatic ? -0.2 : -3.1; j.upper = -j.lower;
    j.scale = urand(0, 1) < 0.2 ? urand(0.5, 1.5) : 1.0;
  }
  return c;
}
}  // namespace

template <class Fmt> void primitive_bounds() {
  using quat_t = typename Fmt::quat_t;
  Status st;
  double eq = 0, er = 0;
  for (int k = 0; k < 100000; ++k) {
    const auto a = rquat<quat_t>(st), b = rquat<quat_t>(st);
    const auto p = qmul<quat_t>(a, b, st);
    const auto pd = qmul<double>(dbl(a), dbl(b), st);
    for (int i = 0; i < 4; ++i) eq = std::max(eq, std::fabs(p.c[i].to_double() - pd.c[i]));
    Vec3<typename Fmt::len_t> v;
    for (int i = 0; i < 3; ++i) v.c[i] = Fmt::len_t::from_double(urand(-1, 1), st);
    const auto r = rotate<typename Fmt::pos_t, typename Fmt::len_tmp_t>(a, v, st);
    const auto rd = rotate<double, double>(dbl(a), dbl(v), st);
    for (int i = 0; i < 3; ++i) er = std::max(er, std::fabs(r.c[i].to_double() - rd.c[i]));
  }
  // qmul: one rounding per component -> at most 1/2 LSB.
  CHECK_MSG(eq <= 0.5 * quat_t::lsb(), "%s qmul error %.3g", Fmt::name, eq);
  // rotate: t rounded (error vector norm <= sqrt(3)/2 LSB of len_tmp_t), carried by w + q_v x (.)
  // with gain <= |w| + |q_v| <= sqrt(2); then the final 1/2 LSB.
  const double bound = std::sqrt(6.0) * 0.5 * Fmt::len_tmp_t::lsb() + 0.5 * Fmt::pos_t::lsb();
  CHECK_MSG(er <= bound, "%s rotate error %.3g > %.3g", Fmt::name, er, bound);
  CHECK(st.flags == 0);
}
TEST_CASE("primitives: qmul and rotate rounding bounds (default)") { primitive_bounds<FmtDefault>(); }
TEST_CASE("primitives: qmul and rotate rounding bounds (compact)") { primitive_bounds<FmtCompact>(); }

TEST_CASE("primitives: conj and inverse rotation undo a rotation to rounding") {
  using F = FmtDefault;
  Status st;
  for (int k = 0; k < 10000; ++k) {
    const auto q = rquat<F::quat_t>(st);
    Vec3<F::jw_t> v;
    for (int i = 0; i < 3; ++i) v.c[i] = F::jw_t::from_double(urand(-1, 1), st);
    const auto r = rotate<F::jw_t, F::jw_tmp_t>(q, v, st);
    const auto b = rotate<F::jw_t, F::jw_tmp_t, true>(q, r, st);
    const auto b2 = rotate<F::jw_t, F::jw_tmp_t>(conj(q, st), r, st);
    for (int i = 0; i < 3; ++i) {
      CHECK(std::fabs(b.c[i].to_double() - v.c[i].to_double()) < 8 * F::jw_t::lsb());
      CHECK(b.c[i].raw == b2.c[i].raw);  // INV is exactly rotation by the conjugate
    }
  }
  CHECK(st.flags == 0);
}

template <class Fmt> void fk_against_double(int n, double off, double pos_tol, double rot_tol, double jac_tol) {
  constexpr int NM = 32;
  double ep = 0, eo = 0, ej = 0;
  uint32_t flags = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const ChainSpec c = random_chain(n, off, 0.2);
    ChainQ<Fmt, NM> cf;
    ChainQ<FmtDouble, NM> cd;
    CHECK(quantize(c, cf).ok());
    CHECK(quantize(c, cd).ok());
    for (int s = 0; s < 10; ++s) {
      Status st;
      typename Fmt::angle_t q[NM];
      double qd[NM];
      for (int i = 0; i < n; ++i) {
        q[i] = Fmt::angle_t::from_double(urand(c.joints[i].lower, c.joints[i].upper), st);
        qd[i] = q[i].to_double();
      }
      Frames<Fmt, NM> f; Frames<FmtDouble, NM> fd;
      forward_kinematics(cf, q, f, st);
      forward_kinematics(cd, qd, fd, st);
      Jacobian<Fmt, NM> J; Jacobian<FmtDouble, NM> Jd;
      const int basis = s % 3 == 0 ? -1 : (s % 3 == 1 ? n + 1 : s % (n + 2));
      jacobian(cf, f, n + 1, basis, J, st);
      jacobian(cd, fd, n + 1, basis, Jd, st);
      for (int k = 0; k < n + 2; ++k) {
        double dot = 0, nn = 0;
        for (int a = 0; a < 4; ++a) { dot += f.Q[k].c[a].to_double() * fd.Q[k].c[a]; nn += std::pow(f.Q[k].c[a].to_double(), 2); }
        eo = std::max(eo, 2 * std::acos(std::min(1.0, std::fabs(dot) / std::sqrt(nn))));
        for (int a = 0; a < 3; ++a) ep = std::max(ep, std::fabs(f.p[k].c[a].to_double() - fd.p[k].c[a]));
      }
      for (int i = 0; i < n; ++i)
        for (int a = 0; a < 3; ++a)
          ej = std::max({ej, std::fabs(J.w[i].c[a].to_double() - Jd.w[i].c[a]), std::fabs(J.v[i].c[a].to_double() - Jd.v[i].c[a])});
      flags |= st.flags;
    }
  }
  CHECK_MSG(ep <= pos_tol && eo <= rot_tol && ej <= jac_tol, "%s n=%d: pos %.3g rot %.3g jac %.3g", Fmt::name, n, ep, eo, ej);
  CHECK(flags == 0);
}
// Random chains with origin offsets up to 0.25 m per axis.  Tolerances: 4x the worst seen in
// development; the robot-specific figures are in docs/numerics.md.
TEST_CASE("fk+jacobian: default vs double, 6 joints") { fk_against_double<FmtDefault>(6, 0.25, 4e-6, 2e-6, 4e-6); }
TEST_CASE("fk+jacobian: default vs double, 20 joints") { fk_against_double<FmtDefault>(20, 0.1, 8e-6, 4e-6, 8e-6); }
TEST_CASE("fk+jacobian: compact vs double, 6 joints") { fk_against_double<FmtCompact>(6, 0.25, 1.2e-3, 1.2e-3, 1.5e-3); }

TEST_CASE("fk: identity chain is exact") {
  ChainSpec c;
  c.joints.resize(5);
  for (auto& j : c.joints) { j.lower = -1; j.upper = 1; j.origin_xyz[2] = 0.125; }
  ChainQ<FmtDefault, 8> cq;
  CHECK(quantize(c, cq).ok());
  Status st;
  FmtDefault::angle_t q[8] = {};
  Frames<FmtDefault, 8> f;
  forward_kinematics(cq, q, f, st);
  CHECK(f.Q[6].c[0].raw == (int64_t(1) << FmtDefault::quat_t::F));
  CHECK(f.p[6].c[2].raw == (int64_t(5) << (FmtDefault::pos_t::F - 3)));
  CHECK(st.flags == 0);
}

TEST_CASE("config: bad chains are refused with the right code and field") {
  auto code = [](const ChainSpec& c) { ChainQ<FmtCompact, 8> q; return configure_chain(c, q); };
  ChainSpec ok; ok.joints.resize(2);
  for (auto& j : ok.joints) { j.lower = -1; j.upper = 1; }
  CHECK(code(ok).ok());
  { ChainSpec c = ok; c.joints.clear(); CHECK(code(c).code == CFG_JOINT_COUNT); }
  { ChainSpec c = ok; c.joints.resize(9, ok.joints[0]); CHECK(code(c).code == CFG_JOINT_COUNT); }
  { ChainSpec c = ok; c.joints[1].axis[2] = 0; auto r = code(c); CHECK(r.code == CFG_AXIS); CHECK(r.joint == 1); CHECK(r.field == "joints[1].axis"); }
  { ChainSpec c = ok; c.joints[0].origin_quat[0] = 0.9; CHECK(code(c).code == CFG_QUAT); }
  { ChainSpec c = ok; c.joints[0].lower = 2; CHECK(code(c).code == CFG_LIMITS); }
  { ChainSpec c = ok; c.joints[0].upper = 9; CHECK(code(c).code == CFG_LIMITS); }  // beyond |q| < 8
  { ChainSpec c = ok; c.joints[0].scale = 0; CHECK(code(c).code == CFG_SCALE); }
  { ChainSpec c = ok; c.joints[0].scale = 3.5; CHECK(code(c).code == CFG_SCALE); }  // revolute |s| < pi
  { ChainSpec c = ok; c.joints[0].origin_xyz[0] = 4.5; CHECK(code(c).code == CFG_OFFSET); }
  { ChainSpec c = ok; c.joints[0].origin_xyz[0] = 2.5; c.joints[1].origin_xyz[0] = 2.5; CHECK(code(c).code == CFG_REACH); }
  { ChainSpec c = ok; c.joints[0].prismatic = true; c.joints[0].limited = false; CHECK(code(c).code == CFG_LIMITS); }
}

TEST_CASE("jacobian: columns after the reference frame are zero, twist order (omega; v)") {
  using F = FmtDefault;
  ChainSpec c = random_chain(6, 0.2, 0.0);
  ChainQ<F, 8> cq;
  CHECK(quantize(c, cq).ok());
  Status st;
  F::angle_t q[8];
  for (int i = 0; i < 6; ++i) q[i] = F::angle_t::from_double(urand(-1, 1), st);
  Frames<F, 8> f;
  forward_kinematics(cq, q, f, st);
  Jacobian<F, 8> J;
  jacobian(cq, f, 3, -1, J, st);
  for (int i = 3; i < 6; ++i)
    for (int a = 0; a < 3; ++a) CHECK(J.w[i].c[a].raw == 0 && J.v[i].c[a].raw == 0);
  // Column 0 of a revolute joint: omega = z_1 (scale 1), v = z_1 x (p_3 - p_1).
  for (int a = 0; a < 3; ++a) CHECK(std::fabs(J.w[0].c[a].to_double() - f.z[1].c[a].to_double()) <= F::jw_t::lsb());
}
