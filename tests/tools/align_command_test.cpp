// SPDX-License-Identifier: GPL-3.0-or-later
// `ultratrack align` end to end, in process, on simulated inputs with known truth (pipelines/alignment_monte_carlo's
// IMU at rest with HG1700AE errors, GPS attitude = the array's truth + white Euler noise, written as attitude.csv in
// GPS time): the attitude inside its 1-sigma, the files, the array's mounting ([KimAlign] Table 3) estimated within
// 3 sigma, the IMU on a free-running local clock mapped through a PPS record ([OhAttINS]), `fuse --align file:` (the
// attitude and the bias estimates), and
// bad input (no fixed rows, no overlap, NaN, PPS gaps and bad rows) as one InputError naming the file.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <regex>
#include <sstream>
#include <string>

#include "ins/earth_model.hpp"
#include "ins/imu_csv.hpp"
#include "io/input_error.hpp"
#include "io/units.hpp"
#include "pipelines/alignment_monte_carlo.hpp"
#include "pipelines/alignment_run.hpp"
#include "pipelines/fused_nav_csv.hpp"
#include "pipelines/pps_time_sync.hpp"
#include "receive_fusion_options.hpp"
#include "run_command.hpp"
#include "support/test_data.hpp"

namespace fs = std::filesystem;
using ultratrack::io::InputError;
using ultratrack::test_support::run_command;
namespace pl = ultratrack::pipelines;
namespace ins = ultratrack::ins;

