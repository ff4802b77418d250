// SPDX-License-Identifier: GPL-3.0-or-later
// Every numeric field of the time-series inputs (imu.csv in both forms, gnss.csv, odometer.csv, pps.csv,
// attitude.csv) made NaN or infinite, and each file's time going backwards or repeating (issue 21): one InputError
// naming the file and the line of the bad row. A field-by-field sweep over a valid file, so that a column a reader
// forgets to check fails here. (attitude.csv's angles and sigmas may be nan on an unfixed row, as `attitude`
// writes them before a fix: they are swept on a fixed row.)
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "ins/imu_csv.hpp"
#include "ins/odometer_csv.hpp"
#include "pipelines/gnss_fix_csv.hpp"
#include "pipelines/gps_attitude_csv.hpp"
#include "pipelines/pps_time_sync.hpp"
#include "support/expect_input_error.hpp"
#include "support/test_data.hpp"

namespace fs = std::filesystem;

namespace {

struct CsvCase {
  std::string name;
  std::string header;
  std::vector<std::string> rows;  // valid data rows, times increasing
  int time_column;                // the column whose repeat or decrease is an error
  std::function<void(const fs::path&)> read;
};

std::vector<std::string> split(const std::string& row) {
  std::vector<std::string> f;
  std::stringstream ss(row);
  std::string x;
  while (std::getline(ss, x, ',')) f.push_back(x);
  return f;
}

std::string join(const std::vector<std::string>& f) {
  std::string r;
  for (std::size_t i = 0; i < f.size(); ++i) r += (i ? "," : "") + f[i];
  return r;
}

fs::path write(const fs::path& dir, const std::string& name, const CsvCase& c, const std::vector<std::string>& rows) {
  std::string text = c.header + "\n";
  for (const auto& r : rows) text += r + "\n";
  std::ofstream(dir / name) << text;
  return dir / name;
}

std::vector<CsvCase> cases() {
  return {
      {"imu_increments",
       "t_s,dtheta_x_rad,dtheta_y_rad,dtheta_z_rad,dv_x_mps,dv_y_mps,dv_z_mps",
       {"0,0,0,0,0,0,-0.098", "0.01,0.0001,0,0,0,0,-0.098", "0.02,0,0.0001,0,0,0,-0.098", "0.03,0,0,0,0,0,-0.098"},
       0,
       [](const fs::path& f) { ultratrack::ins::read_imu_csv(f); }},
      {"imu_rates",
       "t_s,acc_x_mps2,acc_y_mps2,acc_z_mps2,gyro_x_radps,gyro_y_radps,gyro_z_radps",
       {"0,0,0,-9.8,0,0,0", "0.01,0,0,-9.8,0.01,0,0", "0.02,0,0,-9.8,0,0.01,0", "0.03,0,0,-9.8,0,0,0"},
       0,
       [](const fs::path& f) { ultratrack::ins::read_imu_csv(f); }},
      {"gnss",
       "t_s,lat_deg,lon_deg,height_m,vel_n_mps,vel_e_mps,vel_d_mps,sigma_n_m,sigma_e_m,sigma_d_m",
       {"0,36.37,127.36,100,1,0,0,1.5,1.5,3", "1,36.37001,127.36,100,1,0,0,1.5,1.5,3",
        "2,36.37002,127.36,100,1,0,0,1.5,1.5,3", "3,36.37003,127.36,100,1,0,0,1.5,1.5,3"},
       0,
       [](const fs::path& f) { ultratrack::pipelines::read_gnss_csv(f); }},
      {"odometer",
       "t_s,pulses,distance_m",
       {"0,0,0", "0.1,10,0.2", "0.2,20,0.4", "0.3,30,0.6"},
       0,
       [](const fs::path& f) { ultratrack::ins::read_odometer_csv(f); }},
      {"pps",
       "local_s,gps_week,gps_tow_s",
       {"10.0,2190,518400", "11.0,2190,518401", "12.0,2190,518402", "13.0,2190,518403"},
       0,
       [](const fs::path& f) { ultratrack::pipelines::read_pps_csv(f); }},
      {"attitude",
       "gps_week,tow_s,roll_deg,pitch_deg,yaw_deg,sigma_roll_deg,sigma_pitch_deg,sigma_yaw_deg,num_sats,fixed,ratio",
       {"2190,518400.0,2,-3,35,0.3,0.3,0.1,9,1,8.5", "2190,518400.1,2,-3,35,0.3,0.3,0.1,9,1,8.5",
        "2190,518400.2,2,-3,35,0.3,0.3,0.1,9,1,8.5", "2190,518400.3,2,-3,35,0.3,0.3,0.1,9,1,8.5"},
       1,
       [](const fs::path& f) { ultratrack::pipelines::read_attitude_csv(f); }},
  };
}

TEST(CsvFaults, ValidFilesRead) {
  const fs::path dir = ultratrack::test::scratch_dir();
  for (const auto& c : cases()) EXPECT_NO_THROW(c.read(write(dir, c.name + ".csv", c, c.rows))) << c.name;
}

TEST(CsvFaults, NanOrInfInAnyNumericFieldNamesFileAndLine) {
  const fs::path dir = ultratrack::test::scratch_dir();
  for (const auto& c : cases()) {
    const std::size_t columns = split(c.rows[0]).size();
    for (std::size_t col = 0; col < columns; ++col) {
      for (const std::string bad : {"nan", "inf", "-inf"}) {
        auto rows = c.rows;
        auto f = split(rows[2]);
        f[col] = bad;
        rows[2] = join(f);
        const std::string name = c.name + "_" + std::to_string(col) + "_" + bad + ".csv";
        const fs::path file = write(dir, name, c, rows);
        SCOPED_TRACE(name);
        ultratrack::test::expect_error_at([&] { c.read(file); }, file, 4, "");  // header = line 1, rows[2] = 4
      }
    }
  }
}

TEST(CsvFaults, TimeThatRepeatsOrGoesBackwardsNamesFileAndLine) {
  const fs::path dir = ultratrack::test::scratch_dir();
  for (const auto& c : cases()) {
    for (const bool repeat : {true, false}) {
      auto rows = c.rows;
      auto f = split(rows[2]);
      f[static_cast<std::size_t>(c.time_column)] = split(rows[repeat ? 1 : 0])[static_cast<std::size_t>(c.time_column)];
      rows[2] = join(f);
      const std::string name = c.name + (repeat ? "_repeat.csv" : "_backwards.csv");
      const fs::path file = write(dir, name, c, rows);
      SCOPED_TRACE(name);
      ultratrack::test::expect_error_at([&] { c.read(file); }, file, 4, "");
    }
  }
}

// The GPS side of a PPS record, and the GPS week of attitude.csv, going backwards while the other column increases.
TEST(CsvFaults, GpsTimeBackwardsInPpsAndAttitudeWeekNamesFileAndLine) {
  const fs::path dir = ultratrack::test::scratch_dir();
  for (const auto& c : cases()) {
    if (c.name != "pps" && c.name != "attitude") continue;
    auto rows = c.rows;
    auto f = split(rows[2]);
    const std::size_t week = c.name == "pps" ? 1 : 0;
    f[week] = "2189";
    rows[2] = join(f);
    const fs::path file = write(dir, c.name + "_week_backwards.csv", c, rows);
    SCOPED_TRACE(c.name);
    ultratrack::test::expect_error_at([&] { c.read(file); }, file, 4, "");
  }
}

// A GPS week or a count too large for an int (a corrupt line; found by fuzz_csv_inputs, whose input is kept in
// tests/fuzz/regressions/): an error naming the column, not a cast of a double outside int's range.
TEST(CsvFaults, GpsWeekOrCountBeyondAnIntNamesTheColumn) {
  const fs::path dir = ultratrack::test::scratch_dir();
  for (const auto& c : cases()) {
    if (c.name != "pps" && c.name != "attitude") continue;
    for (const auto& [column, value, what] :
         {std::tuple<std::size_t, std::string, std::string>{0, "2.1925e11", "gps_week"},
          {0, "10000", "gps_week"},
          {0, "2190.5", "gps_week"},
          {8, "1e300", "num_sats"}}) {
      if (c.name == "pps" && what == "num_sats") continue;
      auto rows = c.rows;
      auto f = split(rows[2]);
      const std::size_t index = c.name == "pps" && what == "gps_week" ? 1 : column;
      f[index] = value;
      rows[2] = join(f);
      const fs::path file = write(dir, c.name + "_" + what + "_" + value + ".csv", c, rows);
      SCOPED_TRACE(c.name + " " + what + " = " + value);
      ultratrack::test::expect_error_at([&] { c.read(file); }, file, 4, what + " must be a whole number in [0, ");
    }
  }
}

}  // namespace
