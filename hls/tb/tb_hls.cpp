// C-simulation testbench of the HLS top functions (plain g++ against Xilinx's ap_types headers).
//
// Every output word of every top function (ts_kin_top, ts_solve_top, ts_servo_top and their
// _compact twins) must equal the word the bit-accurate model (fx, model/include) gives for the same
// input:
//   1. tables     the generated ROMs (ts_tables_*.h) hold exactly the model's table entries
//   2. golden     tb/golden/kin_*.npz (the committed vectors), through ts_kin_top
//   3. bindings   servo tick sequences computed by the model through its Python bindings
//                 (make_vectors.py), through ts_servo_top with its warm-start state
//   4. random     N random ticks per configuration across the example chains, each through all three
//                 kernels: in-range ticks near the setpoint, joints at/over their limits, joints at
//                 a singular configuration (measured: cond(J) reported), and stress ticks (raw words
//                 across whole formats, random raw chain constants, large gains) that force
//                 saturations: the status words must match and the saturation bits must be seen
//   5. refusals   invalid configurations: status bit 31, all other words 0, warm start reset
//
// Usage: tb_hls VECTOR_DIR [--ticks N] [--chains a,b,...] [--seed S] [--config C] [--fault N]
// (--fault N corrupts one expected word of every N-th random tick: a self-test of the comparison)
// Exit status 0 only when every comparison matched and every coverage requirement was met.
#include <algorithm>
#include <array>
#include <cinttypes>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "ts_formats_hls.h"
#include "ts_servo_top.h"

using namespace ts;
using namespace ts::hlsio;

