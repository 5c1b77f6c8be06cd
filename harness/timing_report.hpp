#pragma once
// the report of docs/numerics.md, "Timer regions and the communication fraction", as text: the slowest rank's elapsed time, per-region
// minimum, mean and maximum over ranks, and the communication fraction.
#include <string>

#include "region_timers.hpp"

namespace efsi {

// `cells`: global cells, for the Mcell updates per second.
std::string timing_report_text(const TimerReport& rep, long steps, double cells);

}  // namespace efsi
