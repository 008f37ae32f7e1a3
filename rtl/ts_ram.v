// SPDX-License-Identifier: Apache-2.0
// tensor-servo: a small memory of 2^AW words of W bits, one synchronous write port and R
// asynchronous read ports, no reset (every word 0 at power-up).
//
// The engines keep their per-joint configuration and results in these: on ECP5 each read port is
// a copy in distributed RAM (one TRELLIS_DPR16X4 per 16 words x 4 bits), where a register array
// with a reset costs a flip-flop per bit and a multiplexer tree per read.  A read in the cycle of a
// write to the same word returns the old word (as a register array read with nonblocking writes).
// Users must not depend on a reset of the contents: every word they read has been written since.
// Language: Verilog 2005
`resetall
`timescale 1ns / 1ps
`default_nettype none

module ts_ram #(
  // word width (bits)
  parameter integer W = 1,
  // address width (bits): 2^AW words
  parameter integer AW = 1,
  // read ports
  parameter integer R = 1
) (
  input  wire            clk,
  input  wire            in_we,
  input  wire [AW-1:0]   in_waddr,
  input  wire [W-1:0]    in_wdata,
  // read port r: address in_raddr[r*AW +: AW], word out_rdata[r*W +: W]
  input  wire [R*AW-1:0] in_raddr,
  output wire [R*W-1:0]  out_rdata
);

  localparam integer D = 1 << AW;

  reg [W-1:0] mem [0:D-1];

  integer i;
  initial begin
    for (i = 0; i < D; i = i + 1) mem[i] = {W{1'b0}};
  end

  always @(posedge clk) begin
    if (in_we) mem[in_waddr] <= in_wdata;
  end

  genvar r;
  generate
    for (r = 0; r < R; r = r + 1) begin : g_rd
      assign out_rdata[r*W +: W] = mem[in_raddr[r*AW +: AW]];
    end
  endgenerate

endmodule

`default_nettype wire