namespace {

constexpr int NM = TS_NMAX;
using Words = std::vector<int32_t>;
using KV = std::map<std::string, std::vector<int64_t>>;

// ---- bookkeeping -------------------------------------------------------------------------------
int64_t g_compared = 0, g_mismatch = 0;
int g_fail_reqs = 0;
int64_t g_fault_every = 0;  // --fault N: corrupt the model's word 0 on every N-th random tick (self-test)

void require(bool ok, const char* fmt, ...) __attribute__((format(printf, 2, 3)));
void require(bool ok, const char* fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  std::printf(ok ? "  ok    " : "  FAIL  ");
  std::vprintf(fmt, ap);
  std::printf("\n");
  va_end(ap);
  if (!ok) ++g_fail_reqs;
}

bool compare(const char* what, const std::string& ctx, const Words& expect, const Words& got) {
  ++g_compared;
  if (expect == got) return true;
  if (++g_mismatch <= 12) {
    std::printf("MISMATCH %s [%s]:", what, ctx.c_str());
    if (expect.size() != got.size()) std::printf(" sizes %zu vs %zu", expect.size(), got.size());
    for (size_t i = 0; i < std::min(expect.size(), got.size()); ++i)
      if (expect[i] != got[i]) std::printf(" word %zu: model %d hls %d;", i, expect[i], got[i]);
    std::printf("\n");
  }
  return false;
}

KV read_kv(const std::string& path) {
  std::ifstream f(path);
  if (!f) { std::fprintf(stderr, "tb_hls: cannot read %s\n", path.c_str()); std::exit(2); }
  KV kv;
  std::string line;
  while (std::getline(f, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream is(line);
    std::string key;
    size_t n;
    is >> key >> n;
    std::vector<int64_t> v(n);
    for (auto& x : v) is >> x;
    if (!is) { std::fprintf(stderr, "tb_hls: bad line in %s: %s\n", path.c_str(), key.c_str()); std::exit(2); }
    kv[key] = std::move(v);
  }
  return kv;
}
const std::vector<int64_t>& at(const KV& kv, const std::string& k) {
  auto it = kv.find(k);
  if (it == kv.end()) { std::fprintf(stderr, "tb_hls: missing key %s\n", k.c_str()); std::exit(2); }
  return it->second;
}

// ---- raw chain and parameters (the testbench's own description, independent of the kernels) ----
struct ChainRaw {
  int n = 0;
  int64_t qb[4], pb[3], qt[4], pt[3];
  int tool_parent = 0;
  std::vector<int> parent, prismatic;
  std::vector<std::array<int64_t, 4>> qo;
  std::vector<std::array<int64_t, 3>> po, axis;
  std::vector<int64_t> s, k;
  std::vector<std::vector<int>> singular;  // joint sets that make the chain singular at 0
};

ChainRaw chain_from(const KV& kv, const std::string& pre) {
  ChainRaw c;
  c.n = static_cast<int>(at(kv, "n")[0]);
  for (int a = 0; a < 4; ++a) { c.qb[a] = at(kv, pre + "base_quat")[a]; c.qt[a] = at(kv, pre + "tool_quat")[a]; }
  for (int a = 0; a < 3; ++a) { c.pb[a] = at(kv, pre + "base_xyz")[a]; c.pt[a] = at(kv, pre + "tool_xyz")[a]; }
  c.tool_parent = kv.count(pre + "tool_parent") ? static_cast<int>(at(kv, pre + "tool_parent")[0]) : c.n;
  for (int j = 0; j < c.n; ++j) {
    c.parent.push_back(kv.count(pre + "parent_frame") ? static_cast<int>(at(kv, pre + "parent_frame")[j]) : j);
    c.prismatic.push_back(static_cast<int>(at(kv, pre + "prismatic")[j]));
    std::array<int64_t, 4> q;
    std::array<int64_t, 3> p, x;
    for (int a = 0; a < 4; ++a) q[a] = at(kv, pre + "origin_quat")[4 * j + a];
    for (int a = 0; a < 3; ++a) { p[a] = at(kv, pre + "origin_xyz")[3 * j + a]; x[a] = at(kv, pre + "axis")[3 * j + a]; }
    c.qo.push_back(q); c.po.push_back(p); c.axis.push_back(x);
    c.s.push_back(at(kv, pre + "scale")[j]);
    c.k.push_back(at(kv, pre + "kturn")[j]);
  }
  if (kv.count("singular_count"))
    for (int i = 0; i < at(kv, "singular_count")[0]; ++i) {
      std::vector<int> js;
      for (auto v : at(kv, "singular_" + std::to_string(i))) js.push_back(static_cast<int>(v));
      c.singular.push_back(js);
    }
  return c;
}

struct ParamsRaw {
  int64_t L, klim, kp, ko, dt;
  int sweeps, mode, ff, spf, leak = 0, ctl = -1;
  std::vector<int64_t> mu, lo, hi, vmax;
  std::vector<int> limited;
};

ParamsRaw params_from(const KV& kv, const std::string& pre, int n) {
  ParamsRaw p;
  p.L = at(kv, pre + "L")[0]; p.klim = at(kv, pre + "klim")[0]; p.kp = at(kv, pre + "kp")[0];
  p.ko = at(kv, pre + "ko")[0]; p.dt = at(kv, pre + "dt")[0];
  p.sweeps = static_cast<int>(at(kv, pre + "sweeps")[0]); p.mode = static_cast<int>(at(kv, pre + "mode")[0]);
  p.ff = static_cast<int>(at(kv, pre + "feedforward")[0]);
  p.spf = static_cast<int>(at(kv, pre + "setpoint_frame")[0]);
  p.leak = static_cast<int>(at(kv, pre + "warm_leak")[0]);
  for (int j = 0; j < n; ++j) {
    p.mu.push_back(at(kv, pre + "mu")[j]); p.lo.push_back(at(kv, pre + "lo")[j]);
    p.hi.push_back(at(kv, pre + "hi")[j]); p.vmax.push_back(at(kv, pre + "vmax")[j]);
    p.limited.push_back(static_cast<int>(at(kv, pre + "limited")[j]));
  }
  return p;
}

Words chain_words_of(const ChainRaw& c) {
  Words w(chain_words(NM), 0);
  w[CH_N] = c.n;
  for (int a = 0; a < 4; ++a) { w[CH_BASE_Q + a] = int32_t(c.qb[a]); w[CH_TOOL_Q + a] = int32_t(c.qt[a]); }
  for (int a = 0; a < 3; ++a) { w[CH_BASE_P + a] = int32_t(c.pb[a]); w[CH_TOOL_P + a] = int32_t(c.pt[a]); }
  w[CH_TOOL_PARENT] = c.tool_parent;
  for (int j = 0; j < c.n && j < NM; ++j) {
    const int b = CH_JOINT0 + CH_JSTRIDE * j;
    w[b + J_TYPE] = c.prismatic[j];
    w[b + J_PARENT] = c.parent[j];
    for (int a = 0; a < 4; ++a) w[b + J_QO + a] = int32_t(c.qo[j][a]);
    for (int a = 0; a < 3; ++a) { w[b + J_PO + a] = int32_t(c.po[j][a]); w[b + J_AXIS + a] = int32_t(c.axis[j][a]); }
    w[b + J_S] = int32_t(c.s[j]);
    w[b + J_K] = int32_t(c.k[j]);
  }
  return w;
}
Words solver_words_of(const ParamsRaw& p, int n) {
  Words w(solver_words(NM), 0);
  w[SV_L] = int32_t(p.L); w[SV_KLIM] = int32_t(p.klim); w[SV_SWEEPS] = p.sweeps; w[SV_N] = n;
  for (int j = 0; j < n && j < NM; ++j) {
    const int b = SV_JOINT0 + SV_JSTRIDE * j;
    w[b + SJ_MU] = int32_t(p.mu[j]); w[b + SJ_LIMITED] = p.limited[j];
    w[b + SJ_LO] = int32_t(p.lo[j]); w[b + SJ_HI] = int32_t(p.hi[j]); w[b + SJ_VMAX] = int32_t(p.vmax[j]);
  }
  return w;
}
Words servo_words_of(const ParamsRaw& p) {
  Words w(SERVO_WORDS, 0);
  w[SE_KP] = int32_t(p.kp); w[SE_KO] = int32_t(p.ko); w[SE_DT] = int32_t(p.dt); w[SE_MODE] = p.mode;
  w[SE_FEEDFORWARD] = p.ff; w[SE_SETPOINT_FRAME] = p.spf; w[SE_CONTROLLED] = p.ctl; w[SE_WARM_LEAK] = p.leak;
  return w;
}

// ---- the model side ----------------------------------------------------------------------------
template <class M>
struct Model {
  using angle_t = typename M::angle_t;
  using quat_t = typename M::quat_t;
  using qd_t = typename M::qd_t;
  using vel_t = typename M::vel_t;

  // Input word -> format (the kernels' documented contract: saturate and raise the format's bit).
  template <class T>
  static T in(int64_t w, Status& st) {
    if (w > T::RAW_MAX) { st.raise(T::FLAG); return T::from_raw(T::RAW_MAX); }
    if (w < T::RAW_MIN) { st.raise(T::FLAG); return T::from_raw(T::RAW_MIN); }
    return T::from_raw(w);
  }
  template <class T> static int32_t w(const T& x) { return static_cast<int32_t>(x.raw); }

  static void chain(const ChainRaw& c, ChainQ<M, NM, 1>& ch) {
    ch.n = c.n;
    ch.ntips = 1;
    for (int a = 0; a < 4; ++a) { ch.qb.c[a] = quat_t::from_raw(c.qb[a]); ch.qt[0].c[a] = quat_t::from_raw(c.qt[a]); }
    for (int a = 0; a < 3; ++a) {
      ch.pb.c[a] = M::len_t::from_raw(c.pb[a]);
      ch.pt[0].c[a] = M::len_t::from_raw(c.pt[a]);
    }
    ch.tip_parent[0] = c.tool_parent;
    for (int j = 0; j < c.n; ++j) {
      ch.parent[j] = c.parent[j];
      auto& q = ch.j[j];
      q.prismatic = c.prismatic[j] != 0;
      for (int a = 0; a < 4; ++a) q.qo.c[a] = quat_t::from_raw(c.qo[j][a]);
      for (int a = 0; a < 3; ++a) { q.po.c[a] = M::len_t::from_raw(c.po[j][a]); q.axis.c[a] = quat_t::from_raw(c.axis[j][a]); }
      q.s = M::scale_t::from_raw(c.s[j]);
      q.k = M::kturn_t::from_raw(c.k[j]);
    }
  }
  static void params(const ParamsRaw& p, int n, ServoParams<M, NM, 1>& P) {
    auto& S = P.solver;
    S.L = M::lchar_t::from_raw(p.L); S.klim = M::klim_t::from_raw(p.klim); S.sweeps = p.sweeps;
    for (int j = 0; j < n; ++j) {
      S.mu[j] = M::mu_t::from_raw(p.mu[j]); S.limited[j] = p.limited[j] != 0;
      S.lo[j] = angle_t::from_raw(p.lo[j]); S.hi[j] = angle_t::from_raw(p.hi[j]); S.vmax[j] = qd_t::from_raw(p.vmax[j]);
    }
    P.kp = M::gain_t::from_raw(p.kp); P.ko = M::gain_t::from_raw(p.ko); P.dt = M::dt_t::from_raw(p.dt);
    P.mode = p.mode; P.feedforward = p.ff != 0; P.setpoint_frame = p.spf; P.ntasks = 1; P.controlled[0] = p.ctl;
    P.warm_leak = p.leak;
  }

  // Expected output packets, in the layout of ts_config.h.
  static Words kin(const ChainQ<M, NM, 1>& ch, const Words& qw, int ref, int basis, Frames<M, NM, 1>* fo = nullptr) {
    const int n = ch.n;
    Status st;
    angle_t q[NM];
    for (int i = 0; i < n; ++i) q[i] = in<angle_t>(qw[i], st);
    Frames<M, NM, 1> f;
    Jacobian<M, NM> J;
    forward_kinematics(ch, q, f, st);
    jacobian(ch, f, ref < 0 ? n + 1 : ref, basis, J, st);
    Words o;
    for (int k = 0; k <= NM; ++k) {
      for (int a = 0; a < 4; ++a) o.push_back(k <= n ? w(f.Q[k].c[a]) : 0);
      for (int a = 0; a < 3; ++a) o.push_back(k <= n ? w(f.p[k].c[a]) : 0);
    }
    for (int a = 0; a < 4; ++a) o.push_back(w(f.Q[n + 1].c[a]));
    for (int a = 0; a < 3; ++a) o.push_back(w(f.p[n + 1].c[a]));
    for (int i = 1; i <= NM; ++i)
      for (int a = 0; a < 3; ++a) o.push_back(i <= n ? w(f.z[i].c[a]) : 0);
    for (int i = 0; i < NM; ++i) {
      for (int a = 0; a < 3; ++a) o.push_back(i < n ? w(J.w[i].c[a]) : 0);
      for (int a = 0; a < 3; ++a) o.push_back(i < n ? w(J.v[i].c[a]) : 0);
    }
    o.push_back(static_cast<int32_t>(st.flags));
    if (fo) *fo = f;
    return o;
  }

  static Words solve(const ServoParams<M, NM, 1>& P, int n, const Words& in_words) {
    Status st;
    angle_t q[NM];
    qd_t qd[NM];
    Jacobian<M, NM> J;
    J.n = n;
    Vec3<vel_t> Vw, Vv;
    size_t k = 0;
    for (int i = 0; i < NM; ++i, ++k)
      if (i < n) q[i] = in<angle_t>(in_words[k], st);
    for (int i = 0; i < NM; ++i)
      for (int a = 0; a < 6; ++a, ++k)
        if (i < n) {
          if (a < 3) J.w[i].c[a] = in<typename M::jw_t>(in_words[k], st);
          else J.v[i].c[a - 3] = in<typename M::jv_t>(in_words[k], st);
        }
    for (int a = 0; a < 3; ++a) Vw.c[a] = in<vel_t>(in_words[k++], st);
    for (int a = 0; a < 3; ++a) Vv.c[a] = in<vel_t>(in_words[k++], st);
    for (int i = 0; i < NM; ++i, ++k)
      if (i < n) qd[i] = in<qd_t>(in_words[k], st);
    typename M::tw_t vs[6], r[6];
    SolverColumns<M, NM> C;
    solver_target(P.solver, Vw, Vv, 0, nullptr, vs, st);
    solver_prepare(P.solver, J, q, C, st);
    solver_run(P.solver, C, n, vs, qd, r, st);
    Words o;
    for (int i = 0; i < NM; ++i) o.push_back(i < n ? w(qd[i]) : 0);
    for (int a = 0; a < 6; ++a) o.push_back(w(r[a]));
    o.push_back(static_cast<int32_t>(st.flags));
    return o;
  }

  // One servo tick; warm: the model's warm start (raw), updated with q'.
  static Words servo(const ChainQ<M, NM, 1>& ch, const ServoParams<M, NM, 1>& P, const Words& in_words,
                     std::vector<int64_t>& warm, TickResult<M, NM, 1>& R) {
    const int n = ch.n;
    Status st;
    size_t k = 0;
    const int32_t ctrl = in_words[k++];
    if (ctrl & CTRL_COLD) std::fill(warm.begin(), warm.end(), 0);
    angle_t q[NM];
    qd_t wq[NM];
    for (int i = 0; i < NM; ++i, ++k)
      if (i < n) { q[i] = in<angle_t>(in_words[k], st); wq[i] = qd_t::from_raw(warm[i]); }
    Setpoint<M> U;
    for (int a = 0; a < 4; ++a) U.Q.c[a] = in<quat_t>(in_words[k++], st);
    for (int a = 0; a < 3; ++a) U.p.c[a] = in<typename M::pos_t>(in_words[k++], st);
    for (int a = 0; a < 3; ++a) U.w.c[a] = in<vel_t>(in_words[k++], st);
    for (int a = 0; a < 3; ++a) U.v.c[a] = in<vel_t>(in_words[k++], st);
    servo_tick(ch, P, q, &U, wq, R, st);
    Words o;
    for (int i = 0; i < NM; ++i) o.push_back(i < n ? w(R.qd[i]) : 0);
    for (int i = 0; i < NM; ++i) o.push_back(i < n ? w(R.q_next[i]) : 0);
    for (int a = 0; a < 3; ++a) o.push_back(w(R.ep[0].c[a]));
    for (int a = 0; a < 3; ++a) o.push_back(w(R.eo[0].c[a]));
    for (int a = 0; a < 6; ++a) o.push_back(w(R.r[a]));
    o.push_back(static_cast<int32_t>(st.flags));
    for (int i = 0; i < n; ++i) warm[i] = R.qd[i].raw;
    return o;
  }
};

// ---- the HLS side: the top functions through their streams --------------------------------------
template <class M> struct Tops;
template <> struct Tops<FmtDefault> {
  using H = HlsDefault;
  static void kin(const int32_t* c, int r, int b, hls::stream<int32_t>& i, hls::stream<int32_t>& o) { ts_kin_top(c, r, b, i, o); }
  static void solve(const int32_t* c, hls::stream<int32_t>& i, hls::stream<int32_t>& o) { ts_solve_top(c, i, o); }
  static void servo(const int32_t* a, const int32_t* b, const int32_t* c, hls::stream<int32_t>& i, hls::stream<int32_t>& o) {
    ts_servo_top(a, b, c, i, o);
  }
};
template <> struct Tops<FmtCompact> {
  using H = HlsCompact;
  static void kin(const int32_t* c, int r, int b, hls::stream<int32_t>& i, hls::stream<int32_t>& o) { ts_kin_top_compact(c, r, b, i, o); }
  static void solve(const int32_t* c, hls::stream<int32_t>& i, hls::stream<int32_t>& o) { ts_solve_top_compact(c, i, o); }
  static void servo(const int32_t* a, const int32_t* b, const int32_t* c, hls::stream<int32_t>& i, hls::stream<int32_t>& o) {
    ts_servo_top_compact(a, b, c, i, o);
  }
};

Words drain(hls::stream<int32_t>& s, size_t expect_words, const char* what) {
  Words o;
  while (!s.empty()) o.push_back(s.read());
  if (o.size() != expect_words) {
    std::printf("PACKET %s: %zu words, expected %zu\n", what, o.size(), expect_words);
    ++g_mismatch;
  }
  return o;
}

template <class M>
struct Hls {
  static Words kin(const Words& cfg, int ref, int basis, const Words& q) {
    hls::stream<int32_t> i, o;
    for (int k = 0; k < NM; ++k) i.write(k < int(q.size()) ? q[k] : 0);
    Tops<M>::kin(cfg.data(), ref, basis, i, o);
    if (!i.empty()) std::printf("ts_kin_top left input words unread\n");
    return drain(o, kin_out_words(NM), "kin");
  }
  static Words solve(const Words& cfg, const Words& in) {
    hls::stream<int32_t> i, o;
    for (int32_t v : in) i.write(v);
    Tops<M>::solve(cfg.data(), i, o);
    if (!i.empty()) std::printf("ts_solve_top left input words unread\n");
    return drain(o, solve_out_words(NM), "solve");
  }
  static Words servo(const Words& cc, const Words& sc, const Words& vc, const Words& in) {
    hls::stream<int32_t> i, o;
    for (int32_t v : in) i.write(v);
    Tops<M>::servo(cc.data(), sc.data(), vc.data(), i, o);
    if (!i.empty()) std::printf("ts_servo_top left input words unread\n");
    return drain(o, servo_out_words(NM), "servo");
  }
};

// ---- 1. tables ---------------------------------------------------------------------------------
template <class M>
void check_tables() {
  using H = typename Tops<M>::H;
  const auto& tt = TrigTable<M>::get();
  int bad = 0, total = 0;
  for (int k = 0; k < tt.N; ++k) {
    bad += raw_of(TrigTable<H>::sin_at(k)) != tt.s[k].raw;
    bad += raw_of(TrigTable<H>::cos_at(k)) != tt.c[k].raw;
    total += 2;
  }
  bad += raw_of(TrigTable<H>::two_pi()) != tt.twopi_value.raw;
  bad += raw_of(TrigTable<H>::sixth()) != tt.sixth_value.raw;
  total += 2 + (TrigTable<H>::N != tt.N);
  const auto& rt = RecipTable<M>::get();
  for (int j = 0; j < rt.N; ++j, ++total) bad += raw_of(RecipTable<H>::at(j)) != rt.y[j].raw;
  const auto& vt = RotvecTable<M>::get();
  for (int j = 0; j <= vt.N; ++j, total += 2) {
    bad += raw_of(RotvecTable<H>::f_at(j)) != vt.f[j].raw;
    bad += raw_of(RotvecTable<H>::df_at(j)) != vt.df[j].raw;
  }
  bad += (RecipTable<H>::N != rt.N) + (RotvecTable<H>::N != vt.N);
  require(bad == 0, "tables %s: %d ROM entries equal the model's (%d differ)", M::name, total, bad);
}

// ---- 2. golden vectors -------------------------------------------------------------------------
template <class M>
void check_golden(const std::string& dir, const std::string& name) {
  const KV kv = read_kv(dir + "/kin_" + name + "_" + M::name + ".txt");
  const ChainRaw c = chain_from(kv, "const_");
  const int n = c.n, N = static_cast<int>(at(kv, "samples")[0]);
  if (n > NM) { std::printf("  skip  golden %s %s: n = %d > NMAX = %d (covered by the NMAX >= %d build)\n", name.c_str(), M::name, n, NM, n); return; }
  const Words cfg = chain_words_of(c);
  int64_t bad = 0, words = 0;
  const auto &q = at(kv, "q_raw"), &Q = at(kv, "quat_raw"), &P = at(kv, "pos_raw"), &Z = at(kv, "axis_raw");
  const auto &J = at(kv, "J_raw"), &JT = at(kv, "J_tool_raw"), &FL = at(kv, "flags");
  for (int s = 0; s < N; ++s) {
    Words qw(q.begin() + s * n, q.begin() + (s + 1) * n);
    const Words ob = Hls<M>::kin(cfg, -1, -1, qw);      // Jacobian at the tool, root axes
    const Words ot = Hls<M>::kin(cfg, -1, n + 1, qw);   // ... tool axes
    // Expected words straight from the golden arrays (frames 0..n, tool = frame n+1).
    Words e_b(kin_out_words(NM), 0), e_t;
    for (int k = 0; k <= n; ++k) {
      for (int a = 0; a < 4; ++a) e_b[7 * k + a] = int32_t(Q[(s * (n + 2) + k) * 4 + a]);
      for (int a = 0; a < 3; ++a) e_b[7 * k + 4 + a] = int32_t(P[(s * (n + 2) + k) * 3 + a]);
    }
    const int tool = 7 * (NM + 1), axes = tool + 7, jac = axes + 3 * NM, st = jac + 6 * NM;
    for (int a = 0; a < 4; ++a) e_b[tool + a] = int32_t(Q[(s * (n + 2) + n + 1) * 4 + a]);
    for (int a = 0; a < 3; ++a) e_b[tool + 4 + a] = int32_t(P[(s * (n + 2) + n + 1) * 3 + a]);
    for (int i = 0; i < n; ++i)
      for (int a = 0; a < 3; ++a) e_b[axes + 3 * i + a] = int32_t(Z[(s * n + i) * 3 + a]);
    e_t = e_b;
    for (int i = 0; i < n; ++i)
      for (int r = 0; r < 6; ++r) {
        e_b[jac + 6 * i + r] = int32_t(J[(s * 6 + r) * n + i]);
        e_t[jac + 6 * i + r] = int32_t(JT[(s * 6 + r) * n + i]);
      }
    // The golden flags are the OR of FK and both Jacobians; each kernel call reports its own.
    e_b[st] = ob[st];
    e_t[st] = ot[st];
    const bool flags_ok = uint32_t(ob[st] | ot[st]) == uint32_t(FL[s]);
    bad += !compare("golden kin (root axes)", name + " sample " + std::to_string(s), e_b, ob);
    bad += !compare("golden kin (tool axes)", name + " sample " + std::to_string(s), e_t, ot);
    bad += !flags_ok;
    ++g_compared;
    if (!flags_ok) ++g_mismatch;
    words += 2 * int64_t(ob.size());
  }
  require(bad == 0, "golden %s %s: %d samples x 2 bases, %" PRId64 " words, tb/golden/kin_%s_%s.npz", name.c_str(),
          M::name, N, words, name.c_str(), M::name);
}

// ---- 3. servo sequences computed by the model through its Python bindings ----------------------
template <class M>
void check_bindings(const std::string& dir, const std::string& name) {
  const KV ckv = read_kv(dir + "/chain_" + name + "_" + M::name + ".txt");
  const ChainRaw c = chain_from(ckv, "");
  if (c.n > NM) { std::printf("  skip  bindings %s %s: n > NMAX\n", name.c_str(), M::name); return; }
  const KV kv = read_kv(dir + "/servo_" + name + "_" + M::name + ".txt");
  const int n = c.n, nv = static_cast<int>(at(kv, "variants")[0]);
  const Words cc = chain_words_of(c);
  int bad = 0, ticks = 0;
  for (int v = 0; v < nv; ++v) {
    const std::string pre = "v" + std::to_string(v) + "_";
    const ParamsRaw p = params_from(kv, pre, n);
    const Words sc = solver_words_of(p, n), vc = servo_words_of(p);
    const int T = static_cast<int>(at(kv, pre + "ticks")[0]);
    for (int t = 0; t < T; ++t, ++ticks) {
      Words in{int32_t(at(kv, pre + "cold")[t])};
      for (int i = 0; i < NM; ++i) in.push_back(i < n ? int32_t(at(kv, pre + "q")[t * n + i]) : 0);
      for (int a = 0; a < 4; ++a) in.push_back(int32_t(at(kv, pre + "uq")[4 * t + a]));
      for (const char* k : {"up", "uw", "uv"})
        for (int a = 0; a < 3; ++a) in.push_back(int32_t(at(kv, pre + k)[3 * t + a]));
      Words e;
      for (int i = 0; i < NM; ++i) e.push_back(i < n ? int32_t(at(kv, pre + "qd")[t * n + i]) : 0);
      for (int i = 0; i < NM; ++i) e.push_back(i < n ? int32_t(at(kv, pre + "q_next")[t * n + i]) : 0);
      for (const char* k : {"ep", "eo"})
        for (int a = 0; a < 3; ++a) e.push_back(int32_t(at(kv, pre + k)[3 * t + a]));
      for (int a = 0; a < 6; ++a) e.push_back(int32_t(at(kv, pre + "r")[6 * t + a]));
      e.push_back(int32_t(at(kv, pre + "flags")[t]));
      bad += !compare("bindings servo", name + " variant " + std::to_string(v) + " tick " + std::to_string(t), e,
                      Hls<M>::servo(cc, sc, vc, in));
    }
  }
  require(bad == 0, "bindings %s %s: %d servo ticks (%d set-ups) equal _model.Servo.tick_raw", name.c_str(),
          M::name, ticks, nv);
}

// ---- 4. random ticks ---------------------------------------------------------------------------
std::mt19937_64 rng;
double urand(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); }
int irand(int a, int b) { return std::uniform_int_distribution<int>(a, b)(rng); }
int64_t rraw(int W) {  // uniform raw value of a W-bit format
  return static_cast<int64_t>(rng() >> (64 - W)) - (int64_t(1) << (W - 1));
}
template <class T> int64_t raw_of_double(double d) {
  Status s;
  return T::from_double(d, s).raw;
}

// Smallest / largest singular value ratio of the scaled 6 x n Jacobian (Jacobi eigenvalues of J J^T).
double cond_of(const std::vector<double>& J, int n, double L) {
  double A[6][6] = {};
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 6; ++c)
      for (int i = 0; i < n; ++i)
        A[r][c] += J[r * n + i] * (r < 3 ? L : 1) * J[c * n + i] * (c < 3 ? L : 1);
  for (int sweep = 0; sweep < 60; ++sweep) {
    double off = 0;
    for (int p = 0; p < 6; ++p)
      for (int q = p + 1; q < 6; ++q) off += A[p][q] * A[p][q];
    if (off < 1e-300) break;
    for (int p = 0; p < 6; ++p)
      for (int q = p + 1; q < 6; ++q) {
        if (std::fabs(A[p][q]) < 1e-300) continue;
        const double th = 0.5 * std::atan2(2 * A[p][q], A[q][q] - A[p][p]);
        const double c = std::cos(th), s = std::sin(th);
        for (int k = 0; k < 6; ++k) {
          const double akp = A[k][p], akq = A[k][q];
          A[k][p] = c * akp - s * akq;
          A[k][q] = s * akp + c * akq;
        }
        for (int k = 0; k < 6; ++k) {
          const double apk = A[p][k], aqk = A[q][k];
          A[p][k] = c * apk - s * aqk;
          A[q][k] = s * apk + c * aqk;
        }
      }
  }
  double lo = HUGE_VAL, hi = 0;
  for (int k = 0; k < 6; ++k) { lo = std::min(lo, A[k][k]); hi = std::max(hi, A[k][k]); }
  return lo <= 0 ? HUGE_VAL : std::sqrt(hi / lo);
}

