// tensor-servo: the chain as the core sees it, and its quantisation into a number configuration.
//
// ChainSpec is the double-valued description (docs/chain-format.md):
//     T(q) = base * prod_i (origin_i * M_i(q_i)) * tool
// with M_i a rotation by s_i q_i about axis_i (revolute) or a translation by s_i q_i axis_i
// (prismatic), axis_i a unit vector in joint frame i.
//
// ChainQ<Fmt, NMAX> holds the same constants in the formats of Fmt, in fixed-size arrays (the core
// and the HLS code handle any chain up to NMAX joints, configured at run time).  quantize() also
// checks that no signal of the algorithm can leave its format for this chain (docs/numerics.md,
// "Range"), and refuses the chain with a configuration error naming the field otherwise.
#pragma once
#include <cmath>
#include <string>
#include <vector>

#include "formats.hpp"
#include "quat.hpp"
#include "sincos.hpp"

namespace ts {

struct JointSpec {
  int parent = -2;                       // -2: the previous joint (serial); -1: the base frame;
                                         // k >= 0: joint k (k < this joint's index)
  bool prismatic = false;
  double origin_quat[4] = {1, 0, 0, 0};  // w, x, y, z (unit)
  double origin_xyz[3] = {0, 0, 0};
  double axis[3] = {0, 0, 1};            // unit
  double scale = 1.0;
  bool limited = true;                   // false: continuous revolute joint
  double lower = 0.0, upper = 0.0;       // joint units
  double velocity = 0.0;                 // joint units per second (0: none)
};

// A tip: a frame fixed to a joint frame (a tree of chains has several; a serial chain has the tool).
struct TipSpec {
  int parent = -1;                       // joint index (-1: the last joint)
  double quat[4] = {1, 0, 0, 0};
  double xyz[3] = {0, 0, 0};
};

struct ChainSpec {
  double base_quat[4] = {1, 0, 0, 0};
  double base_xyz[3] = {0, 0, 0};
  double tool_quat[4] = {1, 0, 0, 0};    // the single tip when `tips` is empty
  double tool_xyz[3] = {0, 0, 0};
  std::vector<JointSpec> joints;
  std::vector<TipSpec> tips;             // trees of chains (seed section 12); empty: serial + tool
};

// Configuration error codes, shared with the RTL core's CFG_ERROR register.
enum ConfigError : int {
  CFG_OK = 0,
  CFG_JOINT_COUNT = 1,   // no joints, or more than NMAX
  CFG_AXIS = 2,          // axis not a unit vector
  CFG_QUAT = 3,          // a quaternion not of unit norm
  CFG_LIMITS = 4,        // lower > upper, or a limit outside the joint-value format
  CFG_SCALE = 5,         // scale zero or outside its format
  CFG_OFFSET = 6,        // an offset outside the length format
  CFG_REACH = 7,         // the chain could drive a position / lever / Jacobian entry out of range
  CFG_TYPE = 8,          // unknown joint type (RTL register field)
  CFG_TREE = 9,          // a parent index not before its joint, or too many tips
};

struct ConfigResult {
  ConfigError code = CFG_OK;
  int joint = -1;        // joint index, -1 for base/tool/chain
  std::string field;     // e.g. "joints[2].axis"
  std::string message;   // one line
  bool ok() const { return code == CFG_OK; }
};

template <class Fmt>
struct JointQ {
  using quat_t = typename Fmt::quat_t;
  bool prismatic = false;
  Quat<quat_t> qo;                      // origin rotation
  Vec3<typename Fmt::len_t> po;         // origin translation
  Vec3<quat_t> axis;                    // unit axis in joint frame
  typename Fmt::scale_t s;              // joint unit -> rad or m
  typename Fmt::kturn_t k;              // s / (4 pi): joint unit -> half-angle turns
};

// Frame indices: 0 = base, 1..n = joint frames (after motion), n+1..n+ntips = tips (n+1 = tool).
template <class Fmt, int NMAX, int TMAX = 4>
struct ChainQ {
  static constexpr int nmax = NMAX;
  static constexpr int tmax = TMAX;
  int n = 0;
  int ntips = 1;
  Quat<typename Fmt::quat_t> qb;        // base rotation
  Vec3<typename Fmt::len_t> pb;         // base translation
  JointQ<Fmt> j[NMAX];
  int parent[NMAX];                     // frame index of joint j's parent frame (serial: j)
  Quat<typename Fmt::quat_t> qt[TMAX];  // tip rotations (relative to their parent joint frame)
  Vec3<typename Fmt::len_t> pt[TMAX];
  int tip_parent[TMAX];                 // frame index (1..n) of each tip's joint frame
  // The frame a frame index hangs from: joint frame i -> parent[i-1], tip -> its joint frame.
  int parent_frame(int f) const { return f > n ? tip_parent[f - n - 1] : parent[f - 1]; }
};

namespace detail {
inline double norm3(const double* v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }
inline double norm4(const double* v) {
  return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[3] * v[3]);
}
template <class T>
inline double fmt_max() {
  if constexpr (std::is_same_v<T, double>) return HUGE_VAL;
  else return T::max_value();
}
template <class T>
inline bool representable(double d) {
  if constexpr (std::is_same_v<T, double>) return std::isfinite(d);
  else return T::representable(d);
}
template <class T, int N>
inline void quant_array(const double* src, T* dst, Status& st) {
  for (int i = 0; i < N; ++i) dst[i] = from_double<T>(src[i], st);
}
}  // namespace detail

