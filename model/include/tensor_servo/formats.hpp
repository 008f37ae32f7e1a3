// tensor-servo: the named number configurations.
//
// Each configuration is a struct of types, one per signal class of the algorithm, and a few
// constants.  The algorithm (kinematics.hpp, sincos.hpp, ...) is written once against these names;
// FmtDouble makes every signal a double (the second float reference), FmtDefault meets the accuracy
// goals of docs/numerics.md, FmtCompact keeps every multiplier operand at 18 bits or less so each
// product is one MULT18X18D (ECP5) or DSP48E1 (7-series).
//
// Range of each format is justified in docs/numerics.md; the configuration check
// (chain_quant.hpp) refuses chains that could leave these ranges, and every conversion still
// saturates and raises a sticky flag.
//
// The fixed-point configurations are templates over a number family N (fixed.hpp, "Number
// families"): FmtDefault = FmtDefaultT<fx> is the model; hls/ts_formats_hls.h instantiates the same
// formats on ap_fixed (HlsDefault, HlsCompact), so the (W, I) of every signal are written once.
// Each configuration also names the family's type of any format, Fmt::num<W, I, FLAG>, for the
// few intermediates the algorithm names itself, and SWEEPS_MAX, the compile-time bound of the
// solver's sweep loop (SolverParams::sweeps must not exceed it; the model's is 2^30, hardware
// builds choose a small one).
#pragma once
#include "fixed.hpp"

