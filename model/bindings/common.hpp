// Shared helpers of the Python bindings (numpy arrays, shapes, the chain spec dict).
#pragma once
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "tensor_servo/chain.hpp"

namespace tsbind {
namespace py = pybind11;
using namespace ts;

constexpr int NMAX = 64;
using i64arr = py::array_t<int64_t, py::array::c_style | py::array::forcecast>;
using f64arr = py::array_t<double, py::array::c_style | py::array::forcecast>;
using u32arr = py::array_t<uint32_t>;


template <class T> inline int64_t raw_of(const T& v) {
  if constexpr (std::is_same_v<T, double>) return 0;
  else return v.raw;
}
template <class T> inline T of_raw(int64_t r) {
  if constexpr (std::is_same_v<T, double>) return static_cast<double>(r);
  else return T::from_raw(r);
}
template <class T> inline py::tuple fmt_tuple() {
  if constexpr (std::is_same_v<T, double>) return py::make_tuple(64, 0);
  else return py::make_tuple(T::W, T::I);
}

template <class... Ts>
std::vector<py::ssize_t> shp(Ts... s) { return {static_cast<py::ssize_t>(s)...}; }

inline void need_shape(const py::array& a, std::vector<py::ssize_t> want, const char* name) {
  bool ok = a.ndim() == static_cast<py::ssize_t>(want.size());
  for (size_t i = 0; ok && i < want.size(); ++i) ok = want[i] < 0 || a.shape(i) == want[i];
  if (!ok) throw std::invalid_argument(std::string(name) + ": wrong shape");
}

inline ChainSpec spec_from_dict(const py::dict& d) {
  ChainSpec c;
  auto arr = [](const py::handle& h, double* out, size_t n, const char* name) {
    auto v = h.cast<std::vector<double>>();
    if (v.size() != n) throw std::invalid_argument(std::string(name) + ": wrong length");
    for (size_t i = 0; i < n; ++i) out[i] = v[i];
  };
  arr(d["base_quat"], c.base_quat, 4, "base_quat");
  arr(d["base_xyz"], c.base_xyz, 3, "base_xyz");
  arr(d["tool_quat"], c.tool_quat, 4, "tool_quat");
  arr(d["tool_xyz"], c.tool_xyz, 3, "tool_xyz");
  for (const auto& jh : d["joints"].cast<py::list>()) {
    const py::dict jd = jh.cast<py::dict>();
    JointSpec j;
    j.prismatic = jd["prismatic"].cast<bool>();
    arr(jd["origin_quat"], j.origin_quat, 4, "origin_quat");
    arr(jd["origin_xyz"], j.origin_xyz, 3, "origin_xyz");
    arr(jd["axis"], j.axis, 3, "axis");
    j.scale = jd["scale"].cast<double>();
    j.limited = jd["limited"].cast<bool>();
    j.lower = jd["lower"].cast<double>();
    j.upper = jd["upper"].cast<double>();
    j.velocity = jd["velocity"].cast<double>();
    if (jd.contains("parent")) j.parent = jd["parent"].cast<int>();
    c.joints.push_back(j);
  }
  if (d.contains("tips"))
    for (const auto& th : d["tips"].cast<py::list>()) {
      const py::dict td = th.cast<py::dict>();
      TipSpec t;
      t.parent = td["parent"].cast<int>();
      arr(td["quat"], t.quat, 4, "tips.quat");
      arr(td["xyz"], t.xyz, 3, "tips.xyz");
      c.tips.push_back(t);
    }
  return c;
}

}  // namespace tsbind
