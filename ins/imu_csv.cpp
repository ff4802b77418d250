#include "ins/imu_csv.hpp"

#include <fmt/core.h>

#include <array>
#include <fstream>
#include <string>

#include "ins/ins_error.hpp"
#include "io/atomic_file.hpp"
#include "io/numeric_csv.hpp"

namespace ultratrack::ins {
namespace {

const std::vector<std::string>& imu_header() {
  static const std::vector<std::string> h{"t_s",      "dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad",
                                          "dv_x_mps", "dv_y_mps",     "dv_z_mps"};
  return h;
}

}  // namespace

std::vector<ImuIncrement> read_imu_csv(const std::filesystem::path& file) {
  std::vector<ImuIncrement> out;
  io::read_numeric_csv(file, "IMU file", imu_header(), [&](int line, std::span<const double> v) {
    if (!out.empty() && !(v[0] > out.back().t_s))
      throw InputError(file.string(), fmt::format("time does not increase (t_s {})", v[0]), line);
    out.push_back({v[0], {v[1], v[2], v[3]}, {v[4], v[5], v[6]}});
  });
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
