#pragma once
// A set-up that cannot run: bad decomposition, undersized block, dt over a limit, ...
// Thrown identically on every rank before any collective call, so no rank waits on
// another; drivers print what() as one line and exit with status 2.
#include <cstdio>
#include <stdexcept>
#include <string>

namespace efsi {

class ConfigError : public std::runtime_error {
 public:
  explicit ConfigError(const std::string& what) : std::runtime_error(what) {}
};

// A value as an error line names it: "%g" (1e-05, 4.5, 213).
inline std::string format_value(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%g", v);
  return b;
}

}  // namespace efsi
