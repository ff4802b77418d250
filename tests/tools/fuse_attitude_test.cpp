// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack fuse --attitude` end to end, in process: a parked vehicle with a MEMS IMU (imusim truth), 1 Hz GNSS
// fixes (gnsssim) and a GPS attitude file written here from the simulator's truth + Gaussian noise, in GPS time,
// with the antenna array mounted 3 deg off the IMU axes, 20 % of the rows unfixed and a 10 s gap. With
// --align attitude and the mounting configured the heading converges to the GPS attitude level; without GPS
// attitude it does not; a wrong mounting shows as its 3 deg. Counts in summary.json; bad attitude files are one
// InputError with file and line.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "ins/attitude.hpp"
#include "ins/truth_interpolator.hpp"
#include "io/input_error.hpp"
#include "io/units.hpp"
#include "pipelines/gnss_fix_simulation.hpp"
#include "pipelines/gps_attitude_csv.hpp"
#include "run_command.hpp"
#include "signals/gps_time.hpp"
#include "sim/truth_csv.hpp"
#include "support/test_data.hpp"

namespace fs = std::filesystem;
using ultratrack::io::InputError;

namespace {

const ultratrack::signals::GpsTime kOrigin{2190, 604790.0};  // IMU t = 0; the week rolls over 10 s in

void run(const std::vector<std::string>& args) { ultratrack::test_support::run_program(args); }

std::string read_text(const fs::path& f) {
  std::ifstream in(f);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

double json_number(const fs::path& file, const std::string& key, const std::string& section = "") {
  std::string text = read_text(file);
  if (!section.empty()) text = text.substr(std::min(text.size(), text.find("\"" + section + "\": {")));
  std::smatch m;
  if (!std::regex_search(text, m, std::regex("\"" + key + "\": ([-+0-9.eE]+)"))) {
    ADD_FAILURE() << key << " missing in " << file;
    return 1e300;
  }
  return std::stod(m[1]);
}

void write_text(const fs::path& f, const std::string& s) { std::ofstream(f) << s; }

struct AttitudeFile {
  int rows = 0, unfixed = 0;
};

// attitude.csv at t = 0.61 + k (GPS time kOrigin + t): the array frame (mounting `m` off the IMU) from the truth,
// Euler noise of sigma (0.1, 0.1, 0.2) deg; unfixed (nan) rows: 20 % at random and all of [60, 70) s.
AttitudeFile write_attitude(const fs::path& truth_csv, const fs::path& out, const Eigen::Quaterniond& q_ba) {
  const auto nav = ultratrack::sim::read_truth_csv(truth_csv);
  const ultratrack::ins::TruthInterpolator truth(ultratrack::pipelines::truth_samples_from_nav(nav));
  std::mt19937_64 rng(77);
  std::normal_distribution<double> n01;
  std::uniform_real_distribution<double> u01;
  const Eigen::Vector3d sigma_deg(0.1, 0.1, 0.2);
  std::string text =
      "gps_week,tow_s,roll_deg,pitch_deg,yaw_deg,sigma_roll_deg,sigma_pitch_deg,sigma_yaw_deg,num_sats,"
      "fixed,ratio\n";
  AttitudeFile f;
  for (double t = 0.61; t < truth.end_s(); t += 1.0) {
    const auto g = ultratrack::signals::add_seconds(kOrigin, t);
    char line[256];
    const bool unfixed = u01(rng) < 0.2 || (t >= 60.0 && t < 70.0);
    if (unfixed) {
      std::snprintf(line, sizeof line, "%d,%.4f,nan,nan,nan,nan,nan,nan,6,0,1.200\n", g.week, g.tow_s);
      ++f.unfixed;
    } else {
      const auto e = ultratrack::ins::euler_from_quaternion(truth.attitude(t) * q_ba);
      std::snprintf(line, sizeof line, "%d,%.4f,%.5f,%.5f,%.5f,%.5f,%.5f,%.5f,7,1,8.500\n", g.week, g.tow_s,
                    e.roll_rad / ultratrack::io::kRadPerDeg + sigma_deg.x() * n01(rng),
                    e.pitch_rad / ultratrack::io::kRadPerDeg + sigma_deg.y() * n01(rng),
                    e.yaw_rad / ultratrack::io::kRadPerDeg + sigma_deg.z() * n01(rng), sigma_deg.x(), sigma_deg.y(),
                    sigma_deg.z());
    }
    text += line;
    ++f.rows;
  }
  write_text(out, text);
  return f;
}

class FuseAttitude : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(ultratrack::test::scratch_dir());
    run({"imusim", "--profile", "static", "--duration", "150", "--rate", "100", "--preset", "mems", "--seed", "11",
         "--out", (*dir_ / "sim").string()});
    run({"gnsssim", "--truth", (*dir_ / "sim/truth.csv").string(), "--rate", "1", "--first", "0.37", "--seed", "5",
         "--out", (*dir_ / "gnss.csv").string()});
    mounting_ = ultratrack::ins::quaternion_from_euler(
        {0.5 * ultratrack::io::kRadPerDeg, -0.3 * ultratrack::io::kRadPerDeg, 3.0 * ultratrack::io::kRadPerDeg});
    file_ = write_attitude(*dir_ / "sim/truth.csv", *dir_ / "attitude.csv", mounting_);
    write_text(*dir_ / "mounted.toml",
               "[imu]\npreset = \"mems\"\n[attitude]\ngps_time_at_imu_zero = [2190, 604790.0]\n"
               "misalignment_deg = [0.5, -0.3, 3.0]\n");
  }
  static void TearDownTestSuite() { delete dir_; }

