// SPDX-License-Identifier: GPL-3.0-or-later
// Campaign expansion (pipelines/campaign_plan.hpp) and campaign files (config/campaign_toml.hpp): the product's
// count and order, zipped and linear columns, template substitution, and malformed files as InputErrors naming
// the file and the key.
#include "pipelines/campaign_plan.hpp"

#include <gtest/gtest.h>

#include <fstream>
#include <set>
#include <stdexcept>
#include <string>

#include "config/campaign_toml.hpp"
#include "io/input_error.hpp"
#include "support/test_data.hpp"

namespace {

using ultratrack::pipelines::CampaignAxis;
using ultratrack::pipelines::CampaignRun;
using ultratrack::pipelines::expand_campaign;
using ultratrack::pipelines::substitute_parameters;

std::string params(const CampaignRun& run) {
  std::string text;
  for (const auto& [name, value] : run.parameters) text += name + "=" + value + " ";
  return text;
}

TEST(CampaignPlan, ProductHasEveryCombinationFirstAxisSlowest) {
  const std::vector<CampaignAxis> axes{{"cn0", {"24", "26", "28"}, {}},
                                       {"file", {"0", "1"}, {{"seed", {"100", "101"}}}},
                                       {"coupling", {"scalar", "vector"}, {}}};
  const auto runs = expand_campaign(axes);
  ASSERT_EQ(runs.size(), 12u);
  for (std::size_t i = 0; i < runs.size(); ++i) EXPECT_EQ(runs[i].index, static_cast<int>(i));
  EXPECT_EQ(params(runs[0]), "cn0=24 file=0 seed=100 coupling=scalar ");
  EXPECT_EQ(params(runs[1]), "cn0=24 file=0 seed=100 coupling=vector ");
  EXPECT_EQ(params(runs[2]), "cn0=24 file=1 seed=101 coupling=scalar ");
  EXPECT_EQ(params(runs[4]), "cn0=26 file=0 seed=100 coupling=scalar ");
  EXPECT_EQ(params(runs[11]), "cn0=28 file=1 seed=101 coupling=vector ");
  // Every combination exactly once.
  std::set<std::string> distinct;
  for (const auto& r : runs) distinct.insert(params(r));
  EXPECT_EQ(distinct.size(), 12u);
}

TEST(CampaignPlan, NoAxisIsOneRunAndBadAxesThrow) {
  EXPECT_EQ(expand_campaign({}).size(), 1u);
  EXPECT_THROW(expand_campaign({{"a", {}, {}}}), std::invalid_argument);
  EXPECT_THROW(expand_campaign({{"a", {"1"}, {}}, {"a", {"2"}, {}}}), std::invalid_argument);
  EXPECT_THROW(expand_campaign({{"a", {"1", "2"}, {{"b", {"1"}}}}}), std::invalid_argument);
}

TEST(CampaignPlan, SubstitutesNamesAndLeavesOtherBracesAlone) {
  const CampaignRun run{3, {{"seed", "101"}, {"cn0_dbhz", "26.0"}}};
  EXPECT_EQ(substitute_parameters("seed = {seed}\ncn0_dbhz = {cn0_dbhz}\n", run), "seed = 101\ncn0_dbhz = 26.0\n");
  EXPECT_EQ(substitute_parameters("cn0_dbhz_by_prn = { 5 = 40.0 }  x = {}", run),
            "cn0_dbhz_by_prn = { 5 = 40.0 }  x = {}");
  try {
    substitute_parameters("seed = {sed}", run);
    FAIL() << "no throw";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("{sed}"), std::string::npos) << e.what();
  }
  EXPECT_EQ(ultratrack::pipelines::campaign_run_folder(7), "0007");
}

// A campaign file and its scenario template in a scratch folder.
std::filesystem::path write_campaign(const std::filesystem::path& dir, const std::string& campaign,
                                     const std::string& scenario = "[signal]\nseed = {seed}\ncn0_dbhz = {cn0_dbhz}\n") {
  std::ofstream(dir / "s.toml") << scenario;
  std::ofstream(dir / "c.toml") << campaign;
  return dir / "c.toml";
}

const char* const kGood = R"(
[campaign]
name = "t"
[[axis]]
name = "cn0_dbhz"
values = [24, 26.5]
[[axis]]
name = "file"
count = 3
seed = { start = 100, step = 2 }
tow_s = { start = 518400.0, step = 90.0 }
label = ["a", "b", "c"]
[simulate]
scenario = "s.toml"
[compute]
lock_outcomes = { lock_deadline_s = 4.0 }
[[report]]
kind = "lock_threshold"
[slurm]
runs_per_task = 2
extra = ["--qos=low"]
)";

