// SPDX-License-Identifier: GPL-3.0-or-later
#include "pipelines/alignment_run.hpp"

#include <fmt/format.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "ins/coarse_alignment.hpp"
#include "ins/earth_model.hpp"
#include "io/input_error.hpp"
#include "io/json_text.hpp"
#include "io/open_failure.hpp"
#include "io/units.hpp"

namespace ultratrack::pipelines {
namespace {

constexpr double kDeg = io::kRadPerDeg;
constexpr double kDegPerHour = io::kRadPerSecPerDegPerHour;

std::string vec(const Eigen::Vector3d& v, double scale) {
  return fmt::format("[{:.9g}, {:.9g}, {:.9g}]", v.x() / scale, v.y() / scale, v.z() / scale);
}

}  // namespace

AlignRunResult run_alignment(const std::vector<ins::ImuIncrement>& imu, const std::vector<GpsAttitudeRow>& attitude,
                             const AlignSettings& s) {
  const FuseConfig& c = s.config;
  if (imu.size() < 2) throw io::InputError(s.imu_file, "fewer than 2 IMU rows");
  if (!c.position_deg_m)
    throw io::InputError("configuration",
                         "align needs the position (latitude for gravity and earth rate): "
                         "--position LAT LON H or [initial] position_deg_m");
  if (!c.attitude_gps_time_at_imu_zero)
    throw io::InputError("command line",
                         "align needs the GPS time of IMU t = 0: --attitude-origin WEEK TOW, "
                         "--imu-pps, or [attitude] gps_time_at_imu_zero");
  AlignRunResult r;
  r.attitude_rows = static_cast<long long>(attitude.size());
  std::vector<fusion::GnssAttitude> gps;
  for (const auto& row : attitude) {
    if (!row.fixed) continue;
    fusion::GnssAttitude a;
    a.t_s = signals::seconds_between(row.time, *c.attitude_gps_time_at_imu_zero);
    a.euler_a = row.euler;
    a.sigma_euler_rad = {row.sigma_roll_rad, row.sigma_pitch_rad, row.sigma_yaw_rad};
    gps.push_back(a);
  }
  r.fixed_rows = static_cast<long long>(gps.size());
  if (gps.empty())
    throw io::InputError(s.attitude_file, fmt::format("no fixed attitude rows (fixed = 1) among {} rows: the receiver "
                                                      "never resolved the array's ambiguities",
                                                      attitude.size()));
  const double imu_start = imu[0].t_s - (imu[1].t_s - imu[0].t_s);
  if (gps.back().t_s <= imu_start || gps.front().t_s >= imu.back().t_s)
    throw io::InputError(s.attitude_file,
                         fmt::format("fixed attitudes ({:.3f}-{:.3f} s on the IMU time line) do not overlap the IMU "
                                     "data ({:.3f}-{:.3f} s): check --attitude-origin / --imu-pps",
                                     gps.front().t_s, gps.back().t_s, imu_start, imu.back().t_s));

  fusion::StationaryAlignmentOptions o;
  o.filter = s.filter;
  o.ukf = c.ukf;
  o.gate = c.gate;
  o.filter_interval_s = s.filter_interval_s;
  o.duration_s = s.duration_s;
  o.lat_rad = c.position_deg_m->x() * kDeg;
  o.lon_rad = c.position_deg_m->y() * kDeg;
  o.height_m = c.position_deg_m->z();
  o.imu = imu_error_spec(c);
  const Eigen::Vector3d m = c.attitude_misalignment_deg * kDeg;
  o.q_ba = ins::quaternion_from_euler({m.x(), m.y(), m.z()});
  o.max_abs_pitch_rad = c.attitude_max_pitch_deg * kDeg;
  try {
    r.alignment = fusion::align_stationary(imu, gps, o);
  } catch (const std::invalid_argument& e) {
    throw io::InputError(s.attitude_file, std::string(e.what()) + fmt::format(" (attitudes {:.3f}-{:.3f} s, IMU "
                                                                              "{:.3f}-{:.3f} s on the IMU time line)",
                                                                              gps.front().t_s, gps.back().t_s,
                                                                              imu_start, imu.back().t_s));
  }
  const auto& a = r.alignment;
  if (a.history.empty())
    throw io::InputError(s.imu_file, fmt::format("no filter epoch: the IMU data after the first GPS attitude are "
                                                 "shorter than the filter interval ({} s)",
                                                 s.filter_interval_s));
  if (s.duration_s > 0.0 && a.end_s - a.start_s < s.duration_s - s.filter_interval_s)
    r.warnings.push_back(fmt::format("the data covered {:.1f} s of alignment, less than the {:.1f} s asked for",
                                     a.end_s - a.start_s, s.duration_s));

  // Observability at the final attitude ([KimAlign] theorem 1: full rank unless pitch = 90 deg).
  const ins::EulerAngles e = ins::euler_from_quaternion(a.nav.q_nb);
  const double g = ins::gravity_n(o.lat_rad, o.height_m).z();
  r.observability = fusion::alignment_observability(e, fusion::alignment_model_options(o.imu, o.lat_rad, g));
  if (r.observability.rank < 12 || std::abs(e.pitch_rad) > 60.0 * kDeg)
    r.warnings.push_back(
        fmt::format("pitch {:.1f} deg: near 90 deg roll and yaw turn about one axis and the GPS "
                    "attitude observes one angle less (observability rank {} of 12)",
                    e.pitch_rad / kDeg, r.observability.rank));

  // The IMU's own attitude over the same span (levelling + gyrocompassing) and the mounting it implies.
  std::size_t i0 = 0, i1 = 0;
  while (i0 < imu.size() && imu[i0].t_s <= a.start_s) ++i0;
  i1 = i0;
  while (i1 < imu.size() && imu[i1].t_s <= a.end_s + 1e-9) ++i1;
  const auto span = std::span(imu).subspan(i0, i1 - i0);
  const ins::AlignmentResult ref = ins::coarse_align(span, a.start_s, o.lat_rad);
  r.reference_attitude = ref.euler;
  const Eigen::Vector3d noise = ins::alignment_noise_sigma(o.imu, ref.duration_s, o.lat_rad, g);
  const double tilt = std::hypot(o.imu.accel.bias_sigma / g, noise.x());
  const double heading = std::hypot(
      std::hypot(o.imu.gyro.bias_sigma / (ins::kEarthRate_rps * std::cos(o.lat_rad)), tilt * std::tan(o.lat_rad)),
      noise.z());
  r.reference_sigma_rad = {tilt, tilt, heading};
  Eigen::Quaterniond q_nb_ref = ref.q_nb;
  Eigen::Matrix3d P_ref = r.reference_sigma_rad.cwiseAbs2().asDiagonal();
  if (s.reference_attitude) {
    r.reference_attitude = *s.reference_attitude;
    r.reference_sigma_rad = s.reference_sigma_rad;
    q_nb_ref = ins::quaternion_from_euler(*s.reference_attitude);
    const Eigen::Matrix3d M = fusion::euler_rate_to_rotation_n(*s.reference_attitude);
    P_ref = M * s.reference_sigma_rad.cwiseAbs2().asDiagonal() * M.transpose();
  }
  std::vector<fusion::GnssAttitude> in_span;
  for (const auto& ga : gps)
    if (ga.t_s >= a.start_s - 1e-9 && ga.t_s <= a.end_s + 1e-9) in_span.push_back(ga);
  r.rows_in_span = static_cast<long long>(in_span.size());
  r.mounting = fusion::estimate_mounting(in_span, q_nb_ref, P_ref);
  // A mounting the configuration does not know: the GPS level disagrees with the accelerometers' by more than the
  // IMU's bias explains. Small, it shows as horizontal accelerometer biases beyond the IMU's; large, the velocity
  // the INS then builds up fails the zero-velocity gate (as it would if the vehicle moved).
  if (a.zero_velocity_rejected > 0)
    r.warnings.push_back(fmt::format(
        "{} of {} zero-velocity updates rejected: the vehicle moved, or the GPS attitude's "
        "level disagrees with the accelerometers' (the array mounted off the assumed "
        "misalignment_deg? the mounting estimate is ({:.2f}, {:.2f}, {:.2f}) deg); the "
        "alignment is not valid",
        a.zero_velocity_rejected, a.zero_velocity_rejected + a.zero_velocity_updates, r.mounting.angles.roll_rad / kDeg,
        r.mounting.angles.pitch_rad / kDeg, r.mounting.angles.yaw_rad / kDeg));
  const double limit = 5.0 * std::max(o.imu.accel.bias_sigma, 1e-5);
  if (a.accel_bias_b.head<2>().cwiseAbs().maxCoeff() > limit)
    r.warnings.push_back(
        fmt::format("horizontal accelerometer bias estimates ({:.2f}, {:.2f} mg) exceed 5 sigma of "
                    "the IMU's: the array is probably mounted off the assumed misalignment_deg; the "
                    "mounting estimate is ({:.2f}, {:.2f}, {:.2f}) deg",
                    a.accel_bias_b.x() / 9.80665e-3, a.accel_bias_b.y() / 9.80665e-3, r.mounting.angles.roll_rad / kDeg,
                    r.mounting.angles.pitch_rad / kDeg, r.mounting.angles.yaw_rad / kDeg));
  return r;
}

std::string alignment_json(const AlignRunResult& r, const AlignSettings& s) {
  const auto& a = r.alignment;
  const ins::EulerAngles e = ins::euler_from_quaternion(a.nav.q_nb);
  auto sd = [&](int i) { return std::sqrt(std::max(0.0, a.P(i, i))); };
  const Eigen::Vector3d sba(sd(6), sd(7), sd(8)), sbg(sd(9), sd(10), sd(11));
  const auto& m = r.mounting;
  std::string w;
  for (const auto& x : r.warnings) w += (w.empty() ? "" : ", ") + io::json_string(x);
  std::string sv;
  for (int i = 0; i < 12; ++i) sv += fmt::format("{}{:.6g}", i ? ", " : "", r.observability.singular_values(i));
  const Eigen::Vector3d assumed = s.config.attitude_misalignment_deg;
  std::string j = "{\n";
  j += fmt::format("  \"roll_deg\": {:.9f},\n  \"pitch_deg\": {:.9f},\n  \"yaw_deg\": {:.9f},\n", e.roll_rad / kDeg,
                   e.pitch_rad / kDeg, e.yaw_rad / kDeg);
  j += fmt::format("  \"sigma_roll_deg\": {:.9f},\n  \"sigma_pitch_deg\": {:.9f},\n  \"sigma_yaw_deg\": {:.9f},\n",
                   a.sigma_euler_rad.x() / kDeg, a.sigma_euler_rad.y() / kDeg, a.sigma_euler_rad.z() / kDeg);
  j += fmt::format("  \"t_s\": {:.6f},\n  \"start_s\": {:.6f},\n  \"duration_s\": {:.6f},\n", a.end_s, a.start_s,
                   a.end_s - a.start_s);
  j += fmt::format("  \"filter\": \"{}\",\n  \"filter_interval_s\": {},\n",
                   s.filter == fusion::FilterKind::Ukf ? "ukf" : "ekf", s.filter_interval_s);
  j += "  \"accel_bias_mps2\": " + vec(a.accel_bias_b, 1.0) + ",\n";
  j += "  \"sigma_accel_bias_mps2\": " + vec(sba, 1.0) + ",\n";
  j += "  \"gyro_bias_dph\": " + vec(a.gyro_bias_b, kDegPerHour) + ",\n";
  j += "  \"sigma_gyro_bias_dph\": " + vec(sbg, kDegPerHour) + ",\n";
  j += "  \"mounting_assumed_deg\": " + vec(assumed, 1.0) + ",\n";
  j += fmt::format(
      "  \"mounting\": {{\"roll_deg\": {:.6f}, \"pitch_deg\": {:.6f}, \"yaw_deg\": {:.6f}, "
      "\"sigma_roll_deg\": {:.6f}, \"sigma_pitch_deg\": {:.6f}, \"sigma_yaw_deg\": {:.6f}, "
      "\"samples\": {}, \"reference\": \"{}\", "
      "\"reference_deg\": [{:.6f}, {:.6f}, {:.6f}], \"reference_sigma_deg\": {}}},\n",
      m.angles.roll_rad / kDeg, m.angles.pitch_rad / kDeg, m.angles.yaw_rad / kDeg, m.sigma_rad.x() / kDeg,
      m.sigma_rad.y() / kDeg, m.sigma_rad.z() / kDeg, m.samples,
      s.reference_attitude ? "given reference attitude" : "IMU levelling and gyrocompassing",
      r.reference_attitude.roll_rad / kDeg, r.reference_attitude.pitch_rad / kDeg, r.reference_attitude.yaw_rad / kDeg,
      vec(r.reference_sigma_rad, kDeg));
  j += fmt::format("  \"observability_rank\": {},\n  \"observability_singular_values\": [{}],\n", r.observability.rank,
                   sv);
  j += fmt::format(
      "  \"updates\": {{\"zero_velocity\": {}, \"zero_velocity_rejected\": {}, \"attitude\": {}, "
      "\"attitude_rejected\": {}, "
      "\"attitude_unusable\": {}}},\n",
      a.zero_velocity_updates, a.zero_velocity_rejected, a.attitude_updates, a.attitude_rejected, a.attitude_unusable);
  j += fmt::format("  \"attitude_rows\": {},\n  \"fixed_rows\": {},\n", r.attitude_rows, r.fixed_rows);
  j += "  \"imu_file\": " + io::json_string(s.imu_file) + ",\n";
  j += "  \"attitude_file\": " + io::json_string(s.attitude_file) + ",\n";
  j += "  \"time\": " + io::json_string(s.time_note) + ",\n";
  j += "  \"warnings\": [" + w + "]\n}\n";
  return j;
}

std::string alignment_csv(const AlignRunResult& r) {
  std::string out =
      "t_s,roll_deg,pitch_deg,yaw_deg,sigma_roll_deg,sigma_pitch_deg,sigma_yaw_deg,vel_n_mps,vel_e_mps,vel_d_mps,"
      "accel_bias_x_mps2,accel_bias_y_mps2,accel_bias_z_mps2,gyro_bias_x_dph,gyro_bias_y_dph,gyro_bias_z_dph,"
      "attitude_used\n";
  for (const auto& h : r.alignment.history)
    out += fmt::format(
        "{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.6f},{:.9g},{:.9g},{:.9g},"
        "{:.6f},{:.6f},{:.6f},{}\n",
        h.t_s, h.euler.roll_rad / kDeg, h.euler.pitch_rad / kDeg, h.euler.yaw_rad / kDeg, h.sigma_euler_rad.x() / kDeg,
        h.sigma_euler_rad.y() / kDeg, h.sigma_euler_rad.z() / kDeg, h.v_n.x(), h.v_n.y(), h.v_n.z(), h.accel_bias_b.x(),
        h.accel_bias_b.y(), h.accel_bias_b.z(), h.gyro_bias_b.x() / kDegPerHour, h.gyro_bias_b.y() / kDegPerHour,
        h.gyro_bias_b.z() / kDegPerHour, h.attitude_used ? 1 : 0);
  return out;
}

AlignmentFileStart read_alignment_json(const std::filesystem::path& file) {
  const std::string name = file.string();
  std::ifstream in(file);
  if (!in) throw io::InputError(name, "cannot open the alignment file: " + io::open_failure_reason());
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string text = ss.str();
  // Our own file: the top-level keys come first, so the first occurrence of each is the top-level one.
  auto number = [&](const char* key) {
    const std::string k = std::string("\"") + key + "\":";
    const auto p = text.find(k);
    if (p == std::string::npos) throw io::InputError(name, std::string("no \"") + key + "\" (not an alignment.json)");
    const char* start = text.c_str() + p + k.size();
    char* end = nullptr;
    const double v = std::strtod(start, &end);
    if (end == start || !std::isfinite(v))
      throw io::InputError(name, std::string("\"") + key + "\" is not a finite number");
    return v;
  };
  // "key": [x, y, z]
  auto vector3 = [&](const char* key) -> std::optional<Eigen::Vector3d> {
    const std::string k = std::string("\"") + key + "\":";
    const auto p = text.find(k);
    if (p == std::string::npos) return std::nullopt;
    const char* c = text.c_str() + p + k.size();
    const auto bad = [&] {
      return io::InputError(name, std::string("\"") + key + "\" is not a list of 3 finite numbers");
    };
    while (*c == ' ') ++c;
    if (*c++ != '[') throw bad();
    Eigen::Vector3d v;
    for (int i = 0; i < 3; ++i) {
      char* end = nullptr;
      v(i) = std::strtod(c, &end);
      if (end == c || !std::isfinite(v(i))) throw bad();
      c = end;
      while (*c == ' ') ++c;
      if (*c++ != (i < 2 ? ',' : ']')) throw bad();
    }
    return v;
  };
  AlignmentFileStart f;
  f.attitude_deg = {number("roll_deg"), number("pitch_deg"), number("yaw_deg")};
  f.sigma_attitude_deg = {number("sigma_roll_deg"), number("sigma_pitch_deg"), number("sigma_yaw_deg")};
  if (!(f.sigma_attitude_deg.array() > 0.0).all()) throw io::InputError(name, "attitude sigmas must be positive");
  const auto ba = vector3("accel_bias_mps2"), sba = vector3("sigma_accel_bias_mps2");
  const auto bg = vector3("gyro_bias_dph"), sbg = vector3("sigma_gyro_bias_dph");
  const int given = int(ba.has_value()) + int(sba.has_value()) + int(bg.has_value()) + int(sbg.has_value());
  if (given != 0 && given != 4)
    throw io::InputError(name,
                         "accel_bias_mps2, sigma_accel_bias_mps2, gyro_bias_dph and sigma_gyro_bias_dph go "
                         "together (all or none)");
  if (given == 4) {
    if (!(sba->array() > 0.0).all() || !(sbg->array() > 0.0).all())
      throw io::InputError(name, "bias sigmas must be positive");
    f.biases = AlignmentFileStart::Biases{*ba, *sba, *bg * kDegPerHour, *sbg * kDegPerHour};
  }
  return f;
}

void apply_alignment_file(FuseConfig& config, const std::filesystem::path& file) {
  const AlignmentFileStart f = read_alignment_json(file);
  config.attitude_deg = f.attitude_deg;
  config.sigma_attitude_deg = f.sigma_attitude_deg;
  if (f.biases) {
    config.initial_accel_bias_mps2 = f.biases->accel_mps2;
    config.sigma_accel_bias_mps2 = f.biases->sigma_accel_mps2;
    config.initial_gyro_bias_rps = f.biases->gyro_rps;
    config.sigma_gyro_bias_rps = f.biases->sigma_gyro_rps;
  }
}

}  // namespace ultratrack::pipelines
