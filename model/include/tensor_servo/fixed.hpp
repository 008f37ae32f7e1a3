// tensor-servo: the fixed-point scalar that defines every bit of the core.
//
// fx<W, I, FLAG> is a signed two's-complement number of W bits, I of them integer bits *including
// the sign* (exactly Vitis' ap_fixed<W, I>), so F = W - I fraction bits; I may be negative or exceed
// W.  Raw value r means r * 2^-F.
//
// Arithmetic follows ap_fixed: +, -, * and unary - are EXACT and return a wider fx whose format is
// derived at compile time (product: <W1+W2, I1+I2>; sum: max(I)+1 integer bits, max(F) fraction
// bits).  Nothing is ever rounded implicitly: narrowing happens only in an explicit
//
//     cvt<Dst>(x, st)    round to nearest, ties toward +inf (ap_fixed AP_RND), then saturate
//                        (AP_SAT); a saturation sets Dst::FLAG in the sticky status st.
//     wrap<Dst>(x)       round (AP_RND), then keep the low W bits (AP_WRAP); used only where wrapping
//                        is the intended meaning (binary angles, which live modulo one turn).
//
// so every rounding site of the algorithm is visible in its source.  The same algorithm source is
// instantiated on `double` (cvt is the identity there) and, in hls/, on ap_fixed.
//
// Exact intermediates are held in int64_t; formats whose width would exceed 62 bits are rejected
// at compile time, so no intermediate can wrap silently.
//
// Number families.  The algorithm headers never name fx directly; they see a family of numbers
// through a configuration Fmt (formats.hpp) and this small interface, which fx implements here and
// hls/ts_ap_fixed.h implements for ap_fixed:
//   storage types (Fmt::angle_t, ..., and Fmt::num<W, I, FLAG>, the family's type of a format)
//       static W, I, F, FLAG, RAW_MAX, RAW_MIN;  T::from_raw(int64_t);  T{} is zero
//   every value (storage types and the wider results of exact + - *)
//       raw_of(x)                   the two's-complement raw value, as int64_t
//       num_traits<X>::W, I, F      its format (the primary template reads the storage members)
//       cvt<Dst>, wrap<Dst>, cvt_shr<Dst>, ilog2, scale_pow2<K>, < > ==, exact + - * and unary -
// The constant tables (TrigTable, RecipTable, RotvecTable) are read through static accessors, so
// a configuration can specialise them with constant arrays (hls/ts_tables_<config>.h); the
// model's primary templates build them once from std::sin etc.  The double overloads below accept
// exactly double, so a family with an implicit conversion to double (ap_fixed) can never fall
// back to them silently.
#pragma once
#include <cmath>
#include <cstdint>
#include <type_traits>
#ifdef TS_TRACE  // debugging aid: print every saturation (type, flag, value) to stderr
#include <cstdio>
#endif

// HLS directives written next to the loops they shape: `#pragma HLS ...` under Vitis HLS synthesis
// (__SYNTHESIS__), nothing for every other compiler (docs/hls.md).
#if defined(__SYNTHESIS__)
#define TS_PRAGMA_(x) _Pragma(#x)
#define TS_HLS(...) TS_PRAGMA_(HLS __VA_ARGS__)
#else
#define TS_HLS(...)
#endif

namespace ts {

// Sticky status bits.  Saturation of a storage format sets the bit named by that format; the
// other bits are raised by the algorithm (limits, configuration).
enum StatusBit : uint32_t {
  ST_OVF_ANGLE = 1u << 0,   // joint value (input) conversion saturated
  ST_OVF_TURN = 1u << 1,    // reserved: binary angles wrap by definition and never set this
  ST_OVF_TRIG = 1u << 2,    // sin/cos internal signal saturated
  ST_OVF_QUAT = 1u << 3,    // unit-quaternion / unit-vector component saturated
  ST_OVF_POS = 1u << 4,     // frame position saturated
  ST_OVF_LEVER = 1u << 5,   // lever arm r = p_ref - p_i saturated
  ST_OVF_JAC = 1u << 6,     // Jacobian entry saturated
  ST_OVF_CONST = 1u << 7,   // a configuration constant did not fit its format
  ST_OVF_SOLVER = 1u << 8,  // coordinate-solver signal saturated
  ST_OVF_SERVO = 1u << 9,   // servo-law signal saturated
  ST_LIMIT_ACTIVE = 1u << 16,   // a joint position limit shaped the command this tick
  ST_VLIMIT_ACTIVE = 1u << 17,  // a joint velocity limit clipped the command this tick
};
constexpr uint32_t ST_OVF_ANY = 0xFFFFu;

struct Status {
  uint32_t flags = 0;
  void raise(uint32_t b) { flags |= b; }
  bool overflow() const { return (flags & ST_OVF_ANY) != 0; }
};

template <int W_, int I_, uint32_t FLAG_ = 0>
struct fx {
  static_assert(W_ >= 2 && W_ <= 62, "fx width must be 2..62 bits (exact int64 intermediates)");
  static constexpr int W = W_;
  static constexpr int I = I_;
  static constexpr int F = W_ - I_;
  static constexpr uint32_t FLAG = FLAG_;
  static constexpr int64_t RAW_MAX = (int64_t(1) << (W_ - 1)) - 1;
  static constexpr int64_t RAW_MIN = -(int64_t(1) << (W_ - 1));

