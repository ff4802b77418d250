// SPDX-License-Identifier: GPL-3.0-or-later
// SIGINT and SIGTERM mid-run for every long-running command (issue 21): the real program runs as a child process on
// an input long enough that the signal lands mid-run (the test waits for a progress line or an output file, then
// kill()s it), and the test checks what docs/usage.md "Exit status" promises: exit 128 + the signal number (130,
// 143) for a command that stops and finishes its outputs, every final CSV made of whole rows, every JSON file
// valid, summary.json saying "interrupted": true where the command writes one, and no temporary (.partial) file
// left. Commands that compute in memory and write their outputs at the end (align, snapshot) end at once: nothing
// is written, or, when the signal lands during the writes, the writes complete first.
// Skipped (they finish in milliseconds on any input they accept): acquire, compare, covariance. gnsssim is covered
// (its output is one file written at the end); demo is stopped in its simulation and in its receive.
#include <fcntl.h>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "child_program.hpp"
#include "ins/imu_csv.hpp"
#include "ins/imu_error_model.hpp"
#include "io/units.hpp"
#include "pipelines/alignment_monte_carlo.hpp"
#include "signals/nominal_constellation.hpp"
#include "signals/rinex_nav.hpp"
#include "support/test_data.hpp"

namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace {

std::string read_text(const fs::path& f) { return ultratrack::test::read_text_file(f); }

using Child = ultratrack::test::ChildProgram;
using ultratrack::test::start_program;

// Waits (up to `timeout`) until `ready` holds; false if the child ended first or the time ran out.
bool wait_until(const Child& c, const std::function<bool()>& ready, std::chrono::milliseconds timeout = 30s) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < end) {
    if (ready()) return true;
    int status = 0;
    if (waitpid(c.pid, &status, WNOHANG) == c.pid) {
      ADD_FAILURE() << "the command ended before the signal:\n" << read_text(c.log);
      return false;
    }
    std::this_thread::sleep_for(5ms);
  }
  ADD_FAILURE() << "the command never got ready:\n" << read_text(c.log);
  return false;
}

bool log_has(const Child& c, const std::string& text) { return read_text(c.log).find(text) != std::string::npos; }

// Sends `sig` and waits for the end (at most 30 s, then SIGKILL and a failure); returns the wait status.
int stop(const Child& c, int sig) {
  kill(c.pid, sig);
  const auto end = std::chrono::steady_clock::now() + 30s;
  int status = 0;
  while (waitpid(c.pid, &status, WNOHANG) != c.pid) {
    if (std::chrono::steady_clock::now() > end) {
      kill(c.pid, SIGKILL);
      waitpid(c.pid, &status, 0);
      ADD_FAILURE() << "still running 30 s after the signal:\n" << read_text(c.log);
      return status;
    }
    std::this_thread::sleep_for(5ms);
  }
  return status;
}

// The command stopped, finished its outputs and exits 128 + sig.
void expect_stopped_exit(int status, int sig, const Child& c) {
  ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0) << ":\n"
                                 << read_text(c.log);
  EXPECT_EQ(WEXITSTATUS(status), 128 + sig) << read_text(c.log);
}

// A minimal JSON syntax check (RFC 8259 values; nan/inf are not JSON).
struct JsonChecker {
  const std::string& s;
  std::size_t i = 0;
  void ws() {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\n' || s[i] == '\t' || s[i] == '\r')) ++i;
  }
  bool lit(const char* w) {
    const std::string t(w);
    if (s.compare(i, t.size(), t) != 0) return false;
    i += t.size();
    return true;
  }
  bool string() {
    if (s[i] != '"') return false;
    for (++i; i < s.size(); ++i) {
      if (s[i] == '\\') {
        ++i;
        continue;
      }
      if (s[i] == '"') {
        ++i;
        return true;
      }
      if (static_cast<unsigned char>(s[i]) < 0x20) return false;
    }
    return false;
  }
  bool number() {
    const std::size_t start = i;
    if (i < s.size() && s[i] == '-') ++i;
    while (i < s.size() && (std::isdigit(static_cast<unsigned char>(s[i])) || s[i] == '.' || s[i] == 'e' ||
                            s[i] == 'E' || s[i] == '+' || s[i] == '-'))
      ++i;
    return i > start && std::isdigit(static_cast<unsigned char>(s[i - 1]));
  }
  bool value() {
    ws();
    if (i >= s.size()) return false;
    bool ok = false;
    if (s[i] == '{') {
      ++i;
      ws();
      if (i < s.size() && s[i] == '}') {
        ++i;
        return true;
      }
      for (;;) {
        ws();
        if (i >= s.size() || !string()) return false;
        ws();
        if (i >= s.size() || s[i++] != ':') return false;
        if (!value()) return false;
        ws();
        if (i < s.size() && s[i] == ',') {
          ++i;
          continue;
        }
        return i < s.size() && s[i++] == '}';
      }
    }
    if (s[i] == '[') {
      ++i;
      ws();
      if (i < s.size() && s[i] == ']') {
        ++i;
        return true;
      }
      for (;;) {
        if (!value()) return false;
        ws();
        if (i < s.size() && s[i] == ',') {
          ++i;
          continue;
        }
        return i < s.size() && s[i++] == ']';
      }
    }
    if (s[i] == '"') return string();
    ok = lit("true") || lit("false") || lit("null") || number();
    return ok;
  }
};

