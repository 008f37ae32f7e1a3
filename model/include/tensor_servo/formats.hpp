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
#pragma once
#include "fixed.hpp"

namespace ts {

struct FmtDouble {
  static constexpr bool is_float = true;
  static constexpr const char* name = "double";
  using angle_t = double;
  using kturn_t = double;
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
};

// Default: accuracy goal (FK <= 5 um / 10 urad, Jacobian entries within 1e-5) with margin.
// Multiplier operands are at most 27 bits (4 MULT18X18D each on ECP5) except the one
// joint-value x turn-constant product per joint (32 x 30).
struct FmtDefault {
  static constexpr bool is_float = false;
  static constexpr const char* name = "default";
  using angle_t = fx<32, 4, ST_OVF_ANGLE>;     // joint value q, joint units, |q| < 8
  using kturn_t = fx<30, -1, ST_OVF_CONST>;    // s/(4 pi): joint unit -> half-angle turns, |s| < pi
  using turn_t = fx<32, 0>;                    // half angle in turns, modulo one turn (wraps)
  using scale_t = fx<27, 3, ST_OVF_CONST>;     // s: joint unit -> rad or m, |s| < 4
  using tab_t = fx<27, 2, ST_OVF_TRIG>;        // quarter-wave table entries, [0, 1]
  using delta_t = fx<27, -6, ST_OVF_TRIG>;     // residual angle d (rad), 0 <= d < 2^-7
  using dsq_t = fx<27, -13, ST_OVF_TRIG>;      // d^2 and d^2/6, < 2^-14
  using trig_acc_t = fx<35, 2, ST_OVF_TRIG>;   // S h, C sd, ... before the final sum (8 guard bits)
  using quat_t = fx<27, 2, ST_OVF_QUAT>;       // unit quaternion and unit-vector components
  using uvec_tmp_t = fx<27, 3, ST_OVF_QUAT>;   // t = 2 q_v x a when rotating a unit vector
  using len_t = fx<27, 3, ST_OVF_CONST>;       // constant offsets (origin, base, tool), |.| < 4 m
  using len_tmp_t = fx<27, 5, ST_OVF_POS>;     // t = 2 q_v x p when rotating an offset
  using pos_t = fx<32, 5, ST_OVF_POS>;         // frame positions, |.| < 16 m (adders only)
  using lever_t = fx<27, 4, ST_OVF_LEVER>;     // r = p_ref - p_i, |.| < 8 m
  using jw_t = fx<27, 3, ST_OVF_JAC>;          // Jacobian omega rows, |.| <= |s| < 4
  using jv_t = fx<27, 5, ST_OVF_JAC>;          // Jacobian v rows, |.| <= |s| |r| < 16
  using jw_tmp_t = fx<27, 4, ST_OVF_JAC>;      // t when rotating an omega column to another basis
  using jv_tmp_t = fx<27, 6, ST_OVF_JAC>;      // t when rotating a v column to another basis
  static constexpr int TRIG_TABLE_BITS = 8;    // 256 (sin, cos) pairs over a quarter turn
  using twopi_t = fx<27, 4>;                   // 2*pi; error 6e-8 -> < 6e-11 rad on d
  using sixth_t = fx<18, 0>;                   // 1/6 in sin d = d - d (d^2/6)
};

// Compact: every multiplier operand <= 18 bits (one DSP per product on ECP5 and 7-series).
struct FmtCompact {
  static constexpr bool is_float = false;
  static constexpr const char* name = "compact";
  using angle_t = fx<18, 4, ST_OVF_ANGLE>;
  using kturn_t = fx<18, -1, ST_OVF_CONST>;
  using turn_t = fx<26, 0>;
  using scale_t = fx<18, 3, ST_OVF_CONST>;
  using tab_t = fx<18, 2, ST_OVF_TRIG>;
  using delta_t = fx<18, -6, ST_OVF_TRIG>;
  using dsq_t = fx<18, -13, ST_OVF_TRIG>;
  using trig_acc_t = fx<26, 2, ST_OVF_TRIG>;
  using quat_t = fx<18, 2, ST_OVF_QUAT>;
  using uvec_tmp_t = fx<18, 3, ST_OVF_QUAT>;
  using len_t = fx<18, 3, ST_OVF_CONST>;       // |.| < 4 m
  using len_tmp_t = fx<18, 4, ST_OVF_POS>;
  using pos_t = fx<24, 4, ST_OVF_POS>;         // |.| < 8 m (adders only)
  using lever_t = fx<18, 3, ST_OVF_LEVER>;     // |.| < 4 m
  using jw_t = fx<18, 3, ST_OVF_JAC>;
  using jv_t = fx<18, 4, ST_OVF_JAC>;          // |s| |r| < 8
  using jw_tmp_t = fx<18, 4, ST_OVF_JAC>;
  using jv_tmp_t = fx<18, 5, ST_OVF_JAC>;
  static constexpr int TRIG_TABLE_BITS = 8;
  using twopi_t = fx<18, 4>;                   // error 3e-5 -> < 3e-8 rad on d
  using sixth_t = fx<18, 0>;
};


}  // namespace ts
