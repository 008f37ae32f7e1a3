// SPDX-License-Identifier: Apache-2.0
// tensor-servo: the servo law of the core's front half (one task: the tool, setpoint U in the root
// frame, controlled frame = tool), bit-exact with ts::task_error (model/include/tensor_servo/servo.hpp)
// apart from the forward kinematics and the root-basis Jacobian, which rtl/ts_core_fk.v computes.
// From the tool pose (Q_P, p_P), the setpoint U = (Q_U, p_U, w_U, v_U), the gains kp, ko and the
// mode bits:
//   dp = cvt<perr_t>(p_U - p_P)
//   error choice A:  ep = dp,  eo = rotvec(Q_U (x) conj(Q_P))
//                    V_w = cvt<vel_t>(w_U + ko eo),  V_v = cvt<vel_t>(v_U + kp ep)
//   error choice B:  ep = rotate<perr_t, len_tmp_t, INV>(Q_P, dp),  eo = rotvec(conj(Q_P) (x) Q_U)
//                    ffw = rotate<vel_t, jv_tmp_t, INV>(Q_P, w_U)
//                    ffv = rotate<vel_t, jv_tmp_t, INV>(Q_P, cvt<vel_t>(v_U + cross<vel_t>(dp, w_U)))
//                    V_w = cvt<vel_t>(ffw + ko eo),  V_v = cvt<vel_t>(ffv + kp ep)
//   error only (no feed-forward): w_U, v_U (A) or ffw, ffv (B) are zero (and B's feed-forward
//                    rotations are not run, so they raise no flag).
//   rotvec(q): q negated if w < 0 (cvt<quat_t>(-x)); idx = w >> (Q_F - 6), frac = the low bits
//              (idx > 64: 64, frac 0); f = cvt<rvf_t>(F[idx] + dF[idx] frac) (table ROM_FILE,
//              rtl/ts_rotvec_rom_<config>.mem); eo_a = cvt<rot_t>(2 f q_a).
// Sequenced dataflow (one evaluation per in_start, out_busy until out_done; the inputs are
// registered at the start edge).  out_flags: the model's Status bits this evaluation raises
// (bit 3 ovf_quat, 4 ovf_pos, 6 ovf_jac, 9 ovf_servo), sticky from in_start to the next in_start,
// including the flags of the column port below.
// Column port (II = FOLD, latency COL_LAT): a root-basis Jacobian column (omega: jw_t, v: jv_t, as
// ts_core_fk's column port gives it) in, the column in the basis the error uses out: mode B
// rotates both halves by conj(Q_P) (rotate<jw_t, jw_tmp_t, INV>, rotate<jv_t, jv_tmp_t, INV>:
// ts::jacobian with basis = tool), mode A passes it through (same latency).  It uses the tool
// quaternion and mode registered at the last in_start; stream the columns after that start (while
// busy or after done), not across a start.
// Language: Verilog 2005
`resetall
`timescale 1ns / 1ps
`default_nettype none

module ts_core_law #(
  // Number configuration: 0 default, 1 compact
  parameter CONFIG = 0,
  // rotation-vector table memory file (rtl/ts_rotvec_rom_<config>.mem); must match CONFIG
  parameter ROM_FILE = "ts_rotvec_rom_default.mem",
  // Multiplier implementation: "GENERIC" or "ECP5" (see ts_mul)
  parameter TARGET = "GENERIC",
  // ECP5 wide products on three MULT18X18D (see ts_mul)
  parameter MUL3 = 0,
  // Products per multiplier of the quaternion product and the column rotations (ts_mul_bank);
  // the column port's II
  parameter FOLD = 1,
  // Folded multiplier banks (FOLD > 1): 1 holds their operands and products in shift chains
  // (ts_mul_bank CHAIN; the same bits and cycles, more registers, shorter wires).
  parameter CHAIN = 0,
  // Width of quat_t: derived from CONFIG, do not override
  parameter Q_W = (CONFIG == 0) ? 27 : 18,
  // Width of pos_t: derived from CONFIG, do not override
  parameter P_W = (CONFIG == 0) ? 32 : 24,
  // Width of vel_t: derived from CONFIG, do not override
  parameter V_W = (CONFIG == 0) ? 27 : 18,
  // Width of gain_t: derived from CONFIG, do not override
  parameter G_W = (CONFIG == 0) ? 27 : 18,
  // Width of perr_t: derived from CONFIG, do not override
  parameter PE_W = (CONFIG == 0) ? 27 : 18,
  // Width of rot_t: derived from CONFIG, do not override
  parameter RO_W = (CONFIG == 0) ? 27 : 18,
  // Width of jw_t: derived from CONFIG, do not override
  parameter JW_W = (CONFIG == 0) ? 27 : 18,
  // Width of jv_t: derived from CONFIG, do not override
  parameter JV_W = (CONFIG == 0) ? 27 : 18
) (
  input  wire                   clk,
  input  wire                   rst,
  // control
  input  wire                   in_start,
  input  wire                   in_mode_b,      // 1: error choice B
  input  wire                   in_err_only,    // 1: no feed-forward (error-only mode)
  input  wire signed [G_W-1:0]  in_kp,          // gain_t
  input  wire signed [G_W-1:0]  in_ko,          // gain_t
  output reg                    out_busy,
  output reg                    out_done,
  output reg  [15:0]            out_flags,
  // tool pose (root frame), from ts_core_fk
  input  wire signed [Q_W-1:0]  in_tool_q_w,
  input  wire signed [Q_W-1:0]  in_tool_q_x,
  input  wire signed [Q_W-1:0]  in_tool_q_y,
  input  wire signed [Q_W-1:0]  in_tool_q_z,
  input  wire signed [P_W-1:0]  in_tool_p_x,
  input  wire signed [P_W-1:0]  in_tool_p_y,
  input  wire signed [P_W-1:0]  in_tool_p_z,
  // setpoint (root frame)
  input  wire signed [Q_W-1:0]  in_u_q_w,
  input  wire signed [Q_W-1:0]  in_u_q_x,
  input  wire signed [Q_W-1:0]  in_u_q_y,
  input  wire signed [Q_W-1:0]  in_u_q_z,
  input  wire signed [P_W-1:0]  in_u_p_x,
  input  wire signed [P_W-1:0]  in_u_p_y,
  input  wire signed [P_W-1:0]  in_u_p_z,
  input  wire signed [V_W-1:0]  in_u_w_x,
  input  wire signed [V_W-1:0]  in_u_w_y,
  input  wire signed [V_W-1:0]  in_u_w_z,
  input  wire signed [V_W-1:0]  in_u_v_x,
  input  wire signed [V_W-1:0]  in_u_v_y,
  input  wire signed [V_W-1:0]  in_u_v_z,
  // results (valid from out_done until the next in_start)
  output reg  signed [PE_W-1:0] out_ep_x,
  output reg  signed [PE_W-1:0] out_ep_y,
  output reg  signed [PE_W-1:0] out_ep_z,
  output reg  signed [RO_W-1:0] out_eo_x,
  output reg  signed [RO_W-1:0] out_eo_y,
  output reg  signed [RO_W-1:0] out_eo_z,
  output reg  signed [V_W-1:0]  out_vw_x,
  output reg  signed [V_W-1:0]  out_vw_y,
  output reg  signed [V_W-1:0]  out_vw_z,
  output reg  signed [V_W-1:0]  out_vv_x,
  output reg  signed [V_W-1:0]  out_vv_y,
  output reg  signed [V_W-1:0]  out_vv_z,
  // column port
  input  wire                   in_col_valid,
  input  wire signed [JW_W-1:0] in_col_w_x,
  input  wire signed [JW_W-1:0] in_col_w_y,
  input  wire signed [JW_W-1:0] in_col_w_z,
  input  wire signed [JV_W-1:0] in_col_v_x,
  input  wire signed [JV_W-1:0] in_col_v_y,
  input  wire signed [JV_W-1:0] in_col_v_z,
  output wire                   out_col_valid,
  output wire signed [JW_W-1:0] out_col_w_x,
  output wire signed [JW_W-1:0] out_col_w_y,
  output wire signed [JW_W-1:0] out_col_w_z,
  output wire signed [JV_W-1:0] out_col_v_x,
  output wire signed [JV_W-1:0] out_col_v_y,
  output wire signed [JV_W-1:0] out_col_v_z,
  output wire                   out_col_sat
);

  `include "ts_common.vh"
  // Formats of the configuration (ap_fixed<W, I>, F = W - I), the values of rtl/ts_formats.vh
  // (which cannot be included lint-clean here); tb/ts_core_law checks them against the model.
  localparam TS_QUAT_F = (CONFIG == 0) ? 25 : 16;
  localparam TS_POS_F = (CONFIG == 0) ? 27 : 20;
  localparam TS_VEL_F = (CONFIG == 0) ? 21 : 12;
  localparam TS_GAIN_F = (CONFIG == 0) ? 12 : 3;
  localparam TS_PERR_F = (CONFIG == 0) ? 23 : 14;
  localparam TS_ROT_F = (CONFIG == 0) ? 24 : 15;
  localparam TS_RVF_W = (CONFIG == 0) ? 27 : 18;
  localparam TS_RVF_F = (CONFIG == 0) ? 25 : 16;
  localparam TS_LEN_TMP_W = (CONFIG == 0) ? 27 : 18;
  localparam TS_LEN_TMP_F = (CONFIG == 0) ? 22 : 14;
  localparam TS_JV_TMP_W = (CONFIG == 0) ? 27 : 18;
  localparam TS_JV_TMP_F = (CONFIG == 0) ? 21 : 13;
  localparam TS_JW_TMP_W = (CONFIG == 0) ? 27 : 18;
  localparam TS_JW_TMP_F = (CONFIG == 0) ? 23 : 14;
  localparam TS_JW_F = (CONFIG == 0) ? 24 : 15;
  localparam TS_JV_F = (CONFIG == 0) ? 22 : 14;
  localparam TS_ROTVEC_TABLE_BITS = 6;

  localparam Q_F = TS_QUAT_F;
  localparam P_F = TS_POS_F;
  localparam V_F = TS_VEL_F;
  localparam G_F = TS_GAIN_F;
  localparam PE_F = TS_PERR_F;
  localparam RO_F = TS_ROT_F;
  localparam RV_W = TS_RVF_W;
  localparam RV_F = TS_RVF_F;
  localparam RL = ts_round_lat(1);
  localparam TB = TS_ROTVEC_TABLE_BITS;
  // fraction bits of the interpolation weight, index width (w < 2 after the sign flip)
  localparam FB = Q_F - TB;
  localparam IX_W = Q_W - 1 - FB;

  generate
    if ((FB < 1) || (IX_W < TB + 1) || (Q_F + TS_LEN_TMP_F < PE_F) || (Q_F + TS_JV_TMP_F < V_F) ||
        (RO_W != PE_W)) begin : g_bad
      // Elaboration error: a width parameter was overridden inconsistently with CONFIG.
      ts_core_law_inconsistent_width_parameters u_error ();
    end
  endgenerate

  // Status bits (fixed.hpp StatusBit)
  localparam ST_QUAT = 3, ST_POS = 4, ST_JAC = 6, ST_SERVO = 9;

  genvar gi;
  integer k;
  integer ki;  // loop index of the input registers (one loop variable per process: no shared register)

  // ---- inputs, registered at the start edge -------------------------------------------------------
  wire start = in_start && !out_busy;
  reg r_mb, r_ff;
  reg signed [G_W-1:0] r_kp, r_ko;
  reg signed [Q_W-1:0] tq [0:3];
  reg signed [P_W-1:0] tp [0:2];
  reg signed [Q_W-1:0] uq [0:3];
  reg signed [P_W-1:0] up [0:2];
  reg signed [V_W-1:0] uw [0:2];
  reg signed [V_W-1:0] uv [0:2];
  always @(posedge clk) begin
    if (rst) begin
      r_mb <= 1'b0;
      r_ff <= 1'b0;
      r_kp <= {G_W{1'b0}};
      r_ko <= {G_W{1'b0}};
      for (ki = 0; ki < 4; ki = ki + 1) begin
        tq[ki] <= {Q_W{1'b0}};
        uq[ki] <= {Q_W{1'b0}};
      end
      for (ki = 0; ki < 3; ki = ki + 1) begin
        tp[ki] <= {P_W{1'b0}};
        up[ki] <= {P_W{1'b0}};
        uw[ki] <= {V_W{1'b0}};
        uv[ki] <= {V_W{1'b0}};
      end
    end else if (start) begin
      r_mb <= in_mode_b;
      r_ff <= !in_err_only;
      r_kp <= in_kp;
      r_ko <= in_ko;
      tq[0] <= in_tool_q_w; tq[1] <= in_tool_q_x; tq[2] <= in_tool_q_y; tq[3] <= in_tool_q_z;
      tp[0] <= in_tool_p_x; tp[1] <= in_tool_p_y; tp[2] <= in_tool_p_z;
      uq[0] <= in_u_q_w; uq[1] <= in_u_q_x; uq[2] <= in_u_q_y; uq[3] <= in_u_q_z;
      up[0] <= in_u_p_x; up[1] <= in_u_p_y; up[2] <= in_u_p_z;
      uw[0] <= in_u_w_x; uw[1] <= in_u_w_y; uw[2] <= in_u_w_z;
      uv[0] <= in_u_v_x; uv[1] <= in_u_v_y; uv[2] <= in_u_v_z;
    end
  end

  // Pulses of the dataflow: each marks the cycle in which a result is on its wires (it is latched
  // at the end of that cycle).  Every stage below s0 except the quaternion product and the shared
  // rotation reads held registers, so its output stays valid from its latency on.
  reg s0;   // the registered inputs are valid
  reg b0;   // conj(Q_P) and dp latched
  reg c0;   // the error quaternion latched
  reg c1;   // the sign-corrected error quaternion latched
  reg c2;   // f latched
  reg d0;   // every operand of V latched
  reg d_issued;

  // ---- stage A: conj(Q_P) (cvt<quat_t>(-x)) and dp = cvt<perr_t>(p_U - p_P) ---------------------
  wire signed [Q_W-1:0] cq_o [1:3];
  wire [3:1] cq_sat;
  wire signed [PE_W-1:0] dp_o [0:2];
  wire [2:0] dp_sat;
  generate
    for (gi = 1; gi < 4; gi = gi + 1) begin : g_conj
      wire signed [Q_W:0] neg = -{tq[gi][Q_W-1], tq[gi]};
      ts_round_sat #(.IN_W(Q_W+1), .SHIFT(0), .OUT_W(Q_W), .SAT(1)) u_rs (
        .clk(clk), .rst(rst), .in_x(neg), .out_y(cq_o[gi]), .out_sat(cq_sat[gi]));
    end
    for (gi = 0; gi < 3; gi = gi + 1) begin : g_dp
      wire signed [P_W:0] d = {up[gi][P_W-1], up[gi]} - {tp[gi][P_W-1], tp[gi]};
      ts_round_sat #(.IN_W(P_W+1), .SHIFT(P_F-PE_F), .OUT_W(PE_W), .SAT(1)) u_rs (
        .clk(clk), .rst(rst), .in_x(d), .out_y(dp_o[gi]), .out_sat(dp_sat[gi]));
    end
  endgenerate
  wire p_b;
  ts_delay #(.W(1), .DEPTH(RL)) u_pb (.clk(clk), .rst(rst), .din(s0), .dout(p_b));

  reg signed [Q_W-1:0]  cq [0:3];   // conj(Q_P)
  reg signed [PE_W-1:0] dp [0:2];

  // ---- stage B: the error quaternion (A: Q_U (x) conj(Q_P), B: conj(Q_P) (x) Q_U) ---------------
  wire qm_ovalid, qm_sat;
  wire signed [Q_W-1:0] qm_o [0:3];
  wire signed [Q_W-1:0] qm_a [0:3];
  wire signed [Q_W-1:0] qm_b [0:3];
  generate
    for (gi = 0; gi < 4; gi = gi + 1) begin : g_qmin
      assign qm_a[gi] = r_mb ? cq[gi] : uq[gi];
      assign qm_b[gi] = r_mb ? uq[gi] : cq[gi];
    end
  endgenerate
  ts_quat_mul #(.Q_W(Q_W), .Q_F(Q_F), .TARGET(TARGET), .MUL3(MUL3), .FOLD(FOLD), .CHAIN(CHAIN)) u_qm (
    .clk(clk), .rst(rst), .in_valid(b0),
    .in_a_w(qm_a[0]), .in_a_x(qm_a[1]), .in_a_y(qm_a[2]), .in_a_z(qm_a[3]),
    .in_b_w(qm_b[0]), .in_b_x(qm_b[1]), .in_b_y(qm_b[2]), .in_b_z(qm_b[3]),
    .out_valid(qm_ovalid), .out_w(qm_o[0]), .out_x(qm_o[1]), .out_y(qm_o[2]), .out_z(qm_o[3]),
    .out_sat(qm_sat));

  reg signed [Q_W-1:0] qe [0:3];    // error quaternion
  reg signed [Q_W-1:0] qn [0:3];    // sign-corrected (w >= 0)

  // ---- rotation vector ----------------------------------------------------------------------------
  // sign flip: cvt<quat_t>(-x) of every component when w < 0
  wire signed [Q_W-1:0] qneg_o [0:3];
  wire [3:0] qneg_sat;
  generate
    for (gi = 0; gi < 4; gi = gi + 1) begin : g_qneg
      wire signed [Q_W:0] neg = -{qe[gi][Q_W-1], qe[gi]};
      ts_round_sat #(.IN_W(Q_W+1), .SHIFT(0), .OUT_W(Q_W), .SAT(1)) u_rs (
        .clk(clk), .rst(rst), .in_x(neg), .out_y(qneg_o[gi]), .out_sat(qneg_sat[gi]));
    end
  endgenerate
  wire qe_neg = qe[0][Q_W-1];
  wire p_qn;
  ts_delay #(.W(1), .DEPTH(RL)) u_pqn (.clk(clk), .rst(rst), .din(c0), .dout(p_qn));

  // table read: idx = w >> FB (w >= 0, < 2), clamped to 2^TB with frac = 0
  (* rom_style = "logic" *) reg [2*RV_W-1:0] rom [0:(1<<TB)];
  initial $readmemh(ROM_FILE, rom);
  wire [IX_W-1:0] ix_raw = qn[0][Q_W-2:FB];
  localparam [IX_W-1:0] IX_MAX = 1 << TB;
  wire ix_over = (ix_raw > IX_MAX);
  wire [TB:0] ix = ix_over ? {1'b1, {TB{1'b0}}} : ix_raw[TB:0];
  wire [FB-1:0] frac = ix_over ? {FB{1'b0}} : qn[0][FB-1:0];
  wire unused_qn_sign = qn[0][Q_W-1];
  reg [2*RV_W-1:0] rom_q;
  reg signed [FB:0] wgt;
  always @(posedge clk) begin
    if (rst) begin
      rom_q <= {(2*RV_W){1'b0}};
      wgt <= {(FB+1){1'b0}};
    end else begin
      rom_q <= rom[ix];
      wgt <= {1'b0, frac};
    end
  end
  wire signed [RV_W-1:0] tab_f = rom_q[2*RV_W-1:RV_W];
  wire signed [RV_W-1:0] tab_df = rom_q[RV_W-1:0];
  // f = cvt<rvf_t>(F + dF frac)
  localparam MLF = ts_mul_lat(RV_W, FB + 1);
  localparam FS_W = RV_W + FB + 2;
  wire signed [RV_W+FB:0] fprod;
  ts_mul #(.A_W(RV_W), .B_W(FB+1), .TARGET(TARGET), .MUL3(MUL3)) u_fm (
    .clk(clk), .rst(rst), .a(tab_df), .b(wgt), .p(fprod));
  wire signed [FS_W-1:0] fs_a, fs_b;
  ts_resize #(.IN_W(RV_W), .LSH(FB), .OUT_W(FS_W)) u_fsa (.in(tab_f), .out(fs_a));
  ts_resize #(.IN_W(RV_W+FB+1), .LSH(0), .OUT_W(FS_W)) u_fsb (.in(fprod), .out(fs_b));
  reg signed [FS_W-1:0] fsum;
  always @(posedge clk) begin
    if (rst) fsum <= {FS_W{1'b0}};
    else     fsum <= fs_a + fs_b;
  end
  wire signed [RV_W-1:0] f_o;
  wire f_sat;
  ts_round_sat #(.IN_W(FS_W), .SHIFT(FB), .OUT_W(RV_W), .SAT(1)) u_frs (
    .clk(clk), .rst(rst), .in_x(fsum), .out_y(f_o), .out_sat(f_sat));
  wire p_f;
  ts_delay #(.W(1), .DEPTH(1+MLF+1+RL)) u_pf (.clk(clk), .rst(rst), .din(c1), .dout(p_f));
  reg signed [RV_W-1:0] fr;

  // eo_a = cvt<rot_t>(2 f q_a)
  localparam MLE = ts_bank_lat(RV_W, Q_W, FOLD);
  wire signed [RO_W-1:0] eo_o [0:2];
  wire [2:0] eo_sat;
  wire [3*(RV_W+Q_W)-1:0] eo_p;
  ts_mul_bank #(.N(3), .FOLD(FOLD), .CHAIN(CHAIN), .A_W(RV_W), .B_W(Q_W), .TARGET(TARGET), .MUL3(MUL3)) u_meo (
    .clk(clk), .rst(rst), .in_valid(c2), .in_a({fr, fr, fr}), .in_b({qn[3], qn[2], qn[1]}), .out_p(eo_p));
  generate
    for (gi = 0; gi < 3; gi = gi + 1) begin : g_eo
      wire signed [RV_W+Q_W-1:0] prod = eo_p[gi*(RV_W+Q_W) +: RV_W+Q_W];
      ts_round_sat #(.IN_W(RV_W+Q_W), .SHIFT(RV_F+Q_F-1-RO_F), .OUT_W(RO_W), .SAT(1)) u_rs (
        .clk(clk), .rst(rst), .in_x(prod), .out_y(eo_o[gi]), .out_sat(eo_sat[gi]));
    end
  endgenerate
  wire p_eo;
  ts_delay #(.W(1), .DEPTH(MLE+RL)) u_peo (.clk(clk), .rst(rst), .din(c2), .dout(p_eo));
  reg signed [RO_W-1:0] eo [0:2];

  // ---- mode B feed-forward lever: vP = cvt<vel_t>(v_U + cross<vel_t>(dp, w_U)) ---------------------
  localparam MLX = ts_bank_lat(PE_W, V_W, FOLD);
  localparam X_W = PE_W + V_W;
  wire signed [V_W-1:0] lev_o [0:2];
  wire [2:0] lev_sat;
  // products 2 c and 2 c + 1 of component c: dp[j] w[k] and dp[k] w[j], (j, k) = (c+1, c+2) mod 3
  wire [6*X_W-1:0] lev_p;
  ts_mul_bank #(.N(6), .FOLD(FOLD), .CHAIN(CHAIN), .A_W(PE_W), .B_W(V_W), .TARGET(TARGET), .MUL3(MUL3)) u_mlev (
    .clk(clk), .rst(rst), .in_valid(b0),
    .in_a({dp[1], dp[0], dp[0], dp[2], dp[2], dp[1]}), .in_b({uw[0], uw[1], uw[2], uw[0], uw[1], uw[2]}),
    .out_p(lev_p));
  generate
    for (gi = 0; gi < 3; gi = gi + 1) begin : g_lev
      wire signed [X_W-1:0] pa = lev_p[(2*gi)*X_W +: X_W];
      wire signed [X_W-1:0] pb = lev_p[(2*gi+1)*X_W +: X_W];
      reg signed [X_W:0] d;
      always @(posedge clk) begin
        if (rst) d <= {(X_W+1){1'b0}};
        else     d <= {pa[X_W-1], pa} - {pb[X_W-1], pb};
      end
      ts_round_sat #(.IN_W(X_W+1), .SHIFT(PE_F), .OUT_W(V_W), .SAT(1)) u_rs (
        .clk(clk), .rst(rst), .in_x(d), .out_y(lev_o[gi]), .out_sat(lev_sat[gi]));
    end
  endgenerate
  wire p_lev;
  ts_delay #(.W(1), .DEPTH(MLX+1+RL)) u_plev (.clk(clk), .rst(rst), .din(b0), .dout(p_lev));
  reg signed [V_W-1:0] lev [0:2];
  wire signed [V_W-1:0] vp_o [0:2];
  wire [2:0] vp_sat;
  generate
    for (gi = 0; gi < 3; gi = gi + 1) begin : g_vp
      wire signed [V_W:0] s = {uv[gi][V_W-1], uv[gi]} + {lev[gi][V_W-1], lev[gi]};
      ts_round_sat #(.IN_W(V_W+1), .SHIFT(0), .OUT_W(V_W), .SAT(1)) u_rs (
        .clk(clk), .rst(rst), .in_x(s), .out_y(vp_o[gi]), .out_sat(vp_sat[gi]));
    end
  endgenerate
  wire p_vp_raw;
  ts_delay #(.W(1), .DEPTH(1+RL)) u_pvp (.clk(clk), .rst(rst), .din(p_lev), .dout(p_vp_raw));

  // ---- mode B: the rotation by conj(Q_P) of dp (kind perr: perr_t, len_tmp_t, perr_t) and of w_U
  // and vP (kind vel: vel_t, jv_tmp_t, vel_t).  The model's two-stage rotate<Out, Tmp, true>
  // (quat.hpp) on ts_mul_bank / ts_round_sat, one vector per FOLD cycles, with a rounding pair per kind: the
  // two stages' saturations raise different status bits (tmp: ovf_pos for perr, ovf_jac for vel;
  // out: ovf_servo), which ts_quat_rotate's single out_sat cannot tell apart.
  localparam VI_W = ts_max(PE_W, V_W);
  localparam VF0 = PE_F, TF0 = TS_LEN_TMP_F, TW0 = TS_LEN_TMP_W;
  localparam VF1 = V_F, TF1 = TS_JV_TMP_F, TW1 = TS_JV_TMP_W;
  localparam TT_W = ts_max(TW0, TW1);
  localparam OO_W = ts_max(PE_W, V_W);
  localparam MRA = ts_bank_lat(Q_W, VI_W, FOLD);
  localparam MRB = ts_bank_lat(Q_W, TT_W, FOLD);
  localparam RLA = MRA + 1 + RL;                 // t available
  localparam ROT_LAT = ts_rotate_lat(Q_W, VI_W, TT_W, FOLD);   // = RLA + MRB + 2 + RL
  localparam RA_W = Q_W + VI_W;
  localparam RB_W = Q_W + TT_W;
  localparam LS0 = Q_F + TF0 - VF0;              // alignment of v to the stage-B products
  localparam LS1 = Q_F + TF1 - VF1;
  localparam SB_W = ts_max(VI_W + ts_max(LS0, LS1), RB_W) + 2;

  // requests: dp and w_U (B with feed-forward) at b0, vP when it is there; each waits until the
  // rotation's banks can take it (one vector per FOLD cycles), dp first, then w_U, then vP
  localparam GAP_W = (FOLD > 1) ? $clog2(FOLD) : 1;
  localparam integer FOLD_M1 = FOLD - 1;
  localparam [GAP_W-1:0] GAP_MAX = FOLD_M1[GAP_W-1:0];
  reg pend_ep, pend_w, pend_v;
  reg [GAP_W-1:0] rgap;
  wire want_ep = pend_ep || (b0 && r_mb);
  wire want_w = pend_w || (b0 && r_mb && r_ff);
  wire want_v = pend_v || (p_vp_raw && r_mb && r_ff);
  wire rot_can = (rgap == {GAP_W{1'b0}});
  wire rot_go_ep = rot_can && want_ep;
  wire rot_go_w = rot_can && !want_ep && want_w;
  wire rot_go_v = rot_can && !want_ep && !want_w && want_v;
  wire rot_valid = rot_go_ep || rot_go_w || rot_go_v;
  wire rot_kind = !rot_go_ep;                    // 0: perr, 1: vel
  wire [1:0] rot_tag = rot_go_ep ? 2'd0 : (rot_go_w ? 2'd1 : 2'd2);
  always @(posedge clk) begin
    if (rst) begin
      pend_ep <= 1'b0;
      pend_w <= 1'b0;
      pend_v <= 1'b0;
      rgap <= {GAP_W{1'b0}};
    end else begin
      pend_ep <= want_ep && !rot_go_ep;
      pend_w <= want_w && !rot_go_w;
      pend_v <= want_v && !rot_go_v;
      if (rot_valid) rgap <= GAP_MAX;
      else if (!rot_can) rgap <= rgap - 1'b1;
    end
  end
  wire signed [VI_W-1:0] rv [0:2];
  generate
    for (gi = 0; gi < 3; gi = gi + 1) begin : g_rv
      wire signed [VI_W-1:0] rv_dp, rv_w, rv_vp;
      ts_resize #(.IN_W(PE_W), .LSH(0), .OUT_W(VI_W)) u_a (.in(dp[gi]), .out(rv_dp));
      ts_resize #(.IN_W(V_W), .LSH(0), .OUT_W(VI_W)) u_b (.in(uw[gi]), .out(rv_w));
      ts_resize #(.IN_W(V_W), .LSH(0), .OUT_W(VI_W)) u_c (.in(vp_o[gi]), .out(rv_vp));
      assign rv[gi] = rot_go_ep ? rv_dp : (rot_go_w ? rv_w : rv_vp);
    end
  endgenerate
  // stage A: t = 2 (q_v x v) with q_v negated (INV): products (y a2, z a1), (z a0, x a2), (x a1, y a0)
  wire signed [RA_W-1:0] ra [0:5];
  wire [6*RA_W-1:0] ra_p;
  ts_mul_bank #(.N(6), .FOLD(FOLD), .CHAIN(CHAIN), .A_W(Q_W), .B_W(VI_W), .TARGET(TARGET), .MUL3(MUL3)) u_mra (
    .clk(clk), .rst(rst), .in_valid(rot_valid),
    .in_a({tq[2], tq[1], tq[1], tq[3], tq[3], tq[2]}), .in_b({rv[0], rv[1], rv[2], rv[0], rv[1], rv[2]}),
    .out_p(ra_p));
  generate
    for (gi = 0; gi < 6; gi = gi + 1) begin : g_ra
      assign ra[gi] = ra_p[gi*RA_W +: RA_W];
    end
  endgenerate
  wire kind_a;     // kind at the t rounding output
  ts_delay #(.W(1), .DEPTH(RLA)) u_ka (.clk(clk), .rst(rst), .din(rot_kind), .dout(kind_a));
  wire signed [TT_W-1:0] rt [0:2];
  wire [2:0] rt_sat;
  generate
    for (gi = 0; gi < 3; gi = gi + 1) begin : g_rt
      reg signed [RA_W:0] da;
      always @(posedge clk) begin
        if (rst) da <= {(RA_W+1){1'b0}};
        else     da <= {ra[2*gi+1][RA_W-1], ra[2*gi+1]} - {ra[2*gi][RA_W-1], ra[2*gi]};
      end
      wire signed [TW0-1:0] t0;
      wire signed [TW1-1:0] t1;
      wire s0t, s1t;
      ts_round_sat #(.IN_W(RA_W+1), .SHIFT(Q_F+VF0-1-TF0), .OUT_W(TW0), .SAT(1)) u_r0 (
        .clk(clk), .rst(rst), .in_x(da), .out_y(t0), .out_sat(s0t));
      ts_round_sat #(.IN_W(RA_W+1), .SHIFT(Q_F+VF1-1-TF1), .OUT_W(TW1), .SAT(1)) u_r1 (
        .clk(clk), .rst(rst), .in_x(da), .out_y(t1), .out_sat(s1t));
      wire signed [TT_W-1:0] t0w, t1w;
      ts_resize #(.IN_W(TW0), .LSH(0), .OUT_W(TT_W)) u_w0 (.in(t0), .out(t0w));
      ts_resize #(.IN_W(TW1), .LSH(0), .OUT_W(TT_W)) u_w1 (.in(t1), .out(t1w));
      assign rt[gi] = kind_a ? t1w : t0w;
      assign rt_sat[gi] = kind_a ? s1t : s0t;
    end
  endgenerate
  // stage B: out = v + w t + (q_v negated) x t:
  //   r0 = a0 + w b0 + (z b1 - y b2), r1 = a1 + w b1 + (x b2 - z b0), r2 = a2 + w b2 + (y b0 - x b1)
  wire signed [RB_W-1:0] rw [0:2];
  wire signed [RB_W-1:0] rc [0:5];
  // products 0-2: w t_i; 3-8: (z b1, y b2), (x b2, z b0), (y b0, x b1)
  wire rb_valid;
  ts_delay #(.W(1), .DEPTH(RLA)) u_rbv (.clk(clk), .rst(rst), .din(rot_valid), .dout(rb_valid));
  wire [9*RB_W-1:0] rb_p;
  ts_mul_bank #(.N(9), .FOLD(FOLD), .CHAIN(CHAIN), .A_W(Q_W), .B_W(TT_W), .TARGET(TARGET), .MUL3(MUL3)) u_mrb (
    .clk(clk), .rst(rst), .in_valid(rb_valid),
    .in_a({tq[1], tq[2], tq[3], tq[1], tq[2], tq[3], tq[0], tq[0], tq[0]}),
    .in_b({rt[1], rt[0], rt[0], rt[2], rt[2], rt[1], rt[2], rt[1], rt[0]}),
    .out_p(rb_p));
  generate
    for (gi = 0; gi < 3; gi = gi + 1) begin : g_rw
      assign rw[gi] = rb_p[gi*RB_W +: RB_W];
    end
    for (gi = 0; gi < 6; gi = gi + 1) begin : g_rc
      assign rc[gi] = rb_p[(3+gi)*RB_W +: RB_W];
    end
  endgenerate
  wire [3*VI_W-1:0] rv_d;
  ts_delay #(.W(3*VI_W), .DEPTH(RLA+MRB)) u_rvd (
    .clk(clk), .rst(rst), .din({rv[2], rv[1], rv[0]}), .dout(rv_d));
  wire kind_b;     // kind at the stage-B products
  ts_delay #(.W(1), .DEPTH(MRB)) u_kb (.clk(clk), .rst(rst), .din(kind_a), .dout(kind_b));
  wire kind_o;     // kind at the output rounding
  ts_delay #(.W(1), .DEPTH(2+RL)) u_ko (.clk(clk), .rst(rst), .din(kind_b), .dout(kind_o));
  wire [2:0] rt_sat_o;
  ts_delay #(.W(3), .DEPTH(MRB+2+RL)) u_rts (.clk(clk), .rst(rst), .din(rt_sat), .dout(rt_sat_o));
  wire signed [OO_W-1:0] ro_o [0:2];
  wire [2:0] ro_sat;
  generate
    for (gi = 0; gi < 3; gi = gi + 1) begin : g_rb
      wire signed [VI_W-1:0] a = rv_d[gi*VI_W +: VI_W];
      wire signed [SB_W-1:0] a0, a1, pw, pc0, pc1;
      ts_resize #(.IN_W(VI_W), .LSH(LS0), .OUT_W(SB_W)) u_a0 (.in(a), .out(a0));
      ts_resize #(.IN_W(VI_W), .LSH(LS1), .OUT_W(SB_W)) u_a1 (.in(a), .out(a1));
      ts_resize #(.IN_W(RB_W), .LSH(0), .OUT_W(SB_W)) u_pw (.in(rw[gi]), .out(pw));
      ts_resize #(.IN_W(RB_W), .LSH(0), .OUT_W(SB_W)) u_p0 (.in(rc[2*gi]), .out(pc0));
      ts_resize #(.IN_W(RB_W), .LSH(0), .OUT_W(SB_W)) u_p1 (.in(rc[2*gi+1]), .out(pc1));
      reg signed [SB_W-1:0] l1a, l1b, l2;
      always @(posedge clk) begin
        if (rst) begin
          l1a <= {SB_W{1'b0}};
          l1b <= {SB_W{1'b0}};
          l2 <= {SB_W{1'b0}};
        end else begin
          l1a <= (kind_b ? a1 : a0) + pw;
          l1b <= pc0 - pc1;
          l2 <= l1a + l1b;
        end
      end
      wire signed [PE_W-1:0] o0;
      wire signed [V_W-1:0] o1;
      wire so0, so1;
      ts_round_sat #(.IN_W(SB_W), .SHIFT(Q_F+TF0-PE_F), .OUT_W(PE_W), .SAT(1)) u_r0 (
        .clk(clk), .rst(rst), .in_x(l2), .out_y(o0), .out_sat(so0));
      ts_round_sat #(.IN_W(SB_W), .SHIFT(Q_F+TF1-V_F), .OUT_W(V_W), .SAT(1)) u_r1 (
        .clk(clk), .rst(rst), .in_x(l2), .out_y(o1), .out_sat(so1));
      wire signed [OO_W-1:0] o0w, o1w;
      ts_resize #(.IN_W(PE_W), .LSH(0), .OUT_W(OO_W)) u_w0 (.in(o0), .out(o0w));
      ts_resize #(.IN_W(V_W), .LSH(0), .OUT_W(OO_W)) u_w1 (.in(o1), .out(o1w));
      assign ro_o[gi] = kind_o ? o1w : o0w;
      assign ro_sat[gi] = kind_o ? so1 : so0;
    end
  endgenerate
  wire rot_ovalid;
  wire [1:0] rot_otag;
  ts_delay #(.W(3), .DEPTH(ROT_LAT)) u_rov (.clk(clk), .rst(rst), .din({rot_tag, rot_valid}),
    .dout({rot_otag, rot_ovalid}));

  reg signed [V_W-1:0] ffw [0:2];
  reg signed [V_W-1:0] ffv [0:2];
  reg signed [PE_W-1:0] ep [0:2];
  reg have_ep, have_eo, have_ffw, have_ffv;

  // ---- stage D: V_w = cvt<vel_t>(ff_w + ko eo), V_v = cvt<vel_t>(ff_v + kp ep) --------------------
  localparam MLG = ts_bank_lat(G_W, RO_W, FOLD);
  localparam PW_I = G_W - G_F + RO_W - RO_F;
  localparam PW_F = G_F + RO_F;
  localparam PV_I = G_W - G_F + PE_W - PE_F;
  localparam PV_F = G_F + PE_F;
  localparam SW_F = ts_max(V_F, PW_F);
  localparam SW_W = ts_max(V_W - V_F, PW_I) + 1 + SW_F;
  localparam SV_F = ts_max(V_F, PV_F);
  localparam SV_W = ts_max(V_W - V_F, PV_I) + 1 + SV_F;
  wire signed [V_W-1:0] vw_o [0:2];
  wire signed [V_W-1:0] vv_o [0:2];
  wire [2:0] vw_sat, vv_sat;
  // products 0-2: ko eo_i; 3-5: kp ep_i (rot_t and perr_t have the same width)
  wire [6*(G_W+RO_W)-1:0] gv_p;
  ts_mul_bank #(.N(6), .FOLD(FOLD), .CHAIN(CHAIN), .A_W(G_W), .B_W(RO_W), .TARGET(TARGET), .MUL3(MUL3)) u_mg (
    .clk(clk), .rst(rst), .in_valid(d0),
    .in_a({r_kp, r_kp, r_kp, r_ko, r_ko, r_ko}), .in_b({ep[2], ep[1], ep[0], eo[2], eo[1], eo[0]}),
    .out_p(gv_p));
  generate
    for (gi = 0; gi < 3; gi = gi + 1) begin : g_v
      wire signed [V_W-1:0] fw = !r_ff ? {V_W{1'b0}} : (r_mb ? ffw[gi] : uw[gi]);
      wire signed [V_W-1:0] fv = !r_ff ? {V_W{1'b0}} : (r_mb ? ffv[gi] : uv[gi]);
      wire signed [G_W+RO_W-1:0] pwm = gv_p[gi*(G_W+RO_W) +: G_W+RO_W];
      wire signed [G_W+PE_W-1:0] pvm = gv_p[(3+gi)*(G_W+RO_W) +: G_W+PE_W];
      wire signed [SW_W-1:0] wa, wb;
      wire signed [SV_W-1:0] va, vb;
      ts_resize #(.IN_W(V_W), .LSH(SW_F-V_F), .OUT_W(SW_W)) u_wa (.in(fw), .out(wa));
      ts_resize #(.IN_W(G_W+RO_W), .LSH(SW_F-PW_F), .OUT_W(SW_W)) u_wb (.in(pwm), .out(wb));
      ts_resize #(.IN_W(V_W), .LSH(SV_F-V_F), .OUT_W(SV_W)) u_va (.in(fv), .out(va));
      ts_resize #(.IN_W(G_W+PE_W), .LSH(SV_F-PV_F), .OUT_W(SV_W)) u_vb (.in(pvm), .out(vb));
      reg signed [SW_W-1:0] sw;
      reg signed [SV_W-1:0] sv;
      always @(posedge clk) begin
        if (rst) begin
          sw <= {SW_W{1'b0}};
          sv <= {SV_W{1'b0}};
        end else begin
          sw <= wa + wb;
          sv <= va + vb;
        end
      end
      ts_round_sat #(.IN_W(SW_W), .SHIFT(SW_F-V_F), .OUT_W(V_W), .SAT(1)) u_rw (
        .clk(clk), .rst(rst), .in_x(sw), .out_y(vw_o[gi]), .out_sat(vw_sat[gi]));
      ts_round_sat #(.IN_W(SV_W), .SHIFT(SV_F-V_F), .OUT_W(V_W), .SAT(1)) u_rv (
        .clk(clk), .rst(rst), .in_x(sv), .out_y(vv_o[gi]), .out_sat(vv_sat[gi]));
    end
  endgenerate
  wire p_v;
  ts_delay #(.W(1), .DEPTH(MLG+1+RL)) u_pv (.clk(clk), .rst(rst), .din(d0), .dout(p_v));

  // ---- the sequencer --------------------------------------------------------------------------------
  wire ops_ready = have_ep && have_eo && (!(r_mb && r_ff) || (have_ffw && have_ffv));
  always @(posedge clk) begin
    if (rst) begin
      out_busy <= 1'b0;
      out_done <= 1'b0;
      out_flags <= 16'd0;
      s0 <= 1'b0; b0 <= 1'b0; c0 <= 1'b0; c1 <= 1'b0; c2 <= 1'b0; d0 <= 1'b0;
      d_issued <= 1'b0;
      have_ep <= 1'b0; have_eo <= 1'b0; have_ffw <= 1'b0; have_ffv <= 1'b0;
      fr <= {RV_W{1'b0}};
      for (k = 0; k < 4; k = k + 1) begin
        cq[k] <= {Q_W{1'b0}};
        qe[k] <= {Q_W{1'b0}};
        qn[k] <= {Q_W{1'b0}};
      end
      for (k = 0; k < 3; k = k + 1) begin
        dp[k] <= {PE_W{1'b0}};
        ep[k] <= {PE_W{1'b0}};
        eo[k] <= {RO_W{1'b0}};
        lev[k] <= {V_W{1'b0}};
        ffw[k] <= {V_W{1'b0}};
        ffv[k] <= {V_W{1'b0}};
      end
      out_ep_x <= {PE_W{1'b0}}; out_ep_y <= {PE_W{1'b0}}; out_ep_z <= {PE_W{1'b0}};
      out_eo_x <= {RO_W{1'b0}}; out_eo_y <= {RO_W{1'b0}}; out_eo_z <= {RO_W{1'b0}};
      out_vw_x <= {V_W{1'b0}}; out_vw_y <= {V_W{1'b0}}; out_vw_z <= {V_W{1'b0}};
      out_vv_x <= {V_W{1'b0}}; out_vv_y <= {V_W{1'b0}}; out_vv_z <= {V_W{1'b0}};
    end else begin
      s0 <= start;
      b0 <= 1'b0;
      c0 <= 1'b0;
      c1 <= 1'b0;
      c2 <= 1'b0;
      d0 <= 1'b0;
      out_done <= 1'b0;
      if (start) begin
        out_busy <= 1'b1;
        out_flags <= 16'd0;
        d_issued <= 1'b0;
        have_ep <= 1'b0; have_eo <= 1'b0; have_ffw <= 1'b0; have_ffv <= 1'b0;
      end
      // stage A results
      if (p_b) begin
        cq[0] <= tq[0];
        for (k = 1; k < 4; k = k + 1) cq[k] <= cq_o[k];
        for (k = 0; k < 3; k = k + 1) dp[k] <= dp_o[k];
        if (|cq_sat) out_flags[ST_QUAT] <= 1'b1;
        if (|dp_sat) out_flags[ST_SERVO] <= 1'b1;
        if (!r_mb) begin
          for (k = 0; k < 3; k = k + 1) ep[k] <= dp_o[k];
          have_ep <= 1'b1;
        end
        b0 <= 1'b1;
      end
      // error quaternion
      if (qm_ovalid) begin
        for (k = 0; k < 4; k = k + 1) qe[k] <= qm_o[k];
        if (qm_sat) out_flags[ST_QUAT] <= 1'b1;
        c0 <= 1'b1;
      end
      if (p_qn) begin
        for (k = 0; k < 4; k = k + 1) qn[k] <= qe_neg ? qneg_o[k] : qe[k];
        if (qe_neg && (|qneg_sat)) out_flags[ST_QUAT] <= 1'b1;
        c1 <= 1'b1;
      end
      if (p_f) begin
        fr <= f_o;
        if (f_sat) out_flags[ST_SERVO] <= 1'b1;
        c2 <= 1'b1;
      end
      if (p_eo) begin
        for (k = 0; k < 3; k = k + 1) eo[k] <= eo_o[k];
        if (|eo_sat) out_flags[ST_SERVO] <= 1'b1;
        have_eo <= 1'b1;
      end
      // mode B feed-forward lever and the rotations
      if (p_lev) begin
        for (k = 0; k < 3; k = k + 1) lev[k] <= lev_o[k];
        if (r_mb && r_ff && (|lev_sat)) out_flags[ST_SERVO] <= 1'b1;
      end
      if (p_vp_raw && r_mb && r_ff && (|vp_sat)) out_flags[ST_SERVO] <= 1'b1;
      if (rot_ovalid) begin
        if (|ro_sat) out_flags[ST_SERVO] <= 1'b1;
        if (|rt_sat_o) begin
          if (rot_otag == 2'd0) out_flags[ST_POS] <= 1'b1;
          else                  out_flags[ST_JAC] <= 1'b1;
        end
        case (rot_otag)
          2'd0: begin
            for (k = 0; k < 3; k = k + 1) ep[k] <= ro_o[k][PE_W-1:0];
            have_ep <= 1'b1;
          end
          2'd1: begin
            for (k = 0; k < 3; k = k + 1) ffw[k] <= ro_o[k][V_W-1:0];
            have_ffw <= 1'b1;
          end
          default: begin
            for (k = 0; k < 3; k = k + 1) ffv[k] <= ro_o[k][V_W-1:0];
            have_ffv <= 1'b1;
          end
        endcase
      end
      // V
      if (out_busy && ops_ready && !d_issued && !start) begin
        d0 <= 1'b1;
        d_issued <= 1'b1;
      end
      if (p_v) begin
        out_ep_x <= ep[0]; out_ep_y <= ep[1]; out_ep_z <= ep[2];
        out_eo_x <= eo[0]; out_eo_y <= eo[1]; out_eo_z <= eo[2];
        out_vw_x <= vw_o[0]; out_vw_y <= vw_o[1]; out_vw_z <= vw_o[2];
        out_vv_x <= vv_o[0]; out_vv_y <= vv_o[1]; out_vv_z <= vv_o[2];
        if ((|vw_sat) || (|vv_sat)) out_flags[ST_SERVO] <= 1'b1;
        out_busy <= 1'b0;
        out_done <= 1'b1;
      end
      // column port (mode B): ovf_jac
      if (col_ovalid && r_mb && (col_sw || col_sv)) out_flags[ST_JAC] <= 1'b1;
    end
  end

  // ---- column port ----------------------------------------------------------------------------------
  localparam COL_LAT = ts_rotate_lat(Q_W, JW_W, TS_JW_TMP_W, FOLD);   // ts_quat_rotate
  wire col_ovalid, col_ovalid_v, col_sw, col_sv;
  wire signed [JW_W-1:0] cw_o [0:2];
  wire signed [JV_W-1:0] cv_o [0:2];
  ts_quat_rotate #(
    .Q_W(Q_W), .Q_F(Q_F), .V_W(JW_W), .V_F(TS_JW_F), .T_W(TS_JW_TMP_W), .T_F(TS_JW_TMP_F),
    .O_W(JW_W), .O_F(TS_JW_F), .INV(1), .TARGET(TARGET), .MUL3(MUL3), .FOLD(FOLD), .CHAIN(CHAIN)
  ) u_cw (
    .clk(clk), .rst(rst), .in_valid(in_col_valid),
    .in_q_w(tq[0]), .in_q_x(tq[1]), .in_q_y(tq[2]), .in_q_z(tq[3]),
    .in_v_x(in_col_w_x), .in_v_y(in_col_w_y), .in_v_z(in_col_w_z),
    .out_valid(col_ovalid), .out_x(cw_o[0]), .out_y(cw_o[1]), .out_z(cw_o[2]), .out_sat(col_sw));
  ts_quat_rotate #(
    .Q_W(Q_W), .Q_F(Q_F), .V_W(JV_W), .V_F(TS_JV_F), .T_W(TS_JV_TMP_W), .T_F(TS_JV_TMP_F),
    .O_W(JV_W), .O_F(TS_JV_F), .INV(1), .TARGET(TARGET), .MUL3(MUL3), .FOLD(FOLD), .CHAIN(CHAIN)
  ) u_cv (
    .clk(clk), .rst(rst), .in_valid(in_col_valid),
    .in_q_w(tq[0]), .in_q_x(tq[1]), .in_q_y(tq[2]), .in_q_z(tq[3]),
    .in_v_x(in_col_v_x), .in_v_y(in_col_v_y), .in_v_z(in_col_v_z),
    .out_valid(col_ovalid_v), .out_x(cv_o[0]), .out_y(cv_o[1]), .out_z(cv_o[2]), .out_sat(col_sv));
  wire unused_col_ovalid_v = col_ovalid_v;
  // mode A: the root-basis column, delayed to the same latency
  wire [3*JW_W+3*JV_W-1:0] col_d;
  ts_delay #(.W(3*JW_W+3*JV_W), .DEPTH(COL_LAT)) u_cd (
    .clk(clk), .rst(rst),
    .din({in_col_v_z, in_col_v_y, in_col_v_x, in_col_w_z, in_col_w_y, in_col_w_x}), .dout(col_d));
  assign out_col_valid = col_ovalid;
  assign out_col_w_x = r_mb ? cw_o[0] : col_d[JW_W-1:0];
  assign out_col_w_y = r_mb ? cw_o[1] : col_d[2*JW_W-1:JW_W];
  assign out_col_w_z = r_mb ? cw_o[2] : col_d[3*JW_W-1:2*JW_W];
  assign out_col_v_x = r_mb ? cv_o[0] : col_d[3*JW_W+JV_W-1:3*JW_W];
  assign out_col_v_y = r_mb ? cv_o[1] : col_d[3*JW_W+2*JV_W-1:3*JW_W+JV_W];
  assign out_col_v_z = r_mb ? cv_o[2] : col_d[3*JW_W+3*JV_W-1:3*JW_W+2*JV_W];
  assign out_col_sat = r_mb && (col_sw || col_sv);

endmodule

`default_nettype wire
