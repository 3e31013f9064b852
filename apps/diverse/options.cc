#include "options.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <string>

namespace diverse::cli {
namespace {

std::string num(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.15g", v);
  return text;
}

// Whole-text integer parse; false on anything else (sign-only, trailing text, overflow).
bool parse_integer(const std::string& text, long long* out) {
  if (text.empty() || std::isspace(static_cast<unsigned char>(text[0]))) return false;
  errno = 0;
  char* end = nullptr;
  const long long v = std::strtoll(text.c_str(), &end, 10);
  if (errno != 0 || end == text.c_str() || *end != '\0') return false;
  *out = v;
  return true;
}

}  // namespace

CLI::Validator integer_in(long long lo, long long hi) {
  const std::string expect =
      "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  return CLI::Validator(
      [lo, hi, expect](std::string& text) -> std::string {
        long long v = 0;
        if (!parse_integer(text, &v) || v < lo || v > hi) return expect + ", got '" + text + "'";
        return {};
      },
      "INT in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
}

CLI::Validator unsigned_integer() {
  const std::string expect = "expected an integer in [0, 18446744073709551615]";
  return CLI::Validator(
      [expect](std::string& text) -> std::string {
        if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos)
          return expect + ", got '" + text + "'";
        errno = 0;
        char* end = nullptr;
        std::strtoull(text.c_str(), &end, 10);
        if (errno != 0 || *end != '\0') return expect + ", got '" + text + "'";
        return {};
      },
      "UINT64");
}

CLI::Validator number_in(double lo, double hi, Bound low) {
  const std::string range = (low == Bound::kOpen ? "(" : "[") + num(lo) + ", " + num(hi) + "]";
  const std::string expect = "expected a number in " + range;
  return CLI::Validator(
      [lo, hi, low, expect](std::string& text) -> std::string {
        if (text.empty() || std::isspace(static_cast<unsigned char>(text[0])))
          return expect + ", got '" + text + "'";
        errno = 0;
        char* end = nullptr;
        const double v = std::strtod(text.c_str(), &end);
        const bool above_low = low == Bound::kOpen ? v > lo : v >= lo;
        if (end == text.c_str() || *end != '\0' || !std::isfinite(v) || !above_low || !(v <= hi))
          return expect + ", got '" + text + "'";
        return {};
      },
      "NUMBER in " + range);
}

}  // namespace diverse::cli
