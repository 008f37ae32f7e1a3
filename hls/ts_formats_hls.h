// tensor-servo HLS: the model's configurations instantiated on ap_fixed.
//
//   HlsDefault = FmtDefaultT<apfx>, HlsCompact = FmtCompactT<apfx>
//
// so every signal has exactly the (W, I) of FmtDefault / FmtCompact (formats.hpp, written once)
// and the model's algorithm headers run unchanged on ap_fixed.  Only two things differ:
//   SWEEPS_MAX   the bound of the solver's sweep loop (TS_SWEEPS_MAX, default 16; the model's is 2^30)
//   the tables   constant ROMs (ts_tables_default.h, ts_tables_compact.h), generated from the
//                model's tables by hls/gen_tables.py and checked entry by entry in the C-sim.
// model_of<H>::type names the model configuration an HLS configuration reproduces.
//
// This is the one header the HLS sources include: it puts ts_ap_fixed.h before the algorithm.
#pragma once
#include "ts_ap_fixed.h"  // first: the ap_fixed overloads must precede the algorithm templates
#include "tensor_servo/formats.hpp"
#include "tensor_servo/servo.hpp"

#ifndef TS_SWEEPS_MAX
#define TS_SWEEPS_MAX 16
#endif

namespace ts {

struct HlsDefault : FmtDefaultT<apfx> {
  static constexpr const char* name = "hls_default";
  static constexpr int SWEEPS_MAX = TS_SWEEPS_MAX;
};
struct HlsCompact : FmtCompactT<apfx> {
  static constexpr const char* name = "hls_compact";
  static constexpr int SWEEPS_MAX = TS_SWEEPS_MAX;
};

template <class H> struct model_of;
template <> struct model_of<HlsDefault> { using type = FmtDefault; };
template <> struct model_of<HlsCompact> { using type = FmtCompact; };

}  // namespace ts

#include "ts_tables_compact.h"
#include "ts_tables_default.h"
