// SPDX-License-Identifier: Apache-2.0
// tensor-servo: the configuration commit step of the servo core (CTRL.COMMIT), bit-exact with the
// model's ts::commit_config (model/include/tensor_servo/core_config.hpp, with check_chain and
// derive_kturn of chain.hpp): same accept/reject decision, same first failing check (ConfigError
// code, CFG_PARAM = 10) and joint, same turn constants k = cvt<kturn_t>(s * inv4pi).
//
// in_start (the CTRL.COMMIT pulse) copies the register block's global words and the joints' JCFG
// bits (rtl/ts_servo_regs.v, ports in_* named after its out_* ports) into shadow registers, then
// runs the model's checks in the model's order; the first failure ends the commit.  A start while
// busy restarts the commit with the words present at that clock edge.  The shadow configuration
// (out_* after the status ports) changes at the start edge: engines must use it only while
// out_cfg_ok = 1 (the core sequencer holds a COMMIT until no tick is running).
// The joints' other words (origin, axis, scale, limits, VMAX, MU: 15 per joint) have no shadow:
// the checks and the loader's port read in_joint_* directly, so these inputs must not change from
// the start edge until the loader has read them (the core holds the register block's joint writes
// from the start until its loader is done: in_joint_hold of ts_servo_regs).  A shadow would hold
// 15 NMAX words (2,160 flip-flops in compact, 3,248 in default at NMAX 8) that the register block
// already holds.
//
// Arithmetic: one shared signed multiplier (ts_mul, MA_W x MB_W: 18 x 18 in compact, 27 x 32 in
// default), fed one product per cycle:
//   base quaternion, tool quaternion: 4 squares each (exact sums, |sum - 1| <= 2^-10)
//   per joint: 4 origin-quaternion squares, 3 axis squares, s * inv4pi (kturn, AP_RND + AP_SAT),
//              s * lower, s * upper (prismatic stroke |s| max(|lower|, |upper|) = max |s * limit|)
//   reach: smax * reach (the Jacobian bound), the scale of largest magnitude times the L1 reach
// Results are consumed in issue order; a joint's checks are evaluated one cycle after its last
// product.  With in_start high in cycle 0, out_done is high in cycle 10 n + 2 LAT + 15 after a
// successful commit (LAT = ts_mul_lat(MA_W, MB_W): 6 default, 3 compact; n = 6: 87 / 81); a
// failing commit ends at its first failed check (count: 2, base/tool: 12 + LAT, joint j:
// 22 + 10 j + LAT).  tb/ts_core_commit checks these cycles; see docs/rtl/ts_core_commit.md.
//
// Results: out_busy (STATUS.CFG_BUSY) from the start edge to the edge that raises out_done (one
// cycle); then out_cfg_ok or out_cfg_err, out_err_code (CFG_ERROR.CODE), out_err_joint
// (CFG_ERROR.JOINT: the joint index, 0xFF when the error is not a joint's and
// after a successful commit, as the model's joint = -1).  out_joint_kturn: k of
// every revolute joint j < n (0 for a prismatic joint), valid with out_cfg_ok.
// Unreachable model checks: MODE.SWEEPS > 255 and MODE.WARM_LEAK > 20 (the register fields are 8
// and 4 bits wide); SWEEPS = 0 is checked.
// Widths and format constants: derived from CONFIG (0 default, 1 compact), do not override; the
// bench checks them against the model (tensor_servo._model.formats).
// Language: Verilog 2005
`resetall
`timescale 1ns / 1ps
`default_nettype none

module ts_core_commit #(
  // Joint blocks of the register map (1..60)
  parameter NMAX = 8,
  // Number configuration: 0 default, 1 compact
  parameter CONFIG = 0,
  // Multiplier implementation: "GENERIC" or "ECP5" (see ts_mul)
  parameter TARGET = "GENERIC",
  // ECP5 wide products on three MULT18X18D (see ts_mul)
  parameter MUL3 = 0,
  // Register widths (as ts_servo_regs): derived from CONFIG, do not override
  parameter ANGLE_W = (CONFIG == 0) ? 32 : 18,
  parameter DT_W = (CONFIG == 0) ? 32 : 18,
  parameter GAIN_W = (CONFIG == 0) ? 27 : 18,
  parameter KLIM_W = (CONFIG == 0) ? 27 : 18,
  parameter LCHAR_W = 18,
  parameter LEN_W = (CONFIG == 0) ? 27 : 18,
  parameter MU_W = 18,
  parameter QD_W = (CONFIG == 0) ? 27 : 18,
  parameter QUAT_W = (CONFIG == 0) ? 27 : 18,
  parameter SCALE_W = (CONFIG == 0) ? 27 : 18,
  // kturn_t width (out_joint_kturn): derived from CONFIG, do not override
  parameter KT_W = (CONFIG == 0) ? 30 : 18,
  // Fraction bits of the formats the checks use: derived from CONFIG, do not override
  parameter QUAT_F = (CONFIG == 0) ? 25 : 16,
  parameter SCALE_F = (CONFIG == 0) ? 24 : 15,
  parameter LEN_F = (CONFIG == 0) ? 24 : 15,
  parameter ANGLE_F = (CONFIG == 0) ? 28 : 14,
  parameter KT_F = (CONFIG == 0) ? 31 : 20,
  // inv4pi_t and the constant round(2^INV_F / (4 pi)) (INV_W <= 32): derived from CONFIG
  parameter INV_W = (CONFIG == 0) ? 32 : 18,
  parameter INV_F = (CONFIG == 0) ? 34 : 20,
  parameter INV4PI = (CONFIG == 0) ? 1367130551 : 83443,
  // lever_t, pos_t, jv_t (the reach bounds are their RAW_MAX): derived from CONFIG
  parameter LEVER_W = (CONFIG == 0) ? 27 : 18,
  parameter LEVER_F = (CONFIG == 0) ? 23 : 15,
  parameter POS_W = (CONFIG == 0) ? 32 : 24,
  parameter POS_F = (CONFIG == 0) ? 27 : 20,
  parameter JV_W = (CONFIG == 0) ? 27 : 18,
  parameter JV_F = (CONFIG == 0) ? 22 : 14
) (
  input  wire                        clk,
  input  wire                        rst,
  // CTRL.COMMIT pulse
  input  wire                        in_start,
  // register words (ts_servo_regs out_*)
  input  wire [7:0]                  in_njoints,
  input  wire                        in_mode_err_b,
  input  wire                        in_mode_error_only,
  input  wire [7:0]                  in_mode_sweeps,
  input  wire [3:0]                  in_mode_warm_leak,
  input  wire signed [GAIN_W-1:0]    in_kp,
  input  wire signed [GAIN_W-1:0]    in_ko,
  input  wire signed [LCHAR_W-1:0]   in_lchar,
  input  wire signed [KLIM_W-1:0]    in_klim,
  input  wire signed [DT_W-1:0]      in_dt,
  input  wire signed [QUAT_W-1:0]    in_base_qw,
  input  wire signed [QUAT_W-1:0]    in_base_qx,
  input  wire signed [QUAT_W-1:0]    in_base_qy,
  input  wire signed [QUAT_W-1:0]    in_base_qz,
  input  wire signed [LEN_W-1:0]     in_base_px,
  input  wire signed [LEN_W-1:0]     in_base_py,
  input  wire signed [LEN_W-1:0]     in_base_pz,
  input  wire signed [QUAT_W-1:0]    in_tool_qw,
  input  wire signed [QUAT_W-1:0]    in_tool_qx,
  input  wire signed [QUAT_W-1:0]    in_tool_qy,
  input  wire signed [QUAT_W-1:0]    in_tool_qz,
  input  wire signed [LEN_W-1:0]     in_tool_px,
  input  wire signed [LEN_W-1:0]     in_tool_py,
  input  wire signed [LEN_W-1:0]     in_tool_pz,
  input  wire [NMAX-1:0]             in_joint_jcfg_prismatic,
  input  wire [NMAX-1:0]             in_joint_jcfg_limited,
  input  wire [NMAX-1:0]             in_joint_jcfg_vlimited,
  input  wire [NMAX*QUAT_W-1:0]      in_joint_origin_qw,
  input  wire [NMAX*QUAT_W-1:0]      in_joint_origin_qx,
  input  wire [NMAX*QUAT_W-1:0]      in_joint_origin_qy,
  input  wire [NMAX*QUAT_W-1:0]      in_joint_origin_qz,
  input  wire [NMAX*LEN_W-1:0]       in_joint_origin_px,
  input  wire [NMAX*LEN_W-1:0]       in_joint_origin_py,
  input  wire [NMAX*LEN_W-1:0]       in_joint_origin_pz,
  input  wire [NMAX*QUAT_W-1:0]      in_joint_axis_x,
  input  wire [NMAX*QUAT_W-1:0]      in_joint_axis_y,
  input  wire [NMAX*QUAT_W-1:0]      in_joint_axis_z,
  input  wire [NMAX*SCALE_W-1:0]     in_joint_scale,
  input  wire [NMAX*ANGLE_W-1:0]     in_joint_lower,
  input  wire [NMAX*ANGLE_W-1:0]     in_joint_upper,
  input  wire [NMAX*QD_W-1:0]        in_joint_vmax,
  input  wire [NMAX*MU_W-1:0]        in_joint_mu,
  // status (STATUS.CFG_BUSY, CFG_OK, CFG_ERR; CFG_ERROR.CODE, JOINT)
  output reg                         out_busy,
  output reg                         out_done,
  output reg                         out_cfg_ok,
  output reg                         out_cfg_err,
  output reg  [7:0]                  out_err_code,
  output reg  [7:0]                  out_err_joint,
  // shadow configuration (snapshot at the start edge), for the engines
  output wire [7:0]                  out_njoints,
  output wire                        out_mode_err_b,
  output wire                        out_mode_error_only,
  output wire [7:0]                  out_mode_sweeps,
  output wire [3:0]                  out_mode_warm_leak,
  output wire signed [GAIN_W-1:0]    out_kp,
  output wire signed [GAIN_W-1:0]    out_ko,
  output wire signed [LCHAR_W-1:0]   out_lchar,
  output wire signed [KLIM_W-1:0]    out_klim,
  output wire signed [DT_W-1:0]      out_dt,
  output wire signed [QUAT_W-1:0]    out_base_qw,
  output wire signed [QUAT_W-1:0]    out_base_qx,
  output wire signed [QUAT_W-1:0]    out_base_qy,
  output wire signed [QUAT_W-1:0]    out_base_qz,
  output wire signed [LEN_W-1:0]     out_base_px,
  output wire signed [LEN_W-1:0]     out_base_py,
  output wire signed [LEN_W-1:0]     out_base_pz,
  output wire signed [QUAT_W-1:0]    out_tool_qw,
  output wire signed [QUAT_W-1:0]    out_tool_qx,
  output wire signed [QUAT_W-1:0]    out_tool_qy,
  output wire signed [QUAT_W-1:0]    out_tool_qz,
  output wire signed [LEN_W-1:0]     out_tool_px,
  output wire signed [LEN_W-1:0]     out_tool_py,
  output wire signed [LEN_W-1:0]     out_tool_pz,
  output wire [NMAX-1:0]             out_joint_jcfg_prismatic,
  output wire [NMAX-1:0]             out_joint_jcfg_limited,
  output wire [NMAX-1:0]             out_joint_jcfg_vlimited,
  // k = cvt<kturn_t>(s inv4pi) per joint (0 for prismatic joints)
  output wire [NMAX*KT_W-1:0]        out_joint_kturn,
  // The loader's port: while idle (out_busy = 0) the checks' joint multiplexers select joint
  // in_ld_j of in_joint_* (VMAX as the model holds it, with the shadow's JCFG.VLIMITED), and
  // out_ld_* show its words (the core's loader reads them through these instead of a second set of
  // multiplexers); during a commit they follow the checks.
  input  wire [7:0]                  in_ld_j,
  output wire [QUAT_W-1:0]           out_ld_qo0,
  output wire [QUAT_W-1:0]           out_ld_qo1,
  output wire [QUAT_W-1:0]           out_ld_qo2,
  output wire [QUAT_W-1:0]           out_ld_qo3,
  output wire [QUAT_W-1:0]           out_ld_ax0,
  output wire [QUAT_W-1:0]           out_ld_ax1,
  output wire [QUAT_W-1:0]           out_ld_ax2,
  output wire [LEN_W-1:0]            out_ld_pox,
  output wire [LEN_W-1:0]            out_ld_poy,
  output wire [LEN_W-1:0]            out_ld_poz,
  output wire [SCALE_W-1:0]          out_ld_s,
  output wire [ANGLE_W-1:0]          out_ld_lo,
  output wire [ANGLE_W-1:0]          out_ld_hi,
  output wire [QD_W-1:0]             out_ld_vmax,
  output wire [MU_W-1:0]             out_ld_mu
);

  `include "ts_common.vh"

  // ---- derived widths and constants ------------------------------------------------------------
  localparam JI_W = (NMAX > 1) ? $clog2(NMAX) : 1;
  localparam [7:0] NMAX8 = NMAX[7:0];
  // multiplier operands: a = quaternion component or scale, b = quaternion component, inv4pi,
  // limit or reach
  localparam RB = (LEN_F >= LEVER_F) ? LEVER_W + LEN_F - LEVER_F : LEVER_W - (LEVER_F - LEN_F);
  localparam MA_W = ts_max(QUAT_W, SCALE_W);
  localparam MB_W = ts_max(ts_max(QUAT_W, INV_W), ts_max(ANGLE_W, RB));
  localparam PW = MA_W + MB_W;
  localparam LAT = ts_mul_lat(MA_W, MB_W);
  // unit norm: sum of squares (fraction 2 QUAT_F) within 2^-10 of one
  localparam ACC_W = PW + 2;
  localparam [ACC_W-1:0] ONE_C = {{(ACC_W-1){1'b0}}, 1'b1} << (2 * QUAT_F);
  localparam [ACC_W-1:0] TOL_C = {{(ACC_W-1){1'b0}}, 1'b1} << (2 * QUAT_F - 10);
  localparam [ACC_W-1:0] NLO_C = ONE_C - TOL_C;
  localparam [ACC_W-1:0] NHI_C = ONE_C + TOL_C;
  // kturn: product fraction SCALE_F + INV_F -> KT_F, AP_RND then AP_SAT
  localparam SHK = SCALE_F + INV_F - KT_F;
  localparam [PW:0] KHALF_C = {{PW{1'b0}}, 1'b1} << (SHK - 1);
  localparam [PW:0] KTMAX_C = {{(PW + 2 - KT_W){1'b0}}, {(KT_W - 1){1'b1}}};
  localparam [PW:0] KTMIN_C = ~KTMAX_C;
  // prismatic stroke |s| max(|lo|, |hi|), fraction SCALE_F + ANGLE_F -> LEN_F rounded up
  localparam SH = SCALE_F + ANGLE_F - LEN_F;
  localparam SHP = (SH > 0) ? SH : 0;
  localparam SHN = (SH < 0) ? -SH : 0;
  localparam STK_W = PW + SHN - SHP;
  localparam [PW-1:0] CEIL_C = ({{(PW-1){1'b0}}, 1'b1} << SHP) - {{(PW-1){1'b0}}, 1'b1};
  // reach (len_t raw units): at most NMAX + 1 L1 norms and NMAX strokes
  localparam RW = ts_max(STK_W, LEN_W + 2) + $clog2(NMAX + 1) + 2;
  // exact comparisons x 2^-fx < y 2^-fy as (x << SLi) < (y << SRi)
  localparam D1 = LEN_F - LEVER_F;
  localparam D2 = LEN_F - POS_F;
  localparam D3 = SCALE_F + LEN_F - JV_F;
  localparam SL1 = (D1 < 0) ? -D1 : 0;
  localparam SR1 = (D1 > 0) ? D1 : 0;
  localparam SL2 = (D2 < 0) ? -D2 : 0;
  localparam SR2 = (D2 > 0) ? D2 : 0;
  localparam SL3 = (D3 < 0) ? -D3 : 0;
  localparam SR3 = (D3 > 0) ? D3 : 0;
  localparam CW = ts_max(ts_max(RW + 1, PW), ts_max(ts_max(LEVER_W, POS_W), JV_W))
                  + SL1 + SR1 + SL2 + SR2 + SL3 + SR3 + 2;
  localparam [CW-1:0] LVMAX_C = {{(CW - LEVER_W + 1){1'b0}}, {(LEVER_W - 1){1'b1}}} << SR1;
  localparam [CW-1:0] PMAX_C = {{(CW - POS_W + 1){1'b0}}, {(POS_W - 1){1'b1}}} << SR2;
  localparam [CW-1:0] JVMAX_C = {{(CW - JV_W + 1){1'b0}}, {(JV_W - 1){1'b1}}} << SR3;
  localparam [QD_W-1:0] QDMAX_C = {1'b0, {(QD_W - 1){1'b1}}};
  localparam [INV_W-1:0] INV_C = INV4PI[INV_W-1:0];

  // error codes (ConfigError of the model, CFG_PARAM = 10)
  localparam [7:0] E_COUNT = 8'd1, E_AXIS = 8'd2, E_QUAT = 8'd3, E_LIMITS = 8'd4, E_SCALE = 8'd5,
                   E_REACH = 8'd7, E_PARAM = 8'd10;
  localparam [7:0] NOJ = 8'hFF;

  localparam [2:0] S_IDLE = 3'd0, S_COUNT = 3'd1, S_RUN = 3'd2, S_REACH = 3'd3, S_RWAIT = 3'd4,
                   S_FINAL = 3'd5;
  localparam [1:0] PH_G = 2'd0, PH_J = 2'd1, PH_R = 2'd2;
  localparam TAG_W = 1 + 2 + 4 + JI_W;

  // ---- shadow registers ---------------------------------------------------------------------------
  reg [7:0]               sh_n;
  reg                     sh_err_b, sh_error_only;
  reg [7:0]               sh_sweeps;
  reg [3:0]               sh_leak;
  reg [GAIN_W-1:0]        sh_kp, sh_ko;
  reg [LCHAR_W-1:0]       sh_lchar;
  reg [KLIM_W-1:0]        sh_klim;
  reg [DT_W-1:0]          sh_dt;
  reg [QUAT_W-1:0]        sh_bq0, sh_bq1, sh_bq2, sh_bq3, sh_tq0, sh_tq1, sh_tq2, sh_tq3;
  reg [LEN_W-1:0]         sh_bpx, sh_bpy, sh_bpz, sh_tpx, sh_tpy, sh_tpz;
  reg [NMAX-1:0]          sh_pris, sh_lim, sh_vlim;
  reg [NMAX*KT_W-1:0]     sh_kt;

  assign out_njoints = sh_n;
  assign out_mode_err_b = sh_err_b;
  assign out_mode_error_only = sh_error_only;
  assign out_mode_sweeps = sh_sweeps;
  assign out_mode_warm_leak = sh_leak;
  assign out_kp = sh_kp;
  assign out_ko = sh_ko;
  assign out_lchar = sh_lchar;
  assign out_klim = sh_klim;
  assign out_dt = sh_dt;
  assign out_base_qw = sh_bq0;
  assign out_base_qx = sh_bq1;
  assign out_base_qy = sh_bq2;
  assign out_base_qz = sh_bq3;
  assign out_base_px = sh_bpx;
  assign out_base_py = sh_bpy;
  assign out_base_pz = sh_bpz;
  assign out_tool_qw = sh_tq0;
  assign out_tool_qx = sh_tq1;
  assign out_tool_qy = sh_tq2;
  assign out_tool_qz = sh_tq3;
  assign out_tool_px = sh_tpx;
  assign out_tool_py = sh_tpy;
  assign out_tool_pz = sh_tpz;
  assign out_joint_jcfg_prismatic = sh_pris;
  assign out_joint_jcfg_limited = sh_lim;
  assign out_joint_jcfg_vlimited = sh_vlim;
  assign out_joint_kturn = sh_kt;

  // ---- helpers ------------------------------------------------------------------------------------
  // L1 norm of a len_t vector (raw, exact)
  function [LEN_W+1:0] l1;
    input [LEN_W-1:0] x;
    input [LEN_W-1:0] y;
    input [LEN_W-1:0] z;
    reg [LEN_W-1:0] ax, ay, az;
    begin
      ax = x[LEN_W-1] ? -x : x;
      ay = y[LEN_W-1] ? -y : y;
      az = z[LEN_W-1] ? -z : z;
      l1 = {2'b00, ax} + {2'b00, ay} + {2'b00, az};
    end
  endfunction

  // ---- state --------------------------------------------------------------------------------------
  reg [2:0]       state;
  // issue side
  reg             iss_act;
  reg [1:0]       iss_ph;
  reg [3:0]       iss_k;
  reg [JI_W-1:0]  iss_j;
  reg             op_v;
  reg [1:0]       op_ph;
  reg [3:0]       op_k;
  reg [JI_W-1:0]  op_j;
  reg signed [MA_W-1:0] op_a;
  reg signed [MB_W-1:0] op_b;
  reg [TAG_W*LAT-1:0] tpipe;
  // consume side
  reg [ACC_W-1:0] acc;
  reg             base_ok, tool_ok, qo_ok, ax_ok;
  reg [KT_W-1:0]  kt_val;
  reg             kt_ovf;
  reg [PW-1:0]    str_lo, str_m;
  reg             gev, jev;
  reg [JI_W-1:0]  ev_j;
  reg             cur_pris, cur_lim, cur_vlim;
  reg [SCALE_W-1:0] cur_s;
  reg [ANGLE_W-1:0] cur_lo, cur_hi;
  reg [QD_W-1:0]  cur_vmax;
  reg [MU_W-1:0]  cur_mu;
  reg [LEN_W+1:0] cur_l1;
  // |p_i| in two consume steps (k 0, k 1): the joint's select, then the sum.  At k 0 the sign-
  // flipped components (x ^ s) and the signs s; at k 1 the sum with the signs as carries, since
  // |x| = (x ^ s) + s.  In one step (select, negate, two adds) it was the commit engine's
  // critical path (15 ns post-route on LFE5U-85F -6).
  reg [LEN_W-1:0] cur_fx, cur_fy, cur_fz;
  reg [2:0]       cur_sg;
  wire [1:0]      sg_n = {1'b0, cur_sg[0]} + {1'b0, cur_sg[1]} + {1'b0, cur_sg[2]};
  reg [RW-1:0]    reach;
  reg [LEN_W+1:0] l1pb;
  reg [SCALE_W-1:0] smax_abs, smax_s;
  reg [PW-1:0]    jvp;

  wire [7:0] n_m1 = sh_n - 8'd1;
  wire [7:0] iss_j8, ev_j8;
  generate
    if (JI_W < 8) begin : g_j8
      assign iss_j8 = {{(8 - JI_W){1'b0}}, iss_j};
      assign ev_j8 = {{(8 - JI_W){1'b0}}, ev_j};
    end else begin : g_j8same
      assign iss_j8 = iss_j[7:0];
      assign ev_j8 = ev_j[7:0];
    end
  endgenerate

  // ---- operand selection (issue side) -------------------------------------------------------------
  // joint of the issue-side and consume-side multiplexers: the checks' while busy, else the loader's
  wire [JI_W-1:0] iss_jm = out_busy ? iss_j : in_ld_j[JI_W-1:0];
  wire [JI_W-1:0] c_jm;
  wire unused_ld_j = ^in_ld_j;
  wire [QUAT_W-1:0] i_qo0, i_qo1, i_qo2, i_qo3, i_ax0, i_ax1, i_ax2;
  ts_sel #(.W(QUAT_W), .N(NMAX), .IW(JI_W)) u_sel_iq0 (.in_vec(in_joint_origin_qw), .in_idx(iss_jm), .out_el(i_qo0));
  ts_sel #(.W(QUAT_W), .N(NMAX), .IW(JI_W)) u_sel_iq1 (.in_vec(in_joint_origin_qx), .in_idx(iss_jm), .out_el(i_qo1));
  ts_sel #(.W(QUAT_W), .N(NMAX), .IW(JI_W)) u_sel_iq2 (.in_vec(in_joint_origin_qy), .in_idx(iss_jm), .out_el(i_qo2));
  ts_sel #(.W(QUAT_W), .N(NMAX), .IW(JI_W)) u_sel_iq3 (.in_vec(in_joint_origin_qz), .in_idx(iss_jm), .out_el(i_qo3));
  ts_sel #(.W(QUAT_W), .N(NMAX), .IW(JI_W)) u_sel_ia0 (.in_vec(in_joint_axis_x), .in_idx(iss_jm), .out_el(i_ax0));
  ts_sel #(.W(QUAT_W), .N(NMAX), .IW(JI_W)) u_sel_ia1 (.in_vec(in_joint_axis_y), .in_idx(iss_jm), .out_el(i_ax1));
  ts_sel #(.W(QUAT_W), .N(NMAX), .IW(JI_W)) u_sel_ia2 (.in_vec(in_joint_axis_z), .in_idx(iss_jm), .out_el(i_ax2));
  reg [QUAT_W-1:0] q_sel;
  always @* begin
    q_sel = sh_bq0;
    if (iss_ph == PH_G) begin
      case (iss_k[2:0])
        3'd0: q_sel = sh_bq0;
        3'd1: q_sel = sh_bq1;
        3'd2: q_sel = sh_bq2;
        3'd3: q_sel = sh_bq3;
        3'd4: q_sel = sh_tq0;
        3'd5: q_sel = sh_tq1;
        3'd6: q_sel = sh_tq2;
        default: q_sel = sh_tq3;
      endcase
    end else begin
      case (iss_k[2:0])
        3'd0: q_sel = i_qo0;
        3'd1: q_sel = i_qo1;
        3'd2: q_sel = i_qo2;
        3'd3: q_sel = i_qo3;
        3'd4: q_sel = i_ax0;
        3'd5: q_sel = i_ax1;
        default: q_sel = i_ax2;
      endcase
    end
  end
  wire [SCALE_W-1:0] s_iss;
  wire [ANGLE_W-1:0] i_lo, i_hi;
  ts_sel #(.W(SCALE_W), .N(NMAX), .IW(JI_W)) u_sel_is (.in_vec(in_joint_scale), .in_idx(iss_jm), .out_el(s_iss));
  ts_sel #(.W(ANGLE_W), .N(NMAX), .IW(JI_W)) u_sel_ilo (.in_vec(in_joint_lower), .in_idx(iss_jm), .out_el(i_lo));
  ts_sel #(.W(ANGLE_W), .N(NMAX), .IW(JI_W)) u_sel_ihi (.in_vec(in_joint_upper), .in_idx(iss_jm), .out_el(i_hi));
  wire [ANGLE_W-1:0] lim_iss = (iss_k == 4'd8) ? i_lo : i_hi;
  // joint c_j's words as the consume stage takes them
  wire [SCALE_W-1:0] cj_s;
  wire [ANGLE_W-1:0] cj_lo, cj_hi;
  wire [QD_W-1:0] cj_vmax;
  wire [MU_W-1:0] cj_mu;
  wire [LEN_W-1:0] cj_pox, cj_poy, cj_poz;
  ts_sel #(.W(SCALE_W), .N(NMAX), .IW(JI_W)) u_sel_cs (.in_vec(in_joint_scale), .in_idx(c_jm), .out_el(cj_s));
  ts_sel #(.W(ANGLE_W), .N(NMAX), .IW(JI_W)) u_sel_clo (.in_vec(in_joint_lower), .in_idx(c_jm), .out_el(cj_lo));
  ts_sel #(.W(ANGLE_W), .N(NMAX), .IW(JI_W)) u_sel_chi (.in_vec(in_joint_upper), .in_idx(c_jm), .out_el(cj_hi));
  ts_sel #(.W(QD_W), .N(NMAX), .IW(JI_W)) u_sel_cvm (.in_vec(in_joint_vmax), .in_idx(c_jm), .out_el(cj_vmax));
  ts_sel #(.W(MU_W), .N(NMAX), .IW(JI_W)) u_sel_cmu (.in_vec(in_joint_mu), .in_idx(c_jm), .out_el(cj_mu));
  ts_sel #(.W(LEN_W), .N(NMAX), .IW(JI_W)) u_sel_cpx (.in_vec(in_joint_origin_px), .in_idx(c_jm), .out_el(cj_pox));
  ts_sel #(.W(LEN_W), .N(NMAX), .IW(JI_W)) u_sel_cpy (.in_vec(in_joint_origin_py), .in_idx(c_jm), .out_el(cj_poy));
  ts_sel #(.W(LEN_W), .N(NMAX), .IW(JI_W)) u_sel_cpz (.in_vec(in_joint_origin_pz), .in_idx(c_jm), .out_el(cj_poz));
  wire [RB-1:0] reach_op = {1'b0, reach[RB-2:0]};

  wire signed [MA_W-1:0] qa, sa, ma;
  wire signed [MB_W-1:0] qb, ib, lb, rb;
  ts_resize #(.IN_W(QUAT_W), .LSH(0), .OUT_W(MA_W)) u_qa (.in(q_sel), .out(qa));
  ts_resize #(.IN_W(QUAT_W), .LSH(0), .OUT_W(MB_W)) u_qb (.in(q_sel), .out(qb));
  ts_resize #(.IN_W(SCALE_W), .LSH(0), .OUT_W(MA_W)) u_sa (.in(s_iss), .out(sa));
  ts_resize #(.IN_W(SCALE_W), .LSH(0), .OUT_W(MA_W)) u_ma (.in(smax_s), .out(ma));
  ts_resize #(.IN_W(INV_W), .LSH(0), .OUT_W(MB_W)) u_ib (.in(INV_C), .out(ib));
  ts_resize #(.IN_W(ANGLE_W), .LSH(0), .OUT_W(MB_W)) u_lb (.in(lim_iss), .out(lb));
  ts_resize #(.IN_W(RB), .LSH(0), .OUT_W(MB_W)) u_rb (.in(reach_op), .out(rb));

  wire issue_sk = (iss_ph == PH_J) && (iss_k >= 4'd7);
  wire signed [MA_W-1:0] a_sel = issue_sk ? sa : qa;
  wire signed [MB_W-1:0] b_sel = !issue_sk ? qb : ((iss_k == 4'd7) ? ib : lb);

  // ---- the shared multiplier and the tag pipeline ------------------------------------------------
  wire signed [PW-1:0] p;
  ts_mul #(.A_W(MA_W), .B_W(MB_W), .TARGET(TARGET), .MUL3(MUL3)) u_mul (
    .clk(clk), .rst(rst), .a(op_a), .b(op_b), .p(p));

  wire [TAG_W-1:0] t_out = tpipe[TAG_W*LAT-1 -: TAG_W];
  wire             c_v = t_out[TAG_W-1];
  wire [1:0]       c_ph = t_out[TAG_W-2 -: 2];
  wire [3:0]       c_k = t_out[TAG_W-4 -: 4];
  wire [JI_W-1:0]  c_j = t_out[JI_W-1:0];
  assign c_jm = out_busy ? c_j : in_ld_j[JI_W-1:0];
  assign out_ld_qo0 = i_qo0;
  assign out_ld_qo1 = i_qo1;
  assign out_ld_qo2 = i_qo2;
  assign out_ld_qo3 = i_qo3;
  assign out_ld_ax0 = i_ax0;
  assign out_ld_ax1 = i_ax1;
  assign out_ld_ax2 = i_ax2;
  assign out_ld_pox = cj_pox;
  assign out_ld_poy = cj_poy;
  assign out_ld_poz = cj_poz;
  assign out_ld_s = cj_s;
  assign out_ld_lo = cj_lo;
  assign out_ld_hi = cj_hi;
  // velocity limit as the model holds it: VMAX when JCFG.VLIMITED, else max(qd_t)
  assign out_ld_vmax = sh_vlim[c_jm] ? cj_vmax : QDMAX_C;
  assign out_ld_mu = cj_mu;

  // ---- consume-side arithmetic --------------------------------------------------------------------
  wire [ACC_W-1:0] p_acc;
  ts_resize #(.IN_W(PW), .LSH(0), .OUT_W(ACC_W)) u_pacc (.in(p), .out(p_acc));
  wire             first_sq = (c_k == 4'd0) || (c_k == 4'd4);
  wire [ACC_W-1:0] acc_next = first_sq ? p_acc : acc + p_acc;
  wire             unit_ok = (acc_next >= NLO_C) && (acc_next <= NHI_C);

  wire signed [PW:0] pk;
  ts_resize #(.IN_W(PW), .LSH(0), .OUT_W(PW + 1)) u_pk (.in(p), .out(pk));
  wire signed [PW:0] khalf = KHALF_C;
  wire signed [PW:0] ktmax = KTMAX_C;
  wire signed [PW:0] ktmin = KTMIN_C;
  wire signed [PW:0] kr = (pk + khalf) >>> SHK;
  wire             kr_hi = kr > ktmax;
  wire             kr_lo = kr < ktmin;
  wire [KT_W-1:0]  kr_sat = kr_hi ? ktmax[KT_W-1:0] : (kr_lo ? ktmin[KT_W-1:0] : kr[KT_W-1:0]);

  wire [PW-1:0]    p_abs = p[PW-1] ? -p : p;
  wire [PW-1:0]    str_max = (p_abs > str_lo) ? p_abs : str_lo;

  // stroke of the evaluated joint, rounded up to len_t
  wire [STK_W-1:0] stroke;
  generate
    if (SH > 0) begin : g_ceil
      wire [PW-1:0] str_up = str_m + CEIL_C;
      assign stroke = str_up[PW-1:SHP];
      wire unused_str = ^str_up[SHP-1:0];
    end else begin : g_lsh
      assign stroke = {str_m, {SHN{1'b0}}};
      wire unused_ceil = ^CEIL_C;
    end
  endgenerate

  // ---- checks of the evaluated joint -------------------------------------------------------------
  // The comparisons are registered every cycle: cur_* are taken at k 0 and smax_abs at the previous
  // joint's check, both at least ten cycles before jev, so the registered flags are those of the
  // current words when jev acts (the comparators, the error priority and the enables fanning out
  // from it were the commit engine's critical path in one cycle, 14.5 ns post-route).
  wire [SCALE_W-1:0] s_abs = cur_s[SCALE_W-1] ? -cur_s : cur_s;
  reg              s_zero, lo_gt_hi, vmax_bad, s_gt_max;
  always @(posedge clk) begin
    s_zero <= (cur_s == {SCALE_W{1'b0}});
    lo_gt_hi <= $signed(cur_hi) < $signed(cur_lo);
    vmax_bad <= cur_vmax[QD_W-1] || (cur_vmax == {QD_W{1'b0}});
    s_gt_max <= s_abs > smax_abs;
  end
  wire [RW-1:0]    l1_w, stroke_w;
  generate
    if (RW > LEN_W + 2) begin : g_l1w
      assign l1_w = {{(RW - LEN_W - 2){1'b0}}, cur_l1};
    end else begin : g_l1same
      assign l1_w = cur_l1;
    end
    if (RW > STK_W) begin : g_stkw
      assign stroke_w = {{(RW - STK_W){1'b0}}, stroke};
    end else begin : g_stksame
      assign stroke_w = stroke;
    end
  endgenerate
  wire [RW-1:0]    reach_next = reach + l1_w + (cur_pris ? stroke_w : {RW{1'b0}});

  // ---- reach bounds -------------------------------------------------------------------------------
  wire [CW-1:0] reach_c = {{(CW - RW){1'b0}}, reach};
  wire [CW-1:0] l1pb_c = {{(CW - LEN_W - 2){1'b0}}, l1pb};
  wire [CW-1:0] jvp_c = {{(CW - PW){1'b0}}, jvp};
  wire [CW-1:0] r2_c = reach_c + l1pb_c;
  wire          r1_ok = (reach_c << SL1) < LVMAX_C;
  wire          r2_ok = (r2_c << SL2) < PMAX_C;
  wire          r3_ok = (jvp_c << SL3) < JVMAX_C;

  // ---- servo parameters ---------------------------------------------------------------------------
  wire lchar_bad = sh_lchar[LCHAR_W-1] || (sh_lchar == {LCHAR_W{1'b0}});
  wire dt_bad = sh_dt[DT_W-1] || (sh_dt == {DT_W{1'b0}});
  wire gain_bad = sh_kp[GAIN_W-1] || sh_ko[GAIN_W-1];
  wire klim_bad = sh_klim[KLIM_W-1];
  wire sweeps_bad = (sh_sweeps == 8'd0);

  // ---- sequencer ----------------------------------------------------------------------------------
  task finish;
    input       ok;
    input [7:0] code;
    input [7:0] joint;
    begin
      state <= S_IDLE;
      iss_act <= 1'b0;
      out_busy <= 1'b0;
      out_done <= 1'b1;
      out_cfg_ok <= ok;
      out_cfg_err <= !ok;
      out_err_code <= code;
      out_err_joint <= joint;
    end
  endtask

  integer ki;
  always @(posedge clk) begin
    if (rst) begin
      state <= S_IDLE;
      out_busy <= 1'b0;
      out_done <= 1'b0;
      out_cfg_ok <= 1'b0;
      out_cfg_err <= 1'b0;
      out_err_code <= 8'd0;
      out_err_joint <= 8'd0;
      sh_n <= 8'd0;
      sh_err_b <= 1'b0;
      sh_error_only <= 1'b0;
      sh_sweeps <= 8'd0;
      sh_leak <= 4'd0;
      sh_kp <= {GAIN_W{1'b0}};
      sh_ko <= {GAIN_W{1'b0}};
      sh_lchar <= {LCHAR_W{1'b0}};
      sh_klim <= {KLIM_W{1'b0}};
      sh_dt <= {DT_W{1'b0}};
      sh_bq0 <= {QUAT_W{1'b0}};
      sh_bq1 <= {QUAT_W{1'b0}};
      sh_bq2 <= {QUAT_W{1'b0}};
      sh_bq3 <= {QUAT_W{1'b0}};
      sh_tq0 <= {QUAT_W{1'b0}};
      sh_tq1 <= {QUAT_W{1'b0}};
      sh_tq2 <= {QUAT_W{1'b0}};
      sh_tq3 <= {QUAT_W{1'b0}};
      sh_bpx <= {LEN_W{1'b0}};
      sh_bpy <= {LEN_W{1'b0}};
      sh_bpz <= {LEN_W{1'b0}};
      sh_tpx <= {LEN_W{1'b0}};
      sh_tpy <= {LEN_W{1'b0}};
      sh_tpz <= {LEN_W{1'b0}};
      sh_pris <= {NMAX{1'b0}};
      sh_lim <= {NMAX{1'b0}};
      sh_vlim <= {NMAX{1'b0}};
      sh_kt <= {(NMAX*KT_W){1'b0}};
      iss_act <= 1'b0;
      iss_ph <= PH_G;
      iss_k <= 4'd0;
      iss_j <= {JI_W{1'b0}};
      op_v <= 1'b0;
      op_ph <= PH_G;
      op_k <= 4'd0;
      op_j <= {JI_W{1'b0}};
      op_a <= {MA_W{1'b0}};
      op_b <= {MB_W{1'b0}};
      tpipe <= {(TAG_W*LAT){1'b0}};
      acc <= {ACC_W{1'b0}};
      base_ok <= 1'b0;
      tool_ok <= 1'b0;
      qo_ok <= 1'b0;
      ax_ok <= 1'b0;
      kt_val <= {KT_W{1'b0}};
      kt_ovf <= 1'b0;
      str_lo <= {PW{1'b0}};
      str_m <= {PW{1'b0}};
      gev <= 1'b0;
      jev <= 1'b0;
      ev_j <= {JI_W{1'b0}};
      cur_pris <= 1'b0;
      cur_lim <= 1'b0;
      cur_vlim <= 1'b0;
      cur_s <= {SCALE_W{1'b0}};
      cur_lo <= {ANGLE_W{1'b0}};
      cur_hi <= {ANGLE_W{1'b0}};
      cur_vmax <= {QD_W{1'b0}};
      cur_mu <= {MU_W{1'b0}};
      cur_l1 <= {(LEN_W+2){1'b0}};
      cur_fx <= {LEN_W{1'b0}};
      cur_fy <= {LEN_W{1'b0}};
      cur_fz <= {LEN_W{1'b0}};
      cur_sg <= 3'b000;
      reach <= {RW{1'b0}};
      l1pb <= {(LEN_W+2){1'b0}};
      smax_abs <= {SCALE_W{1'b0}};
      smax_s <= {SCALE_W{1'b0}};
      jvp <= {PW{1'b0}};
    end else begin
      // defaults: one-cycle strobes, tag pipeline shifts
      out_done <= 1'b0;
      gev <= 1'b0;
      jev <= 1'b0;
      op_v <= 1'b0;
      tpipe <= {tpipe[TAG_W*(LAT-1)-1:0], op_v, op_ph, op_k, op_j};

      if (in_start) begin
        // snapshot and (re)start
        sh_n <= in_njoints;
        sh_err_b <= in_mode_err_b;
        sh_error_only <= in_mode_error_only;
        sh_sweeps <= in_mode_sweeps;
        sh_leak <= in_mode_warm_leak;
        sh_kp <= in_kp;
        sh_ko <= in_ko;
        sh_lchar <= in_lchar;
        sh_klim <= in_klim;
        sh_dt <= in_dt;
        sh_bq0 <= in_base_qw;
        sh_bq1 <= in_base_qx;
        sh_bq2 <= in_base_qy;
        sh_bq3 <= in_base_qz;
        sh_bpx <= in_base_px;
        sh_bpy <= in_base_py;
        sh_bpz <= in_base_pz;
        sh_tq0 <= in_tool_qw;
        sh_tq1 <= in_tool_qx;
        sh_tq2 <= in_tool_qy;
        sh_tq3 <= in_tool_qz;
        sh_tpx <= in_tool_px;
        sh_tpy <= in_tool_py;
        sh_tpz <= in_tool_pz;
        sh_pris <= in_joint_jcfg_prismatic;
        sh_lim <= in_joint_jcfg_limited;
        sh_vlim <= in_joint_jcfg_vlimited;
        sh_kt <= {(NMAX*KT_W){1'b0}};
        state <= S_COUNT;
        iss_act <= 1'b0;
        tpipe <= {(TAG_W*LAT){1'b0}};
        out_busy <= 1'b1;
        out_cfg_ok <= 1'b0;
        out_cfg_err <= 1'b0;
        out_err_code <= 8'd0;
        out_err_joint <= NOJ;
      end else begin
        case (state)
          S_COUNT: begin
            // 1. joint count
            if ((sh_n == 8'd0) || (sh_n > NMAX8)) begin
              finish(1'b0, E_COUNT, NOJ);
            end else begin
              state <= S_RUN;
              iss_act <= 1'b1;
              iss_ph <= PH_G;
              iss_k <= 4'd0;
              iss_j <= {JI_W{1'b0}};
              reach <= {{(RW - LEN_W - 2){1'b0}}, l1(sh_tpx, sh_tpy, sh_tpz)};
              l1pb <= l1(sh_bpx, sh_bpy, sh_bpz);
              smax_abs <= {SCALE_W{1'b0}};
              smax_s <= {SCALE_W{1'b0}};
            end
          end

          S_RUN: begin
            // issue: base and tool squares, then 10 products per joint
            if (iss_act) begin
              op_v <= 1'b1;
              op_ph <= iss_ph;
              op_k <= iss_k;
              op_j <= iss_j;
              op_a <= a_sel;
              op_b <= b_sel;
              if (iss_ph == PH_G) begin
                if (iss_k == 4'd7) begin
                  iss_ph <= PH_J;
                  iss_k <= 4'd0;
                end else begin
                  iss_k <= iss_k + 4'd1;
                end
              end else if (iss_k == 4'd9) begin
                iss_k <= 4'd0;
                if (iss_j8 == n_m1) iss_act <= 1'b0;
                else iss_j <= iss_j + {{(JI_W-1){1'b0}}, 1'b1};
              end else begin
                iss_k <= iss_k + 4'd1;
              end
            end

            // consume, in issue order
            if (c_v && (c_ph == PH_G)) begin
              acc <= acc_next;
              if (c_k == 4'd3) base_ok <= unit_ok;
              if (c_k == 4'd7) begin
                tool_ok <= unit_ok;
                gev <= 1'b1;
              end
            end
            if (c_v && (c_ph == PH_J)) begin
              if (c_k == 4'd0) begin
                cur_pris <= sh_pris[c_j];
                cur_lim <= sh_lim[c_j];
                cur_vlim <= sh_vlim[c_j];
                cur_s <= cj_s;
                cur_lo <= cj_lo;
                cur_hi <= cj_hi;
                cur_vmax <= cj_vmax;
                cur_mu <= cj_mu;
                cur_fx <= cj_pox ^ {LEN_W{cj_pox[LEN_W-1]}};
                cur_fy <= cj_poy ^ {LEN_W{cj_poy[LEN_W-1]}};
                cur_fz <= cj_poz ^ {LEN_W{cj_poz[LEN_W-1]}};
                cur_sg <= {cj_poz[LEN_W-1], cj_poy[LEN_W-1], cj_pox[LEN_W-1]};
              end
              if (c_k == 4'd1)
                cur_l1 <= ({2'b00, cur_fx} + {2'b00, cur_fy}) + ({2'b00, cur_fz} + {{LEN_W{1'b0}}, sg_n});
              if (c_k <= 4'd6) acc <= acc_next;
              if (c_k == 4'd3) qo_ok <= unit_ok;
              if (c_k == 4'd6) ax_ok <= unit_ok;
              if (c_k == 4'd7) begin
                kt_val <= kr_sat;
                kt_ovf <= kr_hi || kr_lo;
              end
              if (c_k == 4'd8) str_lo <= p_abs;
              if (c_k == 4'd9) begin
                str_m <= str_max;
                jev <= 1'b1;
                ev_j <= c_j;
              end
            end

            // 2. base and tool quaternions
            if (gev) begin
              if (!base_ok) finish(1'b0, E_QUAT, NOJ);
              else if (!tool_ok) finish(1'b0, E_QUAT, NOJ);
            end
            // 3. joint ev_j, in the model's order
            if (jev) begin
              if (!qo_ok) finish(1'b0, E_QUAT, ev_j8);
              else if (!ax_ok) finish(1'b0, E_AXIS, ev_j8);
              else if (s_zero) finish(1'b0, E_SCALE, ev_j8);
              else if (!cur_pris && kt_ovf) finish(1'b0, E_SCALE, ev_j8);
              else if (cur_pris && !cur_lim) finish(1'b0, E_LIMITS, ev_j8);
              else if (cur_lim && lo_gt_hi) finish(1'b0, E_LIMITS, ev_j8);
              else if (cur_vlim && vmax_bad) finish(1'b0, E_LIMITS, ev_j8);
              else if (cur_mu[MU_W-1]) finish(1'b0, E_PARAM, ev_j8);
              else begin
                for (ki = 0; ki < NMAX; ki = ki + 1)
                  if ({{(32 - JI_W){1'b0}}, ev_j} == ki) sh_kt[ki*KT_W +: KT_W] <= cur_pris ? {KT_W{1'b0}} : kt_val;
                reach <= reach_next;
                if (s_gt_max) begin
                  smax_abs <= s_abs;
                  smax_s <= cur_s;
                end
                if (ev_j8 == n_m1) state <= S_REACH;
              end
            end
          end

          S_REACH: begin
            // 4c. smax * reach
            op_v <= 1'b1;
            op_ph <= PH_R;
            op_k <= 4'd0;
            op_j <= {JI_W{1'b0}};
            op_a <= ma;
            op_b <= rb;
            state <= S_RWAIT;
          end

          S_RWAIT: begin
            if (c_v && (c_ph == PH_R)) begin
              jvp <= p_abs;
              state <= S_FINAL;
            end
          end

          S_FINAL: begin
            // 4. reach, 5. servo parameters
            if (!r1_ok) finish(1'b0, E_REACH, NOJ);
            else if (!r2_ok) finish(1'b0, E_REACH, NOJ);
            else if (!r3_ok) finish(1'b0, E_REACH, NOJ);
            else if (lchar_bad) finish(1'b0, E_PARAM, NOJ);
            else if (dt_bad) finish(1'b0, E_PARAM, NOJ);
            else if (gain_bad) finish(1'b0, E_PARAM, NOJ);
            else if (klim_bad) finish(1'b0, E_PARAM, NOJ);
            else if (sweeps_bad) finish(1'b0, E_PARAM, NOJ);
            else finish(1'b1, 8'd0, NOJ);
          end

          default: begin
          end
        endcase
      end
    end
  end

endmodule

`default_nettype wire