// Tolerance on unit norms accepted here (the JSON loader normalises within 1e-6 and rejects beyond).
constexpr double kUnitTol = 1e-6;

// Bound on the distance between two frame origins of the chain (from the first joint frame on):
// sum of all origin offsets and prismatic strokes plus the longest tip offset (for a tree this
// sums every branch: conservative).
inline double chain_reach(const ChainSpec& c) {
  double r = 0;
  if (c.tips.empty()) r = detail::norm3(c.tool_xyz);
  for (const auto& t : c.tips) r = std::max(r, detail::norm3(t.xyz));
  for (const auto& j : c.joints) {
    r += detail::norm3(j.origin_xyz);
    if (j.prismatic) r += std::fabs(j.scale) * std::max(std::fabs(j.lower), std::fabs(j.upper));
  }
  return r;
}

// k = s/(4 pi) from the quantised scale: one multiply by the constant 1/(4 pi) (the core computes
// it at commit the same way); saturation of kturn_t means the scale is out of range.
template <class Fmt>
inline typename Fmt::kturn_t derive_kturn(typename Fmt::scale_t s, Status& st) {
  if constexpr (Fmt::is_float) { (void)st; return s / (4.0 * kPi); }
  else {
    Status c;
    static const typename Fmt::inv4pi_t inv = Fmt::inv4pi_t::from_double(1.0 / (4.0 * kPi), c);
    return cvt<typename Fmt::kturn_t>(s * inv, st);
  }
}

// A storage value from a raw register word (saturating: a word outside the format flags nothing
// here; the register map documents the widths).
template <class T>
inline T of_raw_storage(int64_t r) {
  if constexpr (std::is_same_v<T, double>) return static_cast<double>(r);
  else return T::from_raw(r > T::RAW_MAX ? T::RAW_MAX : (r < T::RAW_MIN ? T::RAW_MIN : r));
}

