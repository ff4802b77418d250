#include "ins/imu_csv.hpp"

#include <fmt/core.h>

#include <array>
#include <fstream>
#include <string>

#include "ins/atomic_file.hpp"
#include "ins/csv_util.hpp"
#include "ins/ins_error.hpp"

namespace ultratrack::ins {
namespace {

const std::vector<std::string>& imu_header() {
  static const std::vector<std::string> h{"t_s",      "dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad",
                                          "dv_x_mps", "dv_y_mps",     "dv_z_mps"};
  return h;
}

}  // namespace

std::vector<ImuIncrement> read_imu_csv(const std::filesystem::path& file) {
  const std::string name = file.string();
  std::ifstream in(file);
  if (!in) throw InputError(name, "cannot open IMU file");
  std::vector<ImuIncrement> out;
  std::string line;
  int line_no = 0;
  bool have_header = false;
  while (std::getline(in, line)) {
    ++line_no;
    const std::string_view t = trim(line);
    if (t.empty()) continue;
    if (!have_header) {
      check_header(name, line_no, t, imu_header());
      have_header = true;
      continue;
    }
    std::array<double, 7> v{};
    parse_row(name, line_no, t, v);
    if (!out.empty() && !(v[0] > out.back().t_s))
      throw InputError(name, "time does not increase (t_s " + fmt::format("{}", v[0]) + ")", line_no);
    out.push_back({v[0], {v[1], v[2], v[3]}, {v[4], v[5], v[6]}});
  }
  if (!have_header) throw InputError(name, "empty file: missing header");
  if (out.empty()) throw InputError(name, "no IMU rows");
  return out;
}

ImuCsvWriter::ImuCsvWriter(const std::filesystem::path& file) : out_(std::make_unique<AtomicFile>(file)) {
  std::string h;
  for (const auto& n : imu_header()) h += (h.empty() ? "" : ",") + n;
  out_->write(h + "\n");
}

ImuCsvWriter::~ImuCsvWriter() = default;

void ImuCsvWriter::write(const ImuIncrement& i) {
  fmt::print(out_->handle(), "{},{},{},{},{},{},{}\n", i.t_s, i.dtheta_b.x(), i.dtheta_b.y(), i.dtheta_b.z(),
             i.dv_b.x(), i.dv_b.y(), i.dv_b.z());
}

void ImuCsvWriter::commit() { out_->commit(); }

void write_imu_csv(const std::filesystem::path& file, std::span<const ImuIncrement> imu) {
  ImuCsvWriter w(file);
  for (const auto& i : imu) w.write(i);
  w.commit();
}

}  // namespace ultratrack::ins
