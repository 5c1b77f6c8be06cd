#include "timing_report.hpp"

#include <cstdio>

namespace efsi {

std::string timing_report_text(const TimerReport& rep, long steps, double cells) {
  std::string out;
  char b[256];
  std::snprintf(b, sizeof b, "timing over %ld steps (slowest rank %.4g s, %.4g s/step, %.3g Mcell updates/s):\n", steps,
                rep.elapsed.max, rep.elapsed.max / double(steps), cells * double(steps) / rep.elapsed.max / 1e6);
  out += b;
  std::snprintf(b, sizeof b, "  %-14s %12s %12s %12s\n", "region", "min s", "mean s", "max s");
  out += b;
  auto line = [&](const char* name, const Spread& sp) {
    std::snprintf(b, sizeof b, "  %-14s %12.5g %12.5g %12.5g\n", name, sp.min, sp.mean, sp.max);
    out += b;
  };
  line("elapsed", rep.elapsed);
  for (int r = 0; r < region_count(); ++r)
    if (rep.region[r].max > 0) line(std::string(to_string(Region{r})).c_str(), rep.region[r]);
  line("comm", rep.comm);
  std::snprintf(b, sizeof b,
                "  comm fraction %.4f (mean halo MPI and wait + reductions + transposes / slowest elapsed)\n",
                rep.comm_fraction);
  out += b;
  return out;
}

}  // namespace efsi
