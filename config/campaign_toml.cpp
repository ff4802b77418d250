// SPDX-License-Identifier: GPL-3.0-or-later
#include "config/campaign_toml.hpp"

#include <fmt/core.h>
#include <toml++/toml.h>

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include "config/fuse_config_toml.hpp"
#include "config/receive_config_toml.hpp"
#include "config/scenario_toml.hpp"
#include "fusion/vector_tracking.hpp"
#include "ins/imu_error_model.hpp"
#include "io/input_error.hpp"
#include "io/units.hpp"
#include "receiver/nav_bit_source.hpp"
#include "signals/rinex_nav.hpp"

namespace ultratrack::config {
namespace {

namespace fs = std::filesystem;
using pipelines::CampaignReduction;

int line_of(const toml::node& node) { return static_cast<int>(node.source().begin.line); }

// Reading one table strictly: each key asked for once; check_done() rejects any key nobody asked for.
struct Table {
  const std::string& file;
  std::string name;  // "receive", "axis[2]"
  const toml::table& table;
  std::set<std::string> seen;

  const toml::node* get(const std::string& key) {
    seen.insert(key);
    return table.get(key);
  }
  std::string key_name(const std::string& key) const {
    return name.empty() ? key : key.empty() ? name : name + "." + key;
  }
  [[noreturn]] void fail(const toml::node& node, const std::string& key, const std::string& problem) const {
    throw io::InputError(file, "key '" + key_name(key) + "' " + problem, line_of(node));
  }
  std::string text(const std::string& key, std::string fallback) {
    const toml::node* n = get(key);
    if (!n) return fallback;
    if (auto v = n->value<std::string>()) return *v;
    fail(*n, key, "must be a string");
  }
  double number(const std::string& key, double fallback) {
    const toml::node* n = get(key);
    if (!n) return fallback;
    if (auto v = n->value<double>()) return *v;
    fail(*n, key, "must be a number");
  }
  int integer(const std::string& key, int fallback, int min) {
    const toml::node* n = get(key);
    if (!n) return fallback;
    const auto v = n->value<std::int64_t>();
    if (!v) fail(*n, key, "must be an integer");
    if (*v < min || *v > 1000000) fail(*n, key, fmt::format("must be in [{}, 1000000]", min));
    return static_cast<int>(*v);
  }
  bool boolean(const std::string& key, bool fallback) {
    const toml::node* n = get(key);
    if (!n) return fallback;
    if (auto v = n->value<bool>()) return *v;
    fail(*n, key, "must be true or false");
  }
  std::vector<std::string> texts(const std::string& key) {
    std::vector<std::string> out;
    const toml::node* n = get(key);
    if (!n) return out;
    const toml::array* a = n->as_array();
    if (!a) fail(*n, key, "must be an array of strings");
    for (const toml::node& item : *a) {
      const auto v = item.value<std::string>();
      if (!v) fail(item, key, "must be an array of strings");
      out.push_back(*v);
    }
    return out;
  }
  void check_done() const {
    for (const auto& [key, node] : table)
      if (!seen.count(std::string(key.str())))
        throw io::InputError(file, "unknown key '" + key_name(std::string(key.str())) + "'", line_of(node));
  }
};

// A parameter value as text: strings as written, integers in decimal, floats with a decimal point or exponent so
// that a TOML template reads them back as floats.
std::string value_text(const toml::node& node, Table& where, const std::string& key) {
  if (auto s = node.value_exact<std::string>()) return *s;
  if (auto i = node.value_exact<std::int64_t>()) return std::to_string(*i);
  if (auto d = node.value_exact<double>()) {
    std::string t = fmt::format("{}", *d);
    if (t.find_first_of(".eEn") == std::string::npos) t += ".0";
    return t;
  }
  if (auto b = node.value_exact<bool>()) return *b ? "true" : "false";
  where.fail(node, key, "values must be numbers, strings or booleans");
}

std::vector<std::string> values_of(const toml::node& node, Table& where, const std::string& key) {
  const toml::array* a = node.as_array();
  if (!a || a->empty()) where.fail(node, key, "must be a non-empty array");
  std::vector<std::string> out;
  for (const toml::node& item : *a) out.push_back(value_text(item, where, key));
  return out;
}

pipelines::CampaignAxis read_axis(const std::string& file, const toml::table& t, int i) {
  Table table{file, fmt::format("axis[{}]", i), t, {}};
  pipelines::CampaignAxis axis;
  const toml::node* name = table.get("name");
  if (!name || !name->value<std::string>() || name->value<std::string>()->empty())
    throw io::InputError(file, "key '" + table.key_name("name") + "' must be a non-empty string", line_of(t));
  axis.name = *name->value<std::string>();
  const toml::node* values = table.get("values");
  const toml::node* count = table.get("count");
  if ((values != nullptr) == (count != nullptr))
    throw io::InputError(file, "axis '" + axis.name + "' needs either 'values' or 'count'", line_of(t));
  if (values) {
    axis.values = values_of(*values, table, "values");
  } else {
    const int n = table.integer("count", 0, 1);
    for (int k = 0; k < n; ++k) axis.values.push_back(std::to_string(k));
  }
  for (const auto& [key_view, node] : t) {
    const std::string key(key_view.str());
    if (key == "name" || key == "values" || key == "count") continue;
    table.seen.insert(key);
    std::vector<std::string> column;
    if (const toml::table* linear = node.as_table()) {
      Table l{file, table.key_name(key), *linear, {}};
      const toml::node* start = l.get("start");
      const toml::node* step = l.get("step");
      if (!start || !step) l.fail(node, "", "must have start and step");
      l.check_done();
      const auto is = [](const toml::node* n) { return n->value_exact<std::int64_t>().has_value(); };
      for (std::size_t k = 0; k < axis.values.size(); ++k) {
        std::int64_t offset = 0, value = 0;
        if (is(start) && is(step)) {
          if (__builtin_mul_overflow(static_cast<std::int64_t>(k), *step->value<std::int64_t>(), &offset) ||
              __builtin_add_overflow(*start->value<std::int64_t>(), offset, &value))
            l.fail(node, "", "overflows a 64-bit integer");
          column.push_back(std::to_string(value));
        } else {
          const auto s0 = start->value<double>(), ds = step->value<double>();
          if (!s0 || !ds) l.fail(node, "", "start and step must be numbers");
          toml::value<double> v(*s0 + static_cast<double>(k) * *ds);
          column.push_back(value_text(v, table, key));
        }
      }
    } else {
      column = values_of(node, table, key);
      if (column.size() != axis.values.size())
        table.fail(node, key, fmt::format("has {} values, the axis {}", column.size(), axis.values.size()));
    }
    axis.columns.emplace_back(key, std::move(column));
  }
  return axis;
}

// The recordings as the first axis, "recording": their names, and a column per key.
pipelines::CampaignAxis read_recordings(const std::string& file, const std::vector<const toml::table*>& list,
                                        const fs::path& base) {
  static const char* const kKeys[] = {"input", "format", "sample_rate_hz", "if_hz", "imu", "truth"};
  pipelines::CampaignAxis axis{"recording", {}, {}};
  for (const char* key : kKeys) axis.columns.emplace_back(key, std::vector<std::string>{});
  int i = 0;
  for (const toml::table* t : list) {
    Table table{file, fmt::format("recording[{}]", i), *t, {}};
    axis.values.push_back(table.text("name", fmt::format("recording{}", i)));
    for (auto& [key, column] : axis.columns) {
      const toml::node* n = table.get(key);
      std::string text = n ? value_text(*n, table, key) : "";
      if ((key == "input" || key == "imu" || key == "truth") && !text.empty()) text = (base / text).lexically_normal();
      if ((key == "input" || key == "sample_rate_hz") && text.empty())
        throw io::InputError(file, "key '" + table.key_name(key) + "' is required", line_of(*t));
      column.push_back(text);
    }
    table.check_done();
    ++i;
  }
  return axis;
}

CampaignReduction read_reduction(const std::string& file, const toml::table& t, int i, const CampaignFile& c) {
  Table table{file, fmt::format("report[{}]", i), t, {}};
  CampaignReduction r;
  const std::string kind = table.text("kind", "");
  r.group = table.texts("group");
  if (kind == "lock_threshold") {
    r.kind = CampaignReduction::Kind::kLockThreshold;
    r.level = table.text("level", "cn0_dbhz");
    if (!c.metrics.lock_outcomes)
      throw io::InputError(file, "a lock_threshold report needs [compute] lock_outcomes", line_of(t));
  } else if (kind == "nav_consistency") {
    r.kind = CampaignReduction::Kind::kNavConsistency;
    if (!c.metrics.nav_z_times_s)
      throw io::InputError(file, "a nav_consistency report needs [compute] nav_z_times_s", line_of(t));
    r.times_s = *c.metrics.nav_z_times_s;
  } else if (kind == "stats") {
    r.kind = CampaignReduction::Kind::kStats;
    r.value = table.text("value", "");
    if (r.value.empty()) throw io::InputError(file, "key '" + table.key_name("value") + "' is required", line_of(t));
  } else if (kind == "rms" || kind == "table" || kind == "error_stats") {
    const char* key = kind == "rms" ? "values" : kind == "table" ? "columns" : "axes";
    r.kind = kind == "rms"     ? CampaignReduction::Kind::kRms
             : kind == "table" ? CampaignReduction::Kind::kTable
                               : CampaignReduction::Kind::kErrorStats;
    r.values = table.texts(key);
    if (r.values.empty())
      throw io::InputError(file, "key '" + table.key_name(key) + "' must be a non-empty array of strings", line_of(t));
  } else {
    throw io::InputError(file,
                         "key '" + table.key_name("kind") +
                             "' must be lock_threshold, nav_consistency, stats, rms, table or error_stats",
                         line_of(t));
  }
  table.check_done();
  std::set<std::string> names;
  for (const auto& axis : c.axes) {
    names.insert(axis.name);
    for (const auto& [name, values] : axis.columns) names.insert(name);
  }
  for (const std::string& g : r.group)
    if (!names.count(g))
      throw io::InputError(file, "key '" + table.key_name("group") + "' names no parameter '" + g + "'", line_of(t));
  if (r.kind == CampaignReduction::Kind::kLockThreshold && !names.count(r.level))
    throw io::InputError(file, "key '" + table.key_name("level") + "' names no parameter '" + r.level + "'",
                         line_of(t));
  return r;
}

const toml::table* section(const std::string& file, const toml::table& root, const std::string& name) {
  const toml::node* n = root.get(name);
  if (!n) return nullptr;
  if (const toml::table* t = n->as_table()) return t;
  throw io::InputError(file, "'" + name + "' must be a table [" + name + "]", line_of(*n));
}

// The tables of an array of tables ([[name]]); none when absent.
std::vector<const toml::table*> tables_of(const std::string& file, const toml::table& root, const std::string& name) {
  std::vector<const toml::table*> tables;
  const toml::node* n = root.get(name);
  if (!n) return tables;
  const toml::array* a = n->as_array();
  if (!a) throw io::InputError(file, "'" + name + "' must be [[" + name + "]] tables", line_of(*n));
  for (const toml::node& item : *a) {
    if (!item.as_table()) throw io::InputError(file, "'" + name + "' must be [[" + name + "]] tables", line_of(item));
    tables.push_back(item.as_table());
  }
  return tables;
}

std::string read_text(const fs::path& path, const std::string& who) {
  std::ifstream in(path);
  if (!in) throw io::InputError(who, "cannot read the scenario template " + path.string());
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string substitute(const CampaignFile& c, const std::string& text, const pipelines::CampaignRun& run,
                       const std::string& where) {
  try {
    return pipelines::substitute_parameters(text, run);
  } catch (const std::invalid_argument& e) {
    throw io::InputError(where, std::string(e.what()) + " (campaign file " + c.source.string() + ")");
  }
}

fs::path resolve(const CampaignFile& c, const std::string& path) {
  return path.empty() ? fs::path() : (c.base_dir / path).lexically_normal();
}

// The scenario template of a run: [simulate] scenario with the run's parameters filled in.
fs::path scenario_path(const CampaignFile& c, const pipelines::CampaignRun& run) {
  return resolve(c, substitute(c, c.scenario_spec, run, c.source.string() + ": [simulate] scenario"));
}

}  // namespace

CampaignFile read_campaign(const fs::path& path, const fs::path& base_dir) {
  const std::string file = path.string();
  toml::table root;
  try {
    root = toml::parse_file(file);
  } catch (const toml::parse_error& e) {
    std::error_code ec;
    if (!fs::exists(path, ec)) throw io::InputError(file, "campaign file not found");
    throw io::InputError(file, std::string(e.description()), static_cast<int>(e.source().begin.line));
  }
  CampaignFile c;
  c.source = path;
  c.base_dir = base_dir.empty() ? fs::absolute(path).parent_path() : fs::absolute(base_dir);
  Table top{file, "", root, {}};
  for (const char* s : {"campaign", "axis", "simulate", "recording", "step", "file", "alignment_mc", "receive",
                        "compute", "report", "slurm"})
    top.get(s);
  top.check_done();

  if (const toml::table* t = section(file, root, "campaign")) {
    Table table{file, "campaign", *t, {}};
    c.name = table.text("name", "");
    c.description = table.text("description", "");
    table.check_done();
  }
  const std::vector<const toml::table*> recordings = tables_of(file, root, "recording");
  const toml::table* simulate = section(file, root, "simulate");
  const std::vector<const toml::table*> steps = tables_of(file, root, "step");
  const toml::table* alignment = section(file, root, "alignment_mc");
  if (!recordings.empty() + (simulate != nullptr) + !steps.empty() + (alignment != nullptr) != 1)
    throw io::InputError(file, "a campaign has one of [simulate], [[recording]], [[step]] or [alignment_mc]");
  if (!recordings.empty()) {
    c.recordings = true;
    c.axes.push_back(read_recordings(file, recordings, c.base_dir));
  }
  int axis_number = 0;
  for (const toml::table* t : tables_of(file, root, "axis")) c.axes.push_back(read_axis(file, *t, axis_number++));
  try {
    (void)pipelines::expand_campaign(c.axes);
  } catch (const std::invalid_argument& e) {
    throw io::InputError(file, e.what());
  }
  if (simulate) {
    Table table{file, "simulate", *simulate, {}};
    c.scenario_spec = table.text("scenario", "");
    if (c.scenario_spec.empty()) throw io::InputError(file, "key 'simulate.scenario' is required", line_of(*simulate));
    if (const toml::node* n = table.get("set")) {
      const toml::table* set = n->as_table();
      if (!set) table.fail(*n, "set", "must be a table of dotted keys: { \"signal.cn0_dbhz\" = \"{cn0_dbhz}\" }");
      Table entries{file, "simulate.set", *set, {}};
      for (auto&& [key, value] : *set) {
        const std::string k(key.str());
        try {
          (void)parse_toml_override(k + "=x");
        } catch (const std::invalid_argument& e) {
          table.fail(value, "set", e.what());
        }
        c.scenario_set.emplace_back(k, value_text(value, entries, k));
      }
    }
    c.keep_samples = table.boolean("keep_samples", false);
    table.check_done();
  }
  for (const toml::table* s : steps) {
    Table table{file, fmt::format("step[{}]", c.steps.size()), *s, {}};
    c.steps.push_back(table.texts("args"));
    if (c.steps.back().empty()) table.fail(*s, "args", "must be a non-empty array of strings");
    table.check_done();
  }
  for (const toml::table* f : tables_of(file, root, "file")) {
    Table table{file, fmt::format("file[{}]", c.files.size()), *f, {}};
    CampaignTemplateFile written;
    written.source = resolve(c, table.text("template", ""));
    written.name = table.text("name", "");
    if (written.source.empty() || written.name.empty() || written.name.find('/') != std::string::npos)
      table.fail(*f, "", "needs template (a file) and name (a file name in the run folder)");
    table.check_done();
    written.text = read_text(written.source, file);
    c.files.push_back(std::move(written));
  }

  if (alignment) {
    Table table{file, "alignment_mc", *alignment, {}};
    CampaignAlignment a;
    const auto text_of = [&](const char* key, std::string& into) {
      if (const toml::node* n = table.get(key)) into = value_text(*n, table, key);
    };
    text_of("seed", a.seed);
    text_of("filter", a.filter);
    text_of("imu", a.imu);
    text_of("lat_deg", a.lat_deg);
    text_of("duration_s", a.duration_s);
    if (const toml::node* n = table.get("gps_sigma_deg")) {
      a.gps_sigma_deg = values_of(*n, table, "gps_sigma_deg");
      if (a.gps_sigma_deg.size() != 3) table.fail(*n, "gps_sigma_deg", "must hold 3 values (roll, pitch, yaw)");
    }
    table.check_done();
    c.alignment = a;
  }
  if (const toml::table* t = section(file, root, "receive")) {
    Table table{file, "receive", *t, {}};
    CampaignReceive& r = c.receive;
    r.nav = table.text("nav", "");
    r.config = table.text("config", "");
    r.fusion_config = table.text("fusion_config", "");
    r.coupling = table.text("coupling", r.coupling);
    r.filter = table.text("filter", r.filter);
    r.align = table.text("align", r.align);
    r.nav_bits = table.text("nav_bits", r.nav_bits);
    r.vector_carrier = table.text("vector_carrier", r.vector_carrier);
    r.threads = table.integer("threads", r.threads, 0);
    const std::string prns = table.text("prns", "simulated");
    if (prns != "simulated" && prns != "all") table.fail(*t->get("prns"), "prns", "must be \"simulated\" or \"all\"");
    r.prns_from_simulation = prns == "simulated";
    table.check_done();
  }
  if (const toml::table* t = section(file, root, "compute")) {
    Table table{file, "compute", *t, {}};
    if (const toml::node* n = table.get("lock_outcomes")) {
      if (!n->as_table()) table.fail(*n, "lock_outcomes", "must be a table { lock_deadline_s = 5.0, strong_s = 0.0 }");
      Table l{file, "compute.lock_outcomes", *n->as_table(), {}};
      pipelines::LockOutcomeOptions o;
      o.lock_deadline_s = l.number("lock_deadline_s", o.lock_deadline_s);
      o.strong_s = l.number("strong_s", o.strong_s);
      l.check_done();
      c.metrics.lock_outcomes = o;
    }
    if (const toml::node* n = table.get("nav_z_times_s")) {
      const toml::array* a = n->as_array();
      if (!a || a->empty()) table.fail(*n, "nav_z_times_s", "must be a non-empty array of times (s)");
      std::vector<double> times;
      for (const toml::node& item : *a) {
        const auto v = item.value<double>();
        if (!v) table.fail(item, "nav_z_times_s", "must be a non-empty array of times (s)");
        times.push_back(*v);
      }
      c.metrics.nav_z_times_s = times;
    }
    if (const toml::node* n = table.get("weak_part_from_s")) {
      const auto v = n->value<double>();
      if (!v || !(*v >= 0.0)) table.fail(*n, "weak_part_from_s", "must be a time >= 0 (s)");
      c.metrics.weak_part_from_s = *v;
    }
    c.remove_after = table.texts("remove");
    for (const std::string& r : c.remove_after)
      if (r.empty() || r.front() == '/' || r.find("..") != std::string::npos)
        throw io::InputError(file, "key 'compute.remove': '" + r + "' must be a path inside the run folder");
    if (const toml::node* n = table.get("json")) {
      if (!n->as_table()) table.fail(*n, "json", "must be a table { name = \"FILE:dotted.path\" }");
      for (const auto& [key, value] : *n->as_table()) {
        const auto spec = value.value<std::string>();
        try {
          if (!spec) throw std::invalid_argument("must be a string FILE:dotted.path");
          c.metrics.json_scalars.push_back(pipelines::parse_campaign_json_scalar(std::string(key.str()), *spec));
        } catch (const std::invalid_argument& e) {
          table.fail(value, "json." + std::string(key.str()), e.what());
        }
      }
    }
    table.check_done();
  }
  if ((!c.files.empty() || !c.remove_after.empty()) && steps.empty())
    throw io::InputError(file, "[[file]] and [compute] remove go with [[step]] tables");
  int report_number = 0;
  for (const toml::table* t : tables_of(file, root, "report"))
    c.reductions.push_back(read_reduction(file, *t, report_number++, c));
  if (const toml::table* t = section(file, root, "slurm")) {
    Table table{file, "slurm", *t, {}};
    SlurmResources& s = c.slurm;
    s.time = table.text("time", s.time);
    s.mem = table.text("mem", s.mem);
    s.partition = table.text("partition", s.partition);
    s.account = table.text("account", s.account);
    s.cpus_per_task = table.integer("cpus_per_task", s.cpus_per_task, 1);
    s.runs_per_task = table.integer("runs_per_task", s.runs_per_task, 1);
    s.max_parallel = table.integer("max_parallel", s.max_parallel, 0);
    s.extra = table.texts("extra");
    table.check_done();
  }
  // Every run's templates must fill in: a misspelt {name} fails here, before any run.
  const std::vector<pipelines::CampaignRun> runs = pipelines::expand_campaign(c.axes);
  if (simulate)  // each scenario template the runs name, read once
    for (const pipelines::CampaignRun& run : runs) {
      const fs::path path = scenario_path(c, run);
      if (!c.scenario_texts.contains(path)) c.scenario_texts[path] = read_text(path, file);
    }
  if (!runs.empty()) {
    if (simulate) {
      const fs::path path = scenario_path(c, runs.front());
      (void)substitute(c, c.scenario_texts.at(path), runs.front(), path.string());
      for (const auto& [key, value] : c.scenario_set)
        (void)substitute(c, value, runs.front(), file + ": [simulate] set");
    }
    for (const auto& args : c.steps)
      for (const std::string& arg : args) (void)fill_in(c, arg, runs.front(), file + ": [[step]]");
    for (const CampaignTemplateFile& f : c.files) (void)fill_in(c, f.text, runs.front(), f.source.string());
    if (c.alignment) (void)campaign_job(c, runs.front());
    for (const std::string* text : {&c.receive.nav, &c.receive.config, &c.receive.coupling, &c.receive.filter,
                                    &c.receive.align, &c.receive.nav_bits, &c.receive.vector_carrier})
      (void)substitute(c, *text, runs.front(), file + ": [receive]");
  }
  return c;
}

std::string fill_in(const CampaignFile& c, const std::string& text, const pipelines::CampaignRun& run,
                    const std::string& where) {
  pipelines::CampaignRun with_folder = run;
  with_folder.parameters.emplace_back("campaign_dir", c.base_dir.string());
  return substitute(c, text, with_folder, where);
}

namespace {

double number_in(const std::string& text, const std::string& where, const std::string& key) {
  try {
    std::size_t used = 0;
    const double v = std::stod(text, &used);
    if (used == text.size() && std::isfinite(v)) return v;
  } catch (const std::exception&) {
  }
  throw io::InputError(where, "key '" + key + "' must be a number, got '" + text + "'");
}

pipelines::CampaignAlignmentJob alignment_job(const CampaignFile& c, const pipelines::CampaignRun& run) {
  const std::string where = c.source.string() + ": [alignment_mc]";
  const CampaignAlignment& a = *c.alignment;
  const auto value = [&](const std::string& text, const std::string& key) {
    return number_in(fill_in(c, text, run, where), where, key);
  };
  pipelines::CampaignAlignmentJob job;
  const double seed = value(a.seed, "seed");
  if (seed < 0 || seed != std::floor(seed) || seed > 9e15)
    throw io::InputError(where, "key 'seed' must be a non-negative integer");
  job.seed = static_cast<std::uint64_t>(seed);
  const std::string imu = fill_in(c, a.imu, run, where);
  try {
    job.scenario.imu = ins::imu_preset(imu);
  } catch (const std::exception& e) {
    throw io::InputError(where, "key 'imu': " + std::string(e.what()));
  }
  job.scenario.lat_rad = value(a.lat_deg, "lat_deg") * io::kRadPerDeg;
  job.scenario.duration_s = value(a.duration_s, "duration_s");
  for (int i = 0; i < 3; ++i)
    job.scenario.gps_sigma_euler_rad(i) =
        value(a.gps_sigma_deg[static_cast<std::size_t>(i)], "gps_sigma_deg") * io::kRadPerDeg;
  if (job.scenario.duration_s <= 2.0 || job.scenario.gps_sigma_euler_rad.minCoeff() <= 0.0)
    throw io::InputError(where, "duration_s must exceed 2 s and gps_sigma_deg be positive");
  job.options.imu = job.scenario.imu;
  const std::string filter = fill_in(c, a.filter, run, where);
  if (filter != "ekf" && filter != "ukf")
    throw io::InputError(where, "filter must be ekf or ukf, got '" + filter + "'");
  job.options.filter = filter == "ukf" ? fusion::FilterKind::Ukf : fusion::FilterKind::Ekf;
  return job;
}

}  // namespace

pipelines::CampaignJob campaign_job(const CampaignFile& c, const pipelines::CampaignRun& run) {
  const std::string file = c.source.string();
  pipelines::CampaignJob job;
  job.run = run;
  job.keep_samples = c.keep_samples;
  job.metrics = c.metrics;
  job.prns_from_simulation = c.receive.prns_from_simulation;
  if (c.alignment) {
    job.alignment = alignment_job(c, run);
    return job;
  }
  if (!c.steps.empty()) throw std::logic_error("a [[step]] campaign's runs are tools::run_campaign_steps's");
  if (!c.recordings) {
    const fs::path path = scenario_path(c, run);
    const std::string text = substitute(c, c.scenario_texts.at(path), run, path.string());
    std::vector<TomlOverride> overrides;
    for (const auto& [key, value] : c.scenario_set)
      overrides.push_back({key, substitute(c, value, run, file + ": [simulate] set")});
    job.scenario = parse_scenario(text, path, overrides);
    job.scenario_echo = to_toml(*job.scenario);
  } else {
    const auto param = [&](const char* name) { return run.find(name) ? *run.find(name) : std::string(); };
    pipelines::ReceiveFileJob& rx = job.receive;
    rx.input = param("input");
    const auto format = signals::parse_sample_format(param("format").empty() ? "i8" : param("format"));
    if (!format)
      throw io::InputError(file, "recording " + param("recording") + ": unknown format '" + param("format") + "'");
    rx.format = *format;
    try {
      rx.source.fs_hz = std::stod(param("sample_rate_hz"));
      rx.source.if_hz = param("if_hz").empty() ? 0.0 : std::stod(param("if_hz"));
    } catch (const std::exception&) {
      throw io::InputError(file, "recording " + param("recording") + ": sample_rate_hz and if_hz must be numbers");
    }
    rx.options.receiver.fs_hz = rx.source.fs_hz;
    job.truth_csv = param("truth");
    job.imu_csv = param("imu");
  }
  pipelines::ReceiveOptions& o = job.receive.options;
  const std::string where = file + ": [receive]";
  if (const std::string config = substitute(c, c.receive.config, run, where); !config.empty())
    apply_receive_config(resolve(c, config), o.receiver);
  o.receiver.threads = c.receive.threads;
  const std::string coupling = substitute(c, c.receive.coupling, run, where);
  const auto parsed = pipelines::coupling_from_string(coupling);
  if (!parsed)
    throw io::InputError(where, "coupling must be scalar, vector, loose, tight or ultra-tight, got '" + coupling + "'");
  o.coupling = *parsed;
  const std::string filter = substitute(c, c.receive.filter, run, where);
  if (filter != "ekf" && filter != "ukf")
    throw io::InputError(where, "filter must be ekf or ukf, got '" + filter + "'");
  o.filter = filter == "ukf" ? fusion::FilterKind::Ukf : fusion::FilterKind::Ekf;
  const std::string align = substitute(c, c.receive.align, run, where);
  const auto mode = pipelines::align_mode_from_string(align);
  if (!mode || *mode == pipelines::AlignMode::Attitude)  // attitude alignment is `fuse`'s
    throw io::InputError(where, "align must be static, motion or config, got '" + align + "'");
  o.align = *mode;
  if (!c.receive.fusion_config.empty()) o.navigation = read_fuse_config(resolve(c, c.receive.fusion_config));
  if (const std::string bits = substitute(c, c.receive.nav_bits, run, where); !bits.empty())
    o.receiver.nav_bits = receiver::parse_nav_bit_source(where + ": nav_bits", bits);
  if (const std::string carrier = substitute(c, c.receive.vector_carrier, run, where); !carrier.empty()) {
    if (o.coupling != pipelines::Coupling::kVector)
      throw io::InputError(where, "vector_carrier '" + carrier + "' needs the vector coupling");
    const auto parsed_carrier = fusion::vector_carrier_from_string(carrier);
    if (!parsed_carrier)
      throw io::InputError(where, "vector_carrier must be aided-pll, fll or pll, got '" + carrier + "'");
    o.vector_carrier = *parsed_carrier;
  }
  const std::string nav = substitute(c, c.receive.nav, run, where);
  if (!nav.empty()) job.receive.navigation = signals::read_rinex_nav(resolve(c, nav));
  return job;
}

}  // namespace ultratrack::config
