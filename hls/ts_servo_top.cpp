// tensor-servo HLS: top functions.  Each binds a kernel of ts_kernels.h to a configuration struct
// and declares the interfaces a Vitis user expects:
//   s_axilite (bundle "control")  configuration arrays, scalars and the block protocol (port=return)
//   axis                          the per-tick input and output packets (32-bit TDATA, ts_config.h)
// Intended performance (an estimate from operation counts, not a Vitis report; docs/hls.md):
// one call at a time (the interval equals the latency), xc7z020-1 at 100 MHz, NMAX = 8:
//   ts_kin_top    ~ 660 cycles (6.6 us)
//   ts_solve_top  ~ 590 cycles with 2 sweeps, ~1 900 with 10
//   ts_servo_top  ~ 1 150 cycles (11.5 us) with 2 sweeps, ~2 400 (24 us) with 10
#include "ts_servo_top.h"

#include "ts_kernels.h"

namespace {
// Configuration structs (hls4ml style), one per kernel and number configuration: the formats,
// tables and sweep bound (fmt, ts_formats_hls.h) and the joint bound of the build.
struct kin_config { using fmt = ts::HlsDefault; static const int nmax = TS_NMAX; };
struct kin_config_compact { using fmt = ts::HlsCompact; static const int nmax = TS_NMAX; };
struct solve_config { using fmt = ts::HlsDefault; static const int nmax = TS_NMAX; };
struct solve_config_compact { using fmt = ts::HlsCompact; static const int nmax = TS_NMAX; };
struct servo_config { using fmt = ts::HlsDefault; static const int nmax = TS_NMAX; };
struct servo_config_compact { using fmt = ts::HlsCompact; static const int nmax = TS_NMAX; };
}  // namespace

#define TS_KIN_INTERFACES                                          \
  _Pragma("HLS INTERFACE mode=s_axilite port=chain_cfg bundle=control") \
  _Pragma("HLS INTERFACE mode=s_axilite port=ref bundle=control")       \
  _Pragma("HLS INTERFACE mode=s_axilite port=basis bundle=control")     \
  _Pragma("HLS INTERFACE mode=axis port=q_in")                          \
  _Pragma("HLS INTERFACE mode=axis port=kin_out")                       \
  _Pragma("HLS INTERFACE mode=s_axilite port=return bundle=control")

#define TS_SOLVE_INTERFACES                                         \
  _Pragma("HLS INTERFACE mode=s_axilite port=solver_cfg bundle=control") \
  _Pragma("HLS INTERFACE mode=axis port=s_in")                          \
  _Pragma("HLS INTERFACE mode=axis port=s_out")                         \
  _Pragma("HLS INTERFACE mode=s_axilite port=return bundle=control")

#define TS_SERVO_INTERFACES                                         \
  _Pragma("HLS INTERFACE mode=s_axilite port=chain_cfg bundle=control")  \
  _Pragma("HLS INTERFACE mode=s_axilite port=solver_cfg bundle=control") \
  _Pragma("HLS INTERFACE mode=s_axilite port=servo_cfg bundle=control")  \
  _Pragma("HLS INTERFACE mode=axis port=tick_in")                        \
  _Pragma("HLS INTERFACE mode=axis port=tick_out")                       \
  _Pragma("HLS INTERFACE mode=s_axilite port=return bundle=control")

void ts_kin_top(const int32_t chain_cfg[TS_CHAIN_WORDS], int32_t ref, int32_t basis, hls::stream<int32_t>& q_in,
                hls::stream<int32_t>& kin_out) {
  TS_KIN_INTERFACES
  ts::ts_kin<kin_config>(chain_cfg, ref, basis, q_in, kin_out);
}
void ts_kin_top_compact(const int32_t chain_cfg[TS_CHAIN_WORDS], int32_t ref, int32_t basis,
                        hls::stream<int32_t>& q_in, hls::stream<int32_t>& kin_out) {
  TS_KIN_INTERFACES
  ts::ts_kin<kin_config_compact>(chain_cfg, ref, basis, q_in, kin_out);
}

void ts_solve_top(const int32_t solver_cfg[TS_SOLVER_WORDS], hls::stream<int32_t>& s_in, hls::stream<int32_t>& s_out) {
  TS_SOLVE_INTERFACES
  ts::ts_solve<solve_config>(solver_cfg, s_in, s_out);
}
void ts_solve_top_compact(const int32_t solver_cfg[TS_SOLVER_WORDS], hls::stream<int32_t>& s_in,
                          hls::stream<int32_t>& s_out) {
  TS_SOLVE_INTERFACES
  ts::ts_solve<solve_config_compact>(solver_cfg, s_in, s_out);
}

void ts_servo_top(const int32_t chain_cfg[TS_CHAIN_WORDS], const int32_t solver_cfg[TS_SOLVER_WORDS],
                  const int32_t servo_cfg[TS_SERVO_WORDS], hls::stream<int32_t>& tick_in,
                  hls::stream<int32_t>& tick_out) {
  TS_SERVO_INTERFACES
  ts::ts_servo<servo_config>(chain_cfg, solver_cfg, servo_cfg, tick_in, tick_out);
}
void ts_servo_top_compact(const int32_t chain_cfg[TS_CHAIN_WORDS], const int32_t solver_cfg[TS_SOLVER_WORDS],
                          const int32_t servo_cfg[TS_SERVO_WORDS], hls::stream<int32_t>& tick_in,
                          hls::stream<int32_t>& tick_out) {
  TS_SERVO_INTERFACES
  ts::ts_servo<servo_config_compact>(chain_cfg, solver_cfg, servo_cfg, tick_in, tick_out);
}
