// SPDX-License-Identifier: Apache-2.0
// tensor-servo test bench: behavioural simulation model of the Lattice ECP5 MULT18X18D, for the
// subset of the primitive that rtl/ts_ecp5_mult18.v uses (A, B, SIGNEDA/B, CLK0, CE0, RST0, P, and
// REG_INPUTA/B, REG_PIPELINE, REG_OUTPUT each either "NONE" or clocked by CLK0 with CE0/RST0,
// synchronous reset).  Yosys ships only a black box of this cell (techlibs ecp5/cells_bb.v), so the
// ECP5 multiplier variant is simulated against this model; it is NOT a Lattice model, and its
// fidelity to the silicon is an assumption (Lattice FPGA-TN-02205 "ECP5 sysDSP Usage Guide":
// input, pipeline and output registers; P = A * B, signed when SIGNEDA/SIGNEDB).
// Language: Verilog 2005
`resetall
`timescale 1ns / 1ps
`default_nettype none

module MULT18X18D #(
  // "NONE" or "CLK0": register on input A
  parameter REG_INPUTA_CLK = "NONE",
  // clock enable of the A register (only "CE0" modelled)
  parameter REG_INPUTA_CE = "CE0",
  // reset of the A register (only "RST0" modelled)
  parameter REG_INPUTA_RST = "RST0",
  // "NONE" or "CLK0": register on input B
  parameter REG_INPUTB_CLK = "NONE",
  // clock enable of the B register (only "CE0" modelled)
  parameter REG_INPUTB_CE = "CE0",
  // reset of the B register (only "RST0" modelled)
  parameter REG_INPUTB_RST = "RST0",
  // "NONE" or "CLK0": register after the multiplier
  parameter REG_PIPELINE_CLK = "NONE",
  // clock enable of the pipeline register (only "CE0" modelled)
  parameter REG_PIPELINE_CE = "CE0",
  // reset of the pipeline register (only "RST0" modelled)
  parameter REG_PIPELINE_RST = "RST0",
  // "NONE" or "CLK0": register on output P
  parameter REG_OUTPUT_CLK = "NONE",
  // clock enable of the output register (only "CE0" modelled)
  parameter REG_OUTPUT_CE = "CE0",
  // reset of the output register (only "RST0" modelled)
  parameter REG_OUTPUT_RST = "RST0",
  // "SYNC" (modelled) or "ASYNC"
  parameter RESETMODE = "SYNC"
) (
  input  wire A0, A1, A2, A3, A4, A5, A6, A7, A8, A9, A10, A11, A12, A13, A14, A15, A16, A17,
  input  wire B0, B1, B2, B3, B4, B5, B6, B7, B8, B9, B10, B11, B12, B13, B14, B15, B16, B17,
  input  wire SIGNEDA, SIGNEDB, SOURCEA, SOURCEB,
  input  wire CLK0, CE0, RST0,
  output wire P0, P1, P2, P3, P4, P5, P6, P7, P8, P9, P10, P11, P12, P13, P14, P15, P16, P17,
  output wire P18, P19, P20, P21, P22, P23, P24, P25, P26, P27, P28, P29, P30, P31, P32, P33,
  output wire P34, P35
);

  wire [17:0] a = {A17, A16, A15, A14, A13, A12, A11, A10, A9, A8, A7, A6, A5, A4, A3, A2, A1, A0};
  wire [17:0] b = {B17, B16, B15, B14, B13, B12, B11, B10, B9, B8, B7, B6, B5, B4, B3, B2, B1, B0};

  // Each register stage is either present (parameter "CLK0") or a wire ("NONE"); the generate
  // structure keeps the event count low in event-driven simulators.
  wire [17:0] a_s, b_s;
  wire        sa_s, sb_s;
  wire [35:0] m_s, p;

  generate
    if (REG_INPUTA_CLK == "NONE") begin : g_a_comb
      assign a_s = a;
      assign sa_s = SIGNEDA;
    end else begin : g_a_reg
      reg [17:0] a_q;
      reg        sa_q;
      always @(posedge CLK0) begin
        if (RST0) begin a_q <= 18'd0; sa_q <= 1'b0; end
        else if (CE0) begin a_q <= a; sa_q <= SIGNEDA; end
      end
      assign a_s = a_q;
      assign sa_s = sa_q;
    end
    if (REG_INPUTB_CLK == "NONE") begin : g_b_comb
      assign b_s = b;
      assign sb_s = SIGNEDB;
    end else begin : g_b_reg
      reg [17:0] b_q;
      reg        sb_q;
      always @(posedge CLK0) begin
        if (RST0) begin b_q <= 18'd0; sb_q <= 1'b0; end
        else if (CE0) begin b_q <= b; sb_q <= SIGNEDB; end
      end
      assign b_s = b_q;
      assign sb_s = sb_q;
    end
  endgenerate

  // 36-bit two's-complement product of the operands read as signed or unsigned.
  wire signed [18:0] a_e = {sa_s & a_s[17], a_s};
  wire signed [18:0] b_e = {sb_s & b_s[17], b_s};
  wire signed [37:0] full = a_e * b_e;
  wire [35:0] m_d = full[35:0];

  generate
    if (REG_PIPELINE_CLK == "NONE") begin : g_m_comb
      assign m_s = m_d;
    end else begin : g_m_reg
      reg [35:0] m_q;
      always @(posedge CLK0) begin
        if (RST0) m_q <= 36'd0;
        else if (CE0) m_q <= m_d;
      end
      assign m_s = m_q;
    end
    if (REG_OUTPUT_CLK == "NONE") begin : g_p_comb
      assign p = m_s;
    end else begin : g_p_reg
      reg [35:0] p_q;
      always @(posedge CLK0) begin
        if (RST0) p_q <= 36'd0;
        else if (CE0) p_q <= m_s;
      end
      assign p = p_q;
    end
  endgenerate

  assign {P35, P34, P33, P32, P31, P30, P29, P28, P27, P26, P25, P24, P23, P22, P21, P20, P19,
          P18, P17, P16, P15, P14, P13, P12, P11, P10, P9, P8, P7, P6, P5, P4, P3, P2, P1,
          P0} = p;

  wire unused = ^{SOURCEA, SOURCEB, full[37:36], REG_INPUTA_CE, REG_INPUTA_RST, REG_INPUTB_CE,
                  REG_INPUTB_RST, REG_PIPELINE_CE, REG_PIPELINE_RST, REG_OUTPUT_CE, REG_OUTPUT_RST,
                  RESETMODE};

endmodule

`default_nettype wire
