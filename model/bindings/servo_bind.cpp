// Python bindings of the servo tick (solver + servo law) and of the virtual-mode IK loop.
//
//   s = _model.Servo(config, chain_spec, params)
//   s.tick(q, U_quat (T,4), U_pos (T,3), U_w (T,3), U_v (T,3), qd_warm)   one tick, T tasks
//   s.tick_raw(q_raw, U_quat_raw, U_pos_raw, U_w_raw, U_v_raw, qd_warm_raw)
//   s.ik(q0 (N,n), T_quat (N,4), T_pos (N,3), max_ticks, tol_pos, tol_rot)
//
// params (dict): L, kp, ko, dt, klim (floats), sweeps (int), mu (list of n floats), vlimits (bool:
// apply the chain's velocity limits),
// mode ("A" | "B"), feedforward (bool), controlled (list of frame indices, one per task; -1 = tip t),
// weights (list, one per task),
// setpoint_frame (-1 = root, k = frame k of the chain), cg (int, optional: conjugate-direction steps
// after the sweeps, offline IK only; 0 = none, as the core).
#include "common.hpp"
#include "tensor_servo/core_config.hpp"

namespace py = pybind11;
using namespace pybind11::literals;
using namespace ts;
using namespace tsbind;

namespace {

struct ServoBase {
  virtual ~ServoBase() = default;
  virtual int n() const = 0;
  virtual py::dict tick(const py::array& q, const py::array& uq, const py::array& up, const py::array& uw,
                        const py::array& uv, const py::array& qd_warm, bool raw) const = 0;
  virtual py::dict ik(const f64arr& q0, const f64arr& tq, const f64arr& tp, int max_ticks, double tol_pos,
                      double tol_rot) const = 0;
  virtual py::dict params_raw() const = 0;
  virtual py::dict inputs_raw(const py::array& q, const py::array& uq, const py::array& up, const py::array& uw,
                              const py::array& uv, const py::array& qd_warm) const = 0;
  virtual py::dict config_raw() const = 0;
  virtual py::dict solve_raw(const i64arr& J, const i64arr& V, const i64arr& q, const i64arr& warm) const = 0;
};

template <class T> T param(const py::dict& d, const char* key, Status& st) {
  const double v = d[key].cast<double>();
  Status s;
  const T r = from_double<T>(v, s);
  if (s.overflow()) throw std::invalid_argument(std::string(key) + ": " + std::to_string(v) + " outside its format");
  st.flags |= s.flags;
  return r;
}

template <class Fmt>
struct Servo final : ServoBase {
  using angle_t = typename Fmt::angle_t;
  using quat_t = typename Fmt::quat_t;
  using pos_t = typename Fmt::pos_t;
  using vel_t = typename Fmt::vel_t;
  using qd_t = typename Fmt::qd_t;
  ChainQ<Fmt, NMAX> ch;
  ServoParams<Fmt, NMAX> P;  // TMAX = 4 tasks (trees of chains)