bool valid_json(const std::string& text) {
  JsonChecker j{text};
  if (!j.value()) return false;
  j.ws();
  return j.i == text.size();
}

// Every file under `dir`: none temporary (.partial of io::AtomicFile, .part of the sample writer); each CSV ends with a
// newline and each of its data rows has as many fields as its header (comment lines, '#', aside); each JSON file
// parses.
void expect_complete_outputs(const fs::path& dir) {
  ASSERT_TRUE(fs::is_directory(dir)) << dir;
  for (const auto& e : fs::recursive_directory_iterator(dir)) {
    if (!e.is_regular_file()) continue;
    const fs::path& p = e.path();
    EXPECT_EQ(p.filename().string().find(".part"), std::string::npos) << "temporary file left: " << p;
    if (p.extension() == ".csv") {
      const std::string t = read_text(p);
      if (t.empty()) continue;
      EXPECT_EQ(t.back(), '\n') << p << " ends inside a row";
      std::istringstream in(t);
      std::string line;
      long fields = -1;
      int n = 0;
      while (std::getline(in, line)) {
        ++n;
        if (line.empty() || line[0] == '#') continue;
        const long f = std::count(line.begin(), line.end(), ',');
        if (fields < 0) fields = f;
        EXPECT_EQ(f, fields) << p << " line " << n << ": " << line;
        if (f != fields) break;
      }
    } else if (p.extension() == ".json") {
      EXPECT_TRUE(valid_json(read_text(p))) << p << ":\n" << read_text(p);
    }
  }
}

void expect_summary_interrupted(const fs::path& summary) {
  const std::string t = read_text(summary);
  EXPECT_NE(t.find("\"interrupted\": true"), std::string::npos) << summary << ":\n" << t;
}

void run_program(const std::vector<std::string>& args) {
  std::string cmd = ULTRATRACK_PROGRAM;
  for (const auto& a : args) cmd += " '" + a + "'";
  cmd += " > /dev/null 2>&1";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
}

// The shared inputs, made once.
struct Inputs {
  fs::path dir;
  fs::path recording;             // 8 s of the nominal constellation at 2.6 MHz, i8, with imu.csv beside it
  fs::path imu_long, truth_long;  // imusim circle, 1200 s at 100 Hz
  fs::path gnss_long;             // gnsssim at 1 Hz on it
};

// Made once per build of the program, shared by every test process (ctest runs each test alone).
void make_inputs(const fs::path& dir) {
  std::ofstream(dir / "s.toml") << "[signal]\nsample_rate_hz = 2.6e6\nduration_s = 8.0\n[time]\ngps_week = 2190\n"
                                   "tow_s = 518400.0\n[navigation]\nconstellation = \"nominal\"\n"
                                   "[receiver]\nllh_deg_m = [35.274016, 137.013759, 100.0]\n"
                                   "[trajectory]\nprofile = \"static\"\nduration_s = 8.0\nimu_rate_hz = 100.0\n"
                                   "[imu]\npreset = \"hg1700ae\"\n";
  run_program({"simulate", "--quiet", "--scenario", (dir / "s.toml").string(), "--out", (dir / "sim").string()});
  run_program({"imusim", "--profile", "circle", "--duration", "1200", "--rate", "100", "--preset", "hg1700ae", "--out",
               (dir / "imu").string()});
  run_program({"gnsssim", "--truth", (dir / "imu" / "truth.csv").string(), "--rate", "1", "--out",
               (dir / "gnss.csv").string()});
  // align: 600 s at rest with GPS attitude at 10 Hz
  namespace pl = ultratrack::pipelines;
  constexpr double kDeg = ultratrack::io::kRadPerDeg;
  pl::StationaryScenario sc;
  sc.attitude = {2.0 * kDeg, -3.0 * kDeg, 35.0 * kDeg};
  sc.lat_rad = 36.37 * kDeg;
  sc.height_m = 80.0;
  sc.duration_s = 600.0;
  sc.gps_sigma_euler_rad = Eigen::Vector3d(0.3, 0.3, 0.1) * kDeg;
  sc.imu = ultratrack::ins::imu_preset("hg1700ae");
  const pl::StationaryInputs in = pl::simulate_stationary_inputs(sc, 3);
  fs::create_directories(dir / "align");
  ultratrack::ins::write_imu_csv(dir / "align" / "imu.csv", in.imu);
  std::ofstream a(dir / "align" / "attitude.csv");
  a << "gps_week,tow_s,roll_deg,pitch_deg,yaw_deg,sigma_roll_deg,sigma_pitch_deg,sigma_yaw_deg,num_sats,fixed,ratio\n";
  for (const auto& g : in.gps)
    a << fmt::format("2190,{:.3f},{:.6f},{:.6f},{:.6f},0.3,0.3,0.1,9,1,8.5\n", 518400.0 + g.t_s,
                     g.euler_a.roll_rad / kDeg, g.euler_a.pitch_rad / kDeg, g.euler_a.yaw_rad / kDeg);
}

