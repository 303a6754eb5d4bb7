// The nesting depth of JSON text, measured before a parser sees it: nlohmann's parser is
// iterative, but printing a value (scene messages) and tinygltf's reading of `extras` and
// `extensions` recurse once per level, so a file nested 80,000 levels deep would overflow the
// stack. A single pass over the bytes with a counter, no recursion.
#include "scene/scene_internal.hpp"

namespace covrast::detail {

bool json_depth_within(std::string_view text, int limit, std::size_t& offset) {
  int depth = 0;
  std::size_t i = 0;
  const std::size_t n = text.size();
  while (i < n) {
    const char c = text[i];
    if (c == '"') {
      // A string: skip to its closing quote; a backslash escapes the next byte.
      for (++i; i < n && text[i] != '"'; ++i) {
        if (text[i] == '\\') ++i;
      }
    } else if (c == '/' && i + 1 < n && text[i + 1] == '/') {
      while (i < n && text[i] != '\n') ++i;  // line comment (scene files accept comments)
    } else if (c == '/' && i + 1 < n && text[i + 1] == '*') {
      const std::size_t close = text.find("*/", i + 2);
      i = close == std::string_view::npos ? n : close + 1;
    } else if (c == '[' || c == '{') {
      if (++depth > limit) {
        offset = i;
        return false;
      }
    } else if (c == ']' || c == '}') {
      --depth;  // unbalanced text is the parser's to report
    }
    ++i;
  }
  return true;
}

}  // namespace covrast::detail