  Servo(const ChainQ<Fmt, NMAX>& c, const ServoParams<Fmt, NMAX>& p) : ch(c), P(p) {}
  Servo(const ChainSpec& spec, const py::dict& pd) {
    const ConfigResult r = configure_chain<Fmt, NMAX>(spec, ch);
    if (!r.ok()) throw std::invalid_argument(r.field + ": " + r.message);
    Status st;
    auto& S = P.solver;
    S.L = param<typename Fmt::lchar_t>(pd, "L", st);
    if (!(to_double(S.L) > 0)) throw std::invalid_argument("L: must be positive");
    S.klim = param<typename Fmt::klim_t>(pd, "klim", st);
    S.sweeps = pd["sweeps"].cast<int>();
    if (S.sweeps < 1 || S.sweeps > 1000) throw std::invalid_argument("sweeps: must be 1..1000");
    S.cg = pd.contains("cg") ? pd["cg"].cast<int>() : 0;
    if (S.cg < 0 || S.cg > CG_MAX) throw std::invalid_argument("cg: must be 0.." + std::to_string(CG_MAX));
    const auto mu = pd["mu"].cast<std::vector<double>>();
    if (static_cast<int>(mu.size()) != ch.n) throw std::invalid_argument("mu: one value per joint");
    const bool vlimits = pd["vlimits"].cast<bool>();
    for (int i = 0; i < ch.n; ++i) {
      const JointSpec& j = spec.joints[i];
      Status s;
      S.mu[i] = from_double<typename Fmt::mu_t>(mu[i], s);
      if (s.overflow() || mu[i] < 0) throw std::invalid_argument("mu: must lie in [0, 2)");
      S.limited[i] = j.limited;
      // limits rounded inward: a joint value within the quantised limits is within the true ones
      S.lo[i] = from_double_dir<angle_t>(j.limited ? j.lower : 0.0, true, st);
      S.hi[i] = from_double_dir<angle_t>(j.limited ? j.upper : 0.0, false, st);
      if (vlimits && j.velocity > 0) {
        S.vmax[i] = from_double<qd_t>(j.velocity, s);
        if (s.overflow()) throw std::invalid_argument("joints[" + std::to_string(i) + "].limits.velocity: outside the joint-rate format");
      } else {
        S.vmax[i] = max_of<qd_t>();
      }
    }
    P.kp = param<typename Fmt::gain_t>(pd, "kp", st);
    P.ko = param<typename Fmt::gain_t>(pd, "ko", st);
    P.dt = param<typename Fmt::dt_t>(pd, "dt", st);
    if (!(to_double(P.dt) > 0)) throw std::invalid_argument("dt: must be positive");
    const std::string mode = pd["mode"].cast<std::string>();
    if (mode != "A" && mode != "B") throw std::invalid_argument("mode: 'A' or 'B'");
    P.mode = mode == "A" ? ERR_A : ERR_B;
    P.feedforward = pd["feedforward"].cast<bool>();
    P.warm_leak = pd.contains("warm_leak") ? pd["warm_leak"].cast<int>() : 0;
    if (P.warm_leak < 0 || P.warm_leak > 20) throw std::invalid_argument("warm_leak: a shift 0..20");
    // Tasks: "controlled" is a list of frame indices (-1: tip t); "weights" one per task.
    const auto ctl = pd["controlled"].cast<std::vector<int>>();
    const auto wts = pd["weights"].cast<std::vector<double>>();
    P.ntasks = static_cast<int>(ctl.size());
    if (P.ntasks < 1 || P.ntasks > 4 || wts.size() != ctl.size())
      throw std::invalid_argument("controlled: 1..4 tasks, one weight each");
    const int nf = ch.n + ch.ntips;
    P.setpoint_frame = pd["setpoint_frame"].cast<int>();
    for (int t = 0; t < P.ntasks; ++t) {
      P.controlled[t] = ctl[t];
      if (ctl[t] < -1 || ctl[t] == 0 || ctl[t] > nf) throw std::invalid_argument("controlled: frame 1..n+tips or -1 (tip)");
      if (ctl[t] < 0 && t >= ch.ntips) throw std::invalid_argument("controlled: task " + std::to_string(t) + " has no tip");
      Status s;
      P.weight[t] = from_double<typename Fmt::weight_t>(wts[t], s);
      if (s.overflow() || wts[t] < 0) throw std::invalid_argument("weights: must lie in [0, 4)");
      // the setpoint frame must be an ancestor of every controlled frame
      const int c = ctl[t] < 0 ? ch.n + 1 + t : ctl[t];
      if (P.setpoint_frame >= 0) {
        int f = c;
        while (f > P.setpoint_frame) f = ch.parent_frame(f);
        if (f != P.setpoint_frame) throw std::invalid_argument("setpoint_frame: must be a frame the controlled frame hangs from");
      }
    }
    if (P.setpoint_frame < -1 || P.setpoint_frame > ch.n) throw std::invalid_argument("setpoint_frame: -1 or a frame 0..n");
  }
  int n() const override { return ch.n; }