TEST(CampaignToml, ReadsAxesColumnsAndSections) {
  const auto dir = ultratrack::test::scratch_dir();
  const auto c = ultratrack::config::read_campaign(write_campaign(dir, kGood));
  const auto runs = expand_campaign(c.axes);
  ASSERT_EQ(runs.size(), 6u);
  EXPECT_EQ(params(runs[0]), "cn0_dbhz=24 file=0 label=a seed=100 tow_s=518400.0 ");
  EXPECT_EQ(params(runs[5]), "cn0_dbhz=26.5 file=2 label=c seed=104 tow_s=518580.0 ");
  ASSERT_TRUE(c.metrics.lock_outcomes);
  EXPECT_EQ(c.metrics.lock_outcomes->lock_deadline_s, 4.0);
  EXPECT_EQ(c.metrics.lock_outcomes->strong_s, 0.0);
  EXPECT_EQ(c.slurm.runs_per_task, 2);
  ASSERT_EQ(c.slurm.extra.size(), 1u);
  ASSERT_EQ(c.reductions.size(), 1u);
  ASSERT_EQ(c.scenario_texts.size(), 1u);
  EXPECT_EQ(c.scenario_texts.begin()->first, dir / "s.toml");
  // The job of a run is its scenario with the parameters filled in.
  const auto job = ultratrack::config::campaign_job(c, runs[5]);
  ASSERT_TRUE(job.scenario);
  EXPECT_EQ(job.scenario->seed, 104u);
  EXPECT_EQ(job.scenario->cn0_dbhz, 26.5);
}

// A scenario path that names a parameter picks a file per run; [simulate] set changes keys of whichever it is.
TEST(CampaignToml, ScenarioPathAndSetNameParameters) {
  const auto dir = ultratrack::test::scratch_dir();
  std::ofstream(dir / "ut_a.toml") << "[signal]\nseed = 7\nduration_s = 60.0\n";
  std::ofstream(dir / "ut_b.toml") << "[signal]\nseed = 8\nduration_s = 60.0\ncn0_dbhz = 50.0\n";
  std::ofstream(dir / "c.toml") << R"(
[[axis]]
name = "which"
values = ["a", "b"]
[[axis]]
name = "cn0_dbhz"
values = [35.0, 40.0]
[simulate]
scenario = "ut_{which}.toml"
set = { "signal.cn0_dbhz" = "{cn0_dbhz}", "signal.duration_s" = 36.0 }
)";
  const auto c = ultratrack::config::read_campaign(dir / "c.toml");
  EXPECT_EQ(c.scenario_texts.size(), 2u);  // each file read once
  const auto runs = expand_campaign(c.axes);
  ASSERT_EQ(runs.size(), 4u);
  const auto job = ultratrack::config::campaign_job(c, runs[3]);  // which = b, 40 dB-Hz
  ASSERT_TRUE(job.scenario);
  EXPECT_EQ(job.scenario->seed, 8u);
  EXPECT_EQ(job.scenario->cn0_dbhz, 40.0);
  EXPECT_EQ(job.scenario->duration_s, 36.0);
  EXPECT_EQ(job.scenario->source, dir / "ut_b.toml");
  EXPECT_EQ(ultratrack::config::campaign_job(c, runs[0]).scenario->seed, 7u);

  // A value of the axis with no file: the campaign fails when read, naming the file, before any run.
  std::ofstream(dir / "c2.toml") << R"(
[[axis]]
name = "which"
values = ["a", "c"]
[simulate]
scenario = "ut_{which}.toml"
)";
  try {
    (void)ultratrack::config::read_campaign(dir / "c2.toml");
    FAIL() << "no error";
  } catch (const ultratrack::io::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("ut_c.toml"), std::string::npos) << e.what();
  }
  // A key of set that is not dotted, or a parameter that does not exist.
  std::ofstream(dir / "c3.toml") << "[[axis]]\nname = \"which\"\nvalues = [\"a\"]\n[simulate]\n"
                                    "scenario = \"ut_{which}.toml\"\nset = { cn0_dbhz = 35.0 }\n";
  EXPECT_THROW((void)ultratrack::config::read_campaign(dir / "c3.toml"), ultratrack::io::InputError);
  std::ofstream(dir / "c4.toml") << "[[axis]]\nname = \"which\"\nvalues = [\"a\"]\n[simulate]\n"
                                    "scenario = \"ut_{which}.toml\"\nset = { \"signal.cn0_dbhz\" = \"{level}\" }\n";
  EXPECT_THROW((void)ultratrack::config::read_campaign(dir / "c4.toml"), ultratrack::io::InputError);
}

