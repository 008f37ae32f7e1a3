// tensor-servo: element in_idx of a flat bus of N elements of W bits (element k at [k*W +: W]),
// as an N:1 multiplexer; 0 for an index >= N.
//
// Written as a loop over constant part-selects rather than vec[idx*W +: W]: with the variable
// part-select yosys (0.23 and 0.70) builds a barrel shifter after a multiplier for idx*W (it maps
// the multiplication to MULT18X18D) instead of a multiplexer, which made the servo core's
// configuration and packet paths several times larger (docs/resources.md).
// Combinational.  Language: Verilog 2005
`resetall
`timescale 1ns / 1ps
`default_nettype none

module ts_sel #(
  // element width (bits)
  parameter integer W = 1,
  // number of elements
  parameter integer N = 1,
  // index width (bits), 1..31
  parameter integer IW = 1
) (
  input  wire [N*W-1:0] in_vec,
  input  wire [IW-1:0]  in_idx,
  output reg  [W-1:0]   out_el
);

  integer k;
  always @(*) begin
    out_el = {W{1'b0}};
    for (k = 0; k < N; k = k + 1)
      if ({{(32 - IW){1'b0}}, in_idx} == k) out_el = in_vec[k*W +: W];
  end

endmodule

`resetall
