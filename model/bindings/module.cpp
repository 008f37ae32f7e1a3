// Python bindings of the bit-accurate model (module tensor_servo._model).
//
// Every function takes a configuration name ("double", "default", "compact").  Raw integers are the
// two's-complement raw values of the formats (value = raw * 2^-F); float outputs are the same
// values converted exactly to double.  The primitive functions (prim_*) expose the building blocks
// one by one so the RTL benches can check each hardware module against the model.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <stdexcept>
#include <string>

#include "common.hpp"
#include "tensor_servo/core_config.hpp"

namespace py = pybind11;
using namespace pybind11::literals;
using namespace ts;
using namespace tsbind;

void bind_servo(py::module_& m);  // servo_bind.cpp
void bind_pinv(py::module_& m);   // pinv_bind.cpp

namespace {

// ---- the chain model -------------------------------------------------------------------------
struct ModelBase {
  virtual ~ModelBase() = default;
  virtual int n() const = 0;
  virtual py::dict quantize_q(const f64arr& q) const = 0;
  virtual py::dict fk(const py::array& q, bool raw) const = 0;
  virtual py::dict jacobian(const py::array& q, bool raw, int ref, int basis) const = 0;
  virtual py::dict constants() const = 0;
};

template <class Fmt>
struct Model final : ModelBase {
  using angle_t = typename Fmt::angle_t;
  ChainQ<Fmt, NMAX> ch;

  // checked: the core's configuration rule (configure_chain). Unchecked: only the quantisation
  // (every constant in its format), so that benches can drive chains whose kinematics saturate.
  Model(const ChainSpec& spec, bool checked) {
    const ConfigResult r = checked ? configure_chain<Fmt, NMAX>(spec, ch) : quantize<Fmt, NMAX>(spec, ch);
    if (!r.ok()) throw std::invalid_argument(r.field + ": " + r.message);
  }
  int n() const override { return ch.n; }

  // Joint values of sample s, from float (quantised, saturation flagged) or raw integers.
  void load_q(const py::array& qa, bool raw, py::ssize_t s, angle_t* q, Status& st) const {
    for (int i = 0; i < ch.n; ++i) {
      if (raw) {
        if constexpr (Fmt::is_float) throw std::invalid_argument("raw input needs a fixed-point configuration");
        else {
          const int64_t r = static_cast<const int64_t*>(qa.data())[s * ch.n + i];
          if (r > angle_t::RAW_MAX || r < angle_t::RAW_MIN) throw std::invalid_argument("q_raw: outside the angle format");
          q[i] = angle_t::from_raw(r);
        }
      } else {
        q[i] = from_double<angle_t>(static_cast<const double*>(qa.data())[s * ch.n + i], st);
      }
    }
  }
  py::array prepare(const py::array& q, bool raw) const {
    py::array a = raw ? py::array(i64arr::ensure(q)) : py::array(f64arr::ensure(q));
    if (!a) throw std::invalid_argument("q: not a numeric array");
    need_shape(a, {-1, ch.n}, "q");
    return a;
  }

  py::dict quantize_q(const f64arr& qa) const override {
    need_shape(qa, {-1, ch.n}, "q");
    const py::ssize_t N = qa.shape(0);
    i64arr raw(shp(N, ch.n));
    py::array_t<bool> ok(N);
    auto r = raw.mutable_unchecked<2>();
    auto o = ok.mutable_unchecked<1>();
    for (py::ssize_t s = 0; s < N; ++s) {
      Status st;
      for (int i = 0; i < ch.n; ++i) r(s, i) = raw_of(from_double<angle_t>(qa.at(s, i), st));
      o(s) = !st.overflow();
    }
    return py::dict("q_raw"_a = raw, "ok"_a = ok);
  }