namespace {

constexpr double kDeg = ultratrack::io::kRadPerDeg;
const ultratrack::signals::GpsTime kOrigin{2190, 518400.0};  // GPS time of IMU t = 0

std::string read_text(const fs::path& f) {
  std::ifstream in(f);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

double json_number(const std::string& text, const std::string& key, std::size_t from = 0) {
  std::smatch m;
  const std::string sub = text.substr(from);
  if (!std::regex_search(sub, m, std::regex("\"" + key + "\": ([-+0-9.eE]+)"))) {
    ADD_FAILURE() << key << " missing";
    return 1e300;
  }
  return std::stod(m[1]);
}

pl::StationaryScenario scenario(const Eigen::Vector3d& mounting_deg) {
  pl::StationaryScenario sc;
  sc.attitude = {2.0 * kDeg, -3.0 * kDeg, 35.0 * kDeg};
  sc.lat_rad = 36.37 * kDeg;
  sc.height_m = 80.0;
  sc.duration_s = 102.0;
  sc.attitude_offset_s = 0.3;
  sc.gps_sigma_euler_rad = Eigen::Vector3d(0.3, 0.3, 0.1) * kDeg;
  sc.q_ba = ins::quaternion_from_euler({mounting_deg.x() * kDeg, mounting_deg.y() * kDeg, mounting_deg.z() * kDeg});
  sc.imu = ins::imu_preset("hg1700ae");
  return sc;
}

// attitude.csv of the inputs (every row fixed unless all_unfixed), GPS time = kOrigin + t.
void write_attitude(const fs::path& file, const pl::StationaryInputs& in, bool all_unfixed = false) {
  std::string t =
      "gps_week,tow_s,roll_deg,pitch_deg,yaw_deg,sigma_roll_deg,sigma_pitch_deg,sigma_yaw_deg,num_sats,"
      "fixed,ratio\n";
  for (const auto& a : in.gps) {
    char line[400];
    if (all_unfixed)
      std::snprintf(line, sizeof line, "%d,%.3f,nan,nan,nan,nan,nan,nan,9,0,1.2\n", kOrigin.week,
                    kOrigin.tow_s + a.t_s);
    else
      std::snprintf(line, sizeof line, "%d,%.3f,%.6f,%.6f,%.6f,%.4f,%.4f,%.4f,9,1,8.5\n", kOrigin.week,
                    kOrigin.tow_s + a.t_s, a.euler_a.roll_rad / kDeg, a.euler_a.pitch_rad / kDeg,
                    a.euler_a.yaw_rad / kDeg, a.sigma_euler_rad.x() / kDeg, a.sigma_euler_rad.y() / kDeg,
                    a.sigma_euler_rad.z() / kDeg);
    t += line;
  }
  std::ofstream(file) << t;
}

struct Case {
  fs::path dir, imu, attitude;
  pl::StationaryInputs inputs;
};

Case make_case(const std::string& name, const pl::StationaryScenario& sc, std::uint64_t seed) {
  Case c;
  c.dir = ultratrack::test::scratch_dir() / name;
  fs::create_directories(c.dir);
  c.inputs = pl::simulate_stationary_inputs(sc, seed);
  c.imu = c.dir / "imu.csv";
  c.attitude = c.dir / "attitude.csv";
  ins::write_imu_csv(c.imu, c.inputs.imu);
  write_attitude(c.attitude, c.inputs);
  return c;
}

Case make_case(const std::string& name, const Eigen::Vector3d& mounting_deg, std::uint64_t seed) {
  return make_case(name, scenario(mounting_deg), seed);
}

std::vector<std::string> base_args(const Case& c, const std::string& out) {
  return {"--imu",
          c.imu.string(),
          "--attitude",
          c.attitude.string(),
          "--attitude-origin",
          "2190",
          "518400",
          "--position",
          "36.37",
          "127.36",
          "80",
          "--out",
          (c.dir / out).string()};
}

TEST(AlignCommand, AlignsInsideSigmaAndWritesItsFiles) {
  const Case c = make_case("plain", Eigen::Vector3d::Zero(), 3);
  run_command("align", base_args(c, "out"));
  const std::string j = read_text(c.dir / "out" / "alignment.json");
  const pl::StationaryScenario sc = scenario(Eigen::Vector3d::Zero());
  const double truth[3] = {sc.attitude.roll_rad / kDeg, sc.attitude.pitch_rad / kDeg, sc.attitude.yaw_rad / kDeg};
  const char* keys[3] = {"roll", "pitch", "yaw"};
  for (int i = 0; i < 3; ++i) {
    const double est = json_number(j, std::string(keys[i]) + "_deg");
    const double sigma = json_number(j, "sigma_" + std::string(keys[i]) + "_deg");
    EXPECT_LT(std::abs(est - truth[i]), 4.0 * sigma) << keys[i];
    EXPECT_LT(sigma, 0.05) << keys[i];
  }
  EXPECT_EQ(json_number(j, "observability_rank"), 12);
  EXPECT_NEAR(json_number(j, "duration_s"), 100.0, 0.02);
  EXPECT_NE(j.find("\"warnings\": []"), std::string::npos) << j;
  // One history row per filter epoch (1 Hz over 100 s) after the header.
  const std::string csv = read_text(c.dir / "out" / "alignment.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 101);
  EXPECT_FALSE(fs::exists(c.dir / "out" / "alignment.json.partial"));
  // The file starts a `config` alignment of fuse / receive.
  const pl::AlignmentFileStart f = pl::read_alignment_json(c.dir / "out" / "alignment.json");
  EXPECT_NEAR(f.attitude_deg.z(), json_number(j, "yaw_deg"), 1e-9);
  EXPECT_NEAR(f.sigma_attitude_deg.x(), json_number(j, "sigma_roll_deg"), 1e-9);
  // `fuse --align file:` starts from it: the alignment's attitude at the first fix.
  std::string gnss = "t_s,lat_deg,lon_deg,height_m,vel_n_mps,vel_e_mps,vel_d_mps,sigma_n_m,sigma_e_m,sigma_d_m\n";
  for (int k = 1; k <= 100; ++k) gnss += std::to_string(k + 0.5) + ",36.37,127.36,80,0,0,0,1,1,2\n";
  std::ofstream(c.dir / "gnss.csv") << gnss;
  run_command("fuse", {"--imu", c.imu.string(), "--gnss", (c.dir / "gnss.csv").string(), "--align",
                       "file:" + (c.dir / "out" / "alignment.json").string(), "--out", (c.dir / "fuse").string()});
  const std::string fj = read_text(c.dir / "fuse" / "summary.json");
  const std::size_t at = fj.find("\"alignment\": {");
  ASSERT_NE(at, std::string::npos);
  EXPECT_NEAR(json_number(fj, "yaw_deg", at), json_number(j, "yaw_deg"), 1e-5);
  EXPECT_NEAR(json_number(fj, "roll_deg", at), json_number(j, "roll_deg"), 1e-5);
  // `receive --imu --coupling loose --align file:` reads it into the configured start.
  ultratrack::tools::ReceiveFusionArgs ra;
  ra.coupling = "loose";
  ra.imu = c.imu.string();
  ra.align = "file:" + (c.dir / "out" / "alignment.json").string();
  ultratrack::pipelines::ReceiveOptions ro;
  ultratrack::tools::apply_receive_coupling_args(ra, ro);
  EXPECT_EQ(ro.align, pl::AlignMode::Config);
  ASSERT_TRUE(ro.navigation.attitude_deg.has_value());
  EXPECT_NEAR(ro.navigation.attitude_deg->z(), json_number(j, "yaw_deg"), 1e-9);
  ra.align = "file:" + (c.dir / "missing.json").string();
  EXPECT_THROW(ultratrack::tools::apply_receive_coupling_args(ra, ro), InputError);
  // The UKF agrees.
  std::vector<std::string> ukf = base_args(c, "ukf");
  ukf.insert(ukf.end(), {"--filter", "ukf"});
  run_command("align", ukf);
  const std::string ju = read_text(c.dir / "ukf" / "alignment.json");
  EXPECT_NEAR(json_number(ju, "yaw_deg"), json_number(j, "yaw_deg"), 0.1 * json_number(j, "sigma_yaw_deg"));
}

TEST(AlignCommand, EstimatesTheArrayMountingWithinThreeSigma) {
  // Seed 000 Table 3: the array mounted 1-2 deg off the IMU on every axis, the configuration unaware of it.
  const Eigen::Vector3d mounting(1.5, -1.2, 2.0);
  for (std::uint64_t seed : {11u, 12u}) {
    const Case c = make_case("mounting" + std::to_string(seed), mounting, seed);
    run_command("align", base_args(c, "out"));
    const std::string j = read_text(c.dir / "out" / "alignment.json");
    const std::size_t m = j.find("\"mounting\": {");
    ASSERT_NE(m, std::string::npos);
    const char* keys[3] = {"roll", "pitch", "yaw"};
    for (int i = 0; i < 3; ++i) {
      const double est = json_number(j, std::string(keys[i]) + "_deg", m);
      const double sigma = json_number(j, "sigma_" + std::string(keys[i]) + "_deg", m);
      EXPECT_LT(std::abs(est - mounting(i)), 3.0 * sigma) << keys[i] << " seed " << seed;
      EXPECT_GT(sigma, 0.0);
    }
    // Levelling sees the tilt to the accelerometer bias (1 mg ~ 0.06 deg), gyrocompassing the heading to 1 deg/h
    // over the earth rate's horizontal part (~6 deg at 36 deg N); tilted 2-3 deg, the body's heading uncertainty
    // leaks into the array's roll and pitch by sin(tilt): 6 deg x 0.05 = 0.3 deg.
    EXPECT_LT(json_number(j, "sigma_pitch_deg", m), 0.6);
    EXPECT_LT(json_number(j, "sigma_roll_deg", m), 0.6);
    EXPECT_GT(json_number(j, "sigma_yaw_deg", m), 3.0);
    EXPECT_NE(j.find("misalignment_deg"), std::string::npos) << "the unknown mounting is flagged" << j;
  }
  // Against a reference attitude of the body ([KimAlign]'s MAPS INS, here the truth to 0.005 deg), every axis of the
  // mounting to a few hundredths of a degree: the mean of 100 GPS attitudes.
  {
    const Case c = make_case("mounting_reference", mounting, 14);
    std::vector<std::string> args = base_args(c, "out");
    args.insert(args.end(), {"--reference-attitude", "2", "-3", "35", "0.005", "0.005", "0.005"});
    run_command("align", args);
    const std::string j = read_text(c.dir / "out" / "alignment.json");
    const std::size_t m = j.find("\"mounting\": {");
    const char* keys[3] = {"roll", "pitch", "yaw"};
    for (int i = 0; i < 3; ++i) {
      const double sigma = json_number(j, "sigma_" + std::string(keys[i]) + "_deg", m);
      EXPECT_LT(std::abs(json_number(j, std::string(keys[i]) + "_deg", m) - mounting(i)), 3.0 * sigma) << keys[i];
      EXPECT_LT(sigma, 0.04) << keys[i];  // 0.3 deg / sqrt(100) per tilt axis, 0.1 / 10 in yaw, + the reference
    }
  }
  // Configured, the alignment is the body's again.
  const Case c = make_case("mounting_known", mounting, 13);
  const fs::path cfg = c.dir / "c.toml";
  std::ofstream(cfg) << "[attitude]\nmisalignment_deg = [1.5, -1.2, 2.0]\n";
  std::vector<std::string> args = base_args(c, "out");
  args.insert(args.end(), {"--config", cfg.string()});
  run_command("align", args);
  const std::string j = read_text(c.dir / "out" / "alignment.json");
  EXPECT_LT(std::abs(json_number(j, "yaw_deg") - 35.0), 4.0 * json_number(j, "sigma_yaw_deg"));
  EXPECT_LT(std::abs(json_number(j, "pitch_deg") + 3.0), 4.0 * json_number(j, "sigma_pitch_deg"));
  EXPECT_NE(j.find("\"warnings\": []"), std::string::npos);
}

TEST(AlignCommand, WarnsNearPitch90) {
  // At 70 deg of pitch the GPS attitude still serves (the filter's limit is 80 deg) but roll and yaw are turning
  // about one axis: the result says so ([KimAlign] theorem 1: the rank drops at 90 deg).
  pl::StationaryScenario sc = scenario(Eigen::Vector3d::Zero());
  sc.attitude = {10.0 * kDeg, 70.0 * kDeg, -60.0 * kDeg};
  sc.duration_s = 20.0;
  const Case c = make_case("steep", sc, 8);
  std::vector<std::string> args = base_args(c, "out");
  args.insert(args.end(), {"--duration", "15"});
  run_command("align", args);
  const std::string j = read_text(c.dir / "out" / "alignment.json");
  EXPECT_NE(j.find("pitch 70.0 deg: near 90 deg"), std::string::npos) << j;
  EXPECT_LT(std::abs(json_number(j, "pitch_deg") - 70.0), 4.0 * json_number(j, "sigma_pitch_deg"));
}

void expect_input_error(const std::vector<std::string>& args, const std::string& file, const std::string& text) {
  try {
    run_command("align", args);
    ADD_FAILURE() << "no error; expected " << text;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
  }
}

TEST(AlignCommand, BadInputIsOneClearError) {
  const Case c = make_case("bad", Eigen::Vector3d::Zero(), 5);
  const fs::path unfixed = c.dir / "unfixed.csv";
  write_attitude(unfixed, c.inputs, true);
  std::vector<std::string> args = base_args(c, "o1");
  args[3] = unfixed.string();
  expect_input_error(args, unfixed.string(), "no fixed attitude rows");
  args = base_args(c, "o2");
  args[6] = "517000";  // attitude 1400 s after the IMU
  expect_input_error(args, c.attitude.string(), "do not overlap");
  const fs::path nan_imu = c.dir / "nan_imu.csv";
  std::string text = read_text(c.imu);
  const std::size_t p = text.find('\n', text.find('\n') + 1);
  text.insert(p + 1, "0.0105,nan,0,0,0,0,0\n");
  std::ofstream(nan_imu) << text;
  args = base_args(c, "o3");
  args[1] = nan_imu.string();
  expect_input_error(args, nan_imu.string(), "");
  args = base_args(c, "o4");
  args.erase(args.begin() + 7, args.begin() + 11);  // no --position
  expect_input_error(args, "", "position");
  EXPECT_FALSE(fs::exists(c.dir / "o1" / "alignment.json"));
}

// PPS edges of a local clock running 50 ppm fast with an offset: local = 1000.25 + (gps - origin) (1 + 50e-6) + jitter.
double local_of(double gps_since_origin) { return 1000.25 + gps_since_origin * (1.0 + 50e-6); }

TEST(PpsTimeSync, MapsA50ppmClockWithin10usDespiteAMissingAndAWildPulse) {
  std::mt19937_64 rng(9);
  std::normal_distribution<double> jitter(0.0, 1e-6);
  std::vector<pl::PpsEdge> edges;
  for (int k = 0; k <= 120; ++k) {
    if (k == 40) continue;  // a missing pulse
    double local = local_of(k) + jitter(rng);
    if (k == 70) local += 3e-3;  // one pulse 3 ms off
    edges.push_back({k + 2, local, {kOrigin.week, kOrigin.tow_s + k}});
  }
  const pl::PpsClockFit fit = pl::fit_pps_clock(edges, "pps.csv");
  EXPECT_EQ(fit.rejected, 1);
  EXPECT_NEAR(fit.drift, 1.0 / (1.0 + 50e-6) - 1.0, 1e-7);
  for (double t = 0.0; t <= 120.0; t += 0.37) {
    ins::ImuIncrement r{local_of(t), {}, {}};
    const auto mapped = pl::imu_on_gps_time(std::span(&r, 1), fit, kOrigin, "imu.csv");
    EXPECT_NEAR(mapped[0].t_s, t, 10e-6) << t;
  }
}

TEST(PpsTimeSync, GapsAndBadRowsAreClearErrors) {
  const fs::path dir = ultratrack::test::scratch_dir();
  std::vector<pl::PpsEdge> gap;
  for (int k : {0, 1, 2, 3, 12, 13, 14}) gap.push_back({k + 2, local_of(k), {kOrigin.week, kOrigin.tow_s + k}});
  try {
    pl::fit_pps_clock(gap, "pps.csv");
    ADD_FAILURE() << "a 9 s gap passed";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("gap of 9.0 s"), std::string::npos) << e.what();
  }
  auto bad = [&](const std::string& body, const std::string& text) {
    const fs::path f = dir / "pps.csv";
    std::ofstream(f) << "local_s,gps_week,gps_tow_s\n" << body;
    try {
      pl::read_pps_csv(f);
      ADD_FAILURE() << "accepted: " << body;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(f.string()), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
    }
  };
  bad("1000.1,2190,518400\n1001.1,2190,518400.5\n", "whole second");
  bad("1000.1,2190,518400\n999.1,2190,518401\n", "local_s must increase");
  bad("1000.1,2190,518400\n1001.1,2190,x\n", "not a number");
  bad("1000.1,2190,518400\n1001.1,2190,518399\n", "GPS time must increase");
}

TEST(AlignCommand, ImuOnALocalClockThroughPps) {
  Case c = make_case("pps", Eigen::Vector3d::Zero(), 21);
  run_command("align", base_args(c, "gps"));
  // The same IMU stamped by the local clock, and its PPS record (one pulse missing, 1 us jitter).
  std::vector<ins::ImuIncrement> local = c.inputs.imu;
  for (auto& r : local) r.t_s = local_of(r.t_s);
  const fs::path local_imu = c.dir / "imu_local.csv", pps = c.dir / "pps.csv";
  ins::write_imu_csv(local_imu, local);
  std::mt19937_64 rng(4);
  std::normal_distribution<double> jitter(0.0, 1e-6);
  std::string t = "local_s,gps_week,gps_tow_s\n";
  for (int k = 0; k <= 103; ++k) {
    if (k == 50) continue;
    char line[100];
    std::snprintf(line, sizeof line, "%.7f,%d,%.0f\n", local_of(k) + jitter(rng), kOrigin.week, kOrigin.tow_s + k);
    t += line;
  }
  std::ofstream(pps) << t;
  std::vector<std::string> args = base_args(c, "pps");
  args[1] = local_imu.string();
  args.insert(args.end(), {"--imu-pps", pps.string()});
  run_command("align", args);
  const std::string a = read_text(c.dir / "gps" / "alignment.json"), b = read_text(c.dir / "pps" / "alignment.json");
  EXPECT_NEAR(json_number(b, "yaw_deg"), json_number(a, "yaw_deg"), 0.05 * json_number(a, "sigma_yaw_deg"));
  EXPECT_NEAR(json_number(b, "roll_deg"), json_number(a, "roll_deg"), 0.05 * json_number(a, "sigma_roll_deg"));
  EXPECT_NE(b.find("103 edges used, 0 rejected"), std::string::npos) << b;
  // A gap in the PPS record is refused, naming the file.
  std::string gappy = "local_s,gps_week,gps_tow_s\n";
  for (int k : {0, 1, 2, 30, 31, 32})
    gappy += std::to_string(local_of(k)) + ",2190," + std::to_string(518400 + k) + "\n";
  std::ofstream(pps) << gappy;
  args.back() = pps.string();
  args[args.size() - 3] = (c.dir / "pps2").string();
  expect_input_error(args, pps.string(), "gap of");
}

// receive --imu --imu-pps: the local stamps on GPS time since the first PPS edge, which becomes the IMU time origin;
// --imu-time-origin beside it, or --imu-pps without a GNSS/INS coupling, is an InputError.
TEST(ReceiveImuPps, MapsTheImuAndSetsTheTimeOrigin) {
  const fs::path dir = ultratrack::test::scratch_dir() / "receive_pps";
  fs::create_directories(dir);
  std::string t = "local_s,gps_week,gps_tow_s\n";
  for (int k = 0; k <= 20; ++k) t += fmt::format("{:.7f},{},{}\n", local_of(k), kOrigin.week, kOrigin.tow_s + 3 + k);
  std::ofstream(dir / "pps.csv") << t;
  ultratrack::tools::ReceiveFusionArgs ra;
  ra.coupling = "tight";
  ra.imu = (dir / "imu.csv").string();
  ra.imu_pps = (dir / "pps.csv").string();
  ultratrack::pipelines::ReceiveOptions ro;
  ultratrack::tools::apply_receive_coupling_args(ra, ro);
  std::vector<ins::ImuIncrement> imu;
  for (int k = 1; k <= 1900; ++k) imu.push_back({local_of(0.01 * k), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()});
  ultratrack::tools::put_receive_imu_on_pps(ra, imu, ro);
  EXPECT_EQ(ro.imu_time_origin.kind, pl::ImuTimeOrigin::Kind::Tow);
  EXPECT_EQ(ro.imu_time_origin.tow_s, kOrigin.tow_s + 3);
  for (int k = 1; k <= 1900; k += 37) EXPECT_NEAR(imu[k - 1].t_s, 0.01 * k, 1e-9) << k;
  ra.time_origin = "tow";
  EXPECT_THROW(ultratrack::tools::apply_receive_coupling_args(ra, ro), InputError);
  ra.time_origin.clear();
  ra.coupling = "scalar";
  EXPECT_THROW(ultratrack::tools::apply_receive_coupling_args(ra, ro), InputError);
  // IMU rows well past the record: the IMU file is named.
  ra.coupling = "tight";
  imu.assign(1, {local_of(40.0), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()});
  try {
    ultratrack::tools::put_receive_imu_on_pps(ra, imu, ro);
    ADD_FAILURE() << "IMU beyond the PPS record accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("imu.csv"), std::string::npos) << e.what();
  }
}

// --align file: carries the bias estimates and their 1-sigma into fuse. Truth: the simulated IMU's effective biases
// over the alignment span (mean measured rate minus the closed-form stationary input: turn-on bias plus scale factor
// and misalignment times that input, plus the bias instability). Then one minute of pure inertial navigation (a
// single GNSS fix starts it): the alignment's attitude absorbed the accelerometer bias it estimated (the zero
// velocity updates fix tilt x g + bias together), so starting from that attitude with zero biases leaves an
// uncompensated specific force and the position drifts; with the file's biases it nearly does not.
TEST(AlignCommand, AlignmentBiasesStartFuseWithinThreeSigma) {
  pl::StationaryScenario sc = scenario(Eigen::Vector3d::Zero());
  sc.duration_s = 172.0;
  const Case c = make_case("bias", sc, 9);
  run_command("align", base_args(c, "out"));
  const fs::path with_file = c.dir / "out" / "alignment.json";
  const pl::AlignmentFileStart f = pl::read_alignment_json(with_file);
  ASSERT_TRUE(f.biases.has_value());
  const std::string j = read_text(with_file);
  const double end_s = json_number(j, "t_s");
  const Eigen::Matrix3d C_bn = ins::quaternion_from_euler(sc.attitude).toRotationMatrix().transpose();
  const Eigen::Vector3d f_b = C_bn * -ins::gravity_n(sc.lat_rad, sc.height_m),
                        w_b = C_bn * ins::earth_rate_n(sc.lat_rad);
  const auto& e = c.inputs.errors;  // output = (I + M) input + bias + noise; at rest M acts as a bias too
  const Eigen::Vector3d accel = e.accel.bias + e.accel.scale_misalignment * f_b;
  const Eigen::Vector3d gyro = e.gyro.bias + e.gyro.scale_misalignment * w_b;
  for (int i = 0; i < 3; ++i) {
    EXPECT_LT(std::abs(f.biases->accel_mps2(i) - accel(i)), 3.0 * f.biases->sigma_accel_mps2(i)) << i;
    EXPECT_LT(std::abs(f.biases->gyro_rps(i) - gyro(i)), 3.0 * f.biases->sigma_gyro_rps(i)) << i;
  }
  // The same alignment without the bias keys (attitude only, as before).
  const fs::path without_file = c.dir / "attitude_only.json";
  std::ofstream(without_file) << fmt::format(
      "{{\"roll_deg\": {}, \"pitch_deg\": {}, \"yaw_deg\": {}, \"sigma_roll_deg\": {}, \"sigma_pitch_deg\": {}, "
      "\"sigma_yaw_deg\": {}}}\n",
      f.attitude_deg.x(), f.attitude_deg.y(), f.attitude_deg.z(), f.sigma_attitude_deg.x(), f.sigma_attitude_deg.y(),
      f.sigma_attitude_deg.z());
  EXPECT_FALSE(pl::read_alignment_json(without_file).biases.has_value());
  // One exact fix right after the alignment (between IMU rows), then a minute of pure inertial navigation.
  std::ofstream(c.dir / "gnss.csv")
      << "t_s,lat_deg,lon_deg,height_m,vel_n_mps,vel_e_mps,vel_d_mps,sigma_n_m,sigma_e_m,sigma_d_m\n"
      << fmt::format("{:.3f},36.37,127.36,80,0,0,0,0.1,0.1,0.1\n", end_s + 0.205);
  auto drift = [&](const fs::path& alignment, const std::string& out) {
    run_command("fuse", {"--imu", c.imu.string(), "--gnss", (c.dir / "gnss.csv").string(), "--align",
                         "file:" + alignment.string(), "--quiet", "--out", (c.dir / out).string()});
    const auto rows = pl::read_fused_nav_csv(c.dir / out / "nav.csv");
    const double t0 = rows.front().nav.t_s;
    double ss = 0.0, worst = 0.0;
    int m = 0;
    for (const auto& r : rows) {
      if (r.nav.t_s > t0 + 60.0) break;
      const double north = (r.nav.lat_rad - 36.37 * kDeg) * 6.3567e6;
      const double east = (r.nav.lon_rad - 127.36 * kDeg) * 6.3567e6 * std::cos(36.37 * kDeg);
      const double h = std::hypot(north, east);
      ss += h * h;
      worst = std::max(worst, h);
      ++m;
    }
    EXPECT_GT(rows.back().nav.t_s, t0 + 60.0);
    return std::pair(std::sqrt(ss / m), worst);
  };
  const auto [rms_with, max_with] = drift(with_file, "fuse_with");
  const auto [rms_without, max_without] = drift(without_file, "fuse_without");
  std::printf(
      "first minute of pure inertial navigation, horizontal error RMS / max: with the alignment's biases "
      "%.3f / %.3f m, without %.3f / %.3f m\n",
      rms_with, max_with, rms_without, max_without);
  EXPECT_LT(rms_with, 0.5 * rms_without);
  // fuse started from the file's biases: no update touched them in pure inertial navigation.
  const std::string fj = read_text(c.dir / "fuse_with" / "summary.json");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(fj, m, std::regex("\"gyro_dph\": \\[([-+0-9.eE]+)")));
  EXPECT_NEAR(std::stod(m[1]), f.biases->gyro_rps.x() / (kDeg / 3600.0),
              1e-3 * f.biases->sigma_gyro_rps.x() / (kDeg / 3600.0) + 1e-5);
}

}  // namespace
