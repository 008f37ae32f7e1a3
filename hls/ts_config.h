// tensor-servo HLS: word layout of the configuration arrays (AXI4-Lite) and of the per-tick stream
// packets (AXI4-Stream), shared by the kernels, the C-simulation and host drivers (docs/hls.md).
//
// Every word is a signed 32-bit integer holding a raw fixed-point value (value = raw * 2^-F of the
// format named in the comment; the formats are those of the configuration, formats.hpp), an index
// or a flag.  Words marked "reserved" are written 0 and ignored.
#pragma once
#include <cstdint>

#ifndef TS_NMAX
#define TS_NMAX 8  // joints per build (chains configured at run time with 1 <= n <= TS_NMAX)
#endif

namespace ts {
namespace hlsio {

// ---- chain_cfg (kinematics and servo kernels) ------------------------------------------------
constexpr int CH_N = 0;            // joint count n, 1..NMAX
constexpr int CH_BASE_Q = 1;       // base rotation w, x, y, z (quat_t)
constexpr int CH_BASE_P = 5;       // base translation x, y, z (len_t)
constexpr int CH_TOOL_Q = 8;       // tool rotation relative to its frame (quat_t)
constexpr int CH_TOOL_P = 12;      // tool offset (len_t)
constexpr int CH_TOOL_PARENT = 15; // frame the tool hangs from, 1..n (a serial chain: n)
constexpr int CH_JOINT0 = 16;      // joint j occupies words CH_JOINT0 + CH_JSTRIDE j + (below)
constexpr int CH_JSTRIDE = 16;
constexpr int J_TYPE = 0;          //   0 revolute, 1 prismatic
constexpr int J_PARENT = 1;        //   parent frame index 0..j (a serial chain: j)
constexpr int J_QO = 2;            //   origin rotation w, x, y, z (quat_t)
constexpr int J_PO = 6;            //   origin translation (len_t)
constexpr int J_AXIS = 9;          //   unit axis (quat_t)
constexpr int J_S = 12;            //   scale s (scale_t)
constexpr int J_K = 13;            //   s / (4 pi) (kturn_t), 0 for prismatic joints
                                   //   14, 15 reserved
constexpr int chain_words(int nmax) { return CH_JOINT0 + CH_JSTRIDE * nmax; }

// ---- solver_cfg (solve and servo kernels) ----------------------------------------------------
constexpr int SV_L = 0;            // characteristic length L (lchar_t), > 0
constexpr int SV_KLIM = 1;         // limit-approach gain (klim_t)
constexpr int SV_SWEEPS = 2;       // sweeps per tick, 1..SWEEPS_MAX
constexpr int SV_N = 3;            // joint count (solve kernel only; the servo kernel uses CH_N)
                                   // 4..7 reserved
constexpr int SV_JOINT0 = 8;       // joint j occupies words SV_JOINT0 + SV_JSTRIDE j + (below)
constexpr int SV_JSTRIDE = 8;
constexpr int SJ_MU = 0;           //   multiplier mu (mu_t), [0, 2)
constexpr int SJ_LIMITED = 1;      //   1: position limits apply
constexpr int SJ_LO = 2;           //   lower limit (angle_t)
constexpr int SJ_HI = 3;           //   upper limit (angle_t)
constexpr int SJ_VMAX = 4;         //   velocity limit (qd_t); the format's maximum for none
                                   //   5..7 reserved
constexpr int solver_words(int nmax) { return SV_JOINT0 + SV_JSTRIDE * nmax; }

// ---- servo_cfg (servo kernel) ----------------------------------------------------------------
constexpr int SE_KP = 0;           // position gain (gain_t)
constexpr int SE_KO = 1;           // orientation gain (gain_t)
constexpr int SE_DT = 2;           // tick period (dt_t), > 0
constexpr int SE_MODE = 3;         // 0: error choice A, 1: B
constexpr int SE_FEEDFORWARD = 4;  // 1: feed the setpoint twist forward, 0: error only
constexpr int SE_SETPOINT_FRAME = 5;  // -1: setpoint in the root frame; k: relative to frame k (0..n)
constexpr int SE_CONTROLLED = 6;   // -1: the tool; k: joint frame k (1..n)
constexpr int SE_WARM_LEAK = 7;    // warm-start leak shift s (0: none), 0..20
constexpr int SERVO_WORDS = 8;

// ---- stream packets (one per tick; fixed length for a build's NMAX) -------------------------
// kinematics   in : q[NMAX] (angle_t; entries j >= n ignored)
//              out: frames 0..NMAX (Q w x y z, p x y z: 7 words each; frames beyond n are 0),
//                   tool (7 words), axes z_1..z_NMAX (3 words each), Jacobian columns 1..NMAX
//                   (omega x y z, v x y z), status
// solve        in : q[NMAX], Jacobian columns 1..NMAX (6 words each), V (omega; v: 6 words,
//                   vel_t), warm start q'[NMAX] (qd_t)
//              out: q'[NMAX] (qd_t), scaled residual r (6 words, tw_t), status
// servo        in : control word (bit 0: cold start, the warm start is 0 this tick), q[NMAX],
//                   setpoint Q (4, quat_t), p (3, pos_t), omega (3, vel_t), v (3, vel_t)
//              out: q'[NMAX] (qd_t), q + q' dt [NMAX] (angle_t), e_p (3, perr_t),
//                   e_o (3, rot_t), scaled residual r (6, tw_t), status
// Status: the model's sticky bits (fixed.hpp StatusBit) and, in bit 31, ST_HLS_CONFIG.  An input
// word outside its format saturates and raises that format's bit, as a conversion would.
constexpr int kin_in_words(int nmax) { return nmax; }
constexpr int kin_out_words(int nmax) { return 7 * (nmax + 1) + 7 + 3 * nmax + 6 * nmax + 1; }
constexpr int solve_in_words(int nmax) { return nmax + 6 * nmax + 6 + nmax; }
constexpr int solve_out_words(int nmax) { return nmax + 6 + 1; }
constexpr int servo_in_words(int nmax) { return 1 + nmax + 13; }
constexpr int servo_out_words(int nmax) { return 2 * nmax + 12 + 1; }

// The configuration was refused (a count, index or raw value out of range): every output word of
// the tick is 0 except the status, and the servo kernel's warm start is reset.
constexpr uint32_t ST_HLS_CONFIG = 1u << 31;
constexpr int32_t CTRL_COLD = 1;

}  // namespace hlsio
}  // namespace ts