  py::dict fk(const py::array& q_in, bool raw) const override {
    const py::array q = prepare(q_in, raw);
    const py::ssize_t N = q.shape(0);
    const int nf = ch.n + 1 + ch.ntips;
    f64arr quat(shp(N, nf, 4)), pos(shp(N, nf, 3)), axis(shp(N, ch.n, 3));
    i64arr quat_r(shp(N, nf, 4)), pos_r(shp(N, nf, 3)), axis_r(shp(N, ch.n, 3));
    u32arr flags(N);
    auto Qf = quat.mutable_unchecked<3>(); auto Pf = pos.mutable_unchecked<3>(); auto Zf = axis.mutable_unchecked<3>();
    auto Qr = quat_r.mutable_unchecked<3>(); auto Pr = pos_r.mutable_unchecked<3>(); auto Zr = axis_r.mutable_unchecked<3>();
    auto Fl = flags.mutable_unchecked<1>();
    Frames<Fmt, NMAX> f;
    angle_t qq[NMAX];
    for (py::ssize_t s = 0; s < N; ++s) {
      Status st;
      load_q(q, raw, s, qq, st);
      forward_kinematics(ch, qq, f, st);
      for (int k = 0; k < nf; ++k) {
        for (int a = 0; a < 4; ++a) { Qf(s, k, a) = to_double(f.Q[k].c[a]); Qr(s, k, a) = raw_of(f.Q[k].c[a]); }
        for (int a = 0; a < 3; ++a) { Pf(s, k, a) = to_double(f.p[k].c[a]); Pr(s, k, a) = raw_of(f.p[k].c[a]); }
      }
      for (int i = 0; i < ch.n; ++i)
        for (int a = 0; a < 3; ++a) { Zf(s, i, a) = to_double(f.z[i + 1].c[a]); Zr(s, i, a) = raw_of(f.z[i + 1].c[a]); }
      Fl(s) = st.flags;
    }
    py::dict d("quat"_a = quat, "pos"_a = pos, "axis"_a = axis, "flags"_a = flags);
    if (!Fmt::is_float) { d["quat_raw"] = quat_r; d["pos_raw"] = pos_r; d["axis_raw"] = axis_r; }
    return d;
  }

  py::dict jacobian(const py::array& q_in, bool raw, int ref, int basis) const override {
    const py::array q = prepare(q_in, raw);
    const py::ssize_t N = q.shape(0);
    const int nf = ch.n + 1 + ch.ntips;
    if (ref < 0) ref = ch.n + 1;
    if (ref < 1 || ref > ch.n + ch.ntips) throw std::invalid_argument("ref: frame index outside 1..n+tips");
    if (basis < -1 || basis > ch.n + ch.ntips) throw std::invalid_argument("basis: frame index outside -1..n+tips");
    f64arr J(shp(N, 6, ch.n)), quat(shp(N, nf, 4)), pos(shp(N, nf, 3));
    i64arr J_r(shp(N, 6, ch.n)), quat_r(shp(N, nf, 4)), pos_r(shp(N, nf, 3));
    u32arr flags(N);
    auto Jf = J.mutable_unchecked<3>(); auto Jr = J_r.mutable_unchecked<3>();
    auto Qf = quat.mutable_unchecked<3>(); auto Pf = pos.mutable_unchecked<3>();
    auto Qr = quat_r.mutable_unchecked<3>(); auto Pr = pos_r.mutable_unchecked<3>();
    auto Fl = flags.mutable_unchecked<1>();
    Frames<Fmt, NMAX> f;
    Jacobian<Fmt, NMAX> jac;
    angle_t qq[NMAX];
    for (py::ssize_t s = 0; s < N; ++s) {
      Status st;
      load_q(q, raw, s, qq, st);
      forward_kinematics(ch, qq, f, st);
      ts::jacobian(ch, f, ref, basis, jac, st);
      for (int i = 0; i < ch.n; ++i)
        for (int a = 0; a < 3; ++a) {
          Jf(s, a, i) = to_double(jac.w[i].c[a]); Jr(s, a, i) = raw_of(jac.w[i].c[a]);
          Jf(s, a + 3, i) = to_double(jac.v[i].c[a]); Jr(s, a + 3, i) = raw_of(jac.v[i].c[a]);
        }
      for (int k = 0; k < nf; ++k) {
        for (int a = 0; a < 4; ++a) { Qf(s, k, a) = to_double(f.Q[k].c[a]); Qr(s, k, a) = raw_of(f.Q[k].c[a]); }
        for (int a = 0; a < 3; ++a) { Pf(s, k, a) = to_double(f.p[k].c[a]); Pr(s, k, a) = raw_of(f.p[k].c[a]); }
      }
      Fl(s) = st.flags;
    }
    py::dict d("J"_a = J, "quat"_a = quat, "pos"_a = pos, "flags"_a = flags);
    if (!Fmt::is_float) { d["J_raw"] = J_r; d["quat_raw"] = quat_r; d["pos_raw"] = pos_r; }
    return d;
  }

