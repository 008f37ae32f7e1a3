// tensor-servo: out_y = max(in_lo, min(in_hi, in_x)), signed, bit-exact with the model's clamps
// (std::min then std::max, any in_lo and in_hi, in_lo > in_hi included: the result is then in_lo).
//
// The three comparisons run side by side and two multiplexer levels combine them:
//   t = (hi < x) ? hi : x;   y = (lo < t) ? t : lo,   where lo < t = (hi < x) ? (lo < hi) : (lo < x).
// Written as two clamps in series, the second comparator's carry chain waited for the first
// comparator and multiplexer: in the solver that chain was the engine's critical path
// (two 32-bit carry chains, 17 ns after place and route on LFE5U-85F -6).
// Combinational.  Language: Verilog 2005
`resetall
`timescale 1ns / 1ps
`default_nettype none

module ts_clamp #(
  // operand width (bits)
  parameter integer W = 32
) (
  input  wire signed [W-1:0] in_x,
  input  wire signed [W-1:0] in_lo,
  input  wire signed [W-1:0] in_hi,
  output wire signed [W-1:0] out_y
);

  wire hi_lt_x  = in_hi < in_x;
  wire lo_lt_hi = in_lo < in_hi;
  wire lo_lt_x  = in_lo < in_x;
  wire lo_lt_t  = hi_lt_x ? lo_lt_hi : lo_lt_x;
  wire signed [W-1:0] t = hi_lt_x ? in_hi : in_x;
  assign out_y = lo_lt_t ? t : in_lo;

endmodule

`default_nettype wire
