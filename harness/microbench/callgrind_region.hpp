#pragma once
// Callgrind's client requests for the counted CI gate (harness/microbench/README.md).  The
// gate runs bench_kernels under callgrind with instrumentation and collection off at start
// (--instr-atstart=no --collect-atstart=no); each kernel switches instrumentation on for a
// warm-up call (so the simulated caches hold what a repeated call finds), collection on for
// the measured call, and dumps the counts under the kernel's name.  Outside valgrind every
// request is a few no-op instructions.  Without valgrind's headers (EFSI_HAVE_CALLGRIND
// undefined) they compile to nothing and count mode is refused.
#ifdef EFSI_HAVE_CALLGRIND
#include <valgrind/callgrind.h>
#endif

#include <string>

namespace efsi::bench {

inline constexpr bool kCallgrindRequests =
#ifdef EFSI_HAVE_CALLGRIND
    true;
#else
    false;
#endif

inline void callgrind_toggle_collect() {
#ifdef EFSI_HAVE_CALLGRIND
  CALLGRIND_TOGGLE_COLLECT;
#endif
}

inline void callgrind_start_instrumentation() {
#ifdef EFSI_HAVE_CALLGRIND
  CALLGRIND_START_INSTRUMENTATION;
#endif
}

// Writes the events collected since the last dump to a new part of the output, headed
// "desc: Trigger: Client Request: <name>", and zeroes them.
inline void callgrind_dump(const std::string& name) {
#ifdef EFSI_HAVE_CALLGRIND
  CALLGRIND_DUMP_STATS_AT(name.c_str());
#else
  (void)name;
#endif
}

// Running under valgrind at all.
inline bool running_on_valgrind() {
#ifdef EFSI_HAVE_CALLGRIND
  return RUNNING_ON_VALGRIND != 0;
#else
  return false;
#endif
}

}  // namespace efsi::bench