  py::dict constants() const override {
    const int n = ch.n;
    i64arr qo(shp(n, 4)), po(shp(n, 3)), ax(shp(n, 3)), s(shp(n)), k(shp(n)), qb(shp(4)), pb(shp(3)), qt(shp(4)), pt(shp(3));
    py::array_t<bool> pr(n);
    for (int i = 0; i < n; ++i) {
      const auto& j = ch.j[i];
      for (int a = 0; a < 4; ++a) qo.mutable_at(i, a) = raw_of(j.qo.c[a]);
      for (int a = 0; a < 3; ++a) { po.mutable_at(i, a) = raw_of(j.po.c[a]); ax.mutable_at(i, a) = raw_of(j.axis.c[a]); }
      s.mutable_at(i) = raw_of(j.s);
      k.mutable_at(i) = raw_of(j.k);
      pr.mutable_at(i) = j.prismatic;
    }
    for (int a = 0; a < 4; ++a) { qb.mutable_at(a) = raw_of(ch.qb.c[a]); qt.mutable_at(a) = raw_of(ch.qt[0].c[a]); }
    for (int a = 0; a < 3; ++a) { pb.mutable_at(a) = raw_of(ch.pb.c[a]); pt.mutable_at(a) = raw_of(ch.pt[0].c[a]); }
    py::array_t<int32_t> parent(n), tip_parent(ch.ntips);
    i64arr tq(shp(ch.ntips, 4)), tp(shp(ch.ntips, 3));
    for (int i = 0; i < n; ++i) parent.mutable_at(i) = ch.parent[i];
    for (int t = 0; t < ch.ntips; ++t) {
      tip_parent.mutable_at(t) = ch.tip_parent[t];
      for (int a = 0; a < 4; ++a) tq.mutable_at(t, a) = raw_of(ch.qt[t].c[a]);
      for (int a = 0; a < 3; ++a) tp.mutable_at(t, a) = raw_of(ch.pt[t].c[a]);
    }
    const bool serial = ch.ntips == 1 && tip_parent.at(0) == n && [&] { for (int i = 0; i < n; ++i) if (ch.parent[i] != i) return false; return true; }();
    if (!serial)
      return py::dict("origin_quat"_a = qo, "origin_xyz"_a = po, "axis"_a = ax, "scale"_a = s, "kturn"_a = k,
                      "prismatic"_a = pr, "base_quat"_a = qb, "base_xyz"_a = pb, "parent_frame"_a = parent,
                      "tip_parent_frame"_a = tip_parent, "tip_quat"_a = tq, "tip_xyz"_a = tp);
    return py::dict("origin_quat"_a = qo, "origin_xyz"_a = po, "axis"_a = ax, "scale"_a = s, "kturn"_a = k,
                    "prismatic"_a = pr, "base_quat"_a = qb, "base_xyz"_a = pb, "tool_quat"_a = qt, "tool_xyz"_a = pt);
  }
};

std::unique_ptr<ModelBase> make_model(const std::string& cfg, const py::dict& spec, bool checked) {
  const ChainSpec c = spec_from_dict(spec);
  if (cfg == "double") return std::make_unique<Model<FmtDouble>>(c, checked);
  if (cfg == "default") return std::make_unique<Model<FmtDefault>>(c, checked);
  if (cfg == "compact") return std::make_unique<Model<FmtCompact>>(c, checked);
  throw std::invalid_argument("config: unknown configuration '" + cfg + "' (double, default, compact)");
}

template <class F>
auto dispatch_fixed(const std::string& cfg, F&& f) {
  if (cfg == "default") return f(FmtDefault{});
  if (cfg == "compact") return f(FmtCompact{});
  throw std::invalid_argument("config: unknown fixed-point configuration '" + cfg + "' (default, compact)");
}

// ---- primitives (for the RTL benches) --------------------------------------------------------
template <class Fmt>
py::dict formats_of() {
  py::dict d;
#define TS_FMT(name) d[#name] = fmt_tuple<typename Fmt::name>();
  TS_FMT(angle_t) TS_FMT(kturn_t) TS_FMT(turn_t) TS_FMT(scale_t) TS_FMT(tab_t) TS_FMT(delta_t) TS_FMT(dsq_t)
  TS_FMT(trig_acc_t) TS_FMT(quat_t) TS_FMT(uvec_tmp_t) TS_FMT(len_t) TS_FMT(len_tmp_t) TS_FMT(pos_t)
  TS_FMT(lever_t) TS_FMT(jw_t) TS_FMT(jv_t) TS_FMT(jw_tmp_t) TS_FMT(jv_tmp_t) TS_FMT(twopi_t) TS_FMT(sixth_t)
  TS_FMT(lchar_t) TS_FMT(tw_t) TS_FMT(jsc_t) TS_FMT(qd_t) TS_FMT(gk_t) TS_FMT(mant_t) TS_FMT(recip_t) TS_FMT(mu_t)
  TS_FMT(step_t) TS_FMT(bfm_t) TS_FMT(cgy_t) TS_FMT(cge_t) TS_FMT(cgx_t) TS_FMT(cgr_t) TS_FMT(klim_t) TS_FMT(gain_t) TS_FMT(dt_t) TS_FMT(vel_t) TS_FMT(perr_t) TS_FMT(rot_t) TS_FMT(rvf_t)
  TS_FMT(tacc_t) TS_FMT(qdiff_t) TS_FMT(inv4pi_t) TS_FMT(weight_t)
#undef TS_FMT
  d["TRIG_TABLE_BITS"] = Fmt::TRIG_TABLE_BITS;
  d["RECIP_TABLE_BITS"] = Fmt::RECIP_TABLE_BITS;
  d["ROTVEC_TABLE_BITS"] = Fmt::ROTVEC_TABLE_BITS;
  return d;
}

template <class T> T in(const i64arr& a, py::ssize_t s, int k, int stride) {
  return T::from_raw(a.data()[s * stride + k]);
}

template <class Fmt>
py::tuple prim_qmul(const i64arr& a, const i64arr& b) {
  using Q = typename Fmt::quat_t;
  need_shape(a, {-1, 4}, "a"); need_shape(b, {a.shape(0), 4}, "b");
  const py::ssize_t N = a.shape(0);
  i64arr out(shp(N, 4)); u32arr fl(N);
  for (py::ssize_t s = 0; s < N; ++s) {
    Status st; Quat<Q> x, y;
    for (int k = 0; k < 4; ++k) { x.c[k] = in<Q>(a, s, k, 4); y.c[k] = in<Q>(b, s, k, 4); }
    const Quat<Q> r = qmul<Q>(x, y, st);
    for (int k = 0; k < 4; ++k) out.mutable_at(s, k) = r.c[k].raw;
    fl.mutable_at(s) = st.flags;
  }
  return py::make_tuple(out, fl);
}

template <class Out, class Tmp, class V, class Fmt>
py::tuple rotate_impl(const i64arr& q, const i64arr& v, bool inverse) {
  using Q = typename Fmt::quat_t;
  need_shape(q, {-1, 4}, "q"); need_shape(v, {q.shape(0), 3}, "v");
  const py::ssize_t N = q.shape(0);
  i64arr out(shp(N, 3)); u32arr fl(N);
  for (py::ssize_t s = 0; s < N; ++s) {
    Status st; Quat<Q> x; Vec3<V> y;
    for (int k = 0; k < 4; ++k) x.c[k] = in<Q>(q, s, k, 4);
    for (int k = 0; k < 3; ++k) y.c[k] = in<V>(v, s, k, 3);
    const Vec3<Out> r = inverse ? rotate<Out, Tmp, true>(x, y, st) : rotate<Out, Tmp, false>(x, y, st);
    for (int k = 0; k < 3; ++k) out.mutable_at(s, k) = r.c[k].raw;
    fl.mutable_at(s) = st.flags;
  }
  return py::make_tuple(out, fl);
}

template <class Fmt>
py::tuple prim_rotate(const std::string& kind, bool inverse, const i64arr& q, const i64arr& v) {
  if (kind == "axis") return rotate_impl<typename Fmt::quat_t, typename Fmt::uvec_tmp_t, typename Fmt::quat_t, Fmt>(q, v, inverse);
  if (kind == "offset") return rotate_impl<typename Fmt::pos_t, typename Fmt::len_tmp_t, typename Fmt::len_t, Fmt>(q, v, inverse);
  if (kind == "jw") return rotate_impl<typename Fmt::jw_t, typename Fmt::jw_tmp_t, typename Fmt::jw_t, Fmt>(q, v, inverse);
  if (kind == "jv") return rotate_impl<typename Fmt::jv_t, typename Fmt::jv_tmp_t, typename Fmt::jv_t, Fmt>(q, v, inverse);
  throw std::invalid_argument("kind: one of axis, offset, jw, jv");
}

template <class Fmt>
py::tuple prim_sincos(const i64arr& u) {
  using T = typename Fmt::turn_t;
  need_shape(u, {-1}, "u");
  const py::ssize_t N = u.shape(0);
  i64arr out(shp(N, 2)); u32arr fl(N);
  for (py::ssize_t s = 0; s < N; ++s) {
    Status st; typename Fmt::quat_t sn, cs;
    sincos_turns<Fmt>(wrap<T>(fx<62, 62 - T::F>::from_raw(u.at(s))), sn, cs, st);
    out.mutable_at(s, 0) = sn.raw; out.mutable_at(s, 1) = cs.raw; fl.mutable_at(s) = st.flags;
  }
  return py::make_tuple(out, fl);
}

template <class Fmt>
py::tuple prim_joint_quat(const i64arr& angle, const i64arr& kturn, const i64arr& axis) {
  need_shape(angle, {-1}, "angle"); need_shape(kturn, {angle.shape(0)}, "kturn"); need_shape(axis, {angle.shape(0), 3}, "axis");
  const py::ssize_t N = angle.shape(0);
  i64arr out(shp(N, 4)); u32arr fl(N);
  for (py::ssize_t s = 0; s < N; ++s) {
    Status st; JointQ<Fmt> j;
    j.k = Fmt::kturn_t::from_raw(kturn.at(s));
    for (int k = 0; k < 3; ++k) j.axis.c[k] = in<typename Fmt::quat_t>(axis, s, k, 3);
    const auto r = joint_quat<Fmt>(j, Fmt::angle_t::from_raw(angle.at(s)), st);
    for (int k = 0; k < 4; ++k) out.mutable_at(s, k) = r.c[k].raw;
    fl.mutable_at(s) = st.flags;
  }
  return py::make_tuple(out, fl);
}

template <class Fmt>
py::tuple prim_screw(const py::array_t<bool>& prismatic, const i64arr& s_raw, const i64arr& z, const i64arr& pref,
                     const i64arr& pi) {
  need_shape(prismatic, {-1}, "prismatic");
  const py::ssize_t N = prismatic.shape(0);
  need_shape(s_raw, {N}, "s"); need_shape(z, {N, 3}, "z"); need_shape(pref, {N, 3}, "p_ref"); need_shape(pi, {N, 3}, "p_i");
  i64arr w(shp(N, 3)), v(shp(N, 3)); u32arr fl(N);
  for (py::ssize_t s = 0; s < N; ++s) {
    Status st; Vec3<typename Fmt::quat_t> zz; Vec3<typename Fmt::pos_t> a, b;
    for (int k = 0; k < 3; ++k) {
      zz.c[k] = in<typename Fmt::quat_t>(z, s, k, 3);
      a.c[k] = in<typename Fmt::pos_t>(pref, s, k, 3);
      b.c[k] = in<typename Fmt::pos_t>(pi, s, k, 3);
    }
    Vec3<typename Fmt::jw_t> ow; Vec3<typename Fmt::jv_t> ov;
    screw_column<Fmt>(prismatic.at(s), Fmt::scale_t::from_raw(s_raw.at(s)), zz, a, b, ow, ov, st);
    for (int k = 0; k < 3; ++k) { w.mutable_at(s, k) = ow.c[k].raw; v.mutable_at(s, k) = ov.c[k].raw; }
    fl.mutable_at(s) = st.flags;
  }
  return py::make_tuple(w, v, fl);
}

// The solver's reciprocal table and the rotation vector's phi/sin(phi) table (f, df), raw.
template <class Fmt>
py::dict solver_tables() {
  constexpr int NR = 1 << Fmt::RECIP_TABLE_BITS, NV = 1 << Fmt::ROTVEC_TABLE_BITS;
  i64arr y(shp(NR)), f(shp(NV + 1)), df(shp(NV + 1));
  for (int j = 0; j < NR; ++j) y.mutable_at(j) = RecipTable<Fmt>::at(j).raw;
  for (int j = 0; j <= NV; ++j) { f.mutable_at(j) = RotvecTable<Fmt>::f_at(j).raw; df.mutable_at(j) = RotvecTable<Fmt>::df_at(j).raw; }
  Status st;
  const auto inv = Fmt::inv4pi_t::from_double(1.0 / (4.0 * kPi), st);
  return py::dict("recip"_a = y, "rotvec_f"_a = f, "rotvec_df"_a = df, "inv4pi"_a = inv.raw);
}

template <class Fmt>
py::tuple trig_table() {
  const auto& t = TrigTable<Fmt>::get();
  i64arr s(shp(t.N)), c(shp(t.N));
  for (int k = 0; k < t.N; ++k) { s.mutable_at(k) = t.s[k].raw; c.mutable_at(k) = t.c[k].raw; }
  return py::make_tuple(s, c);
}

}  // namespace

