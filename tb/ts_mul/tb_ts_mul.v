// SPDX-License-Identifier: Apache-2.0
// tensor-servo test bench wrapper: four ts_mul instances with the operand shapes of one
// configuration, in parallel; each product is delayed to the longest latency so the four share
// out_valid (a wrong instance latency shows up as misaligned products).
//   in_a<k>, in_b<k>: operands of instance k (low A_W_k / B_W_k bits of 64)
//   out_p<k>: product of instance k, sign-extended to 72 bits
// Language: Verilog 2005
`resetall
`timescale 1ns / 1ps
`default_nettype none

module tb_ts_mul #(
  // instance 0..3 operand widths
  parameter AW0 = 27, parameter BW0 = 27,
  // instance 1
  parameter AW1 = 32, parameter BW1 = 30,
  // instance 2
  parameter AW2 = 23, parameter BW2 = 27,
  // instance 3
  parameter AW3 = 27, parameter BW3 = 18,
  // multiplier implementation
  parameter TARGET = "GENERIC",
  // ts_mul MUL3 (ECP5: three-multiplier wide products)
  parameter MUL3 = 0
) (
  input  wire        clk,
  input  wire        rst,
  input  wire        in_valid,
  input  wire [63:0] in_a0, in_b0, in_a1, in_b1, in_a2, in_b2, in_a3, in_b3,
  output wire        out_valid,
  output wire [71:0] out_p0, out_p1, out_p2, out_p3
);

  `include "ts_common.vh"

  localparam LMAX = ts_max(ts_max(ts_mul_lat(AW0, BW0), ts_mul_lat(AW1, BW1)),
                           ts_max(ts_mul_lat(AW2, BW2), ts_mul_lat(AW3, BW3)));
  wire [4*64-1:0] ina = {in_a3, in_a2, in_a1, in_a0};
  wire [4*64-1:0] inb = {in_b3, in_b2, in_b1, in_b0};
  wire [4*72-1:0] outp;
  assign {out_p3, out_p2, out_p1, out_p0} = outp;

  genvar k;
  generate
    for (k = 0; k < 4; k = k + 1) begin : g_inst
      localparam AW = (k == 0) ? AW0 : (k == 1) ? AW1 : (k == 2) ? AW2 : AW3;
      localparam BW = (k == 0) ? BW0 : (k == 1) ? BW1 : (k == 2) ? BW2 : BW3;
      wire signed [AW+BW-1:0] p;
      ts_mul #(.A_W(AW), .B_W(BW), .TARGET(TARGET), .MUL3(MUL3)) u_mul (
        .clk(clk), .rst(rst), .a(ina[64*k +: AW]), .b(inb[64*k +: BW]), .p(p));
      wire [AW+BW-1:0] pd;
      ts_delay #(.W(AW+BW), .DEPTH(LMAX - ts_mul_lat(AW, BW))) u_d (.clk(clk), .rst(rst), .din(p), .dout(pd));
      ts_resize #(.IN_W(AW+BW), .LSH(0), .OUT_W(72)) u_x (.in(pd), .out(outp[72*k +: 72]));
    end
  endgenerate

  ts_delay #(.W(1), .DEPTH(LMAX)) u_valid (.clk(clk), .rst(rst), .din(in_valid), .dout(out_valid));

endmodule

`default_nettype wire
