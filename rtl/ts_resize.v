// SPDX-License-Identifier: Apache-2.0
// tensor-servo: combinational resize of a signed value: out = (in * 2^LSH) mod 2^OUT_W, with sign
// extension.  Aligns binary points (LSH = fraction bits to add) and sizes operands for the adder
// trees without lint-unclean implicit extension; truncation (OUT_W < IN_W + LSH) keeps the low
// bits, which is exact whenever the value fits OUT_W (modular sums).  No logic beyond wiring.
// Language: Verilog 2005
`resetall
`timescale 1ns / 1ps
`default_nettype none

module ts_resize #(
  // Input width (signed)
  parameter IN_W = 8,
  // Left shift in bits (>= 0): zero fraction bits appended
  parameter LSH = 0,
  // Output width (signed)
  parameter OUT_W = 8
) (
  input  wire signed [IN_W-1:0]  in,
  output wire signed [OUT_W-1:0] out
);

  localparam SH_W = IN_W + LSH;

  wire signed [SH_W-1:0] sh;

  generate
    if (LSH > 0) begin : g_shift
      assign sh = {in, {LSH{1'b0}}};
    end else begin : g_noshift
      assign sh = in;
    end

    if (OUT_W > SH_W) begin : g_ext
      assign out = {{(OUT_W - SH_W){sh[SH_W-1]}}, sh};
    end else if (OUT_W == SH_W) begin : g_same
      assign out = sh;
    end else begin : g_trunc
      assign out = sh[OUT_W-1:0];
      // The dropped high bits are redundant when the value fits (documented contract).
      wire unused_high = ^sh[SH_W-1:OUT_W];
    end
  endgenerate

endmodule

`default_nettype wire
