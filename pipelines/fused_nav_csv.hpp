// SPDX-License-Identifier: GPL-3.0-or-later
// nav.csv of `ultratrack fuse` and `receive --coupling loose|tight|ultra-tight`: the INS nav.csv columns
// (ins/nav_csv.hpp) followed by the filter's 1-sigma
// `sigma_n_m,sigma_e_m,sigma_d_m,sigma_vn_mps,sigma_ve_mps,sigma_vd_mps,sigma_att_n_deg,sigma_att_e_deg,
// sigma_att_d_deg` (NED position and velocity; attitude as the psi-angle about north, east, down: tilts and
// heading). Written atomically with round-trip precision; the reader is strict (tests, post-processing).
#pragma once

#include <Eigen/Core>
#include <filesystem>
#include <memory>
#include <vector>

#include "ins/nav_state.hpp"
#include "pipelines/nav_sigma.hpp"

namespace ultratrack::io {
class AtomicFile;
}

namespace ultratrack::pipelines {

struct FusedNavRow {
  ins::NavState nav;
  NavSigma sigma;
};

class FusedNavCsvWriter {
 public:
  explicit FusedNavCsvWriter(const std::filesystem::path& file);
  ~FusedNavCsvWriter();
  void write(const ins::NavState& s, const NavSigma& sigma);
  void commit();

 private:
  std::unique_ptr<io::AtomicFile> out_;
};

std::vector<FusedNavRow> read_fused_nav_csv(const std::filesystem::path& file);

}  // namespace ultratrack::pipelines
