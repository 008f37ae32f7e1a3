// SPDX-License-Identifier: Apache-2.0
// tensor-servo: rotation of a 3-vector by a unit quaternion q = (w, x, y, z), bit-exact with
// ts::rotate<Out, Tmp, INV> (model/include/tensor_servo/quat.hpp):
//   t   = 2 (q_v x v)              rounded to the tmp format (T_W, T_F)
//   out = v + w t + q_v x t        rounded to the output format (O_W, O_F)
// INV = 1 rotates by the conjugate (q* v q): the vector part enters negated, folded into the
// differences (each difference is formed with swapped operands, then rounded), as in the model.
// The same module serves the model's four kinds by its format parameters (axis, offset, jw, jv).
// Stage A: 6 products, registered difference, round/saturate -> t.  Stage B: 9 products, two
// registered adder levels, round/saturate.  Each stage's products on a ts_mul_bank (6 / FOLD and
// 9 / FOLD multipliers, rounded up).  Latency ts_bank_lat(Q_W, V_W, FOLD) + ts_bank_lat(Q_W, T_W,
// FOLD) + 7 cycles, II = FOLD; the bits do not depend on FOLD.  out_sat = 1 when t or an output
// component saturated.
// Language: Verilog 2005
`resetall
`timescale 1ns / 1ps
`default_nettype none

module ts_quat_rotate #(
  // Quaternion component width (quat_t W)
  parameter Q_W = 27,
  // Quaternion fraction bits
  parameter Q_F = 25,
  // Input vector component width
  parameter V_W = 27,
  // Input vector fraction bits
  parameter V_F = 25,
  // Intermediate t = 2 q_v x v width (tmp format)
  parameter T_W = 27,
  // Intermediate t fraction bits
  parameter T_F = 24,
  // Output vector component width
  parameter O_W = 27,
  // Output vector fraction bits
  parameter O_F = 25,
  // 0: q v q*; 1: q* v q (rotation by the conjugate)
  parameter INV = 0,
  // Multiplier implementation: "GENERIC" or "ECP5" (see ts_mul)
  parameter TARGET = "GENERIC",
  // ECP5 wide products on three MULT18X18D (see ts_mul)
  parameter MUL3 = 0,
  // Products per multiplier (cycles per vector, II); 1: 15 multipliers in parallel
  parameter FOLD = 1,
  // Folded multiplier banks (FOLD > 1): 1 holds their operands and products in shift chains
  // (ts_mul_bank CHAIN; the same bits and cycles, more registers, shorter wires).
  parameter CHAIN = 0
) (
  input  wire                  clk,
  input  wire                  rst,
  input  wire                  in_valid,
  input  wire signed [Q_W-1:0] in_q_w,
  input  wire signed [Q_W-1:0] in_q_x,
  input  wire signed [Q_W-1:0] in_q_y,
  input  wire signed [Q_W-1:0] in_q_z,
  input  wire signed [V_W-1:0] in_v_x,
  input  wire signed [V_W-1:0] in_v_y,
  input  wire signed [V_W-1:0] in_v_z,
  output wire                  out_valid,
  output wire signed [O_W-1:0] out_x,
  output wire signed [O_W-1:0] out_y,
  output wire signed [O_W-1:0] out_z,
  output wire                  out_sat
);

  `include "ts_common.vh"

  localparam MLA = ts_bank_lat(Q_W, V_W, FOLD);
  localparam MLB = ts_bank_lat(Q_W, T_W, FOLD);
  // Stage A latency (t available), total latency.
  localparam LA = MLA + 1 + ts_round_lat(1);
  localparam LATENCY = ts_rotate_lat(Q_W, V_W, T_W, FOLD);   // = LA + MLB + 2 + ts_round_lat(1)

  // ---- stage A: t = 2 q_v x v ---------------------------------------------------------------
  localparam PA_W = Q_W + V_W;
  wire signed [PA_W-1:0] pa [0:5];
  // Products in the order of the three differences: (y a2, z a1), (z a0, x a2), (x a1, y a0).
  wire [6*PA_W-1:0] pa_bus;
  ts_mul_bank #(.N(6), .FOLD(FOLD), .CHAIN(CHAIN), .A_W(Q_W), .B_W(V_W), .TARGET(TARGET), .MUL3(MUL3)) u_pa (
    .clk(clk), .rst(rst), .in_valid(in_valid),
    .in_a({in_q_y, in_q_x, in_q_x, in_q_z, in_q_z, in_q_y}),
    .in_b({in_v_x, in_v_y, in_v_z, in_v_x, in_v_y, in_v_z}),
    .out_p(pa_bus));
  genvar i;
  generate
    for (i = 0; i < 6; i = i + 1) begin : g_pa
      assign pa[i] = pa_bus[i*PA_W +: PA_W];
    end
  endgenerate

  reg signed [PA_W:0] da [0:2];
  integer k;
  integer ks;  // loop index of the sum stage (one loop variable per process: no shared register)
  always @(posedge clk) begin
    if (rst) begin
      for (k = 0; k < 3; k = k + 1) da[k] <= {(PA_W+1){1'b0}};
    end else begin
      for (k = 0; k < 3; k = k + 1) begin
        if (INV == 0) da[k] <= {pa[2*k][PA_W-1], pa[2*k]} - {pa[2*k+1][PA_W-1], pa[2*k+1]};
        else          da[k] <= {pa[2*k+1][PA_W-1], pa[2*k+1]} - {pa[2*k][PA_W-1], pa[2*k]};
      end
    end
  end

  // 2 (q_v x v): the factor 2 moves the binary point (fraction Q_F + V_F - 1).
  wire signed [T_W-1:0] t [0:2];
  wire [2:0] sat_t;
  generate
    for (i = 0; i < 3; i = i + 1) begin : g_t
      ts_round_sat #(.IN_W(PA_W+1), .SHIFT(Q_F+V_F-1-T_F), .OUT_W(T_W), .SAT(1)) u_rs (
        .clk(clk), .rst(rst), .in_x(da[i]), .out_y(t[i]), .out_sat(sat_t[i]));
    end
  endgenerate

  // ---- stage B: out = v + w t + q_v x t -----------------------------------------------------
  // q delayed to meet t; v delayed to meet the stage-B products.
  wire [4*Q_W-1:0] q_d;
  ts_delay #(.W(4*Q_W), .DEPTH(LA)) u_qd (
    .clk(clk), .rst(rst), .din({in_q_z, in_q_y, in_q_x, in_q_w}), .dout(q_d));
  wire signed [Q_W-1:0] w_b = q_d[Q_W-1:0];
  wire signed [Q_W-1:0] x_b = q_d[2*Q_W-1:Q_W];
  wire signed [Q_W-1:0] y_b = q_d[3*Q_W-1:2*Q_W];
  wire signed [Q_W-1:0] z_b = q_d[4*Q_W-1:3*Q_W];
  wire [3*V_W-1:0] v_d;
  ts_delay #(.W(3*V_W), .DEPTH(LA+MLB)) u_vd (
    .clk(clk), .rst(rst), .din({in_v_z, in_v_y, in_v_x}), .dout(v_d));

  localparam PB_W = Q_W + T_W;
  localparam PB_F = Q_F + T_F;
  wire signed [PB_W-1:0] wt [0:2];
  wire signed [PB_W-1:0] pb [0:5];
  // stage B operands are valid (t out of its rounding) LA cycles after in_valid
  wire b_valid;
  ts_delay #(.W(1), .DEPTH(LA)) u_bv (.clk(clk), .rst(rst), .din(in_valid), .dout(b_valid));
  // products 0-2: w t_i; 3-8: the cross terms, same order as stage A: (y b2, z b1), (z b0, x b2),
  // (x b1, y b0)
  wire [9*PB_W-1:0] pb_bus;
  ts_mul_bank #(.N(9), .FOLD(FOLD), .CHAIN(CHAIN), .A_W(Q_W), .B_W(T_W), .TARGET(TARGET), .MUL3(MUL3)) u_pb (
    .clk(clk), .rst(rst), .in_valid(b_valid),
    .in_a({y_b, x_b, x_b, z_b, z_b, y_b, w_b, w_b, w_b}),
    .in_b({t[0], t[1], t[2], t[0], t[1], t[2], t[2], t[1], t[0]}),
    .out_p(pb_bus));
  generate
    for (i = 0; i < 3; i = i + 1) begin : g_wt
      assign wt[i] = pb_bus[i*PB_W +: PB_W];
    end
    for (i = 0; i < 6; i = i + 1) begin : g_pb
      assign pb[i] = pb_bus[(3+i)*PB_W +: PB_W];
    end
  endgenerate

  // Exact sum format: fraction FS = max(V_F, PB_F); integer bits max + 2 (two additions).
  localparam FS = ts_max(V_F, PB_F);
  localparam IS = ts_max(V_W - V_F, PB_W - PB_F) + 2;
  localparam S_W = IS + FS;

  wire signed [S_W-1:0] va [0:2];
  wire signed [S_W-1:0] wa [0:2];
  wire signed [S_W-1:0] pe [0:5];
  generate
    for (i = 0; i < 3; i = i + 1) begin : g_align
      ts_resize #(.IN_W(V_W), .LSH(FS-V_F), .OUT_W(S_W)) u_va (.in(v_d[V_W*i +: V_W]), .out(va[i]));
      ts_resize #(.IN_W(PB_W), .LSH(FS-PB_F), .OUT_W(S_W)) u_wa (.in(wt[i]), .out(wa[i]));
    end
    for (i = 0; i < 6; i = i + 1) begin : g_palign
      ts_resize #(.IN_W(PB_W), .LSH(FS-PB_F), .OUT_W(S_W)) u_pe (.in(pb[i]), .out(pe[i]));
    end
  endgenerate

  reg signed [S_W-1:0] s1 [0:2];
  reg signed [S_W-1:0] c1 [0:2];
  reg signed [S_W-1:0] s2 [0:2];
  always @(posedge clk) begin
    if (rst) begin
      for (ks = 0; ks < 3; ks = ks + 1) begin
        s1[ks] <= {S_W{1'b0}};
        c1[ks] <= {S_W{1'b0}};
        s2[ks] <= {S_W{1'b0}};
      end
    end else begin
      for (ks = 0; ks < 3; ks = ks + 1) begin
        s1[ks] <= va[ks] + wa[ks];
        if (INV == 0) c1[ks] <= pe[2*ks] - pe[2*ks+1];
        else          c1[ks] <= pe[2*ks+1] - pe[2*ks];
        s2[ks] <= s1[ks] + c1[ks];
      end
    end
  end

  wire [2:0] sat_o;
  wire signed [O_W-1:0] o [0:2];
  generate
    for (i = 0; i < 3; i = i + 1) begin : g_o
      ts_round_sat #(.IN_W(S_W), .SHIFT(FS-O_F), .OUT_W(O_W), .SAT(1)) u_rs (
        .clk(clk), .rst(rst), .in_x(s2[i]), .out_y(o[i]), .out_sat(sat_o[i]));
    end
  endgenerate
  assign out_x = o[0];
  assign out_y = o[1];
  assign out_z = o[2];

  wire sat_t_d;
  ts_delay #(.W(1), .DEPTH(LATENCY-LA)) u_satd (.clk(clk), .rst(rst), .din(|sat_t), .dout(sat_t_d));
  assign out_sat = sat_t_d | (|sat_o);

  ts_delay #(.W(1), .DEPTH(LATENCY)) u_valid (.clk(clk), .rst(rst), .din(in_valid), .dout(out_valid));

endmodule

`default_nettype wire