PYBIND11_MODULE(_model, m) {
  m.doc() = "tensor-servo bit-accurate model (C++), see tensor_servo.model for the Python API";
  m.attr("NMAX") = NMAX;
  m.attr("CONFIGS") = py::make_tuple("double", "default", "compact");
  bind_servo(m);
  bind_pinv(m);
  py::class_<ModelBase>(m, "Model")
      .def(py::init(&make_model), py::arg("config"), py::arg("spec"), py::arg("checked") = true)
      .def_property_readonly("n", &ModelBase::n)
      .def("quantize_q", &ModelBase::quantize_q, py::arg("q"))
      .def("fk", &ModelBase::fk, py::arg("q"), py::arg("raw") = false)
      .def("jacobian", &ModelBase::jacobian, py::arg("q"), py::arg("raw") = false, py::arg("ref") = -1,
           py::arg("basis") = -1)
      .def("constants", &ModelBase::constants);
  m.def("formats", [](const std::string& cfg) { return dispatch_fixed(cfg, [](auto f) { return formats_of<decltype(f)>(); }); });
  m.def("trig_table", [](const std::string& cfg) { return dispatch_fixed(cfg, [](auto f) { return trig_table<decltype(f)>(); }); });
  m.def("solver_tables", [](const std::string& cfg) { return dispatch_fixed(cfg, [](auto f) { return solver_tables<decltype(f)>(); }); });
  m.def("prim_qmul", [](const std::string& cfg, const i64arr& a, const i64arr& b) {
    return dispatch_fixed(cfg, [&](auto f) { return prim_qmul<decltype(f)>(a, b); });
  });
  m.def("prim_rotate", [](const std::string& cfg, const std::string& kind, bool inverse, const i64arr& q, const i64arr& v) {
    return dispatch_fixed(cfg, [&](auto f) { return prim_rotate<decltype(f)>(kind, inverse, q, v); });
  }, py::arg("config"), py::arg("kind"), py::arg("inverse"), py::arg("q"), py::arg("v"));
  m.def("prim_sincos", [](const std::string& cfg, const i64arr& u) {
    return dispatch_fixed(cfg, [&](auto f) { return prim_sincos<decltype(f)>(u); });
  });
  m.def("prim_joint_quat", [](const std::string& cfg, const i64arr& angle, const i64arr& kturn, const i64arr& axis) {
    return dispatch_fixed(cfg, [&](auto f) { return prim_joint_quat<decltype(f)>(angle, kturn, axis); });
  });
  m.def("prim_screw", [](const std::string& cfg, const py::array_t<bool>& pr, const i64arr& s, const i64arr& z,
                         const i64arr& pref, const i64arr& pi) {
    return dispatch_fixed(cfg, [&](auto f) { return prim_screw<decltype(f)>(pr, s, z, pref, pi); });
  });
}
