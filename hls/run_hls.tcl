# tensor-servo: Vitis HLS flow for one top function (csim, csynth, cosim, export).
#
#   python hls/tb/make_vectors.py build/hls/vectors          # the testbench's inputs, from the model
#   vitis_hls -f hls/run_hls.tcl                              # ts_servo_top on xc7z020clg400-1, 100 MHz
#   vitis_hls -f hls/run_hls.tcl -tclargs TOP PART PERIOD_NS STEPS NMAX
#       TOP       ts_servo_top | ts_kin_top | ts_solve_top, or the same with _compact
#       PART      e.g. xc7z020clg400-1, xczu3eg-sbva484-1-e
#       PERIOD_NS clock period in ns (10 = 100 MHz)
#       STEPS     any of csim,csynth,cosim,export (comma separated)
#       NMAX      joints per build (TS_NMAX, default 8)
# Run from the repository root.  Written for Vitis HLS 2022.2 or later (INTERFACE mode= syntax)
# with a front end that accepts -std=c++17 (the model uses if constexpr).  Not run in this
# repository's CI, which checks the same sources by C-simulation with g++ (hls/tb/csim.py) and by
# scripts/hls_lint.py.  See docs/hls.md.

set top    ts_servo_top
set part   xc7z020clg400-1
set period 10
set steps  {csim csynth cosim export}
set nmax   8
if {[info exists argv] && [llength $argv] > 0} { set top    [lindex $argv 0] }
if {[info exists argv] && [llength $argv] > 1} { set part   [lindex $argv 1] }
if {[info exists argv] && [llength $argv] > 2} { set period [lindex $argv 2] }
if {[info exists argv] && [llength $argv] > 3} { set steps  [split [lindex $argv 3] ,] }
if {[info exists argv] && [llength $argv] > 4} { set nmax   [lindex $argv 4] }

set root    [pwd]
set vectors $root/build/hls/vectors
set config  [expr {[string match *_compact $top] ? "compact" : "default"}]
set cflags  "-std=c++17 -DTS_NMAX=$nmax -I$root/model/include -I$root/hls"

open_project -reset build/hls_prj/$top
set_top $top
add_files $root/hls/ts_servo_top.cpp -cflags $cflags
add_files -tb $root/hls/tb/tb_hls.cpp -cflags "$cflags -Wno-unknown-pragmas" -csimflags "$cflags"
open_solution -reset sol1 -flow_target vivado
set_part $part
create_clock -period $period -name default
# Loops of up to 64 iterations are pipelined automatically unless a pragma says otherwise (the
# Vitis default, stated here because the latency estimates of docs/hls.md assume it).
config_compile -pipeline_loops 64

# The testbench compares every output of every top function with the model (fx); in csim all
# tops run as C++, in cosim the synthesised one runs as RTL (so keep the tick count small).
if {[lsearch $steps csim] >= 0} {
  csim_design -argv "$vectors --config $config --ticks 2000"
}
if {[lsearch $steps csynth] >= 0} {
  csynth_design
}
if {[lsearch $steps cosim] >= 0} {
  cosim_design -argv "$vectors --config $config --ticks 20 --chains puma560" -trace_level none
}
if {[lsearch $steps export] >= 0} {
  export_design -format ip_catalog -vendor tensor-servo.org -library hls -version 0.1 \
      -description "tensor-servo $top (bit-exact with the C++ model)"
}
exit
