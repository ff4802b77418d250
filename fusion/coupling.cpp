// SPDX-License-Identifier: GPL-3.0-or-later
#include "fusion/coupling.hpp"

namespace ultratrack::fusion {

std::optional<Coupling> coupling_from_string(std::string_view text) {
  if (text == "scalar" || text == "none") return Coupling::kScalar;
  if (text == "vector") return Coupling::kVector;
  if (text == "loose") return Coupling::kLoose;
  if (text == "tight") return Coupling::kTight;
  if (text == "ultra-tight") return Coupling::kUltraTight;
  return std::nullopt;
}

std::string to_string(Coupling coupling) {
  switch (coupling) {
    case Coupling::kScalar:
      return "scalar";
    case Coupling::kVector:
      return "vector";
    case Coupling::kLoose:
      return "loose";
    case Coupling::kTight:
      return "tight";
    case Coupling::kUltraTight:
      return "ultra-tight";
  }
  return "?";
}

}  // namespace ultratrack::fusion
