// Which model terms a released calibration can carry (see the header).
#include "station/parts/deliverable_terms.hpp"

#include <fmt/format.h>

namespace station {

namespace sc = station::compensation;

bool deliverable_term(sc::Term t) {
  return t == sc::Term::dT || t == sc::Term::dT2 || t == sc::Term::dT3 || t == sc::Term::dT4 ||
         t == sc::Term::gradT;
}

std::optional<std::string> undeliverable_terms(std::span<const sc::Term> terms) {
  for (const auto t : terms)
    if (!deliverable_term(t))
      return fmt::format(
          "term {} cannot be delivered: gyro_tc_correct() applies B0, k1..k4 (dT..dT4) and k0 "
          "(gradT) only",
          sc::term_option_name(t));
  return std::nullopt;
}

std::vector<sc::Term> deliverable_only(std::span<const sc::Term> terms) {
  std::vector<sc::Term> out;
  for (const auto t : terms)
    if (deliverable_term(t)) out.push_back(t);
  return out;
}

}  // namespace station
