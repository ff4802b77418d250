// SPDX-License-Identifier: GPL-3.0-or-later
#include "io/json_lookup.hpp"

#include <cctype>
#include <stdexcept>
#include <string>
#include <vector>

namespace ultratrack::io {
namespace {

// A recursive-descent walk over the document that keeps the scalar found at the wanted path.
struct Walker {
  std::string_view text;
  std::size_t at = 0;
  std::vector<std::string_view> path;  // the keys still to match below the current value
  std::optional<std::string> found;

  [[noreturn]] void fail(const char* what) const {
    throw std::invalid_argument("not JSON at character " + std::to_string(at) + ": " + what);
  }
  void skip_space() {
    while (at < text.size() && std::isspace(static_cast<unsigned char>(text[at]))) ++at;
  }
  void expect(char c) {
    skip_space();
    if (at >= text.size() || text[at] != c) fail((std::string("expected '") + c + "'").c_str());
    ++at;
  }
  // Consumes `c` when it comes next (after white space).
  bool next_is(char c) {
    skip_space();
    if (at >= text.size() || text[at] != c) return false;
    ++at;
    return true;
  }
  std::string string_value() {
    expect('"');
    std::string out;
    while (at < text.size() && text[at] != '"') {
      if (text[at] == '\\') {
        if (++at >= text.size()) break;
        if (text[at] != '"' && text[at] != '\\') out += '\\';  // other escapes stay as written
        out += text[at];
      } else {
        out += text[at];
      }
      ++at;
    }
    if (at >= text.size()) fail("unterminated string");
    ++at;
    return out;
  }
  std::string scalar() {
    skip_space();
    const std::size_t begin = at;
    while (at < text.size() && (std::isalnum(static_cast<unsigned char>(text[at])) || text[at] == '-' ||
                                text[at] == '+' || text[at] == '.'))
      ++at;
    const std::string_view word = text.substr(begin, at - begin);
    if (word.empty()) fail("expected a value");
    if (word != "true" && word != "false" && word != "null") {
      std::size_t used = 0;
      try {
        (void)std::stod(std::string(word), &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != word.size()) fail("not a number");
    }
    return std::string(word);
  }
  // One value; `depth` keys of the path matched so far (the path applies while `on_path`).
  void value(std::size_t depth, bool on_path) {
    skip_space();
    if (at >= text.size()) fail("unexpected end");
    const char c = text[at];
    if (c == '{' || c == '[') {
      // Members (key: value) or elements, each matched against the path's next key or index.
      const char close = c == '{' ? '}' : ']';
      ++at;
      if (next_is(close)) return;
      for (std::size_t index = 0;; ++index) {
        std::string key = std::to_string(index);
        if (c == '{') {
          key = string_value();
          expect(':');
        }
        value(depth + 1, on_path && depth < path.size() && key == path[depth]);
        if (next_is(',')) continue;
        expect(close);
        return;
      }
    }
    std::string v = c == '"' ? string_value() : scalar();
    if (on_path && depth == path.size() && !found) found = std::move(v);
  }
};

}  // namespace

std::optional<std::string> json_scalar_at(std::string_view json, std::string_view path) {
  Walker w{json, 0, {}, std::nullopt};
  for (std::size_t begin = 0; begin <= path.size();) {
    const std::size_t dot = std::min(path.find('.', begin), path.size());
    w.path.push_back(path.substr(begin, dot - begin));
    begin = dot + 1;
  }
  w.value(0, true);
  w.skip_space();
  if (w.at != json.size()) w.fail("trailing text");
  return w.found;
}

}  // namespace ultratrack::io