enum Cat { NORMAL, LIMIT, SINGULAR, STRESS, NCAT };
const char* cat_name[NCAT] = {"in-range", "limit", "singular", "stress"};

template <class M>
struct RandomRun {
  using angle_t = typename M::angle_t;
  int64_t ticks[NCAT] = {}, limit_active = 0, vlimit_active = 0, near_singular = 0, sat_ticks = 0, bad = 0;
  uint32_t flags_or[NCAT] = {}, kin_flags_or = 0, solve_flags_or = 0;
  int64_t kin_calls = 0, solve_calls = 0, raw_chain_blocks = 0, over_range_inputs = 0;

  // A random, valid servo set-up around the chain's default parameters.
  ParamsRaw vary(const ParamsRaw& base, int n, bool stress) {
    ParamsRaw p = base;
    p.mode = irand(0, 1);
    p.ff = irand(0, 3) ? 1 : 0;
    // half of the set-ups 1..4 sweeps, a quarter the project's default 10, a quarter up to the bound
    const int sw = irand(0, 3);
    p.sweeps = sw < 2 ? irand(1, 4) : sw == 2 ? std::min(10, HlsDefault::SWEEPS_MAX) : irand(5, HlsDefault::SWEEPS_MAX);
    p.ctl = irand(0, 4) ? -1 : irand(1, n);
    const int top = p.ctl < 0 ? n : p.ctl - 1;  // serial chains: the frames below the controlled one
    p.spf = irand(0, 2) ? -1 : irand(0, top);
    if (irand(0, 2) == 0) p.L = raw_of_double<typename M::lchar_t>(urand(0.1, 2.0));
    if (irand(0, 2) == 0) p.klim = raw_of_double<typename M::klim_t>(urand(5, 900));
    if (irand(0, 2) == 0) { p.kp = raw_of_double<typename M::gain_t>(urand(1, 600)); p.ko = raw_of_double<typename M::gain_t>(urand(1, 600)); }
    if (irand(0, 3) == 0) p.dt = raw_of_double<typename M::dt_t>(urand(1e-4, 0.01));
    for (int j = 0; j < n; ++j) {
      if (irand(0, 4) == 0) p.mu[j] = raw_of_double<typename M::mu_t>(irand(0, 5) == 0 ? 0.0 : urand(0.2, 1.9));
      if (irand(0, 4) == 0) p.vmax[j] = M::qd_t::RAW_MAX;
      else if (irand(0, 4) == 0) p.vmax[j] = raw_of_double<typename M::qd_t>(urand(0.2, 4));
    }
    if (stress) {
      p.kp = rraw(M::gain_t::W) & M::gain_t::RAW_MAX;  // up to the format's maximum
      p.ko = rraw(M::gain_t::W) & M::gain_t::RAW_MAX;
      p.klim = rraw(M::klim_t::W) & M::klim_t::RAW_MAX;
      p.dt = rraw(M::dt_t::W) & M::dt_t::RAW_MAX;
      for (int j = 0; j < n; ++j) p.mu[j] = rraw(M::mu_t::W) & M::mu_t::RAW_MAX;
    }
    return p;
  }

