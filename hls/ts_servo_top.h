// tensor-servo HLS: the top functions (one per kernel and configuration) and their configuration
// structs.  Vitis HLS synthesises one of them per solution (hls/run_hls.tcl); docs/hls.md maps
// their ports to AXI4-Lite registers and AXI4-Stream packets.
#pragma once
#include <hls_stream.h>

#include <cstdint>

#include "ts_config.h"

// Sizes of the configuration arrays for this build's TS_NMAX (ts_config.h).  The configuration
// structs of the kernels (hls4ml style) are in ts_servo_top.cpp.
#define TS_CHAIN_WORDS (ts::hlsio::chain_words(TS_NMAX))
#define TS_SOLVER_WORDS (ts::hlsio::solver_words(TS_NMAX))
#define TS_SERVO_WORDS (ts::hlsio::SERVO_WORDS)

// Kinematics: FK of every frame + Jacobian at `ref` in the axes of `basis`.
void ts_kin_top(const int32_t chain_cfg[TS_CHAIN_WORDS], int32_t ref, int32_t basis, hls::stream<int32_t>& q_in,
                hls::stream<int32_t>& kin_out);
void ts_kin_top_compact(const int32_t chain_cfg[TS_CHAIN_WORDS], int32_t ref, int32_t basis,
                        hls::stream<int32_t>& q_in, hls::stream<int32_t>& kin_out);
// Coordinate-descent solve of J q' = V with joint limits.
void ts_solve_top(const int32_t solver_cfg[TS_SOLVER_WORDS], hls::stream<int32_t>& s_in, hls::stream<int32_t>& s_out);
void ts_solve_top_compact(const int32_t solver_cfg[TS_SOLVER_WORDS], hls::stream<int32_t>& s_in,
                          hls::stream<int32_t>& s_out);
// The full servo tick.
void ts_servo_top(const int32_t chain_cfg[TS_CHAIN_WORDS], const int32_t solver_cfg[TS_SOLVER_WORDS],
                  const int32_t servo_cfg[TS_SERVO_WORDS], hls::stream<int32_t>& tick_in,
                  hls::stream<int32_t>& tick_out);
void ts_servo_top_compact(const int32_t chain_cfg[TS_CHAIN_WORDS], const int32_t solver_cfg[TS_SOLVER_WORDS],
                          const int32_t servo_cfg[TS_SERVO_WORDS], hls::stream<int32_t>& tick_in,
                          hls::stream<int32_t>& tick_out);
