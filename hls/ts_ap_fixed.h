// tensor-servo HLS: the number family of the model (fixed.hpp, "Number families") on Xilinx
// ap_fixed, so the model's algorithm headers instantiate on ap_fixed bit for bit.
//
//   apfx<W, I, FLAG>   a storage type: exactly an ap_fixed<W, I> (it derives from it; arithmetic,
//                      comparisons and widths are ap_fixed's own) that also carries the model's
//                      storage interface: W, I, F, FLAG (the sticky status bit its saturation
//                      raises), RAW_MAX, RAW_MIN, from_raw, and zero as its default value.  It has
//                      no converting constructor: as in the model, every narrowing is an explicit
//                      cvt/wrap below, never an implicit ap_fixed assignment.
//   cvt<Dst>(x, st)    AP_RND then AP_SAT; the flag is computed as in the model: x is rounded into
//                      a type with Dst's fraction bits and room for every value (no wrap), then
//                      compared with Dst's range.
//   wrap<Dst>(x)       AP_RND then AP_WRAP.
//   cvt_shr<Dst>(x,k)  run-time power of two: the model's own integer core on the raw value.
//   ilog2, scale_pow2<K>, raw_of, num_traits   as in fixed.hpp.
//
// Include order: this header must come before the model's algorithm headers (ts_formats_hls.h
// does it), so that their templates see these overloads; the model's double overloads accept only
// double, so a wrong order is a compile error, not a silent conversion.
#pragma once
#include <ap_fixed.h>

#include <cstdint>

#include "tensor_servo/fixed.hpp"

namespace ts {

template <int W_, int I_, uint32_t FLAG_ = 0>
struct apfx : ap_fixed<W_, I_> {
  using base_t = ap_fixed<W_, I_>;
  static_assert(W_ >= 2 && W_ <= 62, "apfx width must be 2..62 bits (as fx)");
  static constexpr int W = W_;
  static constexpr int I = I_;
  static constexpr int F = W_ - I_;
  static constexpr uint32_t FLAG = FLAG_;
  static constexpr int64_t RAW_MAX = (int64_t(1) << (W_ - 1)) - 1;
  static constexpr int64_t RAW_MIN = -(int64_t(1) << (W_ - 1));

  apfx() : base_t(0) {}
  apfx(const apfx&) = default;
  apfx& operator=(const apfx&) = default;
  static apfx from_raw(int64_t r) {
    apfx x;
    x.range(W_ - 1, 0) = static_cast<uint64_t>(r);
    return x;
  }
};

// Formats of the intermediate ap_fixed values (sums, products, negations).
template <int W_, int I_, ap_q_mode Q, ap_o_mode O, int N>
struct num_traits<ap_fixed<W_, I_, Q, O, N>> {
  static constexpr int W = W_, I = I_, F = W_ - I_;
};
template <int W_, int I_, bool S, ap_q_mode Q, ap_o_mode O, int N>
struct num_traits<ap_fixed_base<W_, I_, S, Q, O, N>> {
  static_assert(S, "signed formats only");
  static constexpr int W = W_, I = I_, F = W_ - I_;
};

// Two's-complement raw value, sign-extended to 64 bits.
template <int W, int I, bool S, ap_q_mode Q, ap_o_mode O, int N>
inline int64_t raw_of(const ap_fixed_base<W, I, S, Q, O, N>& x) {
  static_assert(S && W <= 64, "signed formats of at most 64 bits");
  const uint64_t u = x.range(W - 1, 0).to_uint64();
  return static_cast<int64_t>(u << (64 - W)) >> (64 - W);
}

namespace detail {
// Integer bits of the rounding type of cvt: the source's plus one (a round-up carry), and at
// least enough for a two-bit type.
constexpr int cvt_int_bits(int I, int Fd) { return cmax(I + 1, 2 - Fd); }
}  // namespace detail

template <class Dst, int W, int I, bool S, ap_q_mode Q, ap_o_mode O, int N>
inline Dst cvt(const ap_fixed_base<W, I, S, Q, O, N>& x, Status& st) {
  constexpr int RI = detail::cvt_int_bits(I, Dst::F);
  static_assert(RI + Dst::F <= 64, "rounding type wider than 64 bits");
  const ap_fixed<RI + Dst::F, RI, AP_RND, AP_WRAP> r = x;  // AP_RND; never wraps (one spare bit)
  const Dst hi = Dst::from_raw(Dst::RAW_MAX);
  const Dst lo = Dst::from_raw(Dst::RAW_MIN);
  if (r > hi) { st.raise(Dst::FLAG); return hi; }
  if (r < lo) { st.raise(Dst::FLAG); return lo; }
  return Dst::from_raw(raw_of(r));  // in range: r's raw value is Dst's
}

template <class Dst, int W, int I, bool S, ap_q_mode Q, ap_o_mode O, int N>
inline Dst wrap(const ap_fixed_base<W, I, S, Q, O, N>& x) {
  const ap_fixed<Dst::W, Dst::I, AP_RND, AP_WRAP> r = x;
  return Dst::from_raw(raw_of(r));
}

template <class Dst, int W, int I, bool S, ap_q_mode Q, ap_o_mode O, int N>
inline Dst cvt_shr(const ap_fixed_base<W, I, S, Q, O, N>& x, int k, Status& st) {
  bool sat;
  const int64_t r = detail::shr_round_sat(raw_of(x), W - I, k, Dst::F, Dst::RAW_MIN, Dst::RAW_MAX, sat);
  if (sat) st.raise(Dst::FLAG);
  return Dst::from_raw(r);
}

// Leading one of a positive value (a priority encoder over the W bits); x <= 0 gives -2^20.
template <int W, int I, bool S, ap_q_mode Q, ap_o_mode O, int N>
inline int ilog2(const ap_fixed_base<W, I, S, Q, O, N>& x) {
  const int64_t r = raw_of(x);
  if (r <= 0) return -(1 << 20);
  int b = 0;
  for (int i = 0; i < W - 1; ++i)
    if ((r >> i) & 1) b = i;
  return b - (W - I);
}

// 2^K x: the same bits, the binary point moved.
template <int K, int W, int I, bool S, ap_q_mode Q, ap_o_mode O, int N>
inline ap_fixed<W, I + K> scale_pow2(const ap_fixed_base<W, I, S, Q, O, N>& x) {
  ap_fixed<W, I + K> r;
  r.range(W - 1, 0) = x.range(W - 1, 0);
  return r;
}

}  // namespace ts
