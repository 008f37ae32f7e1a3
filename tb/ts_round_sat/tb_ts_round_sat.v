// SPDX-License-Identifier: Apache-2.0
// tensor-servo test bench wrapper: eight ts_round_sat instances with the (IN_W, SHIFT, OUT_W, SAT)
// sets of one configuration, in parallel from packed buses (64-bit slots):
//   in_x<k>  input of instance k (low IN_W_k bits of 64)
//   out_y<k> output of instance k (sign-extended to 64 bits); out_sat bit k: its flag
// out_valid = in_valid delayed by the module latency (ts_round_lat).
// Language: Verilog 2005
`resetall
`timescale 1ns / 1ps
`default_nettype none

module tb_ts_round_sat #(
  // instance 0..7: input width, shift, output width, saturate (1) or wrap (0)
  parameter IW0 = 56, parameter SH0 = 25, parameter OW0 = 27, parameter SA0 = 1,
  // instance 1
  parameter IW1 = 56, parameter SH1 = 25, parameter OW1 = 27, parameter SA1 = 1,
  // instance 2
  parameter IW2 = 56, parameter SH2 = 25, parameter OW2 = 27, parameter SA2 = 1,
  // instance 3
  parameter IW3 = 56, parameter SH3 = 25, parameter OW3 = 27, parameter SA3 = 1,
  // instance 4
  parameter IW4 = 56, parameter SH4 = 25, parameter OW4 = 27, parameter SA4 = 1,
  // instance 5
  parameter IW5 = 56, parameter SH5 = 25, parameter OW5 = 27, parameter SA5 = 1,
  // instance 6
  parameter IW6 = 56, parameter SH6 = 25, parameter OW6 = 27, parameter SA6 = 1,
  // instance 7
  parameter IW7 = 56, parameter SH7 = 25, parameter OW7 = 27, parameter SA7 = 1
) (
  input  wire            clk,
  input  wire            rst,
  input  wire            in_valid,
  input  wire [63:0]     in_x0, in_x1, in_x2, in_x3, in_x4, in_x5, in_x6, in_x7,
  output wire            out_valid,
  output wire [63:0]     out_y0, out_y1, out_y2, out_y3, out_y4, out_y5, out_y6, out_y7,
  output wire [7:0]      out_sat
);

  wire [8*64-1:0] in_bus = {in_x7, in_x6, in_x5, in_x4, in_x3, in_x2, in_x1, in_x0};
  wire [8*64-1:0] out_bus;
  assign {out_y7, out_y6, out_y5, out_y4, out_y3, out_y2, out_y1, out_y0} = out_bus;

  `include "ts_common.vh"

  genvar k;
  generate
    for (k = 0; k < 8; k = k + 1) begin : g_inst
      localparam IW = (k == 0) ? IW0 : (k == 1) ? IW1 : (k == 2) ? IW2 : (k == 3) ? IW3 :
                      (k == 4) ? IW4 : (k == 5) ? IW5 : (k == 6) ? IW6 : IW7;
      localparam SH = (k == 0) ? SH0 : (k == 1) ? SH1 : (k == 2) ? SH2 : (k == 3) ? SH3 :
                      (k == 4) ? SH4 : (k == 5) ? SH5 : (k == 6) ? SH6 : SH7;
      localparam OW = (k == 0) ? OW0 : (k == 1) ? OW1 : (k == 2) ? OW2 : (k == 3) ? OW3 :
                      (k == 4) ? OW4 : (k == 5) ? OW5 : (k == 6) ? OW6 : OW7;
      localparam SA = (k == 0) ? SA0 : (k == 1) ? SA1 : (k == 2) ? SA2 : (k == 3) ? SA3 :
                      (k == 4) ? SA4 : (k == 5) ? SA5 : (k == 6) ? SA6 : SA7;
      wire signed [OW-1:0] y;
      ts_round_sat #(.IN_W(IW), .SHIFT(SH), .OUT_W(OW), .SAT(SA)) u_rs (
        .clk(clk), .rst(rst), .in_x(in_bus[64*k +: IW]), .out_y(y), .out_sat(out_sat[k]));
      ts_resize #(.IN_W(OW), .LSH(0), .OUT_W(64)) u_x (.in(y), .out(out_bus[64*k +: 64]));
    end
  endgenerate

  ts_delay #(.W(1), .DEPTH(ts_round_lat(1))) u_valid (.clk(clk), .rst(rst), .din(in_valid), .dout(out_valid));

endmodule

`default_nettype wire