  static std::vector<std::string> fuse_args(const std::string& out) {
    return {"fuse",
            "--imu",
            (*dir_ / "sim/imu.csv").string(),
            "--gnss",
            (*dir_ / "gnss.csv").string(),
            "--truth",
            (*dir_ / "sim/truth.csv").string(),
            "--quiet",
            "--out",
            (*dir_ / out).string()};
  }
  static std::vector<std::string> with(std::vector<std::string> a, const std::vector<std::string>& more) {
    a.insert(a.end(), more.begin(), more.end());
    return a;
  }

  static fs::path* dir_;
  static Eigen::Quaterniond mounting_;
  static AttitudeFile file_;
};
fs::path* FuseAttitude::dir_ = nullptr;
Eigen::Quaterniond FuseAttitude::mounting_;
AttitudeFile FuseAttitude::file_;

TEST_F(FuseAttitude, HeadingConvergesWithGpsAttitudeOnlyAndCountsAddUp) {
  const fs::path d = *dir_;
  run(with(fuse_args("with"), {"--attitude", (d / "attitude.csv").string(), "--align", "attitude", "--config",
                               (d / "mounted.toml").string()}));
  // Without GPS attitude: the configured attitude with the truth's tilt and a 5 deg heading error (1-sigma 5 deg).
  write_text(d / "config.toml",
             "[imu]\npreset = \"mems\"\n[initial]\nattitude_deg = [0.0, 0.0, 5.0]\n"
             "sigma_attitude_deg = [1.0, 1.0, 5.0]\n");
  run(with(fuse_args("without"), {"--align", "config", "--config", (d / "config.toml").string()}));
  // The mounting left out: GPS attitude of the array taken for the IMU's.
  run(with(fuse_args("unmounted"), {"--attitude", (d / "attitude.csv").string(), "--align", "attitude",
                                    "--attitude-origin", "2190", "604790", "--config", (d / "config.toml").string()}));
  const fs::path sw = d / "with/summary.json", so = d / "without/summary.json", su = d / "unmounted/summary.json";
  const double h_with = json_number(sw, "heading_deg", "rms_all");
  const double h_without = json_number(so, "heading_deg", "rms_all");
  const double h_unmounted = json_number(su, "heading_deg", "rms_all");
  const double sigma_with = json_number(sw, "heading_deg", "final_sigma");
  const double sigma_without = json_number(so, "heading_deg", "final_sigma");
  std::printf(
      "fuse, parked MEMS 150 s: heading RMS with GPS attitude %.4f deg (final 1-sigma %.4f), without %.2f deg "
      "(1-sigma %.2f), mounting not configured %.3f deg\n",
      h_with, sigma_with, h_without, sigma_without, h_unmounted);
  // GPS yaw sigma 0.2 deg, one attitude a second averaged by the filter: the heading RMS below it.
  EXPECT_LT(h_with, 0.2);
  EXPECT_LE(sigma_with, 0.2);
  EXPECT_GT(h_without, 2.0);
  EXPECT_GT(sigma_without, 3.0);
  EXPECT_NEAR(h_unmounted, 3.0, 0.3);  // the 3 deg yaw mounting shows in full
  // Counts: every row accounted for; unfixed rows are the fallback.
  EXPECT_EQ(json_number(sw, "rows", "attitude"), file_.rows);
  EXPECT_EQ(json_number(sw, "unfixed_skipped", "attitude"), file_.unfixed);
  const double fixed = json_number(sw, "fixed_rows", "attitude");
  EXPECT_EQ(fixed, file_.rows - file_.unfixed);
  EXPECT_EQ(json_number(sw, "before_start", "attitude") + json_number(sw, "used", "attitude") +
                json_number(sw, "after_end", "attitude") + json_number(sw, "in_outage", "attitude"),
            fixed);
  EXPECT_EQ(json_number(sw, "before_start", "attitude"), 1.0);  // the alignment's row
  EXPECT_EQ(json_number(sw, "updates", "attitude"), json_number(sw, "used", "attitude"));
  EXPECT_EQ(json_number(sw, "updates_accepted", "attitude") + json_number(sw, "updates_rejected", "attitude"),
            json_number(sw, "used", "attitude"));
  EXPECT_LE(json_number(sw, "updates_rejected", "attitude"), 1.0);
  EXPECT_GE(json_number(sw, "fallback_fixes", "attitude"), 10.0);  // at least the 10 s gap
  // nav.csv keeps its columns.
  std::string h1, h2;
  std::ifstream(d / "with/nav.csv") >> h1;
  std::ifstream(d / "without/nav.csv") >> h2;
  EXPECT_EQ(h1, h2);
  EXPECT_EQ(read_text(so).find("\"attitude\": {"), std::string::npos);
}

