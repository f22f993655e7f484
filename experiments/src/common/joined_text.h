#pragma once
// A list of names in a message ("a, b, c"): the one join behind the error and log
// texts that name keys, figures, files or allowed values. Internal.
#include <string>
#include <string_view>
#include <vector>

namespace rocklab::experiments::detail {

/// The values in order with `separator` between them; "" for none.
inline std::string joinedText(const std::vector<std::string>& values, std::string_view separator = ", ") {
  std::string text;
  for (const std::string& v : values) {
    if (!text.empty()) text += separator;
    text += v;
  }
  return text;
}

}  // namespace rocklab::experiments::detail