  // Random raw constants across whole formats (serial chain): forces saturations in FK.
  ChainRaw random_chain(const ChainRaw& base) {
    ChainRaw c = base;
    auto rq = [&](int64_t* q) { for (int a = 0; a < 4; ++a) q[a] = rraw(M::quat_t::W); };
    auto rp = [&](int64_t* p) { for (int a = 0; a < 3; ++a) p[a] = rraw(M::len_t::W); };
    rq(c.qb); rq(c.qt); rp(c.pb); rp(c.pt);
    for (int j = 0; j < c.n; ++j) {
      rq(c.qo[j].data()); rp(c.po[j].data());
      for (int a = 0; a < 3; ++a) c.axis[j][a] = rraw(M::quat_t::W);
      c.s[j] = rraw(M::scale_t::W);
      c.k[j] = c.prismatic[j] ? 0 : rraw(M::kturn_t::W);
    }
    return c;
  }

  void run_chain(const std::string& dir, const std::string& name, int nticks) {
    const KV kv = read_kv(dir + "/chain_" + name + "_" + M::name + ".txt");
    const ChainRaw base_chain = chain_from(kv, "");
    const int n = base_chain.n;
    if (n > NM) { std::printf("  skip  random %s %s: n = %d > NMAX = %d\n", name.c_str(), M::name, n, NM); return; }
    const ParamsRaw base = params_from(kv, "", n);
    const int block = 40;
    for (int done = 0; done < nticks;) {
      const bool stress_block = irand(0, 9) == 0;
      const bool raw_chain = stress_block && irand(0, 1);
      const ChainRaw c = raw_chain ? random_chain(base_chain) : base_chain;
      raw_chain_blocks += raw_chain;
      const ParamsRaw p = vary(base, n, stress_block);
      auto ch = std::make_unique<ChainQ<M, NM, 1>>();
      auto P = std::make_unique<ServoParams<M, NM, 1>>();
      Model<M>::chain(c, *ch);
      Model<M>::params(p, n, *P);
      const Words cc = chain_words_of(c), sc = solver_words_of(p, n), vc = servo_words_of(p);
      const int ref = irand(0, 2) ? -1 : irand(1, n + 1);
      const int basis = irand(0, 1) ? -1 : irand(0, n + 1);
      std::vector<int64_t> warm(NM, 0);
      auto R = std::make_unique<TickResult<M, NM, 1>>();
      for (int t = 0; t < block && done < nticks; ++t, ++done) {
        const Cat cat = stress_block ? STRESS : Cat(irand(0, 9) < 6 ? NORMAL : (irand(0, 1) ? LIMIT : SINGULAR));
        // Joint values: in range, at/over limits, at a singular configuration, or raw anywhere.
        std::vector<double> qv(n);
        Words qw(NM, 0);
        for (int i = 0; i < n; ++i) {
          const double lo = angle_t::from_raw(p.lo[i]).to_double();
          const double hi = angle_t::from_raw(p.hi[i]).to_double();
          qv[i] = p.limited[i] ? urand(lo, hi) : urand(-3.1, 3.1);
        }
        if (cat == LIMIT)
          for (int m = irand(1, 3); m > 0; --m) {
            const int i = irand(0, n - 1);
            const double lo = angle_t::from_raw(p.lo[i]).to_double(), hi = angle_t::from_raw(p.hi[i]).to_double();
            const int how = irand(0, 3);
            qv[i] = how == 0 ? lo : how == 1 ? hi : how == 2 ? lo - urand(0, 0.3) : hi + urand(0, 0.3);
          }
        if (cat == SINGULAR && !c.singular.empty()) {
          const auto& js = c.singular[irand(0, int(c.singular.size()) - 1)];
          for (int i : js) qv[i] = irand(0, 1) ? 0.0 : urand(-1e-4, 1e-4);
        }
        for (int i = 0; i < n; ++i) qw[i] = int32_t(raw_of_double<angle_t>(qv[i]));
        if (cat == STRESS)
          for (int i = 0; i < n; ++i) {
            int64_t r = rraw(std::min(angle_t::W, 32));
            if (irand(0, 3) == 0) r = irand(0, 1) ? angle_t::RAW_MAX - irand(0, 1 << 12) : angle_t::RAW_MIN + irand(0, 1 << 12);
            if (angle_t::W < 32 && irand(0, 19) == 0) { r = rraw(32); ++over_range_inputs; }  // outside the format
            qw[i] = int32_t(r);
          }
        // Setpoint: the model's pose of the controlled frame at a nearby q (relative to the
        // setpoint frame), a small twist; stress: raw words across whole formats.
        Words in{t == 0 || irand(0, 29) == 0 ? CTRL_COLD : 0};
        for (int i = 0; i < NM; ++i) in.push_back(qw[i]);
        if (cat != STRESS) {
          Words qs(NM, 0);
          const double dq = cat == NORMAL ? 0.003 : 0.05;
          for (int i = 0; i < n; ++i) qs[i] = int32_t(raw_of_double<angle_t>(qv[i] + urand(-dq, dq)));
          Frames<M, NM, 1> f;
          Model<M>::kin(*ch, qs, -1, -1, &f);
          const int ctl = p.ctl < 0 ? n + 1 : p.ctl;
          Status s;
          Quat<typename M::quat_t> UQ = f.Q[ctl];
          Vec3<typename M::pos_t> Up = f.p[ctl];
          if (p.spf >= 0) {
            UQ = qmul<typename M::quat_t>(conj(f.Q[p.spf], s), f.Q[ctl], s);
            Up = rotate<typename M::pos_t, typename M::len_tmp_t, true>(
                f.Q[p.spf], vsub<typename M::lever_t>(f.p[ctl], f.p[p.spf], s), s);
          }
          for (int a = 0; a < 4; ++a) in.push_back(int32_t(UQ.c[a].raw));
          for (int a = 0; a < 3; ++a) in.push_back(int32_t(Up.c[a].raw));
          for (int a = 0; a < 6; ++a) in.push_back(int32_t(raw_of_double<typename M::vel_t>(urand(-0.2, 0.2))));
        } else {
          for (int a = 0; a < 4; ++a) in.push_back(int32_t(irand(0, 1) ? rraw(M::quat_t::W) : raw_of_double<typename M::quat_t>(urand(-1, 1))));
          for (int a = 0; a < 3; ++a) in.push_back(int32_t(rraw(std::min(M::pos_t::W, 32))));
          for (int a = 0; a < 6; ++a) in.push_back(int32_t(rraw(M::vel_t::W)));
        }
        // servo
        Words es = Model<M>::servo(*ch, *P, in, warm, *R);
        const bool fault = g_fault_every > 0 && done % g_fault_every == 0;
        if (fault) es[0] ^= 1;
        const Words hs = Hls<M>::servo(cc, sc, vc, in);
        const std::string ctx = name + " " + cat_name[cat] + " tick " + std::to_string(done);
        bad += !compare("random servo", ctx, es, hs);
        const uint32_t fl = uint32_t(es.back());
        ++ticks[cat];
        flags_or[cat] |= fl;
        limit_active += (fl & ST_LIMIT_ACTIVE) != 0;
        vlimit_active += (fl & ST_VLIMIT_ACTIVE) != 0;
        sat_ticks += (fl & ST_OVF_ANY) != 0;
        if (cat == SINGULAR) {
          std::vector<double> J(6 * n);
          for (int i = 0; i < n; ++i)
            for (int a = 0; a < 3; ++a) { J[a * n + i] = R->J[0].w[i].c[a].to_double(); J[(a + 3) * n + i] = R->J[0].v[i].c[a].to_double(); }
          near_singular += n >= 6 && cond_of(J, n, P->solver.L.to_double()) > 1e4;
        }
        // kinematics (same q)
        Words qk(qw.begin(), qw.begin() + NM);
        Words ek = Model<M>::kin(*ch, qk, ref, basis);
        if (fault) ek[kin_out_words(NM) - 2] ^= 1;
        bad += !compare("random kin", ctx, ek, Hls<M>::kin(cc, ref, basis, qk));
        kin_flags_or |= uint32_t(ek.back());
        ++kin_calls;
        // solve: the tick's own Jacobian and a target, or raw words (stress)
        Words si;
        for (int i = 0; i < NM; ++i) si.push_back(qw[i]);
        for (int i = 0; i < NM; ++i)
          for (int a = 0; a < 6; ++a) {
            int64_t v = 0;
            if (i < n) v = cat == STRESS && irand(0, 1) ? rraw(a < 3 ? M::jw_t::W : M::jv_t::W)
                                                        : (a < 3 ? R->J[0].w[i].c[a].raw : R->J[0].v[i].c[a - 3].raw);
            si.push_back(int32_t(v));
          }
        for (int a = 0; a < 6; ++a)
          si.push_back(int32_t(cat == STRESS ? rraw(M::vel_t::W) : raw_of_double<typename M::vel_t>(urand(-1, 1))));
        for (int i = 0; i < NM; ++i)
          si.push_back(i < n ? int32_t(cat == STRESS ? rraw(M::qd_t::W) : raw_of_double<typename M::qd_t>(urand(-0.5, 0.5))) : 0);
        ServoParams<M, NM, 1>& PP = *P;
        Words ev = Model<M>::solve(PP, n, si);
        if (fault) ev[solve_out_words(NM) - 2] ^= 1;
        bad += !compare("random solve", ctx, ev, Hls<M>::solve(sc, si));
        solve_flags_or |= uint32_t(ev.back());
        ++solve_calls;
      }
    }
  }