  template <class T, int N>
  static void load(const py::array& a, bool raw, T* out, const char* name, py::ssize_t row = -1) {
    const py::ssize_t off = row < 0 ? 0 : row * N;
    if (raw) {
      if constexpr (Fmt::is_float) throw std::invalid_argument("raw input needs a fixed-point configuration");
      else for (int k = 0; k < N; ++k) out[k] = T::from_raw(static_cast<const int64_t*>(a.data())[off + k]);
    } else {
      Status s;
      for (int k = 0; k < N; ++k) out[k] = from_double<T>(static_cast<const double*>(a.data())[off + k], s);
      if (s.overflow()) throw std::invalid_argument(std::string(name) + ": value outside its format");
    }
    (void)name;
  }
  py::array as(const py::array& a, bool raw) const {
    return raw ? py::array(i64arr::ensure(a)) : py::array(f64arr::ensure(a));
  }

  // U arrays: (T,4), (T,3), (T,3), (T,3) for T = ntasks setpoints.
  // A tick's inputs in the model's formats (float inputs quantised as the tick does; the status
  // collects the quantisation flags, which the tick reports with its own).
  void load_inputs(const py::array& q_in, const py::array& uq_in, const py::array& up_in, const py::array& uw_in,
                   const py::array& uv_in, const py::array& w_in, bool raw, angle_t* qq, Setpoint<Fmt>* U,
                   qd_t* warm, Status& st) const {
    const int n = ch.n, T = P.ntasks;
    const py::array q = as(q_in, raw), uq = as(uq_in, raw), up = as(up_in, raw), uw = as(uw_in, raw),
                    uv = as(uv_in, raw), w = as(w_in, raw);
    need_shape(q, {n}, "q"); need_shape(uq, {T, 4}, "U_quat"); need_shape(up, {T, 3}, "U_pos");
    need_shape(uw, {T, 3}, "U_w"); need_shape(uv, {T, 3}, "U_v"); need_shape(w, {n}, "qd_warm");
    for (int i = 0; i < n; ++i)
      qq[i] = raw ? of_raw<angle_t>(static_cast<const int64_t*>(q.data())[i])
                  : from_double<angle_t>(static_cast<const double*>(q.data())[i], st);
    for (int t = 0; t < T; ++t) {
      load<quat_t, 4>(uq, raw, U[t].Q.c, "U_quat", t);
      load<pos_t, 3>(up, raw, U[t].p.c, "U_pos", t);
      load<vel_t, 3>(uw, raw, U[t].w.c, "U_w", t);
      load<vel_t, 3>(uv, raw, U[t].v.c, "U_v", t);
    }
    for (int i = 0; i < n; ++i)
      warm[i] = raw ? of_raw<qd_t>(static_cast<const int64_t*>(w.data())[i])
                    : from_double<qd_t>(static_cast<const double*>(w.data())[i], st);
  }

