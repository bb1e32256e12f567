// A fit's model formula.
#include "station/report/report_model.hpp"

#include <algorithm>

namespace station::report {

namespace {

/// A coefficient's term as the paper writes it (eq. (4): k1·ΔT, k0·∇T), the others after
/// compensation/fit_terms.cpp's table; empty for B0, the name itself for one not known here.
std::string term_of(const std::string& name) {
  static const std::pair<const char*, const char*> kTerms[] = {
      {"k1", "k1\u00b7\u0394T"},
      {"k2", "k2\u00b7\u0394T\u00b2"},
      {"k3", "k3\u00b7\u0394T\u00b3"},
      {"k4", "k4\u00b7\u0394T\u2074"},
      {"k0", "k0\u00b7\u2207T"},
      {"kr", "kr\u00b7dT/dt"},
      {"kc", "kc\u00b7c"},
      {"kg", "kg\u00b7\u2207T\u00b7\u0394T"}};
  for (const auto& [coefficient, text] : kTerms)
    if (name == coefficient) return text;
  return name;
}

}  // namespace

std::string model_formula(const compensation::FitResult& fit) {
  std::string out = "B = B0";
  for (const auto& name : fit.names)
    if (name != "B0") out += " + " + term_of(name);
  return out;
}

}  // namespace station::report
