// The sin/cos unit: accuracy against std::sin/cos, exact special values, table well-defined.
#include <random>

#include "check.hpp"
#include "tensor_servo/formats.hpp"
#include "tensor_servo/sincos.hpp"

using namespace ts;

namespace {
template <class Fmt>
double max_error(int n, uint64_t seed, Status& st) {
  using turn_t = typename Fmt::turn_t;
  std::mt19937_64 g(seed);
  double e = 0;
  for (int k = 0; k < n; ++k) {
    const auto u = turn_t::from_raw(static_cast<int64_t>(g() >> (64 - turn_t::W)) + turn_t::RAW_MIN);
    typename Fmt::quat_t s, c;
    sincos_turns<Fmt>(u, s, c, st);
    const double a = 2 * kPi * u.to_double();
    e = std::max({e, std::fabs(s.to_double() - std::sin(a)), std::fabs(c.to_double() - std::cos(a))});
  }
  return e;
}

template <class Fmt>
void check_fmt() {
  using quat_t = typename Fmt::quat_t;
  using turn_t = typename Fmt::turn_t;
  Status st;
  const double lsb = quat_t::lsb();
  const double e = max_error<Fmt>(300000, 11, st);
  // Budget (docs/numerics.md): table rounding 1/2 LSB + final rounding 1/2 LSB + polynomial and
  // intermediate rounding < 0.01 LSB.
  CHECK_MSG(e <= 1.01 * lsb, "%s: max error %.3g = %.3f LSB", Fmt::name, e, e / lsb);
  CHECK(st.flags == 0);
  // Exact special values: 0, quarter, half, three quarters of a turn.
  const int64_t q = int64_t(1) << (turn_t::W - 2);
  const int64_t u[4] = {0, q, -2 * q, -q};
  const int64_t want_s[4] = {0, 1, 0, -1}, want_c[4] = {1, 0, -1, 0};
  for (int k = 0; k < 4; ++k) {
    quat_t s, c;
    sincos_turns<Fmt>(turn_t::from_raw(u[k]), s, c, st);
    CHECK_MSG(s.raw == (want_s[k] << quat_t::F) && c.raw == (want_c[k] << quat_t::F), "%s: k=%d", Fmt::name, k);
  }
  // Odd/even symmetry: sin(-u) = -sin(u), cos(-u) = cos(u) bit for bit away from the table's
  // start points (where the residual differs), checked on table start points only.
  for (int i = 1; i < (1 << Fmt::TRIG_TABLE_BITS); ++i) {
    const int64_t r = int64_t(i) << (turn_t::W - 2 - Fmt::TRIG_TABLE_BITS);
    quat_t s1, c1, s2, c2;
    sincos_turns<Fmt>(turn_t::from_raw(r), s1, c1, st);
    sincos_turns<Fmt>(turn_t::from_raw(-r), s2, c2, st);
    CHECK(s1.raw == -s2.raw);
    CHECK(c1.raw == c2.raw);
  }
}

template <class Fmt>
void check_table_ties() {
  // The table is round(sin(k pi / 2N) 2^F) with ties toward +inf; a value within 1e-6 LSB of a tie
  // could round differently on another libm, so none may be that close.
  const int N = 1 << Fmt::TRIG_TABLE_BITS;
  const int F = Fmt::tab_t::F;
  double closest = 1;
  for (int k = 0; k < N; ++k)
    for (double v : {std::sin(k * kPi / (2.0 * N)), std::cos(k * kPi / (2.0 * N))}) {
      const double x = std::ldexp(v, F);
      closest = std::min(closest, std::fabs(x - std::floor(x) - 0.5));
    }
  CHECK_MSG(closest > 1e-6, "%s: a table entry is %.3g LSB from a rounding tie", Fmt::name, closest);
}
}  // namespace

TEST_CASE("sincos: default within 1 LSB, exact at quarter turns, symmetric") { check_fmt<FmtDefault>(); }
TEST_CASE("sincos: compact within 1 LSB, exact at quarter turns, symmetric") { check_fmt<FmtCompact>(); }
TEST_CASE("sincos: tables have no entry near a rounding tie") {
  check_table_ties<FmtDefault>();
  check_table_ties<FmtCompact>();
}
TEST_CASE("sincos: constants fit their formats") {
  Status st;
  FmtDefault::twopi_t::from_double(2 * kPi, st);
  FmtCompact::twopi_t::from_double(2 * kPi, st);
  FmtDefault::sixth_t::from_double(1.0 / 6, st);
  CHECK(st.flags == 0);
}