  py::dict tick(const py::array& q_in, const py::array& uq_in, const py::array& up_in, const py::array& uw_in,
                const py::array& uv_in, const py::array& w_in, bool raw) const override {
    const int n = ch.n, T = P.ntasks;
    angle_t qq[NMAX]; qd_t warm[NMAX];
    Setpoint<Fmt> U[4];
    Status st;
    load_inputs(q_in, uq_in, up_in, uw_in, uv_in, w_in, raw, qq, U, warm, st);
    auto R = std::make_unique<TickResult<Fmt, NMAX>>();
    servo_tick(ch, P, qq, U, warm, *R, st);
    f64arr qd(shp(n)), qn(shp(n)), ep(shp(T, 3)), eo(shp(T, 3)), r(shp(6 * T));
    i64arr qd_r(shp(n)), qn_r(shp(n)), ep_r(shp(T, 3)), eo_r(shp(T, 3)), r_r(shp(6 * T));
    for (int i = 0; i < n; ++i) {
      qd.mutable_at(i) = to_double(R->qd[i]); qd_r.mutable_at(i) = raw_of(R->qd[i]);
      qn.mutable_at(i) = to_double(R->q_next[i]); qn_r.mutable_at(i) = raw_of(R->q_next[i]);
    }
    for (int t = 0; t < T; ++t)
      for (int a = 0; a < 3; ++a) {
        ep.mutable_at(t, a) = to_double(R->ep[t].c[a]); ep_r.mutable_at(t, a) = raw_of(R->ep[t].c[a]);
        eo.mutable_at(t, a) = to_double(R->eo[t].c[a]); eo_r.mutable_at(t, a) = raw_of(R->eo[t].c[a]);
      }
    for (int a = 0; a < 6 * T; ++a) { r.mutable_at(a) = to_double(R->r[a]); r_r.mutable_at(a) = raw_of(R->r[a]); }
    py::dict d("qd"_a = qd, "q_next"_a = qn, "ep"_a = ep, "eo"_a = eo, "r"_a = r, "flags"_a = st.flags);
    if (!Fmt::is_float) {
      d["qd_raw"] = qd_r; d["q_next_raw"] = qn_r; d["ep_raw"] = ep_r; d["eo_raw"] = eo_r; d["r_raw"] = r_r;
      // intermediate results for the RTL engines: each task's Jacobian (rows omega; v, in the basis
      // its error uses), commanded twist, and the tool pose
      i64arr J_r(shp(T, 6, n)), V_r(shp(T, 6)), tq(shp(4)), tp(shp(3));
      for (int t = 0; t < T; ++t) {
        for (int i = 0; i < n; ++i)
          for (int a = 0; a < 3; ++a) {
            J_r.mutable_at(t, a, i) = raw_of(R->J[t].w[i].c[a]);
            J_r.mutable_at(t, a + 3, i) = raw_of(R->J[t].v[i].c[a]);
          }
        for (int a = 0; a < 3; ++a) { V_r.mutable_at(t, a) = raw_of(R->V_w[t].c[a]); V_r.mutable_at(t, a + 3) = raw_of(R->V_v[t].c[a]); }
      }
      for (int a = 0; a < 4; ++a) tq.mutable_at(a) = raw_of(R->frames.Q[n + 1].c[a]);
      for (int a = 0; a < 3; ++a) tp.mutable_at(a) = raw_of(R->frames.p[n + 1].c[a]);
      d["J_raw"] = J_r; d["V_raw"] = V_r; d["tool_quat_raw"] = tq; d["tool_pos_raw"] = tp;
    }
    return d;
  }

  // Virtual-mode IK: run ticks towards each target (U' = 0) from q0, each solved from a cold start,
  // until the model's own errors are within tolerance (checked before each move) or max_ticks.
  py::dict ik(const f64arr& q0, const f64arr& tq, const f64arr& tp, int max_ticks, double tol_pos,
              double tol_rot) const override {
    const int n = ch.n;
    if (P.ntasks != 1) throw std::invalid_argument("ik: one task (use tick() for several tips)");
    need_shape(q0, {-1, n}, "q0");
    const py::ssize_t N = q0.shape(0);
    need_shape(tq, {N, 4}, "T_quat"); need_shape(tp, {N, 3}, "T_pos");
    f64arr qo(shp(N, n)); py::array_t<int32_t> ticks(N); py::array_t<bool> conv(N); u32arr flags(N);
    auto R = std::make_unique<TickResult<Fmt, NMAX>>();
    for (py::ssize_t s = 0; s < N; ++s) {
      Status st;
      angle_t qq[NMAX]; qd_t warm[NMAX];
      for (int i = 0; i < n; ++i) { qq[i] = from_double<angle_t>(q0.at(s, i), st); warm[i] = qd_t{}; }
      Setpoint<Fmt> U;
      for (int a = 0; a < 4; ++a) U.Q.c[a] = from_double<quat_t>(tq.at(s, a), st);
      for (int a = 0; a < 3; ++a) { U.p.c[a] = from_double<pos_t>(tp.at(s, a), st); U.w.c[a] = vel_t{}; U.v.c[a] = vel_t{}; }
      int t = 0;
      bool ok = false;
      for (; t <= max_ticks; ++t) {
        servo_tick(ch, P, qq, &U, warm, *R, st);
        double ep = 0, eo = 0;
        for (int a = 0; a < 3; ++a) {
          ep = std::max(ep, std::fabs(to_double(R->ep[0].c[a])));
          eo = std::max(eo, std::fabs(to_double(R->eo[0].c[a])));
        }
        if (ep <= tol_pos && eo <= tol_rot) { ok = true; break; }
        if (t == max_ticks) break;
        // Cold start every tick (docs/ik.md: a warm start keeps null-space rates of redundant
        // chains alive and slows convergence in virtual IK).
        for (int i = 0; i < n; ++i) { qq[i] = R->q_next[i]; warm[i] = qd_t{}; }
      }
      for (int i = 0; i < n; ++i) qo.mutable_at(s, i) = to_double(qq[i]);
      ticks.mutable_at(s) = t;
      conv.mutable_at(s) = ok;
      flags.mutable_at(s) = st.flags;
    }
    return py::dict("q"_a = qo, "ticks"_a = ticks, "converged"_a = conv, "flags"_a = flags);
  }