  int64_t raw = 0;

  static constexpr fx from_raw(int64_t r) { fx v; v.raw = r; return v; }
  double to_double() const { return std::ldexp(static_cast<double>(raw), -F); }
  static double lsb() { return std::ldexp(1.0, -F); }
  static double max_value() { return std::ldexp(static_cast<double>(RAW_MAX), -F); }
  static double min_value() { return std::ldexp(static_cast<double>(RAW_MIN), -F); }

  // Quantise a double (configuration constants, inputs): AP_RND then AP_SAT, flagging saturation.
  // Bit-exact with ap_fixed<W,I,AP_RND,AP_SAT>(double) for finite inputs.
  static fx from_double(double d, Status& st) {
    const double s = std::floor(std::ldexp(d, F) + 0.5);
    if (!(s <= static_cast<double>(RAW_MAX))) {  // also catches NaN
      st.raise(FLAG ? FLAG : ST_OVF_CONST);
      return from_raw(std::isnan(d) ? 0 : RAW_MAX);
    }
    if (s < static_cast<double>(RAW_MIN)) { st.raise(FLAG ? FLAG : ST_OVF_CONST); return from_raw(RAW_MIN); }
    return from_raw(static_cast<int64_t>(s));
  }
  // Directed quantisation (configuration constants such as joint limits, which must be rounded
  // inward so that a value inside the quantised limits is inside the true ones).  Saturating.
  static fx from_double_dir(double d, bool up, Status& st) {
    const double s = up ? std::ceil(std::ldexp(d, F)) : std::floor(std::ldexp(d, F));
    if (!(s <= static_cast<double>(RAW_MAX))) { st.raise(FLAG ? FLAG : ST_OVF_CONST); return from_raw(std::isnan(d) ? 0 : RAW_MAX); }
    if (s < static_cast<double>(RAW_MIN)) { st.raise(FLAG ? FLAG : ST_OVF_CONST); return from_raw(RAW_MIN); }
    return from_raw(static_cast<int64_t>(s));
  }
  // True when d lies inside the representable range after rounding (no saturation would occur).
  static bool representable(double d) {
    const double s = std::floor(std::ldexp(d, F) + 0.5);
    return s <= static_cast<double>(RAW_MAX) && s >= static_cast<double>(RAW_MIN);
  }
};

// Format of a value.  The primary template reads the storage-type members (fx, hls' apfx);
// hls/ts_ap_fixed.h specialises it for the intermediate ap_fixed results.
template <class T>
struct num_traits {
  static constexpr int W = T::W;
  static constexpr int I = T::I;
  static constexpr int F = T::F;
};

template <class T> struct is_fx : std::false_type {};
template <int W, int I, uint32_t FL> struct is_fx<fx<W, I, FL>> : std::true_type {};
template <class T> constexpr bool is_fx_v = is_fx<std::decay_t<T>>::value;

// The raw value of a number (storage or intermediate).
template <int W, int I, uint32_t L>
constexpr int64_t raw_of(const fx<W, I, L>& x) { return x.raw; }

namespace detail {
constexpr int cmax(int a, int b) { return a > b ? a : b; }
// Multiply by 2^k without the undefined behaviour of shifting a negative value.
constexpr int64_t shl(int64_t v, int k) { return v * (int64_t(1) << k); }
}  // namespace detail

// ---- exact arithmetic (result formats as ap_fixed) ---------------------------------------------
#ifdef TS_AUDIT_MUL
// Audit build (model/tests/audit/): every product records the wider of its two operand formats,
// so a test can prove a configuration's multiplier operands never exceed a width.
namespace audit { inline int max_operand_width = 0; }
#define TS_MUL_CONSTEXPR
#else
#define TS_MUL_CONSTEXPR constexpr
#endif
template <int W1, int I1, uint32_t L1, int W2, int I2, uint32_t L2>
TS_MUL_CONSTEXPR fx<W1 + W2, I1 + I2> operator*(fx<W1, I1, L1> a, fx<W2, I2, L2> b) {
#ifdef TS_AUDIT_MUL
  audit::max_operand_width = audit::max_operand_width > (W1 > W2 ? W1 : W2) ? audit::max_operand_width : (W1 > W2 ? W1 : W2);
#endif
  return fx<W1 + W2, I1 + I2>::from_raw(a.raw * b.raw);
}

template <int W1, int I1, int W2, int I2>
struct sum_fmt {
  static constexpr int F = detail::cmax(W1 - I1, W2 - I2);
  static constexpr int I = detail::cmax(I1, I2) + 1;
  using type = fx<I + F, I>;
};

template <int W1, int I1, uint32_t L1, int W2, int I2, uint32_t L2>
constexpr typename sum_fmt<W1, I1, W2, I2>::type operator+(fx<W1, I1, L1> a, fx<W2, I2, L2> b) {
  using R = typename sum_fmt<W1, I1, W2, I2>::type;
  return R::from_raw(detail::shl(a.raw, R::F - (W1 - I1)) + detail::shl(b.raw, R::F - (W2 - I2)));
}
template <int W1, int I1, uint32_t L1, int W2, int I2, uint32_t L2>
constexpr typename sum_fmt<W1, I1, W2, I2>::type operator-(fx<W1, I1, L1> a, fx<W2, I2, L2> b) {
  using R = typename sum_fmt<W1, I1, W2, I2>::type;
  return R::from_raw(detail::shl(a.raw, R::F - (W1 - I1)) - detail::shl(b.raw, R::F - (W2 - I2)));
}
template <int W, int I, uint32_t L>
constexpr fx<W + 1, I + 1> operator-(fx<W, I, L> a) { return fx<W + 1, I + 1>::from_raw(-a.raw); }

// Exact scaling by a power of two: only the binary point moves (free in hardware).
template <int K, int W, int I, uint32_t L>
constexpr fx<W, I + K> scale_pow2(fx<W, I, L> a) { return fx<W, I + K>::from_raw(a.raw); }

// ---- explicit narrowing --------------------------------------------------------------------------
namespace detail {
// Round raw value with fraction Fs to fraction Fd, ties toward +inf (floor(x + 1/2)).
constexpr int64_t round_raw(int64_t r, int Fs, int Fd) {
  if (Fs > Fd) {
    const int s = Fs - Fd;
    return (r + (int64_t(1) << (s - 1))) >> s;  // arithmetic shift (C++20; GCC/Clang always)
  }
  return shl(r, Fd - Fs);
}
}  // namespace detail

template <class Dst, int W, int I, uint32_t L>
inline Dst cvt(fx<W, I, L> x, Status& st) {
  static_assert(Dst::F - (W - I) < 62, "widening shift too large");
  const int64_t r = detail::round_raw(x.raw, W - I, Dst::F);
#ifdef TS_TRACE
  if (r > Dst::RAW_MAX || r < Dst::RAW_MIN) std::fprintf(stderr, "saturate to <%d,%d> flag %x: %g\n", Dst::W, Dst::I, Dst::FLAG, x.to_double());
#endif
  if (r > Dst::RAW_MAX) { st.raise(Dst::FLAG); return Dst::from_raw(Dst::RAW_MAX); }
  if (r < Dst::RAW_MIN) { st.raise(Dst::FLAG); return Dst::from_raw(Dst::RAW_MIN); }
  return Dst::from_raw(r);
}

template <class Dst, int W, int I, uint32_t L>
inline Dst wrap(fx<W, I, L> x) {
  const uint64_t r = static_cast<uint64_t>(detail::round_raw(x.raw, W - I, Dst::F));
  const int sh = 64 - Dst::W;
  return Dst::from_raw(static_cast<int64_t>(r << sh) >> sh);
}

// cvt with a run-time power of two: Dst = x * 2^-k rounded (AP_RND) and saturated.  Used where the
// algorithm normalises by a leading-one position found at run time (the solver's reciprocal).
namespace detail {
// The integer core of cvt_shr (shared by every number family): raw value x with fraction Fs,
// times 2^-k, rounded (AP_RND) to fraction Fd and saturated to [rmin, rmax].
inline int64_t shr_round_sat(int64_t x, int Fs, int k, int Fd, int64_t rmin, int64_t rmax, bool& sat) {
  const int s = Fs + k - Fd;  // right shift of the raw value
  int64_t r;
  if (s > 0) {
    r = s >= 62 ? 0 : round_raw(x, s, 0);  // |x| <= 2^61: beyond, |value| <= 1/2 LSB -> 0
  } else {
    const int l = -s;
    const int64_t lim = int64_t(1) << 62;
    if (l >= 62 || x >= (lim >> l) || x < -(lim >> l)) r = x > 0 ? rmax + 1 : (x < 0 ? rmin - 1 : 0);
    else r = shl(x, l);
  }
  sat = r > rmax || r < rmin;
  return r > rmax ? rmax : (r < rmin ? rmin : r);
}
}  // namespace detail

template <class Dst, int W, int I, uint32_t L>
inline Dst cvt_shr(fx<W, I, L> x, int k, Status& st) {
  bool sat;
  const int64_t r = detail::shr_round_sat(x.raw, W - I, k, Dst::F, Dst::RAW_MIN, Dst::RAW_MAX, sat);
  if (sat) st.raise(Dst::FLAG);
  return Dst::from_raw(r);
}
template <class Dst, class D, std::enable_if_t<std::is_same_v<D, double>, int> = 0>
inline double cvt_shr(D x, int k, Status&) { return std::ldexp(x, -k); }

// Position of the leading one of a positive value: returns k with 2^k <= x < 2^(k+1); x <= 0
// returns INT_MIN/2 (callers treat it as "zero").
template <int W, int I, uint32_t L>
inline int ilog2(fx<W, I, L> x) {
  if (x.raw <= 0) return -(1 << 20);
  return (63 - __builtin_clzll(static_cast<unsigned long long>(x.raw))) - (W - I);
}
template <class D, std::enable_if_t<std::is_same_v<D, double>, int> = 0>
inline int ilog2(D x) {
  if (!(x > 0)) return -(1 << 20);
  int e;
  std::frexp(x, &e);
  return e - 1;
}

// Largest value of a storage format (+inf for double).
template <class T>
inline T max_of() {
  if constexpr (std::is_same_v<T, double>) return HUGE_VAL;
  else return T::from_raw(T::RAW_MAX);
}

// ---- double instantiation: the identity ---------------------------------------------------------
template <class Dst, class D, std::enable_if_t<std::is_same_v<D, double>, int> = 0>
inline double cvt(D x, Status&) { return x; }
template <class Dst, class D, std::enable_if_t<std::is_same_v<D, double>, int> = 0>
inline double wrap(D x) { return x - std::floor(x + 0.5); }  // [-1/2, 1/2) turns

template <class T> inline double to_double(const T& v) { return v.to_double(); }
inline double to_double(double v) { return v; }

// Build a value of storage type T from a double (constants); identity for double.
template <class T>
inline T from_double(double d, Status& st) {
  if constexpr (std::is_same_v<T, double>) { (void)st; return d; }
  else return T::from_double(d, st);
}

// Inward-rounded limits: lower rounded up, upper rounded down (identity for double).
template <class T>
inline T from_double_dir(double d, bool up, Status& st) {
  if constexpr (std::is_same_v<T, double>) { (void)up; (void)st; return d; }
  else return T::from_double_dir(d, up, st);
}

// Comparisons on exact values (formats may differ).
template <int W1, int I1, uint32_t L1, int W2, int I2, uint32_t L2>
constexpr bool operator<(fx<W1, I1, L1> a, fx<W2, I2, L2> b) { return (a - b).raw < 0; }
template <int W1, int I1, uint32_t L1, int W2, int I2, uint32_t L2>
constexpr bool operator>(fx<W1, I1, L1> a, fx<W2, I2, L2> b) { return (a - b).raw > 0; }
template <int W1, int I1, uint32_t L1, int W2, int I2, uint32_t L2>
constexpr bool operator==(fx<W1, I1, L1> a, fx<W2, I2, L2> b) { return (a - b).raw == 0; }

}  // namespace ts
