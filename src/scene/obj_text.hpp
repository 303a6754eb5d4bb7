// Line-level text helpers shared by the Wavefront OBJ reader (mesh_obj.cpp) and its material
// library reader (obj_material.cpp): comments, whitespace tokens, numbers as exporters write
// them, and tokens shortened for one-line messages.
#pragma once

#include <covrast/error.hpp>

#include <charconv>
#include <cstddef>
#include <cstdlib>
#include <string>
#include <string_view>

namespace covrast::detail {

inline bool is_blank(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

/// The line without its comment: in OBJ and MTL files a '#' starts one that runs to the end of
/// the line.
inline std::string_view without_comment(std::string_view line) {
  const std::size_t hash = line.find('#');
  return hash == std::string_view::npos ? line : line.substr(0, hash);
}

/// Splits one line into whitespace-separated tokens.
class Tokens {
 public:
  explicit Tokens(std::string_view line) : rest_(line) {}
  bool next(std::string_view& token) {
    std::size_t begin = 0;
    while (begin < rest_.size() && is_blank(rest_[begin])) ++begin;
    std::size_t end = begin;
    while (end < rest_.size() && !is_blank(rest_[end])) ++end;
    token = rest_.substr(begin, end - begin);
    rest_.remove_prefix(end);
    return !token.empty();
  }
  /// What is left of the line, blanks trimmed at both ends (a file name with spaces).
  std::string_view rest() const {
    std::string_view rest = rest_;
    while (!rest.empty() && is_blank(rest.front())) rest.remove_prefix(1);
    while (!rest.empty() && is_blank(rest.back())) rest.remove_suffix(1);
    return rest;
  }

 private:
  std::string_view rest_;
};

/// A token as it may appear in a one-line message: printable ASCII, shortened.
inline std::string printable(std::string_view token) {
  constexpr std::size_t kMaxShown = 32;
  std::string out;
  for (std::size_t i = 0; i < token.size() && i < kMaxShown; ++i) {
    const unsigned char c = static_cast<unsigned char>(token[i]);
    out += (c >= 0x20 && c < 0x7f) ? static_cast<char>(c) : '?';
  }
  if (token.size() > kMaxShown) out += "...";
  return out;
}

/// "name:LINE: message" as an InputError.
[[noreturn]] inline void fail_at(const std::string& name, std::size_t line,
                                 const std::string& message) {
  throw InputError(name + ":" + std::to_string(line) + ": " + message);
}

/// from_chars rejects a leading '+', which some exporters write.
inline std::string_view strip_plus(std::string_view token) {
  if (token.size() >= 2 && token[0] == '+' && token[1] != '-' && token[1] != '+') {
    token.remove_prefix(1);
  }
  return token;
}

inline bool parse_double(std::string_view token, double& value) {
  token = strip_plus(token);
  if (token.empty()) return false;
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, value);
  if (ptr != end) return false;
  if (ec == std::errc::result_out_of_range) {
    // Overflow must become +-inf (and the triangle is then dropped), underflow 0: strtod does
    // exactly that, from_chars leaves the value untouched.
    const std::string copy(token);
    value = std::strtod(copy.c_str(), nullptr);
    return true;
  }
  return ec == std::errc();
}

inline bool parse_integer(std::string_view token, long long& value) {
  token = strip_plus(token);
  if (token.empty()) return false;
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, value);
  return ec == std::errc() && ptr == end;
}

/// Calls on_line(line, line_no) for each '\n'-separated line of an OBJ or MTL file (line
/// numbers from 1), after a UTF-8 byte order mark.
template <class OnLine>
void for_each_line(std::string_view text, OnLine&& on_line) {
  if (text.substr(0, 3) == "\xEF\xBB\xBF") text.remove_prefix(3);
  std::size_t pos = 0;
  std::size_t line_no = 0;
  while (pos < text.size()) {
    std::size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    on_line(text.substr(pos, end - pos), ++line_no);
    pos = end + 1;
  }
}

}  // namespace covrast::detail