const Inputs& inputs() {
  static const Inputs in = [] {
    Inputs r;
    r.dir = ultratrack::test::shared_inputs("interrupt_commands", make_inputs);
    r.recording = r.dir / "sim" / "antenna0.i8.bin";
    r.imu_long = r.dir / "imu" / "imu.csv";
    r.truth_long = r.dir / "imu" / "truth.csv";
    r.gnss_long = r.dir / "gnss.csv";
    return r;
  }();
  return in;
}

class Interrupt : public ::testing::TestWithParam<int> {
 protected:
  int sig() const { return GetParam(); }
  static void SetUpTestSuite() { inputs(); }
  fs::path out(const std::string& name) const {
    const fs::path d = ultratrack::test::scratch_dir() / (name + "_" + std::to_string(sig()));
    fs::remove_all(d);
    fs::create_directories(d);
    return d;
  }
};

TEST_P(Interrupt, Simulate) {
  const fs::path d = out("simulate");
  std::ofstream(d / "s.toml") << "[signal]\nsample_rate_hz = 2.6e6\nduration_s = 30.0\n[time]\ngps_week = 2190\n"
                                 "tow_s = 518400.0\n[navigation]\nconstellation = \"nominal\"\n";
  const Child c =
      start_program({"simulate", "--scenario", (d / "s.toml").string(), "--out", (d / "o").string()}, d / "log");
  if (!wait_until(c, [&] { return log_has(c, "s of signal"); })) return;
  expect_stopped_exit(stop(c, sig()), sig(), c);
  expect_complete_outputs(d / "o");
  expect_summary_interrupted(d / "o" / "summary.json");
  EXPECT_EQ(fs::file_size(d / "o" / "antenna0.i8.bin") % 2, 0u);  // whole I/Q pairs
}

TEST_P(Interrupt, ReceiveScalar) {
  const fs::path d = out("receive");
  const Child c = start_program({"receive", "--input", inputs().recording.string(), "--format", "i8", "--fs", "2.6e6",
                                 "--threads", "1", "--out", (d / "o").string()},
                                d / "log");
  if (!wait_until(c, [&] { return log_has(c, "tracking"); })) return;
  expect_stopped_exit(stop(c, sig()), sig(), c);
  expect_complete_outputs(d / "o");
  expect_summary_interrupted(d / "o" / "summary.json");
}

TEST_P(Interrupt, ReceiveLooseCoupling) {
  const fs::path d = out("receive_loose");
  const Child c = start_program(
      {"receive", "--input", inputs().recording.string(), "--format", "i8", "--fs", "2.6e6", "--threads", "1", "--imu",
       (inputs().dir / "sim" / "imu.csv").string(), "--coupling", "loose", "--out", (d / "o").string()},
      d / "log");
  if (!wait_until(c, [&] { return log_has(c, "tracking"); })) return;
  expect_stopped_exit(stop(c, sig()), sig(), c);
  expect_complete_outputs(d / "o");
  expect_summary_interrupted(d / "o" / "summary.json");
}

TEST_P(Interrupt, Imusim) {
  const fs::path d = out("imusim");
  const Child c = start_program({"imusim", "--profile", "land", "--duration", "100000", "--rate", "200", "--odometer",
                                 "--out", (d / "o").string()},
                                d / "log");
  if (!wait_until(c, [&] { return fs::exists(d / "o" / "imu.csv.partial"); })) return;
  std::this_thread::sleep_for(100ms);
  expect_stopped_exit(stop(c, sig()), sig(), c);
  expect_complete_outputs(d / "o");
  expect_summary_interrupted(d / "o" / "summary.json");
}

