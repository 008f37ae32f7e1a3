// tensor-servo: division-free sine and cosine of a binary angle (quarter-wave table + rotation by
// a small residual angle).
//
// Input: u, an angle in turns modulo one (turn_t, W_u bits; the bit pattern read as unsigned is
// u * 2^W_u).  The bits split as
//     [ quadrant : 2 ][ index : T ][ residual : R = W_u - 2 - T ]
// Table entry k holds S_k = sin(k pi / 2^(T+1)), C_k = cos(k pi / 2^(T+1)) rounded to tab_t; the
// residual angle d = 2 pi * residual * 2^-W_u lies in [0, pi / 2^(T+1)) (< 2^-7 rad for T = 8).
//     d    = cvt<delta_t>(residual_turns * 2 pi)
//     d2   = cvt<dsq_t>(d * d)                       h = d2 / 2  (exact)
//     e    = cvt<dsq_t>(d2 * 1/6)
//     de   = cvt<delta_t>(d * e)
//     sd   = cvt<delta_t>(d - de)                    sin d (error d^5/120 < 2e-13)
//     Sh, Ch, Csd, Ssd = cvt<trig_acc_t>(S h, C h, C sd, S sd)    (guard bits: 8)
//     sn   = cvt<quat_t>(S - Sh + Csd)               sin(a + d), cos d = 1 - h (error d^4/24 < 6e-11)
//     cs   = cvt<quat_t>(C - Ch - Ssd)               cos(a + d)
// then the quadrant maps (sn, cs) to (sin, cos) by swaps and exact negations.  Eight multiplies,
// no divider.  u = 0 gives exactly (0, 1).  For FmtDouble the same entry point is std::sin/cos.
#pragma once
#include <cmath>

#include "fixed.hpp"

namespace ts {

constexpr double kPi = 3.14159265358979323846;

// The quarter-wave table of a configuration: 2^T entries of (sin, cos), and the two constants of
// the residual rotation.  The model builds it once from std::sin/cos; the algorithm reads it only
// through the static accessors, which a configuration may specialise with constant arrays
// (hls/ts_tables_<config>.h, generated from this table).
template <class Fmt>
struct TrigTable {
  using tab_t = typename Fmt::tab_t;
  static constexpr int N = 1 << Fmt::TRIG_TABLE_BITS;
  tab_t s[N];
  tab_t c[N];
  typename Fmt::twopi_t twopi_value;  // 2 pi
  typename Fmt::sixth_t sixth_value;  // 1/6
  TrigTable() {
    Status st;
    for (int k = 0; k < N; ++k) {
      const double a = k * kPi / (2.0 * N);
      s[k] = tab_t::from_double(std::sin(a), st);
      c[k] = tab_t::from_double(std::cos(a), st);
    }
    Status const_st;  // the two constants fit their formats (checked in the unit tests)
    twopi_value = Fmt::twopi_t::from_double(2.0 * kPi, const_st);
    sixth_value = Fmt::sixth_t::from_double(1.0 / 6.0, const_st);
  }
  static const TrigTable& get() {
    static const TrigTable t;
    return t;
  }
  static tab_t sin_at(int k) { return get().s[k]; }
  static tab_t cos_at(int k) { return get().c[k]; }
  static typename Fmt::twopi_t two_pi() { return get().twopi_value; }
  static typename Fmt::sixth_t sixth() { return get().sixth_value; }
};

// sin and cos of 2 pi u (u in turns).  Outputs in Fmt::quat_t.
template <class Fmt>
inline void sincos_turns(typename Fmt::turn_t u, typename Fmt::quat_t& sin_out,
                         typename Fmt::quat_t& cos_out, Status& st) {
  if constexpr (Fmt::is_float) {
    (void)st;
    const double a = 2.0 * kPi * u;
    sin_out = std::sin(a);
    cos_out = std::cos(a);
  } else {
    using turn_t = typename Fmt::turn_t;
    using quat_t = typename Fmt::quat_t;
    using delta_t = typename Fmt::delta_t;
    using dsq_t = typename Fmt::dsq_t;
    using twopi_t = typename Fmt::twopi_t;
    using sixth_t = typename Fmt::sixth_t;
    constexpr int WU = turn_t::W;
    constexpr int T = Fmt::TRIG_TABLE_BITS;
    constexpr int R = WU - 2 - T;
    static_assert(R >= 1, "turn format too narrow for the table");
    static_assert(turn_t::I == 0, "turn_t must be fx<W, 0>");
    const uint64_t bits = static_cast<uint64_t>(raw_of(u)) & ((uint64_t(1) << WU) - 1);
    const int quadrant = static_cast<int>(bits >> (WU - 2));
    const int index = static_cast<int>((bits >> R) & ((1u << T) - 1));
    const int64_t residual = static_cast<int64_t>(bits & ((uint64_t(1) << R) - 1));
    // residual * 2^-WU turns, as an exact fx with R magnitude bits and a sign bit.
    using res_t = typename Fmt::template num<R + 1, R + 1 - WU>;
    const auto delta = res_t::from_raw(residual);
    using tab = TrigTable<Fmt>;
    const twopi_t two_pi = tab::two_pi();
    const sixth_t sixth = tab::sixth();

    const delta_t d = cvt<delta_t>(delta * two_pi, st);
    const dsq_t d2 = cvt<dsq_t>(d * d, st);
    const auto h = scale_pow2<-1>(d2);
    const dsq_t e = cvt<dsq_t>(d2 * sixth, st);
    const delta_t de = cvt<delta_t>(d * e, st);
    const delta_t sd = cvt<delta_t>(d - de, st);
    const auto S = tab::sin_at(index);
    const auto C = tab::cos_at(index);
    using acc_t = typename Fmt::trig_acc_t;
    const acc_t Sh = cvt<acc_t>(S * h, st);
    const acc_t Ch = cvt<acc_t>(C * h, st);
    const acc_t Csd = cvt<acc_t>(C * sd, st);
    const acc_t Ssd = cvt<acc_t>(S * sd, st);
    const quat_t sn = cvt<quat_t>((S - Sh) + Csd, st);
    const quat_t cs = cvt<quat_t>((C - Ch) - Ssd, st);
    switch (quadrant) {
      case 0: sin_out = sn; cos_out = cs; break;
      case 1: sin_out = cs; cos_out = cvt<quat_t>(-sn, st); break;
      case 2: sin_out = cvt<quat_t>(-sn, st); cos_out = cvt<quat_t>(-cs, st); break;
      default: sin_out = cvt<quat_t>(-cs, st); cos_out = sn; break;
    }
  }
}

}  // namespace ts