namespace ts {

struct FmtDouble {
  static constexpr bool is_float = true;
  static constexpr const char* name = "double";
  template <int W, int I, uint32_t FLAG = 0> using num = double;
  static constexpr int SWEEPS_MAX = 1 << 30;
  using angle_t = double;
  using kturn_t = double;
  using inv4pi_t = double;
  using turn_t = double;
  using scale_t = double;
  using tab_t = double;
  using delta_t = double;
  using dsq_t = double;
  using trig_acc_t = double;
  using quat_t = double;
  using uvec_tmp_t = double;
  using len_t = double;
  using len_tmp_t = double;
  using pos_t = double;
  using lever_t = double;
  using jw_t = double;
  using jv_t = double;
  using jw_tmp_t = double;
  using jv_tmp_t = double;
  static constexpr int TRIG_TABLE_BITS = 8;
  using twopi_t = double;
  using sixth_t = double;
  // coordinate solver and servo law
  using lchar_t = double;
  using tw_t = double;
  using jsc_t = double;
  using qd_t = double;
  using gk_t = double;
  using mant_t = double;
  using recip_t = double;
  using mu_t = double;
  using bfm_t = double;
  using cgy_t = double;
  using cge_t = double;
  using cgx_t = double;
  using cgr_t = double;
  using step_t = double;
  using klim_t = double;
  using qdiff_t = double;
  using gain_t = double;
  using dt_t = double;
  using vel_t = double;
  using perr_t = double;
  using rot_t = double;
  using rvf_t = double;
  using tacc_t = double;
  using weight_t = double;
  static constexpr int RECIP_TABLE_BITS = 6;
  static constexpr int ROTVEC_TABLE_BITS = 6;
};

// Default: accuracy goal (FK <= 5 um / 10 urad, Jacobian entries within 1e-5) with margin.
// Multiplier operands are at most 27 bits (4 MULT18X18D each on ECP5) except the one
// joint-value x turn-constant product per joint (32 x 30).
template <template <int, int, uint32_t = 0> class N>
struct FmtDefaultT {
  static constexpr bool is_float = false;
  static constexpr const char* name = "default";
  template <int W, int I, uint32_t FLAG = 0> using num = N<W, I, FLAG>;
  static constexpr int SWEEPS_MAX = 1 << 30;
  using angle_t = N<32, 4, ST_OVF_ANGLE>;      // joint value q, joint units, |q| < 8
  using kturn_t = N<30, -1, ST_OVF_CONST>;     // s/(4 pi): joint unit -> half-angle turns, |s| < pi
  using inv4pi_t = N<32, -2>;                  // 1/(4 pi): k = cvt<kturn_t>(s * 1/(4 pi))
  using turn_t = N<32, 0>;                     // half angle in turns, modulo one turn (wraps)
  using scale_t = N<27, 3, ST_OVF_CONST>;      // s: joint unit -> rad or m, |s| < 4
  using tab_t = N<27, 2, ST_OVF_TRIG>;         // quarter-wave table entries, [0, 1]
  using delta_t = N<27, -6, ST_OVF_TRIG>;      // residual angle d (rad), 0 <= d < 2^-7
  using dsq_t = N<27, -13, ST_OVF_TRIG>;       // d^2 and d^2/6, < 2^-14
  using trig_acc_t = N<35, 2, ST_OVF_TRIG>;    // S h, C sd, ... before the final sum (8 guard bits)
  using quat_t = N<27, 2, ST_OVF_QUAT>;        // unit quaternion and unit-vector components
  using uvec_tmp_t = N<27, 3, ST_OVF_QUAT>;    // t = 2 q_v x a when rotating a unit vector
  using len_t = N<27, 3, ST_OVF_CONST>;        // constant offsets (origin, base, tool), |.| < 4 m
  using len_tmp_t = N<27, 5, ST_OVF_POS>;      // t = 2 q_v x p when rotating an offset
  using pos_t = N<32, 5, ST_OVF_POS>;          // frame positions, |.| < 16 m (adders only)
  using lever_t = N<27, 4, ST_OVF_LEVER>;      // r = p_ref - p_i, |.| < 8 m
  using jw_t = N<27, 3, ST_OVF_JAC>;           // Jacobian omega rows, |.| <= |s| < 4
  using jv_t = N<27, 5, ST_OVF_JAC>;           // Jacobian v rows, |.| <= |s| |r| < 16
  using jw_tmp_t = N<27, 4, ST_OVF_JAC>;       // t when rotating an omega column to another basis
  using jv_tmp_t = N<27, 6, ST_OVF_JAC>;       // t when rotating a v column to another basis
  static constexpr int TRIG_TABLE_BITS = 8;    // 256 (sin, cos) pairs over a quarter turn
  using twopi_t = N<27, 4>;                    // 2*pi; error 6e-8 -> < 6e-11 rad on d
  using sixth_t = N<18, 0>;                    // 1/6 in sin d = d - d (d^2/6)
  // coordinate solver (solver.hpp) and servo law (servo.hpp)
  using lchar_t = N<18, 3, ST_OVF_CONST>;      // characteristic length L (m/rad), 0 < L < 4
  using tw_t = N<27, 6, ST_OVF_SOLVER>;        // scaled target / residual (L omega; v), |.| < 32 m/s
  using jsc_t = N<27, 5, ST_OVF_SOLVER>;       // scaled Jacobian column (L omega_i; v_i), |.| < 16
  using qd_t = N<27, 6, ST_OVF_SOLVER>;        // joint rates q', |.| < 32 joint units/s
  using gk_t = N<27, 7, ST_OVF_SOLVER>;        // <J_i, r> 2^-k_i (normalised projection)
  using mant_t = N<18, 2>;                     // d_i 2^-k_i in [1, 2) (truncated)
  using recip_t = N<18, 2, ST_OVF_SOLVER>;     // 1 / mant in (1/2, 1]
  using mu_t = N<18, 2, ST_OVF_CONST>;         // per-joint multiplier (relaxation), [0, 2)
  using step_t = N<18, 2, ST_OVF_SOLVER>;      // mu_i / mant_i
  using bfm_t = N<27, 2, ST_OVF_SOLVER>;       // IK refinement: block-floating mantissa, |.| <= 1
  using cgy_t = N<27, 3, ST_OVF_SOLVER>;       // IK refinement: refined reciprocal, [1, 2]
  using cge_t = N<27, -10, ST_OVF_SOLVER>;     // IK refinement: Newton error 1 - m y, |.| < 2^-12
  using cgx_t = N<60, 30, ST_OVF_SOLVER>;      // IK refinement: increment of q' / 2^k0 (|r0| < 2^k0)
  using cgr_t = N<60, 4, ST_OVF_SOLVER>;       // IK refinement: residual / 2^k0, |.| < sqrt(24) < 8
  using klim_t = N<27, 15, ST_OVF_CONST>;      // limit-approach gain (1/s)
  using qdiff_t = N<33, 5, ST_OVF_SOLVER>;     // limit - q, exact (33-bit operand: 4 MULT18X18D)
  using gain_t = N<27, 15, ST_OVF_CONST>;      // servo gains K_p, K_o (1/s)
  using dt_t = N<32, -3, ST_OVF_CONST>;        // tick period (s), < 1/8 s
  using vel_t = N<27, 6, ST_OVF_SERVO>;        // setpoint twist U' and command V (omega; v), |.| < 32
  using perr_t = N<27, 4, ST_OVF_SERVO>;       // position error (m), |.| < 8
  using rot_t = N<27, 3, ST_OVF_SERVO>;        // orientation error, rotation vector (rad), |.| <= pi
  using rvf_t = N<27, 2, ST_OVF_SERVO>;        // phi / sin(phi) table for the rotation vector, [1, pi/2]
  using tacc_t = N<60, 17, ST_OVF_SOLVER>;     // exact accumulator of Vs - sum Js_i q'_i (n <= 64)
  using weight_t = N<18, 3, ST_OVF_CONST>;     // per-task row weight (trees of chains), [0, 4)
  static constexpr int RECIP_TABLE_BITS = 6;
  static constexpr int ROTVEC_TABLE_BITS = 6;
};
using FmtDefault = FmtDefaultT<fx>;

// Compact: every multiplier operand <= 18 bits (one DSP per product on ECP5 and 7-series).
template <template <int, int, uint32_t = 0> class N>
struct FmtCompactT {
  static constexpr bool is_float = false;
  static constexpr const char* name = "compact";
  template <int W, int I, uint32_t FLAG = 0> using num = N<W, I, FLAG>;
  static constexpr int SWEEPS_MAX = 1 << 30;
  using angle_t = N<18, 4, ST_OVF_ANGLE>;
  using kturn_t = N<18, -2, ST_OVF_CONST>;      // |s| < pi/2
  using inv4pi_t = N<18, -2>;
  using turn_t = N<26, 0>;
  using scale_t = N<18, 3, ST_OVF_CONST>;
  using tab_t = N<18, 2, ST_OVF_TRIG>;
  using delta_t = N<18, -6, ST_OVF_TRIG>;
  using dsq_t = N<18, -13, ST_OVF_TRIG>;
  using trig_acc_t = N<26, 2, ST_OVF_TRIG>;
  using quat_t = N<18, 2, ST_OVF_QUAT>;
  using uvec_tmp_t = N<18, 3, ST_OVF_QUAT>;
  using len_t = N<18, 3, ST_OVF_CONST>;        // |.| < 4 m
  using len_tmp_t = N<18, 4, ST_OVF_POS>;
  using pos_t = N<24, 4, ST_OVF_POS>;          // |.| < 8 m (adders only)
  using lever_t = N<18, 3, ST_OVF_LEVER>;      // |.| < 4 m
  using jw_t = N<18, 3, ST_OVF_JAC>;
  using jv_t = N<18, 4, ST_OVF_JAC>;           // |s| |r| < 8
  using jw_tmp_t = N<18, 4, ST_OVF_JAC>;
  using jv_tmp_t = N<18, 5, ST_OVF_JAC>;
  static constexpr int TRIG_TABLE_BITS = 8;
  using twopi_t = N<18, 4>;                    // error 3e-5 -> < 3e-8 rad on d
  using sixth_t = N<18, 0>;
  using lchar_t = N<18, 3, ST_OVF_CONST>;
  using tw_t = N<18, 6, ST_OVF_SOLVER>;
  using jsc_t = N<18, 5, ST_OVF_SOLVER>;
  using qd_t = N<18, 6, ST_OVF_SOLVER>;
  using gk_t = N<18, 7, ST_OVF_SOLVER>;
  using mant_t = N<18, 2>;
  using recip_t = N<18, 2, ST_OVF_SOLVER>;
  using mu_t = N<18, 2, ST_OVF_CONST>;
  using step_t = N<18, 2, ST_OVF_SOLVER>;
  using bfm_t = N<18, 2, ST_OVF_SOLVER>;
  using cgy_t = N<18, 3, ST_OVF_SOLVER>;
  using cge_t = N<18, -10, ST_OVF_SOLVER>;
  using cgx_t = N<48, 24, ST_OVF_SOLVER>;
  using cgr_t = N<48, 4, ST_OVF_SOLVER>;
  using klim_t = N<18, 15, ST_OVF_CONST>;
  using qdiff_t = N<18, 5, ST_OVF_SOLVER>;     // limit - q rounded to an 18-bit operand
  using gain_t = N<18, 15, ST_OVF_CONST>;
  using dt_t = N<18, -3, ST_OVF_CONST>;
  using vel_t = N<18, 6, ST_OVF_SERVO>;
  using perr_t = N<18, 4, ST_OVF_SERVO>;
  using rot_t = N<18, 3, ST_OVF_SERVO>;
  using rvf_t = N<18, 2, ST_OVF_SERVO>;
  using tacc_t = N<42, 17, ST_OVF_SOLVER>;
  using weight_t = N<18, 3, ST_OVF_CONST>;
  static constexpr int RECIP_TABLE_BITS = 6;
  static constexpr int ROTVEC_TABLE_BITS = 6;
};
using FmtCompact = FmtCompactT<fx>;

}  // namespace ts
