// tensor-servo: element in_idx of a flat bus of N elements of W bits (element k at [k*W +: W]),
// as an N:1 multiplexer; 0 for an index >= N.
//
// A balanced tree of 2:1 multiplexers, one level per index bit (the bus padded with zero elements
// to a power of two), then zero if an index bit above the tree is set.  Two earlier forms cost
// more: the variable part-select vec[idx*W +: W] made yosys (0.23 and 0.70) build a barrel
// shifter after a multiplier for idx*W (mapped to MULT18X18D), and a loop of
// `if (idx == k) out = vec[k]` became a priority chain of N - 1 multiplexers per bit
// (docs/rtl/shared.md).
// Combinational.  Language: Verilog 2005
`resetall
`timescale 1ns / 1ps
`default_nettype none

module ts_sel #(
  // element width (bits)
  parameter integer W = 1,
  // number of elements
  parameter integer N = 1,
  // index width (bits), 1..31, with 2^IW >= N
  parameter integer IW = 1
) (
  input  wire [N*W-1:0] in_vec,
  input  wire [IW-1:0]  in_idx,
  output wire [W-1:0]   out_el
);

  localparam integer LV = (N > 1) ? $clog2(N) : 0;   // tree levels
  localparam integer NP = 1 << LV;                    // elements after padding

  wire [NP*W-1:0] pad;                                // the bus padded with zero elements
  wire [W-1:0] root;

  genvar l, i;
  generate
    if ((N < 1) || (IW < 1) || (IW > 31) || (LV > IW)) begin : g_bad
      // Elaboration error: the index cannot address every element, or a parameter is out of range.
      ts_sel_bad_parameters u_error ();
    end
    if (NP > N) begin : g_pad
      assign pad = {{((NP-N)*W){1'b0}}, in_vec};
    end else begin : g_nopad
      assign pad = in_vec;
    end
    // level l: NP >> l elements in (u), half as many out (v), selected by index bit l
    for (l = 0; l < LV; l = l + 1) begin : g_lv
      wire [(NP >> l)*W-1:0] u;
      wire [(NP >> (l + 1))*W-1:0] v;
      if (l == 0) begin : g_first
        assign u = pad;
      end else begin : g_next
        assign u = g_lv[l-1].v;
      end
      for (i = 0; i < (NP >> (l + 1)); i = i + 1) begin : g_m
        assign v[i*W +: W] = in_idx[l] ? u[(2*i+1)*W +: W] : u[2*i*W +: W];
      end
    end
    if (LV == 0) begin : g_one
      assign root = pad[W-1:0];
    end else begin : g_tree
      assign root = g_lv[LV-1].v;
    end
    if (IW > LV) begin : g_hi
      assign out_el = (|in_idx[IW-1:LV]) ? {W{1'b0}} : root;
    end else begin : g_nohi
      assign out_el = root;
    end
  endgenerate

endmodule

`default_nettype wire
