// SPDX-License-Identifier: Apache-2.0
// tensor-servo: Hamilton quaternion product r = a (x) b in the model's quaternion format
// (quat_t = ap_fixed<Q_W, Q_W - Q_F>), bit-exact with ts::qmul<quat_t> (model/include/tensor_servo/
// quat.hpp):
//   r.w = (aw bw - ax bx) - (ay by + az bz)      r.x = (aw bx + ax bw) + (ay bz - az by)
//   r.y = (aw by - ax bz) + (ay bw + az bx)      r.z = (aw bz + ax by) - (ay bx - az bw)
// 16 registered products (ts_mul_bank: 16 / FOLD multipliers, rounded up), a registered pairwise
// adder tree (2 levels, exact), one rounding/saturation stage per component (ts_round_sat: AP_RND,
// AP_SAT).  Latency ts_bank_lat(Q_W, Q_W, FOLD) + 4 = ts_mul_lat(Q_W, Q_W) + FOLD + 3 cycles,
// II = FOLD, no back-pressure.  The bits do not depend on FOLD.  out_sat = 1 when any component
// saturated (the model raises ST_OVF_QUAT).
// Language: Verilog 2005
`resetall
`timescale 1ns / 1ps
`default_nettype none

module ts_quat_mul #(
  // Quaternion component width (quat_t W)
  parameter Q_W = 27,
  // Quaternion fraction bits (quat_t W - I)
  parameter Q_F = 25,
  // Multiplier implementation: "GENERIC" or "ECP5" (see ts_mul)
  parameter TARGET = "GENERIC",
  // ECP5 wide products on three MULT18X18D (see ts_mul)
  parameter MUL3 = 0,
  // Products per multiplier (cycles per product, II); 1: 16 multipliers in parallel
  parameter FOLD = 1,
  // Folded multiplier banks (FOLD > 1): 1 holds their operands and products in shift chains
  // (ts_mul_bank CHAIN; the same bits and cycles, more registers, shorter wires).
  parameter CHAIN = 0
) (
  input  wire                  clk,
  input  wire                  rst,
  input  wire                  in_valid,
  input  wire signed [Q_W-1:0] in_a_w,
  input  wire signed [Q_W-1:0] in_a_x,
  input  wire signed [Q_W-1:0] in_a_y,
  input  wire signed [Q_W-1:0] in_a_z,
  input  wire signed [Q_W-1:0] in_b_w,
  input  wire signed [Q_W-1:0] in_b_x,
  input  wire signed [Q_W-1:0] in_b_y,
  input  wire signed [Q_W-1:0] in_b_z,
  output wire                  out_valid,
  output wire signed [Q_W-1:0] out_w,
  output wire signed [Q_W-1:0] out_x,
  output wire signed [Q_W-1:0] out_y,
  output wire signed [Q_W-1:0] out_z,
  output wire                  out_sat
);

  `include "ts_common.vh"

  localparam ML = ts_bank_lat(Q_W, Q_W, FOLD);
  // Latency in clock cycles: products, two adder levels, rounding/saturation.
  localparam LATENCY = ML + 2 + ts_round_lat(1);
  localparam P_W = 2 * Q_W;

  wire signed [Q_W-1:0] a [0:3];
  wire signed [Q_W-1:0] b [0:3];
  assign a[0] = in_a_w; assign a[1] = in_a_x; assign a[2] = in_a_y; assign a[3] = in_a_z;
  assign b[0] = in_b_w; assign b[1] = in_b_x; assign b[2] = in_b_y; assign b[3] = in_b_z;

  // p[4 i + j] = a_i * b_j
  wire signed [P_W-1:0] p [0:15];
  wire [16*Q_W-1:0] ba, bb;
  wire [16*P_W-1:0] bp;
  genvar i, j;
  generate
    for (i = 0; i < 4; i = i + 1) begin : g_row
      for (j = 0; j < 4; j = j + 1) begin : g_col
        assign ba[(4*i+j)*Q_W +: Q_W] = a[i];
        assign bb[(4*i+j)*Q_W +: Q_W] = b[j];
        assign p[4*i+j] = bp[(4*i+j)*P_W +: P_W];
      end
    end
  endgenerate
  ts_mul_bank #(.N(16), .FOLD(FOLD), .CHAIN(CHAIN), .A_W(Q_W), .B_W(Q_W), .TARGET(TARGET), .MUL3(MUL3)) u_bank (
    .clk(clk), .rst(rst), .in_valid(in_valid), .in_a(ba), .in_b(bb), .out_p(bp));

  // Level 1: eight pairwise sums, P_W + 1 bits (exact).
  wire signed [P_W:0] e [0:15];
  generate
    for (i = 0; i < 16; i = i + 1) begin : g_ext
      ts_resize #(.IN_W(P_W), .LSH(0), .OUT_W(P_W+1)) u_e (.in(p[i]), .out(e[i]));
    end
  endgenerate

  reg signed [P_W:0] s0a, s0b, s1a, s1b, s2a, s2b, s3a, s3b;
  always @(posedge clk) begin
    if (rst) begin
      s0a <= {(P_W+1){1'b0}}; s0b <= {(P_W+1){1'b0}};
      s1a <= {(P_W+1){1'b0}}; s1b <= {(P_W+1){1'b0}};
      s2a <= {(P_W+1){1'b0}}; s2b <= {(P_W+1){1'b0}};
      s3a <= {(P_W+1){1'b0}}; s3b <= {(P_W+1){1'b0}};
    end else begin
      s0a <= e[0]  - e[5];    // aw bw - ax bx
      s0b <= e[10] + e[15];   // ay by + az bz
      s1a <= e[1]  + e[4];    // aw bx + ax bw
      s1b <= e[11] - e[14];   // ay bz - az by
      s2a <= e[2]  - e[7];    // aw by - ax bz
      s2b <= e[8]  + e[13];   // ay bw + az bx
      s3a <= e[3]  + e[6];    // aw bz + ax by
      s3b <= e[9]  - e[12];   // ay bx - az bw
    end
  end

  // Level 2: the four exact component sums, P_W + 2 bits.
  reg signed [P_W+1:0] r0, r1, r2, r3;
  always @(posedge clk) begin
    if (rst) begin
      r0 <= {(P_W+2){1'b0}}; r1 <= {(P_W+2){1'b0}};
      r2 <= {(P_W+2){1'b0}}; r3 <= {(P_W+2){1'b0}};
    end else begin
      r0 <= {s0a[P_W], s0a} - {s0b[P_W], s0b};
      r1 <= {s1a[P_W], s1a} + {s1b[P_W], s1b};
      r2 <= {s2a[P_W], s2a} + {s2b[P_W], s2b};
      r3 <= {s3a[P_W], s3a} - {s3b[P_W], s3b};
    end
  end

  // Rounding and saturation to quat_t: the product fraction is 2 Q_F.
  wire [3:0] sat;
  ts_round_sat #(.IN_W(P_W+2), .SHIFT(Q_F), .OUT_W(Q_W), .SAT(1)) u_rs0 (
    .clk(clk), .rst(rst), .in_x(r0), .out_y(out_w), .out_sat(sat[0]));
  ts_round_sat #(.IN_W(P_W+2), .SHIFT(Q_F), .OUT_W(Q_W), .SAT(1)) u_rs1 (
    .clk(clk), .rst(rst), .in_x(r1), .out_y(out_x), .out_sat(sat[1]));
  ts_round_sat #(.IN_W(P_W+2), .SHIFT(Q_F), .OUT_W(Q_W), .SAT(1)) u_rs2 (
    .clk(clk), .rst(rst), .in_x(r2), .out_y(out_y), .out_sat(sat[2]));
  ts_round_sat #(.IN_W(P_W+2), .SHIFT(Q_F), .OUT_W(Q_W), .SAT(1)) u_rs3 (
    .clk(clk), .rst(rst), .in_x(r3), .out_y(out_z), .out_sat(sat[3]));
  assign out_sat = |sat;

  ts_delay #(.W(1), .DEPTH(LATENCY)) u_valid (
    .clk(clk), .rst(rst), .din(in_valid), .dout(out_valid));

endmodule

`default_nettype wire
