// Text for XML, SVG and HTML, shared so every writer of markup escapes alike.
#pragma once

#include <string>
#include <string_view>

namespace liftoff {

/// `text` safe as markup character data and inside a double-quoted attribute: & < > "
/// become &amp; &lt; &gt; &quot;.
inline std::string EscapeMarkup(std::string_view text) {
  std::string escaped;
  for (const char c : text) {
    switch (c) {
      case '&': escaped += "&amp;"; break;
      case '<': escaped += "&lt;"; break;
      case '>': escaped += "&gt;"; break;
      case '"': escaped += "&quot;"; break;
      default: escaped += c;
    }
  }
  return escaped;
}

}  // namespace liftoff
