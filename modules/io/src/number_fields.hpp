#pragma once

#include <charconv>
#include <cmath>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

// Field splitting and strict number parsing for the line-oriented text files (private to
// io/): a field is a number only if all of it is, and NaN or infinity is named as such.

namespace omnislam::io::detail {

/// Whitespace-separated fields (runs of blanks collapse), or with `comma` the fields
/// between commas, each trimmed (so "1,,2" has an empty middle field).
[[nodiscard]] inline std::vector<std::string_view> split_fields(std::string_view line, bool comma) {
  constexpr std::string_view kBlank = " \t\r\n";
  std::vector<std::string_view> fields;
  if (comma) {
    for (std::size_t start = 0;;) {
      const std::size_t end = std::min(line.find(',', start), line.size());
      std::string_view field = line.substr(start, end - start);
      const std::size_t first = field.find_first_not_of(kBlank);
      field = first == std::string_view::npos
                  ? std::string_view{}
                  : field.substr(first, field.find_last_not_of(kBlank) - first + 1);
      fields.push_back(field);
      if (end == line.size()) break;
      start = end + 1;
    }
    return fields;
  }
  for (std::size_t start = line.find_first_not_of(kBlank); start != std::string_view::npos;) {
    const std::size_t end = std::min(line.find_first_of(kBlank, start), line.size());
    fields.push_back(line.substr(start, end - start));
    start = line.find_first_not_of(kBlank, end);
  }
  return fields;
}

// "'name' is 'field'", built by appending (GCC 12 misreports "literal" + std::string as
// overlapping memcpy under -O3).
[[nodiscard]] inline std::string quoted_field(std::string_view name, std::string_view field) {
  std::string text;
  text.append("'").append(name).append("' is '").append(field).append("'");
  return text;
}

/// Parses all of `field` as a finite number into `value`; otherwise returns what is wrong,
/// naming the field as `name`.
[[nodiscard]] inline std::optional<std::string> parse_finite(std::string_view field, std::string_view name,
                                                             double &value) {
  std::string_view digits = field;
  if (digits.size() > 1 && digits.front() == '+') digits.remove_prefix(1);  // from_chars takes no '+'
  const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  const std::string quoted = quoted_field(name, field);
  if (error == std::errc::result_out_of_range) return quoted + ", out of the range of a double";
  if (error != std::errc() || end != digits.data() + digits.size()) return quoted + ", not a number";
  if (!std::isfinite(value)) return quoted + ", not a finite number";
  return std::nullopt;
}

/// The same for an integer.
[[nodiscard]] inline std::optional<std::string> parse_integer(std::string_view field, std::string_view name,
                                                              long &value) {
  const auto [end, error] = std::from_chars(field.data(), field.data() + field.size(), value);
  const std::string quoted = quoted_field(name, field);
  if (error == std::errc::result_out_of_range) return quoted + ", out of range";
  if (error != std::errc() || end != field.data() + field.size()) return quoted + ", not an integer";
  return std::nullopt;
}

}  // namespace omnislam::io::detail