  // The back half of a tick alone (one task): Jacobian J (6, n) raw (rows omega: jw_t, v: jv_t),
  // commanded twist V (6,) raw (vel_t), q (n,) raw, warm start (n,) raw -> q', q_next, r, flags.
  py::dict solve_raw(const i64arr& J, const i64arr& V, const i64arr& q, const i64arr& warm) const override {
    if constexpr (Fmt::is_float) { throw std::invalid_argument("solve_raw needs a fixed-point configuration"); }
    else {
      const int n = ch.n;
      if (P.ntasks != 1) throw std::invalid_argument("solve_raw: one task");
      need_shape(J, {6, n}, "J"); need_shape(V, {6}, "V"); need_shape(q, {n}, "q"); need_shape(warm, {n}, "warm");
      auto R = std::make_unique<TickResult<Fmt, NMAX>>();
      R->J[0].n = n;
      angle_t qq[NMAX]; qd_t w[NMAX];
      for (int i = 0; i < n; ++i) {
        for (int a = 0; a < 3; ++a) {
          R->J[0].w[i].c[a] = of_raw<typename Fmt::jw_t>(J.at(a, i));
          R->J[0].v[i].c[a] = of_raw<typename Fmt::jv_t>(J.at(a + 3, i));
        }
        qq[i] = of_raw<angle_t>(q.at(i));
        w[i] = of_raw<qd_t>(warm.at(i));
      }
      for (int a = 0; a < 3; ++a) { R->V_w[0].c[a] = of_raw<vel_t>(V.at(a)); R->V_v[0].c[a] = of_raw<vel_t>(V.at(a + 3)); }
      Status st;
      servo_back(P, n, qq, w, *R, st);
      i64arr qd(shp(n)), qn(shp(n)), r(shp(6));
      for (int i = 0; i < n; ++i) { qd.mutable_at(i) = raw_of(R->qd[i]); qn.mutable_at(i) = raw_of(R->q_next[i]); }
      for (int a = 0; a < 6; ++a) r.mutable_at(a) = raw_of(R->r[a]);
      return py::dict("qd_raw"_a = qd, "q_next_raw"_a = qn, "r_raw"_a = r, "flags"_a = st.flags);
    }
  }

