// SPDX-License-Identifier: Apache-2.0
// tensor-servo test bench wrapper: ts_resize in its six cases (sign extension, same width, truncation,
// each with and without a left shift), all from one W-bit input.
// Language: Verilog 2005
`resetall
`timescale 1ns / 1ps
`default_nettype none

module tb_ts_resize #(
  // input width
  parameter W = 27,
  // left shift of the shifting cases
  parameter L = 5
) (
  input  wire signed [W-1:0]     in_x,
  output wire signed [W+7:0]     out_ext,
  output wire signed [W-1:0]     out_same,
  output wire signed [W-5:0]     out_trunc,
  output wire signed [W+L+3:0]   out_sh_ext,
  output wire signed [W+L-1:0]   out_sh_same,
  output wire signed [W+L-4:0]   out_sh_trunc
);

  ts_resize #(.IN_W(W), .LSH(0), .OUT_W(W+8))   u0 (.in(in_x), .out(out_ext));
  ts_resize #(.IN_W(W), .LSH(0), .OUT_W(W))     u1 (.in(in_x), .out(out_same));
  ts_resize #(.IN_W(W), .LSH(0), .OUT_W(W-4))   u2 (.in(in_x), .out(out_trunc));
  ts_resize #(.IN_W(W), .LSH(L), .OUT_W(W+L+4)) u3 (.in(in_x), .out(out_sh_ext));
  ts_resize #(.IN_W(W), .LSH(L), .OUT_W(W+L))   u4 (.in(in_x), .out(out_sh_same));
  ts_resize #(.IN_W(W), .LSH(L), .OUT_W(W+L-3)) u5 (.in(in_x), .out(out_sh_trunc));

endmodule

`default_nettype wire
