#include "method_spec.hpp"

#include <stdexcept>

namespace efsi {

std::string MethodChoice::name() const { return spec ? spec->name() : std::string(); }

double MethodChoice::value(const std::string& key) const {
  const auto it = values.find(key);
  if (it == values.end()) throw std::logic_error("method setting '" + key + "' was not resolved");
  return it->second;
}

}  // namespace efsi