template <class Fmt, int NMAX, int TMAX>
inline ConfigResult quantize(const ChainSpec& c, ChainQ<Fmt, NMAX, TMAX>& out) {
  using quat_t = typename Fmt::quat_t;
  using len_t = typename Fmt::len_t;
  using angle_t = typename Fmt::angle_t;
  auto fail = [](ConfigError e, int j, std::string f, std::string m) {
    ConfigResult r;
    r.code = e; r.joint = j; r.field = std::move(f); r.message = std::move(m);
    return r;
  };
  const int n = static_cast<int>(c.joints.size());
  if (n < 1 || n > NMAX)
    return fail(CFG_JOINT_COUNT, -1, "joints",
                "chain has " + std::to_string(n) + " joints; this build handles 1.." + std::to_string(NMAX));
  // Margin for rounding: the bounds below must hold with a few LSB to spare.
  const double margin = 1.0 - 1e-6;
  auto check_quat = [&](const double* q, int j, const std::string& f) {
    return std::fabs(detail::norm4(q) - 1.0) <= kUnitTol ? ConfigResult{}
        : fail(CFG_QUAT, j, f, "quaternion is not of unit norm");
  };
  auto check_off = [&](const double* p, int j, const std::string& f) {
    for (int i = 0; i < 3; ++i)
      if (!std::isfinite(p[i]) || std::fabs(p[i]) >= detail::fmt_max<len_t>() * margin)
        return fail(CFG_OFFSET, j, f, "offset component outside the length format (|x| < " +
                                      std::to_string(detail::fmt_max<len_t>()) + " m)");
    return ConfigResult{};
  };
  for (auto r : {check_quat(c.base_quat, -1, "base.quat_wxyz"), check_quat(c.tool_quat, -1, "tool.quat_wxyz"),
                 check_off(c.base_xyz, -1, "base.xyz"), check_off(c.tool_xyz, -1, "tool.xyz")})
    if (!r.ok()) return r;
  const int ntips = c.tips.empty() ? 1 : static_cast<int>(c.tips.size());
  if (ntips > TMAX)
    return fail(CFG_TREE, -1, "tips", "chain has " + std::to_string(ntips) + " tips; this build handles 1.." + std::to_string(TMAX));
  for (int t = 0; t < static_cast<int>(c.tips.size()); ++t) {
    const std::string pre = "tips[" + std::to_string(t) + "].";
    if (auto r = check_quat(c.tips[t].quat, -1, pre + "quat_wxyz"); !r.ok()) return r;
    if (auto r = check_off(c.tips[t].xyz, -1, pre + "xyz"); !r.ok()) return r;
    if (c.tips[t].parent < -1 || c.tips[t].parent >= n) return fail(CFG_TREE, -1, pre + "parent", "no such joint");
  }
  double smax = 0.0;
  for (int i = 0; i < n; ++i) {
    const JointSpec& js = c.joints[i];
    const std::string pre = "joints[" + std::to_string(i) + "].";
    if (js.parent < -2 || js.parent >= i) return fail(CFG_TREE, i, pre + "parent", "the parent must be an earlier joint or the base");
    if (auto r = check_quat(js.origin_quat, i, pre + "origin.quat_wxyz"); !r.ok()) return r;
    if (auto r = check_off(js.origin_xyz, i, pre + "origin.xyz"); !r.ok()) return r;
    if (std::fabs(detail::norm3(js.axis) - 1.0) > kUnitTol)
      return fail(CFG_AXIS, i, pre + "axis", "axis is not a unit vector");
    const double kmax = detail::fmt_max<typename Fmt::kturn_t>() * 4.0 * kPi;
    if (!(std::fabs(js.scale) > 0.0) || std::fabs(js.scale) >= detail::fmt_max<typename Fmt::scale_t>() * margin ||
        (!js.prismatic && std::fabs(js.scale) >= kmax * margin))
      return fail(CFG_SCALE, i, pre + "scale", "scale is zero or outside its format");
    if (js.limited) {
      if (!(js.lower <= js.upper)) return fail(CFG_LIMITS, i, pre + "limits", "lower > upper");
      if (!detail::representable<angle_t>(js.lower) || !detail::representable<angle_t>(js.upper))
        return fail(CFG_LIMITS, i, pre + "limits",
                    "limit outside the joint-value format (|q| < " + std::to_string(detail::fmt_max<angle_t>()) + ")");
    } else if (js.prismatic) {
      return fail(CFG_LIMITS, i, pre + "limits", "a prismatic joint needs position limits");
    }
    smax = std::max(smax, std::fabs(js.scale));
  }
  (void)smax;  // the reach is checked on the quantised chain (core_config.hpp check_chain)

  Status st;
  out.n = n;
  out.ntips = ntips;
  detail::quant_array<quat_t, 4>(c.base_quat, out.qb.c, st);
  detail::quant_array<len_t, 3>(c.base_xyz, out.pb.c, st);
  if (c.tips.empty()) {
    detail::quant_array<quat_t, 4>(c.tool_quat, out.qt[0].c, st);
    detail::quant_array<len_t, 3>(c.tool_xyz, out.pt[0].c, st);
    out.tip_parent[0] = n;
  }
  for (int t = 0; t < static_cast<int>(c.tips.size()); ++t) {
    detail::quant_array<quat_t, 4>(c.tips[t].quat, out.qt[t].c, st);
    detail::quant_array<len_t, 3>(c.tips[t].xyz, out.pt[t].c, st);
    out.tip_parent[t] = c.tips[t].parent < 0 ? n : c.tips[t].parent + 1;
  }
  for (int i = 0; i < n; ++i) {
    const JointSpec& js = c.joints[i];
    out.parent[i] = js.parent == -2 ? i : js.parent + 1;
    JointQ<Fmt>& q = out.j[i];
    q.prismatic = js.prismatic;
    detail::quant_array<quat_t, 4>(js.origin_quat, q.qo.c, st);
    detail::quant_array<len_t, 3>(js.origin_xyz, q.po.c, st);
    detail::quant_array<quat_t, 3>(js.axis, q.axis.c, st);
    q.s = from_double<typename Fmt::scale_t>(js.scale, st);
    Status ks;
    q.k = js.prismatic ? typename Fmt::kturn_t{} : derive_kturn<Fmt>(q.s, ks);
    if (ks.overflow()) return fail(CFG_SCALE, i, "joints[" + std::to_string(i) + "].scale", "scale outside the range of the turn constant");
  }
  if (st.overflow()) return fail(CFG_OFFSET, -1, "chain", "a constant did not fit its format");
  return ConfigResult{};
}

}  // namespace ts
