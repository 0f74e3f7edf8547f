#include "common/format.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>

namespace talus {

std::string FormatDouble(double v, const char* format) {
  char text[64];
  std::snprintf(text, sizeof text, format, v);
  return text;
}

std::string FormatOrMissing(double v, const char* format, const char* missing) {
  return std::isnan(v) ? missing : FormatDouble(v, format);
}

std::string TenDigits(double v) { return FormatDouble(v, "%.10g"); }

std::string RoundTrip(double v) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, v).ptr;
  return std::string(text, end);
}

std::string XmlEscaped(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

}  // namespace talus