TEST_P(Interrupt, Ins) {
  const fs::path d = out("ins");
  const Child c = start_program(
      {"ins", "--imu", inputs().imu_long.string(), "--init", inputs().truth_long.string(), "--out", (d / "o").string()},
      d / "log");
  if (!wait_until(c, [&] { return fs::exists(d / "o"); })) return;
  expect_stopped_exit(stop(c, sig()), sig(), c);
  expect_complete_outputs(d / "o");
  expect_summary_interrupted(d / "o" / "summary.json");
}

TEST_P(Interrupt, Fuse) {
  const fs::path d = out("fuse");
  const Child c =
      start_program({"fuse", "--imu", inputs().imu_long.string(), "--gnss", inputs().gnss_long.string(), "--align",
                     "motion", "--truth", inputs().truth_long.string(), "--out", (d / "o").string()},
                    d / "log");
  if (!wait_until(c, [&] { return fs::exists(d / "o" / "nav.csv.partial"); })) return;
  std::this_thread::sleep_for(100ms);
  expect_stopped_exit(stop(c, sig()), sig(), c);
  expect_complete_outputs(d / "o");
  expect_summary_interrupted(d / "o" / "summary.json");
}

TEST_P(Interrupt, Attitude) {
  const fs::path d = out("attitude");
  const fs::path sim = inputs().dir / "sim";
  // One recording as all three antennas (no attitude, but the whole receiver runs): one simulated file is enough.
  std::ofstream(d / "a.toml") << "[[antenna]]\nlever_arm_body_m = [0.0, 0.0, 0.0]\n"
                                 "[[antenna]]\nlever_arm_body_m = [1.0, 0.0, 0.0]\n"
                                 "[[antenna]]\nlever_arm_body_m = [0.0, 1.0, 0.0]\n";
  const std::string a0 = (sim / "antenna0.i8.bin").string();
  const Child c = start_program(
      {"attitude", "--input", a0, a0, a0, "--format", "i8", "--fs", "2.6e6", "--antennas", (d / "a.toml").string(),
       "--reference-week", "2190", "--threads", "1", "--out", (d / "o").string()},
      d / "log");
  if (!wait_until(c, [&] { return fs::exists(d / "o"); })) return;
  std::this_thread::sleep_for(200ms);
  expect_stopped_exit(stop(c, sig()), sig(), c);
  expect_complete_outputs(d / "o");
  expect_summary_interrupted(d / "o" / "summary.json");
}

TEST_P(Interrupt, CampaignRunLocal) {
  const fs::path d = out("campaign");
  std::ofstream(d / "s.toml") << "[signal]\nsample_rate_hz = 2.6e6\nformat = \"i8\"\nduration_s = 30.0\n"
                                 "cn0_dbhz = 45.0\nseed = {seed}\n[time]\ngps_week = 2190\ntow_s = 518400.0\n"
                                 "[navigation]\nconstellation = \"nominal\"\n";
  std::ofstream(d / "c.toml") << "[campaign]\nname = \"stop\"\n[[axis]]\nname = \"seed\"\nvalues = [7]\n"
                                 "[simulate]\nscenario = \"s.toml\"\n[receive]\ncoupling = \"scalar\"\n";
  const Child c = start_program(
      {"campaign", "run", (d / "c.toml").string(), "--out", (d / "o").string(), "--engine", "local", "--jobs", "1"},
      d / "log");
  if (!wait_until(c, [&] { return fs::exists(d / "o" / "runs" / "0000"); })) return;
  std::this_thread::sleep_for(300ms);
  expect_stopped_exit(stop(c, sig()), sig(), c);
  expect_complete_outputs(d / "o");
  EXPECT_FALSE(fs::exists(d / "o" / "runs" / "0000" / "complete.csv"));  // a stopped run is not complete
}

// gnsssim writes its one file at the end: stopped mid-run it leaves nothing, or the whole file.
TEST_P(Interrupt, Gnsssim) {
  const fs::path d = out("gnsssim");
  const Child c = start_program(
      {"gnsssim", "--truth", inputs().truth_long.string(), "--rate", "100", "--out", (d / "gnss.csv").string()},
      d / "log");
  std::this_thread::sleep_for(20ms);
  const int status = stop(c, sig());
  EXPECT_TRUE((WIFSIGNALED(status) && WTERMSIG(status) == sig()) ||
              (WIFEXITED(status) && (WEXITSTATUS(status) == 128 + sig() || WEXITSTATUS(status) == 0)))
      << read_text(c.log);
  expect_complete_outputs(d);
}

