// SPDX-License-Identifier: GPL-3.0-or-later
#include "config/toml_override.hpp"

#include <memory>
#include <stdexcept>
#include <string_view>
#include <type_traits>

namespace ultratrack::config {
namespace {

std::string trimmed(std::string_view s) {
  const auto first = s.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  const auto last = s.find_last_not_of(" \t");
  return std::string(s.substr(first, last - first + 1));
}

std::vector<std::string> key_parts(const std::string& key) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  while (true) {
    const std::size_t dot = key.find('.', start);
    parts.push_back(key.substr(start, dot == std::string::npos ? std::string::npos : dot - start));
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  return parts;
}

// A copy of a parsed node without its source position: the position is that of the snippet parsed below, not of
// any line of the document, so an error about the key names no line rather than a wrong one.
std::unique_ptr<toml::node> without_source(const toml::node& node) {
  if (const toml::array* a = node.as_array()) {
    auto copy = std::make_unique<toml::array>();
    for (const toml::node& item : *a) copy->push_back(*without_source(item));
    return copy;
  }
  if (const toml::table* t = node.as_table()) {
    auto copy = std::make_unique<toml::table>();
    for (auto&& [key, item] : *t) copy->insert(std::string(key.str()), *without_source(item));
    return copy;
  }
  return node.visit([](auto&& n) -> std::unique_ptr<toml::node> {
    using Node = std::remove_cvref_t<decltype(n)>;
    if constexpr (toml::is_value<Node>)
      return std::make_unique<Node>(n.get());
    else
      return nullptr;  // arrays and tables are handled above
  });
}

// The value as TOML when the text reads as one value ("35", "[1, 2]", "\"x\"", "true"), else as a string.
std::unique_ptr<toml::node> value_node(const std::string& text) {
  try {
    const toml::table parsed = toml::parse("v = " + text);
    if (parsed.size() == 1 && parsed.contains("v")) return without_source(*parsed.get("v"));
  } catch (const toml::parse_error&) {
  }
  return std::make_unique<toml::value<std::string>>(text);
}

}  // namespace

TomlOverride parse_toml_override(const std::string& text) {
  const std::size_t eq = text.find('=');
  if (eq == std::string::npos) throw std::invalid_argument("'" + text + "' is not KEY=VALUE");
  TomlOverride o{trimmed(std::string_view(text).substr(0, eq)), trimmed(std::string_view(text).substr(eq + 1))};
  const std::vector<std::string> parts = key_parts(o.key);
  bool empty_part = false;
  for (const std::string& p : parts) empty_part = empty_part || p.empty();
  if (parts.size() < 2 || empty_part)
    throw std::invalid_argument("'" + text + "': the key must be dotted, section.key (e.g. signal.cn0_dbhz)");
  return o;
}

void apply_toml_overrides(toml::table& root, const std::vector<TomlOverride>& overrides) {
  for (const TomlOverride& o : overrides) {
    const std::vector<std::string> parts = key_parts(o.key);
    toml::table* table = &root;
    for (std::size_t i = 0; i + 1 < parts.size(); ++i) {
      toml::node* next = table->get(parts[i]);
      if (!next) next = &table->insert_or_assign(parts[i], toml::table{}).first->second;
      if (!next->is_table())
        throw std::invalid_argument("override " + o.key + ": '" + parts[i] + "' is " +
                                    (next->is_array_of_tables() ? "an array of tables" : "a value, not a table"));
      table = next->as_table();
    }
    value_node(o.value)->visit([&](auto&& n) { table->insert_or_assign(parts.back(), std::move(n)); });
  }
}

}  // namespace ultratrack::config
