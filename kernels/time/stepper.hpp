#pragma once
// The interface every pressure method presents to drivers, tests and benchmarks:
// advance one step, report diagnostics.
#include <stdexcept>
#include <string>

#include "flow_diagnostics.hpp"
#include "region_timers.hpp"

namespace efsi {

class Stepper {
 public:
  virtual ~Stepper() = default;
  virtual void step() = 0;
  // Collective. Completes any exchange in flight first.
  virtual FlowDiagnostics diagnostics() = 0;
  virtual long steps_done() const = 0;
  virtual double time() const = 0;
  virtual const RegionTimers& timers() const = 0;
  virtual RegionTimers& timers() = 0;
};

// A run that blew up: non-finite values or velocities past the bound. Thrown on every
// rank at the same step; what() names the step, the quantity and where.
class BlowUp : public std::runtime_error {
 public:
  explicit BlowUp(const std::string& what) : std::runtime_error(what) {}
};

}  // namespace efsi