  // The raw words tick() would use for float inputs: q, U (one task), warm start, and the flags the
  // quantisation raised (the servo core's input packet is these words).
  py::dict inputs_raw(const py::array& q, const py::array& uq, const py::array& up, const py::array& uw,
                      const py::array& uv, const py::array& w) const override {
    if constexpr (Fmt::is_float) { throw std::invalid_argument("inputs_raw needs a fixed-point configuration"); }
    else {
      const int n = ch.n, T = P.ntasks;
      angle_t qq[NMAX]; qd_t warm[NMAX];
      Setpoint<Fmt> U[4];
      Status st;
      load_inputs(q, uq, up, uw, uv, w, false, qq, U, warm, st);
      i64arr q_r(shp(n)), w_r(shp(n)), uq_r(shp(T, 4)), up_r(shp(T, 3)), uw_r(shp(T, 3)), uv_r(shp(T, 3));
      for (int i = 0; i < n; ++i) { q_r.mutable_at(i) = raw_of(qq[i]); w_r.mutable_at(i) = raw_of(warm[i]); }
      for (int t = 0; t < T; ++t) {
        for (int a = 0; a < 4; ++a) uq_r.mutable_at(t, a) = raw_of(U[t].Q.c[a]);
        for (int a = 0; a < 3; ++a) {
          up_r.mutable_at(t, a) = raw_of(U[t].p.c[a]);
          uw_r.mutable_at(t, a) = raw_of(U[t].w.c[a]);
          uv_r.mutable_at(t, a) = raw_of(U[t].v.c[a]);
        }
      }
      return py::dict("q"_a = q_r, "uq"_a = uq_r, "up"_a = up_r, "uw"_a = uw_r, "uv"_a = uv_r, "warm"_a = w_r,
                      "flags"_a = st.flags);
    }
  }

  // The servo core's register words (commit_raw's input, core_config.hpp RawConfig) of this
  // servo: the quantised chain constants and parameters, so that the core commits exactly the
  // state this servo ticks with.  Serial chain, one task (the tool), setpoint in the root frame,
  // as the core supports.
  py::dict config_raw() const override {
    if constexpr (Fmt::is_float) { throw std::invalid_argument("config_raw needs a fixed-point configuration"); }
    else {
      const int n = ch.n;
      for (int i = 0; i < n; ++i)
        if (ch.parent[i] != i) throw std::invalid_argument("chain: a tree of chains (the core takes serial chains)");
      if (ch.ntips != 1 || P.ntasks != 1 || P.controlled[0] != -1)
        throw std::invalid_argument("controlled: the core controls the tool of a serial chain (one task)");
      if (P.setpoint_frame != -1) throw std::invalid_argument("setpoint_frame: the core takes setpoints in the root frame");
      auto v = [](const auto* c, int k) { std::vector<int64_t> o; for (int a = 0; a < k; ++a) o.push_back(raw_of(c[a])); return o; };
      py::list joints;
      for (int i = 0; i < n; ++i) {
        const JointQ<Fmt>& j = ch.j[i];
        const bool vlim = !(P.solver.vmax[i] == max_of<qd_t>());
        const uint32_t jcfg = (j.prismatic ? JCFG_PRISMATIC : 0u) | (P.solver.limited[i] ? JCFG_LIMITED : 0u) |
                              (vlim ? JCFG_VLIMITED : 0u);
        joints.append(py::dict("jcfg"_a = jcfg, "qo"_a = v(j.qo.c, 4), "po"_a = v(j.po.c, 3), "axis"_a = v(j.axis.c, 3),
                               "scale"_a = raw_of(j.s), "lower"_a = raw_of(P.solver.lo[i]), "upper"_a = raw_of(P.solver.hi[i]),
                               "vmax"_a = vlim ? raw_of(P.solver.vmax[i]) : 0, "mu"_a = raw_of(P.solver.mu[i])));
      }
      const uint32_t mode = (P.mode == ERR_B ? MODE_ERR_B : 0u) | (P.feedforward ? 0u : MODE_ERROR_ONLY);
      return py::dict("n"_a = n, "mode"_a = mode, "sweeps"_a = P.solver.sweeps, "warm_leak"_a = P.warm_leak,
                      "kp"_a = raw_of(P.kp), "ko"_a = raw_of(P.ko), "lchar"_a = raw_of(P.solver.L),
                      "klim"_a = raw_of(P.solver.klim), "dt"_a = raw_of(P.dt), "base_q"_a = v(ch.qb.c, 4),
                      "base_p"_a = v(ch.pb.c, 3), "tool_q"_a = v(ch.qt[0].c, 4), "tool_p"_a = v(ch.pt[0].c, 3),
                      "joints"_a = joints);
    }
  }

