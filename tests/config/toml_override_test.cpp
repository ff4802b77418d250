// SPDX-License-Identifier: GPL-3.0-or-later
// config/toml_override.hpp: `simulate --set` and a campaign's [simulate] set, on a scenario as the reader sees it.
#include "config/toml_override.hpp"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

#include "config/scenario_toml.hpp"
#include "io/input_error.hpp"

namespace {

using ultratrack::config::apply_toml_overrides;
using ultratrack::config::parse_scenario;
using ultratrack::config::parse_toml_override;
using ultratrack::config::TomlOverride;

constexpr const char* kScenario = R"([signal]
sample_rate_hz = 2.6e6
duration_s = 60.0
cn0_dbhz = 45.0
seed = 1
)";

TEST(TomlOverride, ParsesKeyAndValueAndRefusesWhatIsNotADottedKeyValue) {
  const TomlOverride o = parse_toml_override(" signal.cn0_dbhz = 35 ");
  EXPECT_EQ(o.key, "signal.cn0_dbhz");
  EXPECT_EQ(o.value, "35");
  EXPECT_EQ(parse_toml_override("a.b=x=y").value, "x=y");  // the first '=' splits
  EXPECT_THROW(parse_toml_override("signal.cn0_dbhz"), std::invalid_argument);
  EXPECT_THROW(parse_toml_override("cn0_dbhz=35"), std::invalid_argument);
  EXPECT_THROW(parse_toml_override("signal..cn0=35"), std::invalid_argument);
  EXPECT_THROW(parse_toml_override(".cn0=35"), std::invalid_argument);
}

TEST(TomlOverride, ValuesKeepTheirTomlTypeAndBareTextIsAString) {
  toml::table t = toml::parse(kScenario);
  apply_toml_overrides(t, {{"signal.cn0_dbhz", "35"},
                           {"signal.duration_s", "2.5"},
                           {"signal.format", "i16"},
                           {"receiver.llh_deg_m", "[35.0, 137.0, 50.0]"},
                           {"atmosphere.ionosphere", "false"}});
  EXPECT_EQ(t["signal"]["cn0_dbhz"].value_exact<std::int64_t>(), 35);
  EXPECT_EQ(t["signal"]["duration_s"].value_exact<double>(), 2.5);
  EXPECT_EQ(t["signal"]["format"].value_exact<std::string>(), "i16");
  ASSERT_TRUE(t["receiver"]["llh_deg_m"].is_array());  // the missing table is made
  EXPECT_EQ(t["receiver"]["llh_deg_m"][2].value<double>(), 50.0);
  EXPECT_EQ(t["atmosphere"]["ionosphere"].value_exact<bool>(), false);
  EXPECT_EQ(t["signal"]["seed"].value_exact<std::int64_t>(), 1);  // the rest untouched
  // A later change of the same key wins; a value in the path is refused.
  apply_toml_overrides(t, {{"signal.cn0_dbhz", "30.0"}, {"signal.cn0_dbhz", "31.0"}});
  EXPECT_EQ(t["signal"]["cn0_dbhz"].value_exact<double>(), 31.0);
  EXPECT_THROW(apply_toml_overrides(t, {{"signal.cn0_dbhz.x", "1"}}), std::invalid_argument);
}

TEST(TomlOverride, TheScenarioReaderChecksTheChangedKeysAsItChecksAFile) {
  const auto s = parse_scenario(kScenario, "s.toml", {{"signal.cn0_dbhz", "35.0"}, {"signal.duration_s", "2.0"}});
  EXPECT_EQ(s.cn0_dbhz, 35.0);
  EXPECT_EQ(s.duration_s, 2.0);
  // A misspelt key, a wrong type: the reader's own errors, naming the file and the key but no line of it.
  try {
    (void)parse_scenario(kScenario, "s.toml", {{"signal.cn0_dbz", "35.0"}});
    FAIL() << "no error";
  } catch (const ultratrack::io::InputError& e) {
    EXPECT_EQ(std::string(e.what()), "s.toml: key signal.cn0_dbz: unknown key in [signal]");
  }
  EXPECT_THROW((void)parse_scenario(kScenario, "s.toml", {{"signal.cn0_dbhz", "loud"}}), ultratrack::io::InputError);
  EXPECT_THROW((void)parse_scenario(kScenario, "s.toml", {{"signal.seed.x", "1"}}), ultratrack::io::InputError);
}

}  // namespace
