// SPDX-License-Identifier: Apache-2.0
// tensor-servo test bench wrapper: eight ts_quat_rotate instances, the model's four kinds (axis,
// offset, jw, jv; vector/tmp/output formats as parameters) each forward (INV = 0) and inverse
// (INV = 1), fed in parallel from packed buses so the bench drives few handles per cycle.
//   in_bus  32-bit slots: 0..3 q (w, x, y, z); 4 + 3 k + c: component c of the vector of kind k
//   out_bus 32-bit slots: 3 m + c component c of instance m = 2 k + inv; then 8 sat bits, then the
//           8 out_valid bits of the instances (all must equal out_valid)
// Language: Verilog 2005
`resetall
`timescale 1ns / 1ps
`default_nettype none

module tb_ts_quat_rotate #(
  // quaternion width
  parameter Q_W = 27,
  // quaternion fraction bits
  parameter Q_F = 25,
  // kind axis: vector, tmp, output formats
  parameter AX_V_W = 27,
  // kind axis: vector fraction bits
  parameter AX_V_F = 25,
  // kind axis: tmp width
  parameter AX_T_W = 27,
  // kind axis: tmp fraction bits
  parameter AX_T_F = 24,
  // kind axis: output width
  parameter AX_O_W = 27,
  // kind axis: output fraction bits
  parameter AX_O_F = 25,
  // kind offset: vector width
  parameter OF_V_W = 27,
  // kind offset: vector fraction bits
  parameter OF_V_F = 24,
  // kind offset: tmp width
  parameter OF_T_W = 27,
  // kind offset: tmp fraction bits
  parameter OF_T_F = 22,
  // kind offset: output width
  parameter OF_O_W = 32,
  // kind offset: output fraction bits
  parameter OF_O_F = 27,
  // kind jw: vector width
  parameter JW_V_W = 27,
  // kind jw: vector fraction bits
  parameter JW_V_F = 24,
  // kind jw: tmp width
  parameter JW_T_W = 27,
  // kind jw: tmp fraction bits
  parameter JW_T_F = 23,
  // kind jw: output width
  parameter JW_O_W = 27,
  // kind jw: output fraction bits
  parameter JW_O_F = 24,
  // kind jv: vector width
  parameter JV_V_W = 27,
  // kind jv: vector fraction bits
  parameter JV_V_F = 22,
  // kind jv: tmp width
  parameter JV_T_W = 27,
  // kind jv: tmp fraction bits
  parameter JV_T_F = 21,
  // kind jv: output width
  parameter JV_O_W = 27,
  // kind jv: output fraction bits
  parameter JV_O_F = 22,
  // multiplier implementation
  parameter TARGET = "GENERIC",
  // products per multiplier (II)
  parameter FOLD = 1
) (
  input  wire           clk,
  input  wire           rst,
  input  wire           in_valid,
  input  wire [16*32-1:0] in_bus,
  output wire           out_valid,
  output wire [24*32+16-1:0] out_bus
);

  wire [7:0] valids;
  wire [7:0] sats;
  genvar m;
  generate
    for (m = 0; m < 8; m = m + 1) begin : g_inst
      localparam K = m / 2;
      localparam V_W = (K == 0) ? AX_V_W : (K == 1) ? OF_V_W : (K == 2) ? JW_V_W : JV_V_W;
      localparam V_F = (K == 0) ? AX_V_F : (K == 1) ? OF_V_F : (K == 2) ? JW_V_F : JV_V_F;
      localparam T_W = (K == 0) ? AX_T_W : (K == 1) ? OF_T_W : (K == 2) ? JW_T_W : JV_T_W;
      localparam T_F = (K == 0) ? AX_T_F : (K == 1) ? OF_T_F : (K == 2) ? JW_T_F : JV_T_F;
      localparam O_W = (K == 0) ? AX_O_W : (K == 1) ? OF_O_W : (K == 2) ? JW_O_W : JV_O_W;
      localparam O_F = (K == 0) ? AX_O_F : (K == 1) ? OF_O_F : (K == 2) ? JW_O_F : JV_O_F;
      wire signed [O_W-1:0] ox, oy, oz;
      ts_quat_rotate #(
        .Q_W(Q_W), .Q_F(Q_F), .V_W(V_W), .V_F(V_F), .T_W(T_W), .T_F(T_F), .O_W(O_W), .O_F(O_F),
        .INV(m % 2), .TARGET(TARGET), .FOLD(FOLD)
      ) u_rot (
        .clk(clk), .rst(rst), .in_valid(in_valid),
        .in_q_w(in_bus[0*32 +: Q_W]), .in_q_x(in_bus[1*32 +: Q_W]),
        .in_q_y(in_bus[2*32 +: Q_W]), .in_q_z(in_bus[3*32 +: Q_W]),
        .in_v_x(in_bus[(4+3*K)*32 +: V_W]), .in_v_y(in_bus[(5+3*K)*32 +: V_W]),
        .in_v_z(in_bus[(6+3*K)*32 +: V_W]),
        .out_valid(valids[m]), .out_x(ox), .out_y(oy), .out_z(oz), .out_sat(sats[m])
      );
      ts_resize #(.IN_W(O_W), .LSH(0), .OUT_W(32)) u_x (.in(ox), .out(out_bus[(3*m+0)*32 +: 32]));
      ts_resize #(.IN_W(O_W), .LSH(0), .OUT_W(32)) u_y (.in(oy), .out(out_bus[(3*m+1)*32 +: 32]));
      ts_resize #(.IN_W(O_W), .LSH(0), .OUT_W(32)) u_z (.in(oz), .out(out_bus[(3*m+2)*32 +: 32]));
    end
  endgenerate
  assign out_bus[24*32 +: 8] = sats;
  assign out_bus[24*32+8 +: 8] = valids;
  assign out_valid = valids[0];

endmodule

`default_nettype wire