  py::dict params_raw() const override {
    const int n = ch.n;
    i64arr mu(shp(n)), lo(shp(n)), hi(shp(n)), vmax(shp(n));
    py::array_t<bool> lim(n);
    for (int i = 0; i < n; ++i) {
      mu.mutable_at(i) = raw_of(P.solver.mu[i]); lo.mutable_at(i) = raw_of(P.solver.lo[i]);
      hi.mutable_at(i) = raw_of(P.solver.hi[i]); vmax.mutable_at(i) = raw_of(P.solver.vmax[i]);
      lim.mutable_at(i) = P.solver.limited[i];
    }
    return py::dict("L"_a = raw_of(P.solver.L), "klim"_a = raw_of(P.solver.klim), "sweeps"_a = P.solver.sweeps,
                    "mu"_a = mu, "lo"_a = lo, "hi"_a = hi, "vmax"_a = vmax, "limited"_a = lim,
                    "kp"_a = raw_of(P.kp), "ko"_a = raw_of(P.ko), "dt"_a = raw_of(P.dt), "mode"_a = P.mode,
                    "feedforward"_a = P.feedforward, "ntasks"_a = P.ntasks, "warm_leak"_a = P.warm_leak,
                    "setpoint_frame"_a = P.setpoint_frame);
  }
};

std::unique_ptr<ServoBase> make_servo(const std::string& cfg, const py::dict& spec, const py::dict& params) {
  const ChainSpec c = spec_from_dict(spec);
  if (cfg == "double") return std::make_unique<Servo<FmtDouble>>(c, params);
  if (cfg == "default") return std::make_unique<Servo<FmtDefault>>(c, params);
  if (cfg == "compact") return std::make_unique<Servo<FmtCompact>>(c, params);
  throw std::invalid_argument("config: unknown configuration '" + cfg + "' (double, default, compact)");
}

// The core's commit step on raw register words (core_config.hpp commit_config).  raw: dict with
// n, mode, sweeps, warm_leak, kp, ko, lchar, klim, dt, base_q (4), base_p (3), tool_q, tool_p,
// joints: list of dicts {jcfg, qo (4), po (3), axis (3), scale, lower, upper, vmax, mu}.
RawConfig raw_from_dict(const py::dict& d) {
  RawConfig rc;
  rc.n = d["n"].cast<int>();
  rc.mode = d["mode"].cast<uint32_t>();
  rc.sweeps = d["sweeps"].cast<int>();
  rc.warm_leak = d["warm_leak"].cast<int>();
  rc.kp = d["kp"].cast<int64_t>(); rc.ko = d["ko"].cast<int64_t>(); rc.lchar = d["lchar"].cast<int64_t>();
  rc.klim = d["klim"].cast<int64_t>(); rc.dt = d["dt"].cast<int64_t>();
  auto arr = [](const py::handle& h, int64_t* out, size_t k) {
    auto v = h.cast<std::vector<int64_t>>();
    if (v.size() != k) throw std::invalid_argument("raw config: wrong vector length");
    for (size_t i = 0; i < k; ++i) out[i] = v[i];
  };
  arr(d["base_q"], rc.base_q, 4); arr(d["base_p"], rc.base_p, 3); arr(d["tool_q"], rc.tool_q, 4); arr(d["tool_p"], rc.tool_p, 3);
  for (const auto& jh : d["joints"].cast<py::list>()) {
    const py::dict jd = jh.cast<py::dict>();
    RawJoint j;
    j.jcfg = jd["jcfg"].cast<uint32_t>();
    arr(jd["qo"], j.qo, 4); arr(jd["po"], j.po, 3); arr(jd["axis"], j.axis, 3);
    j.scale = jd["scale"].cast<int64_t>(); j.lower = jd["lower"].cast<int64_t>(); j.upper = jd["upper"].cast<int64_t>();
    j.vmax = jd["vmax"].cast<int64_t>(); j.mu = jd["mu"].cast<int64_t>();
    rc.joints.push_back(j);
  }
  return rc;
}

template <class Fmt>
py::tuple commit_impl(const py::dict& raw, int core_nmax) {
  const RawConfig rc = raw_from_dict(raw);
  ChainQ<Fmt, NMAX, 1> ch1;
  ServoParams<Fmt, NMAX, 1> p1;
  // The core's NMAX bounds the joint count; the model arrays are NMAX = 64 wide.
  ConfigResult r;
  if (rc.n > core_nmax) { r.code = CFG_JOINT_COUNT; r.field = "NJOINTS"; r.message = "joint count above the core's NMAX"; }
  else r = commit_config<Fmt, NMAX>(rc, ch1, p1);
  py::dict res("code"_a = static_cast<int>(r.code), "joint"_a = r.joint, "field"_a = r.field, "message"_a = r.message);
  if (!r.ok()) return py::make_tuple(res, py::none());
  std::vector<int64_t> k;
  for (int i = 0; i < ch1.n; ++i) k.push_back(raw_of(ch1.j[i].k));
  res["kturn_raw"] = k;
  // A Servo (TMAX = 4 build) holding the committed state.
  ChainQ<Fmt, NMAX> ch;
  ServoParams<Fmt, NMAX> P;
  ch.n = ch1.n; ch.ntips = 1; ch.qb = ch1.qb; ch.pb = ch1.pb; ch.qt[0] = ch1.qt[0]; ch.pt[0] = ch1.pt[0]; ch.tip_parent[0] = ch1.tip_parent[0];
  for (int i = 0; i < ch1.n; ++i) { ch.j[i] = ch1.j[i]; ch.parent[i] = ch1.parent[i]; }
  P.solver = p1.solver; P.kp = p1.kp; P.ko = p1.ko; P.dt = p1.dt; P.mode = p1.mode; P.feedforward = p1.feedforward;
  P.ntasks = 1; P.controlled[0] = -1; P.setpoint_frame = -1; P.warm_leak = p1.warm_leak;
  return py::make_tuple(res, py::cast(static_cast<ServoBase*>(new Servo<Fmt>(ch, P)), py::return_value_policy::take_ownership));
}

}  // namespace

