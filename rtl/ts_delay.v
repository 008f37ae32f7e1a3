// SPDX-License-Identifier: Apache-2.0
// tensor-servo: fixed delay line of DEPTH clock cycles (shift register, synchronous reset to 0).
// DEPTH = 0 is a wire.  Used for the valid pipelines and to align operands across the datapaths.
// Language: Verilog 2005
`resetall
`timescale 1ns / 1ps
`default_nettype none

module ts_delay #(
  // Data width in bits
  parameter W = 1,
  // Delay in clock cycles (>= 0)
  parameter DEPTH = 1
) (
  input  wire         clk,
  input  wire         rst,
  input  wire [W-1:0] din,
  output wire [W-1:0] dout
);

  generate
    if (DEPTH == 0) begin : g_wire
      assign dout = din;
      wire unused_clk = clk ^ rst;
    end else if (DEPTH == 1) begin : g_one
      reg [W-1:0] q;
      always @(posedge clk) begin
        if (rst) q <= {W{1'b0}};
        else     q <= din;
      end
      assign dout = q;
    end else begin : g_regs
      // One flat shift register (a single vector operation per clock in event-driven simulators).
      reg [DEPTH*W-1:0] sr;
      always @(posedge clk) begin
        if (rst) sr <= {(DEPTH*W){1'b0}};
        else     sr <= {sr[(DEPTH-1)*W-1:0], din};
      end
      assign dout = sr[DEPTH*W-1 -: W];
    end
  endgenerate

endmodule

`default_nettype wire
