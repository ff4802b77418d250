// SPDX-License-Identifier: GPL-3.0-or-later
// ultratrack.acquire: FFT acquisition (receiver/acquisition.hpp) of the first K x T_coh of a recording, read
// from a file as `ultratrack acquire` reads it, or of complex baseband samples given as a numpy array. Returns
// one dict per searched PRN (the detected ones, or all).
#include <pybind11/complex.h>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <complex>
#include <vector>

#include "bindings.hpp"
#include "receiver/acquisition.hpp"
#include "receiver/sample_source.hpp"
#include "signals/sample_format.hpp"

namespace ultratrack::python {

namespace {

using Samples = py::array_t<std::complex<float>, py::array::c_style | py::array::forcecast>;

py::list results_list(const std::vector<receiver::AcquisitionResult>& results, bool all) {
  py::list out;
  for (const auto& r : results) {
    if (!r.detected && !all) continue;
    py::dict d;
    d["prn"] = r.prn;
    d["detected"] = r.detected;
    d["doppler_hz"] = r.doppler_hz;
    d["code_phase_chips"] = r.code_phase_chips;
    d["code_phase_samples"] = r.code_phase_samples;
    d["cn0_dbhz"] = r.cn0_dbhz;
    d["metric"] = r.metric;
    d["threshold"] = r.threshold;
    out.append(d);
  }
  return out;
}

// input: a file name (with format) or a numpy array of complex baseband samples (format ignored).
py::list acquire(const py::object& input, const std::string& format, double fs_hz, double if_hz, int coherent_ms,
                 int noncoherent, const std::vector<int>& prns, double doppler_max_hz, double doppler_step_hz,
                 double pfa, bool iq_swap, bool q_negate, bool all) {
  receiver::AcquisitionOptions options;
  options.fs_hz = fs_hz;
  options.coherent_ms = coherent_ms;
  options.noncoherent = noncoherent;
  options.doppler_max_hz = doppler_max_hz;
  options.doppler_step_hz = doppler_step_hz;
  options.pfa = pfa;
  if (std::string why; !options.IsValid(&why)) throw io::InputError("python", why);
  const auto block = static_cast<std::int64_t>(std::llround(options.fs_hz * options.coherent_s()));

  std::vector<std::complex<float>> samples;
  std::string name = "samples";
  if (py::isinstance<py::array>(input)) {
    if (if_hz != 0.0 || iq_swap || q_negate)
      throw io::InputError("python",
                           "acquire on a numpy array takes complex baseband samples: no if_hz, iq_swap or q_negate");
    const Samples array = Samples::ensure(input);
    if (!array || array.ndim() != 1)
      throw io::InputError("python", "samples: a one-dimensional complex array is needed");
    samples.assign(array.data(), array.data() + array.size());
  } else {
    name = py::str(input).cast<std::string>();
    const signals::SampleFormat sample_format = sample_format_from_name(format);
    receiver::SampleSourceOptions source_options;
    source_options.fs_hz = fs_hz;
    source_options.if_hz = if_hz;
    source_options.iq_swap = iq_swap;
    source_options.q_negate = q_negate;
    receiver::SampleSource source(name, sample_format, source_options);
    samples.resize(static_cast<std::size_t>(std::min<std::int64_t>(source.total_samples(), block * noncoherent)));
    if (source.read(samples).count != samples.size())
      throw io::InputError(name, "ended before the samples it reported");
  }
  // Shorter than K blocks: searched with the whole blocks it holds, as the command line does.
  const std::int64_t blocks = static_cast<std::int64_t>(samples.size()) / block;
  if (blocks < 1)
    throw io::InputError(name, "holds " + std::to_string(samples.size()) + " samples, fewer than one " +
                                   std::to_string(coherent_ms) + " ms coherent block (" + std::to_string(block) + ")");
  if (blocks < options.noncoherent) options.noncoherent = static_cast<int>(blocks);

  std::vector<receiver::AcquisitionResult> results;
  {
    py::gil_scoped_release release;
    receiver::Acquisition acquisition(options);
    samples.resize(acquisition.samples_needed());
    results = acquisition.search(samples, prns);
  }
  return results_list(results, all);
}

}  // namespace

void register_acquire(py::module_& m) {
  m.def("_acquire", &acquire, py::arg("input"), py::arg("format"), py::arg("fs"), py::arg("if_hz"), py::arg("ms"),
        py::arg("noncoh"), py::arg("prn"), py::arg("doppler_max"), py::arg("doppler_step"), py::arg("pfa"),
        py::arg("iq_swap"), py::arg("q_negate"), py::arg("all"));
}

}  // namespace ultratrack::python
