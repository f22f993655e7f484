#pragma once
// One form for bad-parameter errors of the agglomerate builders:
// "<function>: <name> = <value>: <what is allowed>", the value in %g form
// ("r0 = 0.5: must be >= 1"). Internal to rocklab_geometry.
#include <sstream>
#include <stdexcept>
#include <string>

namespace rocklab::geometry::detail {

inline std::string formatValue(double value) {
  std::ostringstream s;
  s << value;
  return s.str();
}

inline void requireParameter(bool ok, const std::string& function, const std::string& name,
                             double value, const std::string& allowed) {
  if (!ok)
    throw std::invalid_argument(function + ": " + name + " = " + formatValue(value) + ": " +
                                allowed);
}

}  // namespace rocklab::geometry::detail