// The InputError of a campaign file, or "no InputError".
std::string error_of(const std::string& campaign, const std::string& scenario = "[signal]\nseed = {seed}\n") {
  const auto dir = ultratrack::test::scratch_dir();
  try {
    ultratrack::config::read_campaign(write_campaign(dir, campaign, scenario));
  } catch (const ultratrack::io::InputError& e) {
    EXPECT_NE(std::string(e.what()).find((dir / "c.toml").string()), std::string::npos) << e.what();
    return e.what();
  }
  return "no InputError";
}

TEST(CampaignToml, MalformedFilesNameTheFileAndTheKey) {
  const std::string axis = "[[axis]]\nname = \"seed\"\nvalues = [1, 2]\n[simulate]\nscenario = \"s.toml\"\n";
  EXPECT_NE(error_of(axis + "[receive]\nthreds = 2\n").find("unknown key 'receive.threds'"), std::string::npos);
  EXPECT_NE(error_of(axis + "[receive]\nthreads = \"two\"\n").find("key 'receive.threads' must be an integer"),
            std::string::npos);
  EXPECT_NE(error_of("[[axis]]\nname = \"seed\"\nvalues = [1, 2]\nx = [1]\n[simulate]\nscenario = \"s.toml\"\n")
                .find("key 'axis[0].x' has 1 values"),
            std::string::npos);
  EXPECT_NE(error_of("[[axis]]\nname = \"seed\"\n[simulate]\nscenario = \"s.toml\"\n").find("'values' or 'count'"),
            std::string::npos);
  EXPECT_NE(error_of(axis + "[[report]]\nkind = \"median\"\n").find("key 'report[0].kind'"), std::string::npos);
  EXPECT_NE(error_of(axis + "[[report]]\nkind = \"lock_threshold\"\n").find("needs [compute] lock_outcomes"),
            std::string::npos);
  EXPECT_NE(error_of(axis + "[[report]]\nkind = \"stats\"\nvalue = \"fixes\"\ngroup = [\"coupling\"]\n")
                .find("names no parameter 'coupling'"),
            std::string::npos);
  EXPECT_NE(error_of("[[axis]]\nname = \"seed\"\nvalues = [1]\n")
                .find("one of [simulate], [[recording]], [[step]] or [alignment_mc]"),
            std::string::npos);
  EXPECT_NE(error_of("[simulate\n").find("c.toml"), std::string::npos);
  // [[step]] and [alignment_mc] campaigns
  const std::string seed = "[[axis]]\nname = \"seed\"\nvalues = [1]\n";
  EXPECT_NE(error_of(seed + "[[step]]\nargs = []\n").find("key 'step[0].args' must be a non-empty array"),
            std::string::npos);
  EXPECT_NE(error_of(seed + "[[step]]\nargs = [\"x\"]\n[compute]\njson = { a = \"summary.json\" }\n")
                .find("key 'compute.json.a' must be FILE:dotted.path, got 'summary.json'"),
            std::string::npos);
  EXPECT_NE(error_of(seed + "[[step]]\nargs = [\"x\"]\n[compute]\nremove = [\"../x\"]\n").find("inside the run folder"),
            std::string::npos);
  EXPECT_NE(error_of(seed + "[[step]]\nargs = [\"x\"]\n[[file]]\nname = \"a\"\n").find("needs template"),
            std::string::npos);
  EXPECT_NE(error_of(seed + "[alignment_mc]\nfilter = \"kf\"\n").find("filter must be ekf or ukf, got 'kf'"),
            std::string::npos);
  EXPECT_NE(error_of(seed + "[alignment_mc]\nseed = \"{sed}\"\n").find("{sed} names no campaign parameter"),
            std::string::npos);
  EXPECT_NE(error_of(seed + "[alignment_mc]\n[[report]]\nkind = \"rms\"\n").find("key 'report[0].values'"),
            std::string::npos);
  // A template naming a parameter no axis defines: the template's file and the name.
  const std::string e = error_of(axis, "[signal]\nseed = {sede}\n");
  EXPECT_NE(e.find("{sede}"), std::string::npos) << e;
  EXPECT_NE(e.find("s.toml"), std::string::npos) << e;
}

