// SPDX-License-Identifier: Apache-2.0
// tensor-servo test bench wrapper: ts_delay with DEPTH 0, 1, 3, 17 and D (W bits each) side by side,
// D both as a ring in a memory (the default for data lines, RAM = 1) and as a shift register
// (RAM = 0), and the valid pipeline (itself a ts_delay, W = 1, DEPTH = D) as out_valid.  DEPTH 3 is
// the shortest ring (2 words), DEPTH 17 a ring of exactly 16 words (one distributed-RAM deep).
// Language: Verilog 2005
`resetall
`timescale 1ns / 1ps
`default_nettype none

module tb_ts_delay #(
  // data width
  parameter W = 81,
  // the long delay
  parameter D = 40
) (
  input  wire         clk,
  input  wire         rst,
  input  wire         in_valid,
  input  wire [W-1:0] in_d,
  output wire         out_valid,
  output wire [W-1:0] out_d0,
  output wire [W-1:0] out_d1,
  output wire [W-1:0] out_dd,
  output wire [W-1:0] out_ds,
  output wire [W-1:0] out_d3,
  output wire [W-1:0] out_d17
);

  ts_delay #(.W(W), .DEPTH(0)) u_d0 (.clk(clk), .rst(rst), .din(in_d), .dout(out_d0));
  ts_delay #(.W(W), .DEPTH(1)) u_d1 (.clk(clk), .rst(rst), .din(in_d), .dout(out_d1));
  ts_delay #(.W(W), .DEPTH(D), .RAM(1)) u_dd (.clk(clk), .rst(rst), .din(in_d), .dout(out_dd));
  ts_delay #(.W(W), .DEPTH(D), .RAM(0)) u_ds (.clk(clk), .rst(rst), .din(in_d), .dout(out_ds));
  ts_delay #(.W(W), .DEPTH(3), .RAM(1)) u_d3 (.clk(clk), .rst(rst), .din(in_d), .dout(out_d3));
  ts_delay #(.W(W), .DEPTH(17), .RAM(1)) u_d17 (.clk(clk), .rst(rst), .din(in_d), .dout(out_d17));
  ts_delay #(.W(1), .DEPTH(D)) u_valid (.clk(clk), .rst(rst), .din(in_valid), .dout(out_valid));

endmodule

`default_nettype wire