// A clear InputError naming the file and line for each kind of bad attitude file; none without an origin.
TEST_F(FuseAttitude, BadAttitudeInputIsOneInputError) {
  const fs::path d = *dir_;
  const std::string header =
      "gps_week,tow_s,roll_deg,pitch_deg,yaw_deg,sigma_roll_deg,sigma_pitch_deg,sigma_yaw_deg,num_sats,fixed,ratio\n";
  const std::string good = "2190,604791.0,0.1,0.2,30.0,0.1,0.1,0.2,7,1,5.0\n";
  struct Case {
    std::string body, expect;
    int line;
  };
  const std::vector<Case> cases = {
      {good + "2190,604792.0,0.1,x,30.0,0.1,0.1,0.2,7,1,5.0\n", "pitch_deg is not a number", 3},
      {good + "2190,604792.0,0.1,nan,30.0,0.1,0.1,0.2,7,1,5.0\n", "pitch_deg is not finite", 3},
      {good + "2190,604790.5,0.1,0.2,30.0,0.1,0.1,0.2,7,1,5.0\n", "not after the previous row", 3},
      {good + "2190,604792.0,0.1,0.2,30.0,0.1,0.1,0.2,7,2,5.0\n", "fixed must be 0 or 1", 3},
      {good + "2190,604792.0,0.1,0.2,30.0,0.1,0.1,0.0,7,1,5.0\n", "sigma_yaw_deg must be positive", 3},
      {good + "2190,604792.0,0.1,0.2,30.0,0.1,0.1,0.2,7,1\n", "expected 11 fields", 3},
      {good + "2190,604792.0,0.1,95.0,30.0,0.1,0.1,0.2,7,1,5.0\n", "angle out of range", 3},
  };
  for (const auto& c : cases) {
    const fs::path f = d / "bad_attitude.csv";
    write_text(f, header + c.body);
    try {
      ultratrack::pipelines::read_attitude_csv(f);
      ADD_FAILURE() << "no error for: " << c.body;
    } catch (const InputError& e) {
      EXPECT_EQ(e.line(), c.line) << e.what();
      EXPECT_NE(std::string(e.what()).find(f.string()), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(c.expect), std::string::npos) << e.what();
    }
  }
  write_text(d / "bad_header.csv", "gps_week,tow_s,roll_deg\n" + good);
  EXPECT_THROW(ultratrack::pipelines::read_attitude_csv(d / "bad_header.csv"), InputError);
  // Unfixed rows may be nan; a file of them alone reads.
  write_text(d / "unfixed.csv", header + "2190,604791.0,nan,nan,nan,nan,nan,nan,4,0,0.0\n");
  EXPECT_EQ(ultratrack::pipelines::read_attitude_csv(d / "unfixed.csv").size(), 1u);
  // Through the command: no origin -> InputError; an origin that puts the file outside the IMU data -> InputError.
  try {
    run(with(fuse_args("no_origin"), {"--attitude", (d / "attitude.csv").string()}));
    ADD_FAILURE() << "no error without an origin";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("gps_time_at_imu_zero"), std::string::npos) << e.what();
  }
  try {
    run(with(fuse_args("far"), {"--attitude", (d / "attitude.csv").string(), "--attitude-origin", "2100", "0"}));
    ADD_FAILURE() << "no error for attitudes outside the IMU data";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("do not overlap"), std::string::npos) << e.what();
  }
  EXPECT_THROW(run(with(fuse_args("no_file"), {"--align", "attitude"})), InputError);
}

}  // namespace
