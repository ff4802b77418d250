// SPDX-License-Identifier: GPL-3.0-or-later
#include "config/antenna_config_toml.hpp"

#include <fmt/core.h>
#include <toml++/toml.h>

#include <cmath>
#include <fstream>
#include <sstream>

#include "io/open_failure.hpp"
#include "io/why_invalid.hpp"
#include "signals/input_error.hpp"

namespace ultratrack::config {
namespace {

using signals::InputError;

[[noreturn]] void fail(const std::string& file, const toml::node& n, const std::string& key, const std::string& why) {
  throw InputError(file, "key " + key + ": " + why, static_cast<int>(n.source().begin.line));
}

double number(const std::string& file, const toml::node& n, const std::string& key) {
  if (auto v = n.as_floating_point()) return v->get();
  if (auto v = n.as_integer()) return static_cast<double>(v->get());
  fail(file, n, key, "expected a number");
}

}  // namespace

AntennaConfig read_antenna_config(const std::filesystem::path& path) {
  const std::string file = path.string();
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(file, "cannot open the antenna file: " + io::open_failure_reason());
  std::stringstream text;
  text << in.rdbuf();
  toml::table root;
  try {
    root = toml::parse(text.str(), file);
  } catch (const toml::parse_error& e) {
    throw InputError(file, std::string(e.description()), static_cast<int>(e.source().begin.line));
  }
  AntennaConfig c;
  bool have_antennas = false;
  for (auto&& [section_key, node] : root) {
    const std::string section(section_key.str());
    if (section == "antenna") {
      const auto* arr = node.as_array();
      if (!arr || arr->empty() || !arr->is_array_of_tables())
        fail(file, node, section, "expected [[antenna]] tables with lever_arm_body_m = [x, y, z]");
      for (const auto& e : *arr) {
        bool lever_given = false;
        Eigen::Vector3d lever = Eigen::Vector3d::Zero();
        double bias = 0.0;
        for (auto&& [k, n] : *e.as_table()) {
          const std::string key = "antenna." + std::string(k.str());
          if (k.str() == "lever_arm_body_m") {
            const auto* a = n.as_array();
            if (!a || a->size() != 3) fail(file, n, key, "expected an array of 3 numbers");
            for (std::size_t i = 0; i < 3; ++i) lever[static_cast<Eigen::Index>(i)] = number(file, *a->get(i), key);
            if (lever.cwiseAbs().maxCoeff() > 1000.0) fail(file, n, key, "each component must be within +-1000 m");
            lever_given = true;
          } else if (k.str() == "line_bias_cycles") {
            bias = number(file, n, key);
            if (!(std::abs(bias) <= 1e6)) fail(file, n, key, "must be within +-1e6 cycles");
          } else if (k.str() == "phase_noise_m") {
            number(file, n, key);  // a scenario's simulation setting: accepted, not used
          } else {
            fail(file, n, key, "unknown key in [[antenna]] (lever_arm_body_m, line_bias_cycles)");
          }
        }
        if (!lever_given) fail(file, e, "antenna.lever_arm_body_m", "missing in an [[antenna]] table");
        c.solver.array.lever_arm_body_m.push_back(lever);
        c.line_bias_cycles.push_back(bias);
      }
      have_antennas = true;
    } else if (section == "solver") {
      const auto* t = node.as_table();
      if (!t) fail(file, node, section, "expected a table [solver]");
      for (auto&& [k, n] : *t) {
        const std::string key = "solver." + std::string(k.str());
        if (k.str() == "phase_sigma_m") {
          c.solver.phase_sigma_m = number(file, n, key);
        } else if (k.str() == "elevation_mask_deg") {
          c.solver.elevation_mask_rad = number(file, n, key) * M_PI / 180.0;
        } else if (k.str() == "ratio_threshold") {
          c.solver.ratio_threshold = number(file, n, key);
        } else if (k.str() == "min_satellites") {
          const auto v = n.as_integer();
          if (!v) fail(file, n, key, "expected an integer");
          c.solver.min_satellites = static_cast<int>(v->get());
        } else if (k.str() == "use_length_constraint") {
          const auto v = n.as_boolean();
          if (!v) fail(file, n, key, "expected true or false");
          c.solver.use_length_constraint = v->get();
        } else if (k.str() == "multi_epoch") {
          const auto v = n.as_boolean();
          if (!v) fail(file, n, key, "expected true or false");
          c.solver.multi_epoch = v->get();
        } else {
          fail(file, n, key,
               "unknown key in [solver] (phase_sigma_m, elevation_mask_deg, ratio_threshold, min_satellites, "
               "use_length_constraint, multi_epoch)");
        }
      }
    } else {
      fail(file, node, section, "unknown section ([[antenna]], [solver])");
    }
  }
  if (!have_antennas) throw InputError(file, "no [[antenna]] tables (lever_arm_body_m of each antenna, master first)");
  const auto n = c.solver.array.lever_arm_body_m.size();
  if (n < 2 || n > static_cast<std::size_t>(receiver::kMaxAntennas))
    throw InputError(file, fmt::format("{} antennas: an attitude needs 2..{}", n, receiver::kMaxAntennas));
  if (const std::string why = io::why_invalid(c.solver); !why.empty()) throw InputError(file, why);
  return c;
}

}  // namespace ultratrack::config
