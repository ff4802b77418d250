// SPDX-License-Identifier: GPL-3.0-or-later
#include "ins/odometer_csv.hpp"

#include <fmt/core.h>

#include <cmath>

#include "io/input_error.hpp"
#include "io/numeric_csv.hpp"

namespace ultratrack::ins {

OdometerRecord read_odometer_csv(const std::filesystem::path& file, const OdometerCsvOptions& options) {
  const std::string name = file.string();
  if (options.rate_hz && !(*options.rate_hz > 0.0 && std::isfinite(*options.rate_hz)))
    throw io::InputError(name, fmt::format("the declared odometer rate must be positive, got {}", *options.rate_hz));
  OdometerRecord r;
  std::optional<double> period_s;
  if (options.rate_hz) period_s = 1.0 / *options.rate_hz;
  io::read_numeric_csv(
      file, "odometer file", {"t_s", "pulses", "distance_m"}, [&](int line, std::span<const double> v) {
        const double t = v[0], pulses = v[1], distance = v[2];
        if (pulses < 0.0 || pulses != std::floor(pulses) || pulses > 1e15)
          throw io::InputError(name, fmt::format("pulses must be a whole number in 0..1e15, got {}", pulses), line);
        if (distance < 0.0) throw io::InputError(name, fmt::format("negative distance_m {}", distance), line);
        if (!r.samples.empty()) {
          const double dt = t - r.samples.back().t_s;
          if (!(dt > 0.0))
            throw io::InputError(name, fmt::format("time does not increase (t_s {} after {})", t, r.samples.back().t_s),
                                 line);
          if (!period_s) period_s = dt;
          if (std::abs(dt - *period_s) > 0.01 * *period_s)
            throw io::InputError(
                name,
                fmt::format("an interval of {:.6g} s before t_s {} does not match the {} rate of {:.6g} Hz", dt, t,
                            options.rate_hz ? "declared" : "file's", 1.0 / *period_s),
                line);
        }
        r.samples.push_back({t, static_cast<std::int64_t>(pulses), distance});
      });
  if (r.samples.size() < 2) throw io::InputError(name, "an odometer file needs at least two rows");
  r.rate_hz = 1.0 / *period_s;
  return r;
}

}  // namespace ultratrack::ins
