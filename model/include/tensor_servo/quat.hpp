// tensor-servo: quaternion and 3-vector primitives, one rounding per output component.
//
// Quaternions are stored (w, x, y, z) and are Hamilton products: q = w + x i + y j + z k, and a unit
// quaternion q rotates a vector v as q v q*.  Each primitive forms its outputs as exact sums of
// exact products and rounds once per output (per stage for rotate), which is also how the RTL
// computes them (registered products, registered pairwise adder tree, one rounding stage).
#pragma once
#include "fixed.hpp"

namespace ts {

template <class T> struct Vec3 { T c[3]; };
template <class T> struct Quat { T c[4]; };  // c[0] = w, c[1..3] = x, y, z

// 2^K x, exact: the binary point moves (fx), or a multiplication by a power of two (double).
template <int K, class X>
inline auto pow2(X x) {
  if constexpr (std::is_same_v<X, double>) return std::ldexp(x, K);
  else return scale_pow2<K>(x);
}

template <class Out, class T>
inline Quat<Out> quat_cvt(const Quat<T>& a, Status& st) {
  Quat<Out> r;
  for (int i = 0; i < 4; ++i) r.c[i] = cvt<Out>(a.c[i], st);
  return r;
}
template <class Out, class T>
inline Vec3<Out> vec_cvt(const Vec3<T>& a, Status& st) {
  Vec3<Out> r;
  for (int i = 0; i < 3; ++i) r.c[i] = cvt<Out>(a.c[i], st);
  return r;
}

// Hamilton product a (x) b: 16 products, four 4-term sums, one rounding per component.
template <class Out, class A, class B>
inline Quat<Out> qmul(const Quat<A>& a, const Quat<B>& b, Status& st) {
  const auto& p = a.c;
  const auto& q = b.c;
  Quat<Out> r;
  r.c[0] = cvt<Out>((p[0] * q[0] - p[1] * q[1]) - (p[2] * q[2] + p[3] * q[3]), st);
  r.c[1] = cvt<Out>((p[0] * q[1] + p[1] * q[0]) + (p[2] * q[3] - p[3] * q[2]), st);
  r.c[2] = cvt<Out>((p[0] * q[2] - p[1] * q[3]) + (p[2] * q[0] + p[3] * q[1]), st);
  r.c[3] = cvt<Out>((p[0] * q[3] + p[1] * q[2]) - (p[2] * q[1] - p[3] * q[0]), st);
  return r;
}

// Conjugate: exact for every value of a quaternion format except its most negative raw value,
// which a unit quaternion never reaches (|component| <= 1 + rounding); saturates and flags if so.
template <class T>
inline Quat<T> conj(const Quat<T>& a, Status& st) {
  Quat<T> r;
  r.c[0] = a.c[0];
  for (int i = 1; i < 4; ++i) r.c[i] = cvt<T>(-a.c[i], st);
  return r;
}

// Cross product a x b: six products, one rounding per component.
template <class Out, class A, class B>
inline Vec3<Out> cross(const Vec3<A>& a, const Vec3<B>& b, Status& st) {
  Vec3<Out> r;
  r.c[0] = cvt<Out>(a.c[1] * b.c[2] - a.c[2] * b.c[1], st);
  r.c[1] = cvt<Out>(a.c[2] * b.c[0] - a.c[0] * b.c[2], st);
  r.c[2] = cvt<Out>(a.c[0] * b.c[1] - a.c[1] * b.c[0], st);
  return r;
}

// Rotation of v by the unit quaternion q (INV = false: q v q*, INV = true: q* v q), in the form
//   t   = 2 (q_v x v)                 rounded to Tmp
//   out = v + w t + q_v x t           rounded to Out
// (15 products).  With INV the vector part of q enters negated; the negation is folded into the
// sums, so no extra rounding or width appears.
template <class Out, class Tmp, bool INV = false, class Q, class V>
inline Vec3<Out> rotate(const Quat<Q>& q, const Vec3<V>& v, Status& st) {
  const auto& w = q.c[0];
  const auto& x = q.c[1];
  const auto& y = q.c[2];
  const auto& z = q.c[3];
  const auto& a = v.c;
  Vec3<Tmp> t;
  if constexpr (!INV) {
    t.c[0] = cvt<Tmp>(pow2<1>(y * a[2] - z * a[1]), st);
    t.c[1] = cvt<Tmp>(pow2<1>(z * a[0] - x * a[2]), st);
    t.c[2] = cvt<Tmp>(pow2<1>(x * a[1] - y * a[0]), st);
  } else {
    t.c[0] = cvt<Tmp>(pow2<1>(z * a[1] - y * a[2]), st);
    t.c[1] = cvt<Tmp>(pow2<1>(x * a[2] - z * a[0]), st);
    t.c[2] = cvt<Tmp>(pow2<1>(y * a[0] - x * a[1]), st);
  }
  const auto& b = t.c;
  Vec3<Out> r;
  if constexpr (!INV) {
    r.c[0] = cvt<Out>((a[0] + w * b[0]) + (y * b[2] - z * b[1]), st);
    r.c[1] = cvt<Out>((a[1] + w * b[1]) + (z * b[0] - x * b[2]), st);
    r.c[2] = cvt<Out>((a[2] + w * b[2]) + (x * b[1] - y * b[0]), st);
  } else {
    r.c[0] = cvt<Out>((a[0] + w * b[0]) + (z * b[1] - y * b[2]), st);
    r.c[1] = cvt<Out>((a[1] + w * b[1]) + (x * b[2] - z * b[0]), st);
    r.c[2] = cvt<Out>((a[2] + w * b[2]) + (y * b[0] - x * b[1]), st);
  }
  return r;
}

// a + b (exact sum, one rounding), a - b likewise.
template <class Out, class A, class B>
inline Vec3<Out> vadd(const Vec3<A>& a, const Vec3<B>& b, Status& st) {
  Vec3<Out> r;
  for (int i = 0; i < 3; ++i) r.c[i] = cvt<Out>(a.c[i] + b.c[i], st);
  return r;
}
template <class Out, class A, class B>
inline Vec3<Out> vsub(const Vec3<A>& a, const Vec3<B>& b, Status& st) {
  Vec3<Out> r;
  for (int i = 0; i < 3; ++i) r.c[i] = cvt<Out>(a.c[i] - b.c[i], st);
  return r;
}
// s * a (scalar times vector), one rounding per component.
template <class Out, class S, class A>
inline Vec3<Out> vscale(const S& s, const Vec3<A>& a, Status& st) {
  Vec3<Out> r;
  for (int i = 0; i < 3; ++i) r.c[i] = cvt<Out>(s * a.c[i], st);
  return r;
}

}  // namespace ts