  void report(int64_t total) {
    int64_t all = 0;
    for (int c = 0; c < NCAT; ++c) all += ticks[c];
    require(bad == 0 && all == total, "random %s: %" PRId64 " ticks x 3 kernels bit-exact (%" PRId64 " in-range, %" PRId64
            " limit, %" PRId64 " singular, %" PRId64 " stress; %" PRId64 " blocks with random raw chain constants)",
            M::name, all, ticks[NORMAL], ticks[LIMIT], ticks[SINGULAR], ticks[STRESS], raw_chain_blocks);
    std::printf("        %" PRId64 " ticks with a position limit active, %" PRId64 " with a velocity limit, %" PRId64
                " with a saturation, %" PRId64 " near-singular (cond > 1e4), %" PRId64 " input words over range\n",
                limit_active, vlimit_active, sat_ticks, near_singular, over_range_inputs);
    std::printf("        status bits seen: servo in-range %#x, limit %#x, singular %#x, stress %#x; kin %#x; solve %#x\n",
                flags_or[NORMAL], flags_or[LIMIT], flags_or[SINGULAR], flags_or[STRESS], kin_flags_or, solve_flags_or);
  }
};

// ---- 5. refused configurations -----------------------------------------------------------------
template <class M>
void check_refusals(const std::string& dir) {
  const KV kv = read_kv(dir + "/chain_puma560_" + std::string(M::name) + ".txt");
  const ChainRaw c = chain_from(kv, "");
  const int n = c.n;
  const ParamsRaw p = params_from(kv, "", n);
  const Words cc = chain_words_of(c), sc = solver_words_of(p, n), vc = servo_words_of(p);
  Words in{0};
  for (int i = 0; i < NM; ++i) in.push_back(i < n ? int32_t(raw_of_double<typename M::angle_t>(0.3 * (i + 1) - 1)) : 0);
  for (int a = 0; a < 4; ++a) in.push_back(a == 0 ? int32_t(M::quat_t::RAW_MAX / 2) : 0);
  for (int a = 0; a < 9; ++a) in.push_back(0);
  struct Bad { const char* what; Words cc, sc, vc; };
  std::vector<Bad> cases;
  auto add = [&](const char* w, int which, int idx, int32_t v) {
    Bad b{w, cc, sc, vc};
    (which == 0 ? b.cc : which == 1 ? b.sc : b.vc)[idx] = v;
    cases.push_back(b);
  };
  add("n = 0", 0, CH_N, 0);
  add("n = NMAX + 1", 0, CH_N, NM + 1);
  add("joint 2 parent = 3", 0, CH_JOINT0 + 2 * CH_JSTRIDE + J_PARENT, 3);
  add("joint type 2", 0, CH_JOINT0 + J_TYPE, 2);
  add("tool parent 0", 0, CH_TOOL_PARENT, 0);
  if (M::quat_t::W < 32) add("quaternion word out of format", 0, CH_BASE_Q, int32_t(M::quat_t::RAW_MAX + 1));
  add("sweeps = 0", 1, SV_SWEEPS, 0);
  add("sweeps = SWEEPS_MAX + 1", 1, SV_SWEEPS, HlsDefault::SWEEPS_MAX + 1);
  add("limit flag 2", 1, SV_JOINT0 + SJ_LIMITED, 2);
  add("mode 2", 2, SE_MODE, 2);
  add("warm leak 21", 2, SE_WARM_LEAK, 21);
  add("setpoint frame n + 1", 2, SE_SETPOINT_FRAME, n + 1);
  add("controlled frame 0", 2, SE_CONTROLLED, 0);
  int bad = 0;
  const Words zeros_servo(servo_out_words(NM) - 1, 0);
  for (const auto& b : cases) {
    // a valid tick first, so the warm start is not zero, then the refused one, then a valid tick
    // without the cold bit, which must start from zero (the refusal reset the warm start)
    Words in0 = in;
    in0[0] = CTRL_COLD;
    Hls<M>::servo(cc, sc, vc, in0);
    Hls<M>::servo(cc, sc, vc, in);
    const Words o = Hls<M>::servo(b.cc, b.sc, b.vc, in);
    const bool ok = uint32_t(o.back()) == ST_HLS_CONFIG && Words(o.begin(), o.end() - 1) == zeros_servo;
    auto ch = std::make_unique<ChainQ<M, NM, 1>>();
    auto P = std::make_unique<ServoParams<M, NM, 1>>();
    Model<M>::chain(c, *ch);
    Model<M>::params(p, n, *P);
    std::vector<int64_t> warm(NM, 0);
    auto R = std::make_unique<TickResult<M, NM, 1>>();
    const bool after = compare("after refusal", b.what, Model<M>::servo(*ch, *P, in, warm, *R), Hls<M>::servo(cc, sc, vc, in));
    if (!ok || !after) { ++bad; std::printf("refusal '%s' not handled (status %#x)\n", b.what, uint32_t(o.back())); }
  }
  // The kinematics and solve kernels refuse too.
  Words kb = cc;
  kb[CH_N] = 0;
  const Words ko = Hls<M>::kin(kb, -1, -1, Words(NM, 0));
  bad += !(uint32_t(ko.back()) == ST_HLS_CONFIG && std::all_of(ko.begin(), ko.end() - 1, [](int32_t v) { return v == 0; }));
  const Words kr = Hls<M>::kin(cc, -1, n + 2, Words(NM, 0));  // basis beyond the tool
  bad += uint32_t(kr.back()) != ST_HLS_CONFIG;
  Words sb = sc;
  sb[SV_N] = NM + 1;
  const Words so = Hls<M>::solve(sb, Words(solve_in_words(NM), 0));
  bad += !(uint32_t(so.back()) == ST_HLS_CONFIG && std::all_of(so.begin(), so.end() - 1, [](int32_t v) { return v == 0; }));
  require(bad == 0, "refusals %s: %zu invalid configurations give status bit 31, zero outputs and a reset warm start",
          M::name, cases.size() + 3);
}

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string x;
  while (std::getline(ss, x, ',')) if (!x.empty()) out.push_back(x);
  return out;
}