// align runs its filter in memory and writes at the end: a signal mid-run ends it with nothing written (or, during
// the writes, with both files whole).
TEST_P(Interrupt, Align) {
  const fs::path d = out("align");
  const fs::path inputs_dir = inputs().dir / "align";
  const Child c = start_program(
      {"align", "--imu", (inputs_dir / "imu.csv").string(), "--attitude", (inputs_dir / "attitude.csv").string(),
       "--attitude-origin", "2190", "518400", "--position", "36.37", "127.36", "80", "--duration", "0",
       "--filter-interval", "0.01", "--out", (d / "o").string()},
      d / "log");
  std::this_thread::sleep_for(300ms);  // its progress lines are buffered (stdout to a file): a fixed wait
  int status = 0;
  ASSERT_EQ(waitpid(c.pid, &status, WNOHANG), 0) << "align ended before the signal:\n" << read_text(c.log);
  status = stop(c, sig());
  EXPECT_TRUE((WIFSIGNALED(status) && WTERMSIG(status) == sig()) ||
              (WIFEXITED(status) && WEXITSTATUS(status) == 128 + sig()))
      << read_text(c.log);
  if (fs::exists(d / "o")) expect_complete_outputs(d / "o");
}

// snapshot searches in memory (here without --approx-llh: the grid search, seconds) and writes at the end.
TEST_P(Interrupt, Snapshot) {
  const fs::path d = out("snapshot");
  const auto constellation = ultratrack::signals::nominal_constellation({2190, 518400.0});
  ultratrack::signals::RinexNavData nav;
  nav.ephemerides = constellation.ephemerides;
  nav.klobuchar = constellation.klobuchar;
  nav.utc = constellation.utc;
  ultratrack::signals::write_rinex_nav_304(d / "nominal.rnx", nav);
  const Child c =
      start_program({"snapshot", "--input", inputs().recording.string(), "--format", "i8", "--fs", "2.6e6", "--nav",
                     (d / "nominal.rnx").string(), "--time", "2190:518400", "--ms", "100", "--out", (d / "o").string()},
                    d / "log");
  std::this_thread::sleep_for(300ms);
  int status = 0;
  ASSERT_EQ(waitpid(c.pid, &status, WNOHANG), 0) << "snapshot ended before the signal:\n" << read_text(c.log);
  status = stop(c, sig());
  EXPECT_TRUE((WIFSIGNALED(status) && WTERMSIG(status) == sig()) ||
              (WIFEXITED(status) && WEXITSTATUS(status) == 128 + sig()))
      << read_text(c.log);
  if (fs::exists(d / "o")) expect_complete_outputs(d / "o");
}

// demo stopped while it simulates: the simulation's outputs end at the stop and nothing else runs.
TEST(InterruptDemo, SigintInTheSimulationStopsThere) {
  const fs::path d = ultratrack::test::scratch_dir();
  const Child c = start_program({"demo", "--duration", "30", "--out", (d / "o").string()}, d / "log");
  if (!wait_until(c, [&] { return fs::exists(d / "o" / "simulation"); })) return;
  std::this_thread::sleep_for(300ms);
  expect_stopped_exit(stop(c, SIGINT), SIGINT, c);
  expect_complete_outputs(d / "o" / "simulation");
  expect_summary_interrupted(d / "o" / "simulation" / "summary.json");
  EXPECT_FALSE(fs::exists(d / "o" / "receiver"));
}

// demo stopped while it receives (a short simulation first): the receiver's outputs are finished and say so.
TEST(InterruptDemo, SigtermInTheReceiveFinishesItsOutputs) {
  const fs::path d = ultratrack::test::scratch_dir();
  const Child c = start_program({"demo", "--duration", "4", "--out", (d / "o").string()}, d / "log");
  if (!wait_until(
          c, [&] { return fs::exists(d / "o" / "receiver"); }, 120s))
    return;
  expect_stopped_exit(stop(c, SIGTERM), SIGTERM, c);
  expect_complete_outputs(d / "o" / "receiver");
  expect_summary_interrupted(d / "o" / "receiver" / "summary.json");
  EXPECT_TRUE(fs::exists(d / "o" / "simulation" / "antenna0.i8.bin"));  // kept: the run did not end
}

INSTANTIATE_TEST_SUITE_P(Signals, Interrupt, ::testing::Values(SIGINT, SIGTERM),
                         [](const auto& info) { return info.param == SIGINT ? "SIGINT" : "SIGTERM"; });

}  // namespace
