// SPDX-License-Identifier: Apache-2.0
// tensor-servo: fixed delay line of DEPTH clock cycles (synchronous reset: the output is 0 for the
// DEPTH cycles after a reset).  DEPTH = 0 is a wire.  Used for the valid pipelines and to align
// operands across the datapaths.
// Two implementations with the same output in every cycle, reset included:
//   RAM = 0: a shift register (DEPTH * W flip-flops);
//   RAM = 1 (DEPTH >= 3): a ring of DEPTH - 1 words in a memory with an asynchronous read
//     (distributed RAM on ECP5, TRELLIS_DPR16X4 per 16 words x 4 bits; LUTRAM on 7-series) and one
//     output register.  The words are not reset: a fill flag holds the output at 0 until every word
//     has been written since the reset.  W flip-flops and about W / 4 * ceil((DEPTH - 1) / 16)
//     RAM blocks instead of DEPTH * W flip-flops.
// The default takes the ring for data lines (W >= 4) of DEPTH >= 13: a ring costs about 1.5 LUT
// sites per bit on ECP5 (a DPR16X4 is 6), a shift register DEPTH flip-flops, and the core is short
// of LUTs, not of flip-flops, once the long lines are rings.
// Language: Verilog 2005
`resetall
`timescale 1ns / 1ps
`default_nettype none

module ts_delay #(
  // Data width in bits
  parameter W = 1,
  // Delay in clock cycles (>= 0)
  parameter DEPTH = 1,
  // 1: ring buffer in a memory (DEPTH >= 3), 0: shift register (see the header)
  parameter RAM = ((W >= 4) && (DEPTH >= 13)) ? 1 : 0
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
    end else if ((RAM != 0) && (DEPTH >= 3)) begin : g_ram
      localparam integer N = DEPTH - 1;                 // ring words
      localparam integer AW = (N > 1) ? $clog2(N) : 1;
      localparam integer LAST = N - 1;
      // distributed RAM: left to itself yosys put the longest rings in EBR, whose 5.8 ns clock-to-
      // output (no output register at speed grade 6) was the FK engine's critical path
      (* ram_style = "distributed" *) reg [W-1:0]  mem [0:N-1];
      reg [AW-1:0] ptr;
      reg          full;   // every word written since the reset
      reg [W-1:0]  q;
      // The word at ptr was written N cycles ago: read it (before this cycle's write) and replace it.
      always @(posedge clk) begin
        mem[ptr] <= din;
      end
      always @(posedge clk) begin
        if (rst) begin
          ptr  <= {AW{1'b0}};
          full <= 1'b0;
          q    <= {W{1'b0}};
        end else begin
          q <= full ? mem[ptr] : {W{1'b0}};
          if (ptr == LAST[AW-1:0]) begin
            ptr  <= {AW{1'b0}};
            full <= 1'b1;
          end else begin
            ptr <= ptr + 1'b1;
          end
        end
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