// [receive] nav_bits and vector_carrier (templated like coupling) reach the job's options; [compute]
// weak_part_from_s the metrics; a carrier for a coupling other than vector, or an unknown name, is an error naming it.
TEST(CampaignToml, ReceiveBitsCarrierAndWeakPart) {
  const auto dir = ultratrack::test::scratch_dir();
  const std::string campaign = R"(
[[axis]]
name = "mode"
values = ["fll", "oracle"]
coupling = ["vector", "scalar"]
bits = ["decoded", "oracle"]
carrier = ["fll", ""]
[simulate]
scenario = "s.toml"
[receive]
coupling = "{coupling}"
nav_bits = "{bits}"
vector_carrier = "{carrier}"
[compute]
weak_part_from_s = 16.0
)";
  const auto c = ultratrack::config::read_campaign(write_campaign(dir, campaign, "[signal]\nseed = 1\n"));
  ASSERT_TRUE(c.metrics.weak_part_from_s);
  EXPECT_EQ(*c.metrics.weak_part_from_s, 16.0);
  const auto runs = expand_campaign(c.axes);
  ASSERT_EQ(runs.size(), 2u);
  const auto fll = ultratrack::config::campaign_job(c, runs[0]);
  EXPECT_EQ(fll.receive.options.coupling, ultratrack::fusion::Coupling::kVector);
  EXPECT_EQ(fll.receive.options.vector_carrier, ultratrack::fusion::VectorCarrier::kFll);
  EXPECT_EQ(fll.receive.options.receiver.nav_bits, ultratrack::receiver::NavBitSource::kDecoded);
  const auto oracle = ultratrack::config::campaign_job(c, runs[1]);
  EXPECT_EQ(oracle.receive.options.coupling, ultratrack::fusion::Coupling::kScalar);
  EXPECT_EQ(oracle.receive.options.receiver.nav_bits, ultratrack::receiver::NavBitSource::kOracle);

  const auto job_error = [&](const std::string& receive) {
    const auto d = ultratrack::test::scratch_dir();
    const auto file =
        write_campaign(d, "[[axis]]\nname = \"seed\"\nvalues = [1]\n[simulate]\nscenario = \"s.toml\"\n" + receive,
                       "[signal]\nseed = {seed}\n");
    try {
      const auto cc = ultratrack::config::read_campaign(file);
      (void)ultratrack::config::campaign_job(cc, expand_campaign(cc.axes).front());
    } catch (const ultratrack::io::InputError& e) {
      return std::string(e.what());
    }
    return std::string("no InputError");
  };
  EXPECT_NE(job_error("[receive]\nvector_carrier = \"fll\"\n").find("needs the vector coupling"), std::string::npos);
  EXPECT_NE(job_error("[receive]\ncoupling = \"vector\"\nvector_carrier = \"dll\"\n").find("got 'dll'"),
            std::string::npos);
  EXPECT_NE(job_error("[receive]\nnav_bits = \"psychic\"\n").find("nav_bits"), std::string::npos);
  EXPECT_NE(error_of("[[axis]]\nname = \"seed\"\nvalues = [1]\n[simulate]\nscenario = \"s.toml\"\n"
                     "[compute]\nweak_part_from_s = -1.0\n")
                .find("weak_part_from_s"),
            std::string::npos);
}

// Every campaign the repository ships (campaigns/*.toml with a [campaign] table; the others are their templates)
// reads, expands and builds the job of its first and last run: a campaign file broken by a renamed key or template
// parameter fails here, not in a user's hour-long run.
TEST(CampaignToml, EveryShippedCampaignReadsAndBuildsItsJobs) {
  const std::filesystem::path dir = ultratrack::test::scenarios_dir().parent_path() / "campaigns";
  int campaigns = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".toml") continue;
    if (ultratrack::test::read_text_file(entry.path()).find("\n[campaign]") == std::string::npos) continue;
    SCOPED_TRACE(entry.path().string());
    const auto c = ultratrack::config::read_campaign(entry.path());
    const auto runs = expand_campaign(c.axes);
    ASSERT_FALSE(runs.empty());
    if (c.steps.empty()) {  // [[step]] campaigns build their files and arguments when they run
      (void)ultratrack::config::campaign_job(c, runs.front());
      (void)ultratrack::config::campaign_job(c, runs.back());
    }
    ++campaigns;
  }
  EXPECT_GE(campaigns, 11);
}

}  // namespace
