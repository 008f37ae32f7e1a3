// SPDX-License-Identifier: Apache-2.0
// tensor-servo: the model's narrowing, two registered stages (round, then saturate/wrap).
//   SAT = 1: cvt<Dst>   round to nearest, ties toward +inf (ap_fixed AP_RND: add half an output LSB,
//                       arithmetic shift right), then saturate to OUT_W bits (AP_SAT); out_sat = 1
//                       when saturation happened.
//   SAT = 0: wrap<Dst>  same rounding, keep the low OUT_W bits (AP_WRAP); out_sat = 0.
// SHIFT = input fraction bits - output fraction bits; SHIFT <= 0 is an exact left shift.
// Latency 2 cycles (ts_round_lat): the rounding carry chain and the range check with its output
// multiplexer are in separate register stages (one stage measured 150 MHz on ECP5 -6).
// Defined by model/include/tensor_servo/fixed.hpp (detail::round_raw, cvt, wrap).
// Language: Verilog 2005
`resetall
`timescale 1ns / 1ps
`default_nettype none

module ts_round_sat #(
  // Input width (signed)
  parameter IN_W = 56,
  // Right shift: input fraction bits minus output fraction bits (<= 0: exact left shift)
  parameter SHIFT = 25,
  // Output width (signed)
  parameter OUT_W = 27,
  // 1: saturate and flag (cvt); 0: wrap, never flag (wrap)
  parameter SAT = 1
) (
  input  wire                    clk,
  input  wire                    rst,
  input  wire signed [IN_W-1:0]  in_x,
  output reg  signed [OUT_W-1:0] out_y,
  output reg                     out_sat
);

  // Width of the rounded value before saturation.
  localparam R_W = (SHIFT > 0) ? (IN_W - SHIFT + 1) : (IN_W - SHIFT);

  wire signed [R_W-1:0] r;

  generate
    if (SHIFT > 0) begin : g_round
      // floor((x + 2^(SHIFT-1)) / 2^SHIFT) = (floor(x / 2^(SHIFT-1)) + 1) >> 1: the carry chain
      // covers only the kept bits and the rounding bit.
      wire signed [R_W:0] inc = {in_x[IN_W-1], in_x[IN_W-1:SHIFT-1]} + {{R_W{1'b0}}, 1'b1};
      assign r = inc[R_W:1];
      if (SHIFT > 1) begin : g_low
        wire unused_low = ^in_x[SHIFT-2:0];
      end
      wire unused_lsb = inc[0];
    end else if (SHIFT == 0) begin : g_none
      assign r = in_x;
    end else begin : g_left
      assign r = {in_x, {(-SHIFT){1'b0}}};
    end
  endgenerate

  // Stage 1: the rounded value.
  reg signed [R_W-1:0] r_q;
  always @(posedge clk) begin
    if (rst) r_q <= {R_W{1'b0}};
    else     r_q <= r;
  end

  // Stage 2: range check and saturation (or wrap).
  wire signed [OUT_W-1:0] y;
  wire                    ovf;

  generate
    if (R_W > OUT_W) begin : g_narrow
      // The value fits when the bits above the output sign bit all equal the sign bit.
      wire [R_W-OUT_W:0] top = r_q[R_W-1:OUT_W-1];
      wire fits = (top == {(R_W-OUT_W+1){1'b0}}) || (top == {(R_W-OUT_W+1){1'b1}});
      if (SAT != 0) begin : g_sat
        assign ovf = ~fits;
        assign y = fits ? r_q[OUT_W-1:0]
                 : (r_q[R_W-1] ? {1'b1, {(OUT_W-1){1'b0}}} : {1'b0, {(OUT_W-1){1'b1}}});
      end else begin : g_wrap
        assign ovf = 1'b0;
        assign y = r_q[OUT_W-1:0];
        wire unused_fits = fits;
      end
    end else if (R_W == OUT_W) begin : g_equal
      assign ovf = 1'b0;
      assign y = r_q;
    end else begin : g_wide
      assign ovf = 1'b0;
      assign y = {{(OUT_W-R_W){r_q[R_W-1]}}, r_q};
    end
  endgenerate

  always @(posedge clk) begin
    if (rst) begin
      out_y   <= {OUT_W{1'b0}};
      out_sat <= 1'b0;
    end else begin
      out_y   <= y;
      out_sat <= ovf;
    end
  end

endmodule

`default_nettype wire
