// fx<W,I> against Xilinx's ap_fixed<W,I,AP_RND,AP_SAT> (hls4ml's open headers): the model's
// rounding and saturation must be bit-exact with what an HLS user gets.
#include <ap_fixed.h>

#include <random>

#include "check.hpp"
#include "tensor_servo/fixed.hpp"

using namespace ts;

namespace {
template <int W, int I>
using apf = ap_fixed<W, I, AP_RND, AP_SAT>;

template <int W, class AP>
int64_t ap_raw(const AP& x) {
  const uint64_t u = x.range(W - 1, 0).to_uint64();
  const int sh = 64 - W;
  return static_cast<int64_t>(u << sh) >> sh;
}
template <int W, int I>
apf<W, I> ap_from_raw(int64_t r) {
  apf<W, I> x;
  x.range(W - 1, 0) = static_cast<uint64_t>(r);
  return x;
}

template <int W1, int I1, int W2, int I2, int WD, int ID>
void product_case(std::mt19937_64& g, int n, int& mism, int& sat_mism) {
  std::uniform_int_distribution<int64_t> d1(fx<W1, I1>::RAW_MIN, fx<W1, I1>::RAW_MAX);
  std::uniform_int_distribution<int64_t> d2(fx<W2, I2>::RAW_MIN, fx<W2, I2>::RAW_MAX);
  for (int k = 0; k < n; ++k) {
    const int64_t a = d1(g), b = d2(g);
    Status st;
    const auto m = cvt<fx<WD, ID, 1>>(fx<W1, I1>::from_raw(a) * fx<W2, I2>::from_raw(b), st);
    const apf<WD, ID> x = ap_from_raw<W1, I1>(a) * ap_from_raw<W2, I2>(b);
    if (m.raw != ap_raw<WD>(x)) ++mism;
    // ap_fixed saturates silently; the model must flag exactly the saturated cases.
    const bool saturated = m.raw == fx<WD, ID>::RAW_MAX || m.raw == fx<WD, ID>::RAW_MIN;
    const ap_fixed<WD + 8, ID + 8, AP_RND, AP_SAT> wide = ap_from_raw<W1, I1>(a) * ap_from_raw<W2, I2>(b);
    const bool out_of_range = wide > x || wide < x;
    if ((st.flags != 0) != out_of_range || (out_of_range && !saturated)) ++sat_mism;
  }
}
}  // namespace

TEST_CASE("fixed: products rounded like ap_fixed AP_RND/AP_SAT") {
  std::mt19937_64 g(7);
  int mism = 0, sat = 0;
  product_case<27, 2, 27, 2, 27, 2>(g, 200000, mism, sat);
  product_case<27, 2, 27, 4, 27, 3>(g, 200000, mism, sat);
  product_case<18, 2, 18, 3, 18, 2>(g, 200000, mism, sat);
  product_case<32, 4, 30, -1, 20, 0>(g, 200000, mism, sat);
  product_case<18, 4, 18, 3, 12, 1>(g, 200000, mism, sat);  // forces saturation often
  CHECK_MSG(mism == 0, "%d value mismatches", mism);
  CHECK_MSG(sat == 0, "%d saturation-flag mismatches", sat);
}

TEST_CASE("fixed: sums and differences exact, then rounded like ap_fixed") {
  std::mt19937_64 g(8);
  std::uniform_int_distribution<int64_t> d1(fx<27, 2>::RAW_MIN, fx<27, 2>::RAW_MAX);
  std::uniform_int_distribution<int64_t> d2(fx<32, 5>::RAW_MIN, fx<32, 5>::RAW_MAX);
  int mism = 0;
  for (int k = 0; k < 200000; ++k) {
    const int64_t a = d1(g), b = d2(g);
    Status st;
    const auto e = fx<27, 2>::from_raw(a) - fx<32, 5>::from_raw(b);
    const auto m = cvt<fx<24, 4, 1>>(e, st);
    const apf<24, 4> x = ap_from_raw<27, 2>(a) - ap_from_raw<32, 5>(b);
    if (m.raw != ap_raw<24>(x)) ++mism;
    const auto m2 = cvt<fx<40, 6, 1>>(e, st);  // widening: exact
    const apf<40, 6> x2 = ap_from_raw<27, 2>(a) - ap_from_raw<32, 5>(b);
    if (m2.raw != ap_raw<40>(x2)) ++mism;
  }
  CHECK_MSG(mism == 0, "%d mismatches", mism);
}

TEST_CASE("fixed: from_double like ap_fixed(double), ties toward +inf") {
  std::mt19937_64 g(9);
  std::uniform_real_distribution<double> u(-9.0, 9.0);
  int mism = 0;
  for (int k = 0; k < 200000; ++k) {
    double d = u(g);
    if (k % 4 == 0) d = std::ldexp(std::floor(std::ldexp(d, 23)) + 0.5, -23);  // exact tie
    Status st;
    const auto m = fx<27, 4, 1>::from_double(d, st);
    const apf<27, 4> x = d;
    if (m.raw != ap_raw<27>(x)) ++mism;
  }
  CHECK_MSG(mism == 0, "%d mismatches", mism);
  Status st;
  CHECK(fx<8, 4>::from_double(-2.5 / 16, st).raw == -2);  // tie -2.5 LSB -> -2 (toward +inf)
  CHECK(fx<8, 4>::from_double(2.5 / 16, st).raw == 3);
  CHECK(st.flags == 0);
  fx<8, 4, ST_OVF_POS>::from_double(100.0, st);
  CHECK(st.flags == ST_OVF_POS);
}

TEST_CASE("fixed: wrap keeps the low bits like AP_WRAP") {
  std::mt19937_64 g(10);
  std::uniform_int_distribution<int64_t> d1(fx<32, 4>::RAW_MIN, fx<32, 4>::RAW_MAX);
  std::uniform_int_distribution<int64_t> d2(fx<30, -1>::RAW_MIN, fx<30, -1>::RAW_MAX);
  int mism = 0;
  for (int k = 0; k < 200000; ++k) {
    const int64_t a = d1(g), b = d2(g);
    const auto m = wrap<fx<32, 0>>(fx<32, 4>::from_raw(a) * fx<30, -1>::from_raw(b));
    const ap_fixed<32, 0, AP_RND, AP_WRAP> x = ap_fixed<32, 4>(ap_from_raw<32, 4>(a)) * ap_fixed<30, -1>(ap_from_raw<30, -1>(b));
    if (m.raw != ap_raw<32>(x)) ++mism;
  }
  CHECK_MSG(mism == 0, "%d mismatches", mism);
}