void bind_servo(py::module_& m) {
  py::class_<ServoBase>(m, "Servo")
      .def(py::init(&make_servo), py::arg("config"), py::arg("spec"), py::arg("params"))
      .def_property_readonly("n", &ServoBase::n)
      .def("tick", [](const ServoBase& s, const py::array& q, const py::array& uq, const py::array& up,
                      const py::array& uw, const py::array& uv, const py::array& w) { return s.tick(q, uq, up, uw, uv, w, false); })
      .def("tick_raw", [](const ServoBase& s, const py::array& q, const py::array& uq, const py::array& up,
                          const py::array& uw, const py::array& uv, const py::array& w) { return s.tick(q, uq, up, uw, uv, w, true); })
      .def("ik", &ServoBase::ik, py::arg("q0"), py::arg("T_quat"), py::arg("T_pos"), py::arg("max_ticks"),
           py::arg("tol_pos"), py::arg("tol_rot"))
      .def("params_raw", &ServoBase::params_raw)
      .def("inputs_raw", &ServoBase::inputs_raw, py::arg("q"), py::arg("U_quat"), py::arg("U_pos"), py::arg("U_w"),
           py::arg("U_v"), py::arg("qd_warm"))
      .def("config_raw", &ServoBase::config_raw)
      .def("solve_raw", &ServoBase::solve_raw, py::arg("J"), py::arg("V"), py::arg("q"), py::arg("warm"));
  m.def("commit_raw", [](const std::string& cfg, const py::dict& raw, int core_nmax) -> py::tuple {
    if (core_nmax < 1 || core_nmax > NMAX) throw std::invalid_argument("core_nmax: 1..64");
    if (cfg == "default") return commit_impl<FmtDefault>(raw, core_nmax);
    if (cfg == "compact") return commit_impl<FmtCompact>(raw, core_nmax);
    throw std::invalid_argument("config: default or compact");
  }, py::arg("config"), py::arg("raw"), py::arg("core_nmax") = 8,
     "The servo core's commit step on raw register words: (result dict, Servo or None).");
}
