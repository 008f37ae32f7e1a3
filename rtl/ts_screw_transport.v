// SPDX-License-Identifier: Apache-2.0
// tensor-servo: one Jacobian column by screw transport, bit-exact with the model's
//   z = rotate<quat_t, uvec_tmp_t>(QF, a)              joint axis in the root basis (ts_quat_rotate)
//   screw_column(prismatic, s, z, p_ref, p_i):         (model/include/tensor_servo/kinematics.hpp)
//     revolute:  w = cvt<jw_t>(s z),  r = cvt<lever_t>(p_ref - p_i),  v = cross<jv_t>(w, r)
//     prismatic: w = 0,               v = cvt<jv_t>(s z)
// The product s z is formed once and rounded to both jw_t and jv_t.  out_flags: the model's Status
// bits of the column: ST_OVF_QUAT (bit 3) from the rotation, ST_OVF_LEVER (bit 5) from the lever
// arm, ST_OVF_JAC (bit 6) from w or v (for a prismatic joint v = s z); signals the model does not
// compute for the joint type never flag.
// Products on ts_mul_bank (FOLD products per multiplier: the rotation's 15, s z's 3 and the cross
// product's 6).  Latency: see LATENCY (docs/rtl/ts_screw_transport.md), II = FOLD; the bits do
// not depend on FOLD.
// Language: Verilog 2005
`resetall
`timescale 1ns / 1ps
`default_nettype none

module ts_screw_transport #(
  // Quaternion / unit vector width (quat_t W): QF, axis a, output z
  parameter Q_W = 27,
  // Quaternion fraction bits
  parameter Q_F = 25,
  // Rotation intermediate width (uvec_tmp_t W)
  parameter UT_W = 27,
  // Rotation intermediate fraction bits
  parameter UT_F = 24,
  // Joint scale width (scale_t W)
  parameter S_W = 27,
  // Joint scale fraction bits
  parameter S_F = 24,
  // Position width (pos_t W): p_ref, p_i
  parameter P_W = 32,
  // Position fraction bits
  parameter P_F = 27,
  // Lever arm width (lever_t W)
  parameter L_W = 27,
  // Lever arm fraction bits
  parameter L_F = 23,
  // Jacobian omega width (jw_t W)
  parameter JW_W = 27,
  // Jacobian omega fraction bits
  parameter JW_F = 24,
  // Jacobian v width (jv_t W)
  parameter JV_W = 27,
  // Jacobian v fraction bits
  parameter JV_F = 22,
  // Multiplier implementation: "GENERIC" or "ECP5" (see ts_mul)
  parameter TARGET = "GENERIC",
  // ECP5 wide products on three MULT18X18D (see ts_mul)
  parameter MUL3 = 0,
  // Products per multiplier (cycles per column, II); 1: 24 multipliers in parallel
  parameter FOLD = 1,
  // Folded multiplier banks (FOLD > 1): 1 holds their operands and products in shift chains
  // (ts_mul_bank CHAIN; the same bits and cycles, more registers, shorter wires).
  parameter CHAIN = 0
) (
  input  wire                   clk,
  input  wire                   rst,
  input  wire                   in_valid,
  input  wire signed [Q_W-1:0]  in_q_w,
  input  wire signed [Q_W-1:0]  in_q_x,
  input  wire signed [Q_W-1:0]  in_q_y,
  input  wire signed [Q_W-1:0]  in_q_z,
  input  wire signed [Q_W-1:0]  in_axis_x,
  input  wire signed [Q_W-1:0]  in_axis_y,
  input  wire signed [Q_W-1:0]  in_axis_z,
  input  wire                   in_prismatic,
  input  wire signed [S_W-1:0]  in_s,
  input  wire signed [P_W-1:0]  in_pref_x,
  input  wire signed [P_W-1:0]  in_pref_y,
  input  wire signed [P_W-1:0]  in_pref_z,
  input  wire signed [P_W-1:0]  in_pi_x,
  input  wire signed [P_W-1:0]  in_pi_y,
  input  wire signed [P_W-1:0]  in_pi_z,
  output wire                   out_valid,
  output reg  signed [Q_W-1:0]  out_z_x,
  output reg  signed [Q_W-1:0]  out_z_y,
  output reg  signed [Q_W-1:0]  out_z_z,
  output reg  signed [JW_W-1:0] out_w_x,
  output reg  signed [JW_W-1:0] out_w_y,
  output reg  signed [JW_W-1:0] out_w_z,
  output reg  signed [JV_W-1:0] out_v_x,
  output reg  signed [JV_W-1:0] out_v_y,
  output reg  signed [JV_W-1:0] out_v_z,
  output reg             [15:0] out_flags
);

  `include "ts_common.vh"

  localparam RL = ts_round_lat(1);
  localparam LR = ts_rotate_lat(Q_W, Q_W, UT_W, FOLD);   // ts_quat_rotate
  localparam MLS = ts_bank_lat(S_W, Q_W, FOLD);
  localparam MLC = ts_bank_lat(JW_W, L_W, FOLD);
  // Cycle at which r, w (and the prismatic v) and the cross product are available; latency.
  localparam C_R = 1 + RL;
  localparam C_W = LR + MLS + RL;
  localparam C_V = C_W + MLC + 1 + RL;
  localparam LATENCY = C_V + 1;

  genvar i;

  // ---- z = R(QF) a ------------------------------------------------------------------------------
  wire signed [Q_W-1:0] z [0:2];
  wire z_valid, z_sat;
  ts_quat_rotate #(
    .Q_W(Q_W), .Q_F(Q_F), .V_W(Q_W), .V_F(Q_F), .T_W(UT_W), .T_F(UT_F), .O_W(Q_W), .O_F(Q_F),
    .INV(0), .TARGET(TARGET), .MUL3(MUL3), .FOLD(FOLD), .CHAIN(CHAIN)
  ) u_rot (
    .clk(clk), .rst(rst), .in_valid(in_valid),
    .in_q_w(in_q_w), .in_q_x(in_q_x), .in_q_y(in_q_y), .in_q_z(in_q_z),
    .in_v_x(in_axis_x), .in_v_y(in_axis_y), .in_v_z(in_axis_z),
    .out_valid(z_valid), .out_x(z[0]), .out_y(z[1]), .out_z(z[2]), .out_sat(z_sat));

  // ---- r = cvt<lever_t>(p_ref - p_i), delayed to meet w ------------------------------------------
  wire signed [P_W-1:0] pref [0:2];
  wire signed [P_W-1:0] pi_ [0:2];
  assign pref[0] = in_pref_x; assign pref[1] = in_pref_y; assign pref[2] = in_pref_z;
  assign pi_[0] = in_pi_x;    assign pi_[1] = in_pi_y;    assign pi_[2] = in_pi_z;
  wire signed [L_W-1:0] r [0:2];
  wire [2:0] sat_r;
  generate
    for (i = 0; i < 3; i = i + 1) begin : g_lever
      reg signed [P_W:0] diff;
      always @(posedge clk) begin
        if (rst) diff <= {(P_W+1){1'b0}};
        else     diff <= {pref[i][P_W-1], pref[i]} - {pi_[i][P_W-1], pi_[i]};
      end
      wire signed [L_W-1:0] r0;
      ts_round_sat #(.IN_W(P_W+1), .SHIFT(P_F-L_F), .OUT_W(L_W), .SAT(1)) u_rs (
        .clk(clk), .rst(rst), .in_x(diff), .out_y(r0), .out_sat(sat_r[i]));
      ts_delay #(.W(L_W), .DEPTH(C_W-C_R)) u_rd (.clk(clk), .rst(rst), .din(r0), .dout(r[i]));
    end
  endgenerate

  // ---- s z, rounded to jw_t (revolute w) and to jv_t (prismatic v) ------------------------------
  wire [S_W-1:0] s_d;
  ts_delay #(.W(S_W), .DEPTH(LR)) u_sd (.clk(clk), .rst(rst), .din(in_s), .dout(s_d));
  wire signed [JW_W-1:0] w [0:2];
  wire signed [JV_W-1:0] vp [0:2];
  wire [2:0] sat_w, sat_vp;
  wire [3*(S_W+Q_W)-1:0] psz_bus;
  ts_mul_bank #(.N(3), .FOLD(FOLD), .CHAIN(CHAIN), .A_W(S_W), .B_W(Q_W), .TARGET(TARGET), .MUL3(MUL3)) u_msz (
    .clk(clk), .rst(rst), .in_valid(z_valid), .in_a({s_d, s_d, s_d}), .in_b({z[2], z[1], z[0]}),
    .out_p(psz_bus));
  generate
    for (i = 0; i < 3; i = i + 1) begin : g_sz
      wire signed [S_W+Q_W-1:0] psz = psz_bus[i*(S_W+Q_W) +: S_W+Q_W];
      ts_round_sat #(.IN_W(S_W+Q_W), .SHIFT(S_F+Q_F-JW_F), .OUT_W(JW_W), .SAT(1)) u_rw (
        .clk(clk), .rst(rst), .in_x(psz), .out_y(w[i]), .out_sat(sat_w[i]));
      ts_round_sat #(.IN_W(S_W+Q_W), .SHIFT(S_F+Q_F-JV_F), .OUT_W(JV_W), .SAT(1)) u_rv (
        .clk(clk), .rst(rst), .in_x(psz), .out_y(vp[i]), .out_sat(sat_vp[i]));
    end
  endgenerate

  // ---- v = cross<jv_t>(w, r) ----------------------------------------------------------------------
  localparam PC_W = JW_W + L_W;
  wire signed [PC_W-1:0] pc [0:5];
  // (w1 r2, w2 r1), (w2 r0, w0 r2), (w0 r1, w1 r0); w (and r) are there C_W cycles after in_valid
  wire w_valid;
  ts_delay #(.W(1), .DEPTH(C_W)) u_wv (.clk(clk), .rst(rst), .din(in_valid), .dout(w_valid));
  wire [6*PC_W-1:0] pc_bus;
  ts_mul_bank #(.N(6), .FOLD(FOLD), .CHAIN(CHAIN), .A_W(JW_W), .B_W(L_W), .TARGET(TARGET), .MUL3(MUL3)) u_mc (
    .clk(clk), .rst(rst), .in_valid(w_valid),
    .in_a({w[1], w[0], w[0], w[2], w[2], w[1]}), .in_b({r[0], r[1], r[2], r[0], r[1], r[2]}),
    .out_p(pc_bus));
  generate
    for (i = 0; i < 6; i = i + 1) begin : g_pc
      assign pc[i] = pc_bus[i*PC_W +: PC_W];
    end
  endgenerate
  wire signed [JV_W-1:0] vc [0:2];
  wire [2:0] sat_vc;
  generate
    for (i = 0; i < 3; i = i + 1) begin : g_cross
      reg signed [PC_W:0] cd;
      always @(posedge clk) begin
        if (rst) cd <= {(PC_W+1){1'b0}};
        else     cd <= {pc[2*i][PC_W-1], pc[2*i]} - {pc[2*i+1][PC_W-1], pc[2*i+1]};
      end
      ts_round_sat #(.IN_W(PC_W+1), .SHIFT(JW_F+L_F-JV_F), .OUT_W(JV_W), .SAT(1)) u_rs (
        .clk(clk), .rst(rst), .in_x(cd), .out_y(vc[i]), .out_sat(sat_vc[i]));
    end
  endgenerate

  // ---- alignment to C_V and the output register -------------------------------------------------
  wire [3*Q_W-1:0] z_d;
  ts_delay #(.W(3*Q_W), .DEPTH(C_V-LR)) u_zd (.clk(clk), .rst(rst), .din({z[2], z[1], z[0]}), .dout(z_d));
  wire [3*JW_W-1:0] w_d;
  ts_delay #(.W(3*JW_W), .DEPTH(C_V-C_W)) u_wd (.clk(clk), .rst(rst), .din({w[2], w[1], w[0]}), .dout(w_d));
  wire [3*JV_W-1:0] vp_d;
  ts_delay #(.W(3*JV_W), .DEPTH(C_V-C_W)) u_vpd (.clk(clk), .rst(rst), .din({vp[2], vp[1], vp[0]}), .dout(vp_d));
  wire pr_d;
  ts_delay #(.W(1), .DEPTH(C_V)) u_prd (.clk(clk), .rst(rst), .din(in_prismatic), .dout(pr_d));
  localparam ST_QUAT = 3, ST_LEVER = 5, ST_JAC = 6;
  wire sat_z_d, sat_r_d, sat_w_d, sat_vp_d;
  ts_delay #(.W(1), .DEPTH(C_V-LR))  u_f0 (.clk(clk), .rst(rst), .din(z_sat),   .dout(sat_z_d));
  ts_delay #(.W(1), .DEPTH(C_V-C_R)) u_f1 (.clk(clk), .rst(rst), .din(|sat_r),  .dout(sat_r_d));
  ts_delay #(.W(1), .DEPTH(C_V-C_W)) u_f2 (.clk(clk), .rst(rst), .din(|sat_w),  .dout(sat_w_d));
  ts_delay #(.W(1), .DEPTH(C_V-C_W)) u_f3 (.clk(clk), .rst(rst), .din(|sat_vp), .dout(sat_vp_d));

  always @(posedge clk) begin
    if (rst) begin
      out_z_x <= {Q_W{1'b0}};  out_z_y <= {Q_W{1'b0}};  out_z_z <= {Q_W{1'b0}};
      out_w_x <= {JW_W{1'b0}}; out_w_y <= {JW_W{1'b0}}; out_w_z <= {JW_W{1'b0}};
      out_v_x <= {JV_W{1'b0}}; out_v_y <= {JV_W{1'b0}}; out_v_z <= {JV_W{1'b0}};
      out_flags <= 16'd0;
    end else begin
      out_z_x <= z_d[Q_W-1:0];
      out_z_y <= z_d[2*Q_W-1:Q_W];
      out_z_z <= z_d[3*Q_W-1:2*Q_W];
      out_flags <= 16'd0;
      out_flags[ST_QUAT] <= sat_z_d;
      if (pr_d) begin
        out_w_x <= {JW_W{1'b0}};
        out_w_y <= {JW_W{1'b0}};
        out_w_z <= {JW_W{1'b0}};
        out_v_x <= vp_d[JV_W-1:0];
        out_v_y <= vp_d[2*JV_W-1:JV_W];
        out_v_z <= vp_d[3*JV_W-1:2*JV_W];
        out_flags[ST_JAC] <= sat_vp_d;
      end else begin
        out_w_x <= w_d[JW_W-1:0];
        out_w_y <= w_d[2*JW_W-1:JW_W];
        out_w_z <= w_d[3*JW_W-1:2*JW_W];
        out_v_x <= vc[0];
        out_v_y <= vc[1];
        out_v_z <= vc[2];
        out_flags[ST_LEVER] <= sat_r_d;
        out_flags[ST_JAC] <= sat_w_d | (|sat_vc);
      end
    end
  end

  ts_delay #(.W(1), .DEPTH(LATENCY)) u_valid (.clk(clk), .rst(rst), .din(in_valid), .dout(out_valid));

endmodule

`default_nettype wire
