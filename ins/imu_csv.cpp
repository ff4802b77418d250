// SPDX-License-Identifier: GPL-3.0-or-later
#include "ins/imu_csv.hpp"

#include <fmt/core.h>

#include <array>
#include <fstream>
#include <string>
#include <string_view>

#include "ins/ins_error.hpp"
#include "io/atomic_file.hpp"
#include "io/numeric_csv.hpp"
#include "io/open_failure.hpp"

namespace ultratrack::ins {
namespace {

const std::vector<std::string>& imu_header() {
  static const std::vector<std::string> h{"t_s",      "dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad",
                                          "dv_x_mps", "dv_y_mps",     "dv_z_mps"};
  return h;
}

const std::vector<std::string>& rate_header() {
  static const std::vector<std::string> h{"t_s",          "acc_x_mps2",   "acc_y_mps2",  "acc_z_mps2",
                                          "gyro_x_radps", "gyro_y_radps", "gyro_z_radps"};
  return h;
}

std::string joined(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ",") + n;
  return s;
}

// Field-by-field equality, spaces around fields ignored.
bool header_is(std::string_view text, const std::vector<std::string>& names) {
  std::size_t i = 0;
  while (true) {
    const std::size_t comma = text.find(',');
    if (i >= names.size() || io::trim(text.substr(0, comma)) != names[i]) return false;
    ++i;
    if (comma == std::string_view::npos) return i == names.size();
    text.remove_prefix(comma + 1);
  }
}

}  // namespace

ImuCsvForm imu_csv_form(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file.string(), "cannot open IMU file: " + io::open_failure_reason());
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string_view t = io::trim(line);
    if (t.empty() || t.front() == '#') continue;
    if (header_is(t, imu_header())) return ImuCsvForm::Increments;
    if (header_is(t, rate_header())) return ImuCsvForm::Rates;
    throw InputError(
        file.string(),
        fmt::format("bad header, expected increments '{}' or rates '{}'", joined(imu_header()), joined(rate_header())),
        line_no);
  }
  throw InputError(file.string(), "empty IMU file: missing header");
}

std::vector<ImuIncrement> read_imu_csv(const std::filesystem::path& file, const ImuCsvOptions& options) {
  const ImuCsvForm form = imu_csv_form(file);
  std::vector<ImuIncrement> out;
  double t_prev = 0.0;
  Eigen::Vector3d f_prev, w_prev;
  bool have_prev = false;
  auto check_time = [&](int line, double t) {
    if (!have_prev) return;
    if (!(t > t_prev)) throw InputError(file.string(), fmt::format("time does not increase (t_s {})", t), line);
    if (t - t_prev > options.max_gap_s)
      throw InputError(
          file.string(),
          fmt::format("a gap of {:.3f} s before t_s {} (the limit is {} s)", t - t_prev, t, options.max_gap_s), line);
  };
  const auto& columns = form == ImuCsvForm::Increments ? imu_header() : rate_header();
  io::read_numeric_csv(file, "IMU file", columns, [&](int line, std::span<const double> v) {
    check_time(line, v[0]);
    if (form == ImuCsvForm::Increments) {
      out.push_back({v[0], {v[1], v[2], v[3]}, {v[4], v[5], v[6]}});
    } else {
      const Eigen::Vector3d f(v[1], v[2], v[3]), w(v[4], v[5], v[6]);
      if (have_prev) {
        const double dt = v[0] - t_prev;
        out.push_back({v[0], 0.5 * (w_prev + w) * dt, 0.5 * (f_prev + f) * dt});
      }
      f_prev = f;
      w_prev = w;
    }
    t_prev = v[0];
    have_prev = true;
  });
  if (out.empty()) throw InputError(file.string(), "IMU file has a single rate sample: no interval to integrate");
  return out;
}

ImuCsvWriter::ImuCsvWriter(const std::filesystem::path& file) : out_(std::make_unique<io::AtomicFile>(file)) {
  std::string h;
  for (const auto& n : imu_header()) h += (h.empty() ? "" : ",") + n;
  out_->write(h + "\n");
}

ImuCsvWriter::~ImuCsvWriter() = default;

void ImuCsvWriter::write(const ImuIncrement& i) {
  out_->write(fmt::format("{},{},{},{},{},{},{}\n", i.t_s, i.dtheta_b.x(), i.dtheta_b.y(), i.dtheta_b.z(), i.dv_b.x(),
                          i.dv_b.y(), i.dv_b.z()));
}

void ImuCsvWriter::commit() { out_->commit(); }

void write_imu_csv(const std::filesystem::path& file, std::span<const ImuIncrement> imu) {
  ImuCsvWriter w(file);
  for (const auto& i : imu) w.write(i);
  w.commit();
}

}  // namespace ultratrack::ins
