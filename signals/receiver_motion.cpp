// SPDX-License-Identifier: GPL-3.0-or-later
#include "signals/receiver_motion.hpp"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <sstream>
#include <string>

#include "io/open_failure.hpp"
#include "signals/input_error.hpp"

namespace ultratrack::signals {

TrajectoryMotion::TrajectoryMotion(std::vector<TrajectorySample> samples) : samples_(std::move(samples)) {
  if (samples_.empty()) samples_.push_back({});
}

AntennaState TrajectoryMotion::antenna_state(int, double t_s) const {
  const auto& first = samples_.front();
  const auto& last = samples_.back();
  if (samples_.size() == 1 || t_s <= first.t_s) return {first.r_e_m + first.v_e_mps * (t_s - first.t_s), first.v_e_mps};
  if (t_s >= last.t_s) return {last.r_e_m + last.v_e_mps * (t_s - last.t_s), last.v_e_mps};
  auto it = std::upper_bound(samples_.begin(), samples_.end(), t_s,
                             [](double t, const TrajectorySample& s) { return t < s.t_s; });
  const auto& b = *it;
  const auto& a = *(it - 1);
  const double h = b.t_s - a.t_s;
  const double u = (t_s - a.t_s) / h;
  // Cubic Hermite basis on [0,1] and its derivative (divided by h for d/dt).
  const double u2 = u * u, u3 = u2 * u;
  // Written with the difference b - a (h00 = 1 - h01, d00 = -d01) so that ECEF magnitudes of 6e6 m do not
  // cost precision.
  const double h10 = u3 - 2 * u2 + u, h01 = -2 * u3 + 3 * u2, h11 = u3 - u2;
  const double d10 = 3 * u2 - 4 * u + 1, d01 = -6 * u2 + 6 * u, d11 = 3 * u2 - 2 * u;
  const Eigen::Vector3d dr = b.r_e_m - a.r_e_m;
  AntennaState s;
  s.r_e_m = a.r_e_m + h01 * dr + h * (h10 * a.v_e_mps + h11 * b.v_e_mps);
  s.v_e_mps = (d01 / h) * dr + d10 * a.v_e_mps + d11 * b.v_e_mps;
  return s;
}

std::vector<TrajectorySample> read_trajectory_csv(const std::filesystem::path& path) {
  const std::string name = path.string();
  std::ifstream in(path);
  if (!in) throw InputError(name, "cannot open the trajectory file: " + io::open_failure_reason());
  std::vector<TrajectorySample> out;
  std::string line;
  int line_no = 0;
  bool header_seen = false;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    if (!header_seen) {
      header_seen = true;
      // A header row starts with a letter; a file without a header is accepted as well.
      if (std::isalpha(static_cast<unsigned char>(line[0]))) continue;
    }
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream ss(line);
    double v[7];
    for (int i = 0; i < 7; ++i) {
      if (!(ss >> v[i])) throw InputError(name, "expected 7 numbers (t_s, x, y, z, vx, vy, vz)", line_no);
    }
    std::string extra;
    if (ss >> extra) throw InputError(name, "more than 7 columns", line_no);
    TrajectorySample s{v[0], {v[1], v[2], v[3]}, {v[4], v[5], v[6]}};
    if (!out.empty()) {
      const double dt = s.t_s - out.back().t_s;
      if (!(dt > 0)) throw InputError(name, "time does not increase", line_no);
      if (dt > 0.1 + 1e-9)
        throw InputError(name, "gap of " + std::to_string(dt) + " s: at least 10 Hz is needed", line_no);
    }
    out.push_back(s);
  }
  if (out.size() < 2) throw InputError(name, "a trajectory needs at least two rows");
  return out;
}

}  // namespace ultratrack::signals
