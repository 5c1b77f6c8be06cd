#pragma once
// Every pressure method of the suite, from one list that the build writes: each folder
// under kernels/pressure/ that registers itself with efsi_pressure_method() in its
// CMakeLists.txt defines `const MethodSpec& <name>_method()`, and appears here (in folder
// order).  Drivers, benchmarks and the campaign tools take the methods from this list.
#include <optional>
#include <string>
#include <vector>

#include "method_spec.hpp"

namespace efsi {

const std::vector<const MethodSpec*>& pressure_methods();

// Throws ConfigError naming `name` and the methods there are.
const MethodSpec& find_method(const std::string& name);

// "acm, fft, sor" (with `separator` between the names).
std::string method_names(const std::string& separator = ", ");

// Every option of every method once, with the methods that take it.
struct RegisteredOption {
  MethodOption option;
  std::vector<std::string> methods;
};
std::vector<RegisteredOption> registered_options();

// The method `name` configured from the values given for the methods' options: a flag that
// `name` does not take is refused ("--ns applies to --method sor only"), as is a fraction
// for a count and a negative --nc; then the method checks and resolves its own.  `nc`:
// --nc, Crank-Nicolson sweeps per step (default: the method's).  Throws ConfigError.
MethodChoice configure_method(const std::string& name, const OptionValues& given, std::optional<int> nc,
                              bool calibrating = false);

// The registry's description, one line per method and option, for --list-methods and the
// campaign tools: "method NAME|SUMMARY|DT|STEPS|NC|async" (sync for a method with no
// asynchronous mode), "variant NAME|LABEL|ARGS" for each setting a campaign sweeps, and
// "option FLAG|METHODS|HELP".
std::string describe_methods();

}  // namespace efsi
