#include "ins/odometer.hpp"

#include <cmath>
#include <stdexcept>

namespace ultratrack::ins {

std::vector<OdometerSample> simulate_odometer(std::span<const TruthSample> truth, const OdometerOptions& o) {
  if (truth.size() < 2) throw std::invalid_argument("simulate_odometer: need at least two truth samples");
  if (!(o.rate_hz > 0.0) || !(o.meters_per_pulse > 0.0)) throw std::invalid_argument("simulate_odometer: bad options");
  const double truth_dt = truth[1].t_s - truth[0].t_s;
  const long long stride = std::llround(1.0 / (o.rate_hz * truth_dt));
  if (stride < 1 || std::fabs(stride * truth_dt * o.rate_hz - 1.0) > 1e-6)
    throw std::invalid_argument("simulate_odometer: odometer rate must divide the truth rate");
  auto count = [&](double d) {
    return static_cast<std::int64_t>(std::floor(d * (1.0 + o.scale_factor_error) / o.meters_per_pulse));
  };
  std::vector<OdometerSample> out;
  std::int64_t prev = count(truth[0].distance_m);
  for (std::size_t i = static_cast<std::size_t>(stride); i < truth.size(); i += static_cast<std::size_t>(stride)) {
    const std::int64_t c = count(truth[i].distance_m);
    out.push_back({truth[i].t_s, c - prev, static_cast<double>(c - prev) * o.meters_per_pulse});
    prev = c;
  }
  return out;
}

}  // namespace ultratrack::ins