template <class M>
void run_config(const std::string& dir, const std::vector<std::string>& chains, int64_t nticks) {
  std::printf("[%s, NMAX = %d, SWEEPS_MAX = %d]\n", M::name, NM, HlsDefault::SWEEPS_MAX);
  check_tables<M>();
  for (const auto& c : chains) check_golden<M>(dir, c);
  for (const auto& c : chains) check_bindings<M>(dir, c);
  RandomRun<M> rr;
  std::vector<std::string> fit;
  for (const auto& c : chains)
    if (at(read_kv(dir + "/chain_" + c + "_" + M::name + ".txt"), "n")[0] <= NM) fit.push_back(c);
  int64_t total = 0;
  for (size_t i = 0; i < fit.size(); ++i) {
    const int64_t k = nticks / int64_t(fit.size()) + (int64_t(i) < nticks % int64_t(fit.size()));
    rr.run_chain(dir, fit[i], static_cast<int>(k));
    total += k;
  }
  rr.report(total);
  if (total > 0) {
    // Coverage: the categories are what they claim to be.
    const uint32_t need = ST_OVF_ANGLE | ST_OVF_QUAT | ST_OVF_POS | ST_OVF_LEVER | ST_OVF_JAC | ST_OVF_SOLVER |
                          ST_OVF_SERVO | ST_LIMIT_ACTIVE | ST_VLIMIT_ACTIVE;
    const uint32_t seen = rr.flags_or[STRESS] | rr.kin_flags_or | rr.solve_flags_or;
    require((seen & need) == need, "saturation coverage %s: status bits %#x forced and matched (need %#x)", M::name,
            seen, need);
    require(rr.limit_active >= rr.ticks[LIMIT] / 4, "limit coverage %s: %" PRId64 " ticks with a position limit active",
            M::name, rr.limit_active);
    require(rr.near_singular >= rr.ticks[SINGULAR] / 4, "singular coverage %s: %" PRId64 " near-singular ticks",
            M::name, rr.near_singular);
  }
  check_refusals<M>(dir);
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s VECTOR_DIR [--ticks N] [--chains a,b] [--seed S] [--config default|compact|both]"
                 " [--fault N]\n", argv[0]);
    return 2;
  }
  const std::string dir = argv[1];
  int64_t nticks = 100000;
  std::string chains = "puma560,ur5,panda,stanford,chain20", config = "both";
  uint64_t seed = 1;
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string k = argv[i];
    if (k == "--ticks") nticks = std::atoll(argv[i + 1]);
    else if (k == "--chains") chains = argv[i + 1];
    else if (k == "--seed") seed = std::strtoull(argv[i + 1], nullptr, 10);
    else if (k == "--config") config = argv[i + 1];
    else if (k == "--fault") g_fault_every = std::atoll(argv[i + 1]);
    else { std::fprintf(stderr, "unknown option %s\n", k.c_str()); return 2; }
  }
  rng.seed(seed);
  const auto cs = split(chains);
  if (config != "compact") run_config<FmtDefault>(dir, cs, nticks);
  if (config != "default") run_config<FmtCompact>(dir, cs, nticks);
  std::printf("summary: %" PRId64 " packets compared, %" PRId64 " mismatches, %d failed requirements\n", g_compared,
              g_mismatch, g_fail_reqs);
  return (g_mismatch == 0 && g_fail_reqs == 0) ? 0 : 1;
}
