// tensor-servo HLS: the three kernels, templated on a configuration struct (hls4ml style):
//
//   struct CONFIG_T { using fmt = HlsDefault; static const int nmax = 8; };
//
//   ts_kin<CONFIG_T>    forward kinematics of every frame + Jacobian (screw transport)
//   ts_solve<CONFIG_T>  the coordinate-descent solve of J q' = V with joint limits
//   ts_servo<CONFIG_T>  the full servo tick (FK, error, Jacobian, solve, virtual-mode step)
//
// Each kernel reads its configuration (raw words, ts_config.h) every call, reads one input packet
// from its input stream, calls the model's algorithm (kinematics.hpp, solver.hpp, servo.hpp)
// instantiated on ap_fixed, and writes one output packet.  One task (tip) per build: TMAX = 1.
// Synthesisable subset only: fixed-size arrays, loops bounded by NMAX, no recursion, no dynamic
// memory, constant tables (checked by scripts/hls_lint.py).
#pragma once
#include <hls_stream.h>

#include <cstdint>

#include "ts_config.h"
#include "ts_formats_hls.h"

namespace ts {
namespace hlsk {

// A configuration word as a value of format T: outside T's range the configuration is refused.
template <class T>
inline T cfg_word(int32_t w, bool& ok) {
  if (w < T::RAW_MIN || w > T::RAW_MAX) ok = false;
  return T::from_raw(w);
}
// A per-tick input word as a value of format T: saturated to T's range, raising T's flag.
template <class T>
inline T in_word(int32_t w, Status& st) {
  if (w > T::RAW_MAX) { st.raise(T::FLAG); return T::from_raw(T::RAW_MAX); }
  if (w < T::RAW_MIN) { st.raise(T::FLAG); return T::from_raw(T::RAW_MIN); }
  return T::from_raw(w);
}
// An output word: the raw value (every output format is at most 32 bits wide), 0 when not live.
template <class T>
inline int32_t out_word(const T& x, bool live) {
  static_assert(num_traits<T>::W <= 32, "output formats fit a 32-bit word");
  return live ? static_cast<int32_t>(raw_of(x)) : 0;
}

// chain_cfg -> ChainQ.  Refuses (returns false) a joint count outside 1..NMAX, a parent that is
// not an earlier frame, a tool parent outside 1..n, a joint type other than 0/1 and raw values
// outside their formats.  Indices are kept in range even when refused.
template <class Fmt, int NMAX>
bool unpack_chain(const int32_t* cfg, ChainQ<Fmt, NMAX, 1>& ch) {
  using namespace hlsio;
  using quat_t = typename Fmt::quat_t;
  using len_t = typename Fmt::len_t;
  bool ok = true;
  const int n = cfg[CH_N];
  if (n < 1 || n > NMAX) ok = false;
  ch.n = ok ? n : 0;
  ch.ntips = 1;
  for (int a = 0; a < 4; ++a) {
    ch.qb.c[a] = cfg_word<quat_t>(cfg[CH_BASE_Q + a], ok);
    ch.qt[0].c[a] = cfg_word<quat_t>(cfg[CH_TOOL_Q + a], ok);
  }
  for (int a = 0; a < 3; ++a) {
    ch.pb.c[a] = cfg_word<len_t>(cfg[CH_BASE_P + a], ok);
    ch.pt[0].c[a] = cfg_word<len_t>(cfg[CH_TOOL_P + a], ok);
  }
  const int tp = cfg[CH_TOOL_PARENT];
  if (tp < 1 || tp > ch.n) ok = false;
  ch.tip_parent[0] = ok ? tp : 0;
  for (int j = 0; j < NMAX; ++j) {
    // 14 words per joint from the AXI4-Lite RAM, one read per cycle: II 14, latency ~14 NMAX + 3.
#pragma HLS PIPELINE II=14
    if (j >= ch.n) continue;
    const int b = CH_JOINT0 + CH_JSTRIDE * j;
    const int type = cfg[b + J_TYPE];
    const int parent = cfg[b + J_PARENT];
    if (type != 0 && type != 1) ok = false;
    if (parent < 0 || parent > j) ok = false;
    ch.parent[j] = (parent < 0 || parent > j) ? j : parent;
    JointQ<Fmt>& jq = ch.j[j];
    jq.prismatic = type == 1;
    for (int a = 0; a < 4; ++a) jq.qo.c[a] = cfg_word<quat_t>(cfg[b + J_QO + a], ok);
    for (int a = 0; a < 3; ++a) {
      jq.po.c[a] = cfg_word<len_t>(cfg[b + J_PO + a], ok);
      jq.axis.c[a] = cfg_word<quat_t>(cfg[b + J_AXIS + a], ok);
    }
    jq.s = cfg_word<typename Fmt::scale_t>(cfg[b + J_S], ok);
    jq.k = cfg_word<typename Fmt::kturn_t>(cfg[b + J_K], ok);
  }
  return ok;
}

// solver_cfg -> SolverParams for joints 0..n-1.  Refuses sweeps outside 1..SWEEPS_MAX, a limit
// flag other than 0/1 and raw values outside their formats.
template <class Fmt, int NMAX>
bool unpack_solver(const int32_t* cfg, int n, SolverParams<Fmt, NMAX>& P) {
  using namespace hlsio;
  bool ok = true;
  P.L = cfg_word<typename Fmt::lchar_t>(cfg[SV_L], ok);
  P.klim = cfg_word<typename Fmt::klim_t>(cfg[SV_KLIM], ok);
  const int sweeps = cfg[SV_SWEEPS];
  if (sweeps < 1 || sweeps > Fmt::SWEEPS_MAX) ok = false;
  P.sweeps = ok ? sweeps : 1;
  for (int j = 0; j < NMAX; ++j) {
#pragma HLS PIPELINE II=5  // 5 words per joint from the AXI4-Lite RAM: II 5, latency ~5 NMAX + 3
    if (j >= n) continue;
    const int b = SV_JOINT0 + SV_JSTRIDE * j;
    const int lim = cfg[b + SJ_LIMITED];
    if (lim != 0 && lim != 1) ok = false;
    P.limited[j] = lim == 1;
    P.mu[j] = cfg_word<typename Fmt::mu_t>(cfg[b + SJ_MU], ok);
    P.lo[j] = cfg_word<typename Fmt::angle_t>(cfg[b + SJ_LO], ok);
    P.hi[j] = cfg_word<typename Fmt::angle_t>(cfg[b + SJ_HI], ok);
    P.vmax[j] = cfg_word<typename Fmt::qd_t>(cfg[b + SJ_VMAX], ok);
  }
  return ok;
}

// servo_cfg -> the servo-law fields of ServoParams (one task).  Refuses a mode or feed-forward
// word other than 0/1, a setpoint frame outside -1..n, a controlled frame outside {-1, 1..n}.
template <class Fmt, int NMAX>
bool unpack_servo(const int32_t* cfg, int n, ServoParams<Fmt, NMAX, 1>& P) {
  using namespace hlsio;
  bool ok = true;
  P.kp = cfg_word<typename Fmt::gain_t>(cfg[SE_KP], ok);
  P.ko = cfg_word<typename Fmt::gain_t>(cfg[SE_KO], ok);
  P.dt = cfg_word<typename Fmt::dt_t>(cfg[SE_DT], ok);
  const int mode = cfg[SE_MODE], ff = cfg[SE_FEEDFORWARD];
  const int spf = cfg[SE_SETPOINT_FRAME], ctl = cfg[SE_CONTROLLED], leak = cfg[SE_WARM_LEAK];
  if (mode != ERR_A && mode != ERR_B) ok = false;
  if (leak < 0 || leak > 20) ok = false;
  P.warm_leak = ok ? leak : 0;
  if (ff != 0 && ff != 1) ok = false;
  if (spf < -1 || spf > n) ok = false;
  if (!(ctl == -1 || (ctl >= 1 && ctl <= n))) ok = false;
  P.mode = mode == ERR_B ? ERR_B : ERR_A;
  P.feedforward = ff == 1;
  P.setpoint_frame = ok ? spf : -1;
  P.ntasks = 1;
  P.controlled[0] = ok ? ctl : -1;
  return ok;
}

}  // namespace hlsk

// ---- kinematics: FK of every frame and the Jacobian at frame `ref` in the axes of `basis` -----
// ref: -1 the tool, else a frame 1..n+1; basis: -1 the root frame, else a frame 0..n+1 (n+1: tool).
template <class CONFIG_T>
void ts_kin(const int32_t* chain_cfg, int32_t ref, int32_t basis, hls::stream<int32_t>& q_in,
            hls::stream<int32_t>& kin_out) {
  using Fmt = typename CONFIG_T::fmt;
  constexpr int NMAX = CONFIG_T::nmax;
  using angle_t = typename Fmt::angle_t;
  ChainQ<Fmt, NMAX, 1> ch;
  bool ok = hlsk::unpack_chain(chain_cfg, ch);
  const int n = ch.n;
  const int rf = ref < 0 ? n + 1 : ref;
  if (rf < 1 || rf > n + 1 || basis < -1 || basis > n + 1) ok = false;
  Status st;
  angle_t q[NMAX];
#pragma HLS ARRAY_PARTITION variable=q type=complete
  for (int i = 0; i < NMAX; ++i) {
#pragma HLS PIPELINE II=1  // one stream word per cycle: latency NMAX + 1
    const int32_t w = q_in.read();
    if (ok && i < n) q[i] = hlsk::in_word<angle_t>(w, st);
  }
  // FK ~40 cycles per joint (serial), Jacobian ~20 + 4 NMAX cycles (kinematics.hpp).
  Frames<Fmt, NMAX, 1> f;
  Jacobian<Fmt, NMAX> J;
  if (ok) {
    forward_kinematics(ch, q, f, st);
    jacobian(ch, f, rf, basis, J, st);
  }
  for (int k = 0; k <= NMAX; ++k) {
#pragma HLS PIPELINE II=7  // 7 words per frame, one per cycle: latency ~7 (NMAX + 1)
    const bool live = ok && k <= n;
    for (int a = 0; a < 4; ++a) kin_out.write(hlsk::out_word(f.Q[k].c[a], live));
    for (int a = 0; a < 3; ++a) kin_out.write(hlsk::out_word(f.p[k].c[a], live));
  }
  for (int a = 0; a < 4; ++a) kin_out.write(hlsk::out_word(f.Q[n + 1].c[a], ok));
  for (int a = 0; a < 3; ++a) kin_out.write(hlsk::out_word(f.p[n + 1].c[a], ok));
  for (int i = 1; i <= NMAX; ++i) {
#pragma HLS PIPELINE II=3  // 3 words per axis, one per cycle
    for (int a = 0; a < 3; ++a) kin_out.write(hlsk::out_word(f.z[i].c[a], ok && i <= n));
  }
  for (int i = 0; i < NMAX; ++i) {
#pragma HLS PIPELINE II=6  // 6 words per column, one per cycle
    for (int a = 0; a < 3; ++a) kin_out.write(hlsk::out_word(J.w[i].c[a], ok && i < n));
    for (int a = 0; a < 3; ++a) kin_out.write(hlsk::out_word(J.v[i].c[a], ok && i < n));
  }
  kin_out.write(static_cast<int32_t>(st.flags | (ok ? 0u : hlsio::ST_HLS_CONFIG)));
}

// ---- solve: J q' = V (scaled by L), bounds from q, warm start from the packet -------------------
template <class CONFIG_T>
void ts_solve(const int32_t* solver_cfg, hls::stream<int32_t>& s_in, hls::stream<int32_t>& s_out) {
  using Fmt = typename CONFIG_T::fmt;
  constexpr int NMAX = CONFIG_T::nmax;
  using angle_t = typename Fmt::angle_t;
  using qd_t = typename Fmt::qd_t;
  using vel_t = typename Fmt::vel_t;
  using tw_t = typename Fmt::tw_t;
  const int ncfg = solver_cfg[hlsio::SV_N];
  bool ok = ncfg >= 1 && ncfg <= NMAX;
  const int n = ok ? ncfg : 0;
  SolverParams<Fmt, NMAX> P;
  if (!hlsk::unpack_solver(solver_cfg, n, P)) ok = false;
  Status st;
  angle_t q[NMAX];
  qd_t qd[NMAX];
  Jacobian<Fmt, NMAX> J;
  Vec3<vel_t> Vw, Vv;
#pragma HLS ARRAY_PARTITION variable=q type=complete
#pragma HLS ARRAY_PARTITION variable=qd type=complete
  J.n = n;
  for (int i = 0; i < NMAX; ++i) {
#pragma HLS PIPELINE II=1  // one stream word per cycle
    const int32_t w = s_in.read();
    if (ok && i < n) q[i] = hlsk::in_word<angle_t>(w, st);
  }
  for (int i = 0; i < NMAX; ++i) {
#pragma HLS PIPELINE II=6  // 6 words per column, one per cycle
    for (int a = 0; a < 6; ++a) {
      const int32_t w = s_in.read();
      if (ok && i < n) {
        if (a < 3) J.w[i].c[a] = hlsk::in_word<typename Fmt::jw_t>(w, st);
        else J.v[i].c[a - 3] = hlsk::in_word<typename Fmt::jv_t>(w, st);
      }
    }
  }
  for (int a = 0; a < 3; ++a) Vw.c[a] = hlsk::in_word<vel_t>(s_in.read(), st);
  for (int a = 0; a < 3; ++a) Vv.c[a] = hlsk::in_word<vel_t>(s_in.read(), st);
  for (int i = 0; i < NMAX; ++i) {
#pragma HLS PIPELINE II=1  // one stream word per cycle
    const int32_t w = s_in.read();
    if (ok && i < n) qd[i] = hlsk::in_word<qd_t>(w, st);
  }
  // Columns ~13 cycles, step factors ~25 + 2 NMAX, residual ~80, each sweep ~20 per joint
  // (solver.hpp): ~590 cycles for NMAX = 8 and 2 sweeps, ~1900 for 10 sweeps.
  SolverColumns<Fmt, NMAX> C;
  tw_t vs[6], r[6];
  if (ok) {
    solver_target(P, Vw, Vv, 0, nullptr, vs, st);
    solver_prepare(P, J, q, C, st);
    solver_run(P, C, n, vs, qd, r, st);
  }
  for (int i = 0; i < NMAX; ++i) {
#pragma HLS PIPELINE II=1  // one stream word per cycle
    s_out.write(hlsk::out_word(qd[i], ok && i < n));
  }
  for (int a = 0; a < 6; ++a) s_out.write(hlsk::out_word(r[a], ok));
  s_out.write(static_cast<int32_t>(st.flags | (ok ? 0u : hlsio::ST_HLS_CONFIG)));
}

// ---- servo: one tick; the warm start is the previous tick's q' (kernel state) ---------------
template <class CONFIG_T>
void ts_servo(const int32_t* chain_cfg, const int32_t* solver_cfg, const int32_t* servo_cfg,
              hls::stream<int32_t>& tick_in, hls::stream<int32_t>& tick_out) {
  using Fmt = typename CONFIG_T::fmt;
  constexpr int NMAX = CONFIG_T::nmax;
  using angle_t = typename Fmt::angle_t;
  using qd_t = typename Fmt::qd_t;
  using vel_t = typename Fmt::vel_t;
  // Warm start (raw q' of the previous tick): the kernel's only state, zero after power-up.
  static int32_t warm_raw[NMAX];
#pragma HLS ARRAY_PARTITION variable=warm_raw type=complete
  ChainQ<Fmt, NMAX, 1> ch;
  ServoParams<Fmt, NMAX, 1> P;
  bool ok = hlsk::unpack_chain(chain_cfg, ch);
  const int n = ch.n;
  if (!hlsk::unpack_solver(solver_cfg, n, P.solver)) ok = false;
  if (!hlsk::unpack_servo(servo_cfg, n, P)) ok = false;
  Status st;
  const int32_t ctrl = tick_in.read();
  angle_t q[NMAX];
  qd_t warm[NMAX];
#pragma HLS ARRAY_PARTITION variable=q type=complete
#pragma HLS ARRAY_PARTITION variable=warm type=complete
  for (int i = 0; i < NMAX; ++i) {
#pragma HLS PIPELINE II=1  // one stream word per cycle
    const int32_t w = tick_in.read();
    if (ok && i < n) q[i] = hlsk::in_word<angle_t>(w, st);
    warm[i] = qd_t::from_raw((ctrl & hlsio::CTRL_COLD) ? 0 : warm_raw[i]);
  }
  Setpoint<Fmt> U;
  for (int a = 0; a < 4; ++a) U.Q.c[a] = hlsk::in_word<typename Fmt::quat_t>(tick_in.read(), st);
  for (int a = 0; a < 3; ++a) U.p.c[a] = hlsk::in_word<typename Fmt::pos_t>(tick_in.read(), st);
  for (int a = 0; a < 3; ++a) U.w.c[a] = hlsk::in_word<vel_t>(tick_in.read(), st);
  for (int a = 0; a < 3; ++a) U.v.c[a] = hlsk::in_word<vel_t>(tick_in.read(), st);
  // FK ~330, Jacobian ~60, error ~30-50, solver ~190 + 160 per sweep (NMAX = 8): the whole tick
  // ~1150 cycles with 2 sweeps, ~2400 with 10 (docs/hls.md); one tick at a time (II = latency).
  TickResult<Fmt, NMAX, 1> R;
  if (ok) servo_tick(ch, P, q, &U, warm, R, st);
  for (int i = 0; i < NMAX; ++i) {
#pragma HLS PIPELINE II=1  // one stream word per cycle
    const int32_t w = hlsk::out_word(R.qd[i], ok && i < n);
    tick_out.write(w);
    warm_raw[i] = w;
  }
  for (int i = 0; i < NMAX; ++i) {
#pragma HLS PIPELINE II=1  // one stream word per cycle
    tick_out.write(hlsk::out_word(R.q_next[i], ok && i < n));
  }
  for (int a = 0; a < 3; ++a) tick_out.write(hlsk::out_word(R.ep[0].c[a], ok));
  for (int a = 0; a < 3; ++a) tick_out.write(hlsk::out_word(R.eo[0].c[a], ok));
  for (int a = 0; a < 6; ++a) tick_out.write(hlsk::out_word(R.r[a], ok));
  tick_out.write(static_cast<int32_t>(st.flags | (ok ? 0u : hlsio::ST_HLS_CONFIG)));
}

}  // namespace ts
