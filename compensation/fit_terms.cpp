// The model's terms: their one table of names and units, their regressors, the design matrix
// and the checks of the data they read (fit.hpp).
#include <Eigen/Dense>
#include <cmath>
#include <string>

#include "compensation/earth_rate.hpp"
#include "compensation/fit.hpp"
#include "compensation/limits.hpp"

namespace station::compensation {
namespace {

// The one table of the terms' names and units, in the order of enum Term.
struct TermInfo {
  Term term;
  std::string_view option;
  std::string_view coefficient;
  std::string_view unit;
};
constexpr TermInfo kTerms[] = {
    {Term::dT, "dT", "k1", "deg/h/C"},
    {Term::dT2, "dT2", "k2", "deg/h/C^2"},
    {Term::dT3, "dT3", "k3", "deg/h/C^3"},
    {Term::dT4, "dT4", "k4", "deg/h/C^4"},
    {Term::gradT, "gradT", "k0", "deg/h/C (gradient)"},
    {Term::dTdt, "dTdt", "kr", "deg/h/(C/h)"},
    {Term::channel, "channel", "kc", "deg/h per channel unit"},
    {Term::gradTdT, "gradTdT", "kg", "deg/h/C^2 (gradient x dT)"},
};
constexpr bool table_in_enum_order() {
  for (std::size_t i = 0; i < std::size(kTerms); ++i) {
    if (static_cast<std::size_t>(kTerms[i].term) != i) return false;
  }
  return std::size(kTerms) == static_cast<std::size_t>(Term::gradTdT) + 1;
}
static_assert(table_in_enum_order(), "kTerms must list every Term in enum order");

const TermInfo& info(Term t) {
  return kTerms[static_cast<int>(t)];
}

std::span<const double> source_of(Term t, const ModelInput& in) {
  switch (t) {
    case Term::dT:
    case Term::dT2:
    case Term::dT3:
    case Term::dT4:
      return in.temp_c;
    case Term::gradT:
    case Term::gradTdT:  // and temp_c, always checked with the bias
      return in.grad_c;
    case Term::dTdt:
      return in.dtdt_c_per_h;
    case Term::channel:
      return in.channel;
  }
  return in.temp_c;  // not reached: the switch covers every Term
}

double regressor(Term t, double x, double temp_c, double ref_temp_c) {
  switch (t) {
    case Term::gradTdT:
      return x * (temp_c - ref_temp_c);
    case Term::dT:
      return x - ref_temp_c;
    case Term::dT2:
      return std::pow(x - ref_temp_c, 2);
    case Term::dT3:
      return std::pow(x - ref_temp_c, 3);
    case Term::dT4:
      return std::pow(x - ref_temp_c, 4);
    case Term::gradT:
    case Term::dTdt:
    case Term::channel:
      return x;
  }
  return x;  // not reached: the switch covers every Term
}

// The physical bound a term's source values must keep (compensation/limits.hpp).
std::string source_problem(Term t, double v) {
  switch (t) {
    case Term::dT:
    case Term::dT2:
    case Term::dT3:
    case Term::dT4:
      return temp_problem(v);
    case Term::gradT:
    case Term::gradTdT:
      return temp_diff_problem(v);
    case Term::dTdt:
    case Term::channel:
      return finite_problem(v);
  }
  return {};  // not reached: the switch covers every Term
}

// Refuses data the model cannot use: every value finite and within its physical bound, so no
// entry of the design matrix, and no sum of their squares, can overflow.
}  // namespace

void check_model_input(const ModelInput& in, const ModelSpec& spec) {
  const std::size_t n = in.bias_dph.size();
  if ((!in.t_s.empty() && in.t_s.size() != n) || (!in.segment.empty() && in.segment.size() != n))
    throw DataError("fit: bin times or runs are not given for every bin");
  for (std::size_t i = 0; i < in.t_s.size(); ++i) {
    if (!std::isfinite(in.t_s[i]) || (i > 0 && in.t_s[i] <= in.t_s[i - 1] &&
                                      (in.segment.empty() || in.segment[i] == in.segment[i - 1])))
      throw DataError("fit: bin " + std::to_string(i) + ": time not finite or not increasing");
  }
  if (auto p = temp_problem(spec.ref_temp_c); !p.empty())
    throw DataError("fit: reference temperature: " + p);
  for (std::size_t i = 0; i < in.bias_dph.size(); ++i) {
    if (auto p = rate_problem(in.bias_dph[i]); !p.empty())
      throw DataError("fit: bin " + std::to_string(i) + " of those used: bias: " + p);
  }
  // gradTdT also reads the temperature: checked as dT's source.
  for (Term t : spec.terms) {
    if (t != Term::gradTdT) continue;
    if (in.temp_c.size() != n)
      throw DataError("fit: term gradTdT has no temperature for every point");
    for (std::size_t i = 0; i < n; ++i)
      if (auto p = temp_problem(in.temp_c[i]); !p.empty())
        throw DataError("fit: bin " + std::to_string(i) + " of those used: temperature: " + p);
  }
  for (Term t : spec.terms) {
    const auto src = source_of(t, in);
    for (std::size_t i = 0; i < src.size(); ++i) {
      if (auto p = source_problem(t, src[i]); !p.empty()) {
        throw DataError("fit: bin " + std::to_string(i) + " of those used: term " +
                        std::string(info(t).option) + ": " + p);
      }
    }
  }
}

Eigen::MatrixXd design_matrix(const ModelInput& in, const ModelSpec& spec) {
  const auto n = static_cast<Eigen::Index>(in.bias_dph.size());
  Eigen::MatrixXd x(n, static_cast<Eigen::Index>(spec.terms.size() + 1));
  x.col(0).setOnes();
  for (std::size_t j = 0; j < spec.terms.size(); ++j) {
    const Term t = spec.terms[j];
    const auto src = source_of(t, in);
    if (src.size() != in.bias_dph.size()) {
      throw DataError("fit: term " + std::string(info(t).option) + " has no data for every point");
    }
    for (Eigen::Index i = 0; i < n; ++i) {
      const auto k = static_cast<std::size_t>(i);
      const double temp = t == Term::gradTdT ? in.temp_c[k] : 0.0;
      x(i, j + 1) = regressor(t, src[k], temp, spec.ref_temp_c);
    }
  }
  return x;
}

std::string_view term_option_name(Term t) {
  return info(t).option;
}
std::string_view term_coefficient_name(Term t) {
  return info(t).coefficient;
}

std::string_view coefficient_unit(std::string_view coefficient_name) {
  if (coefficient_name == "B0") return "deg/h";
  for (const auto& ti : kTerms) {
    if (ti.coefficient == coefficient_name) return ti.unit;
  }
  return {};
}

std::optional<Term> term_from_option_name(std::string_view name) {
  for (const auto& ti : kTerms) {
    if (ti.option == name) return ti.term;
  }
  return std::nullopt;
}

std::string model_text(const ModelSpec& spec) {
  std::string out = "B0";
  for (const Term t : spec.terms) out += "+" + std::string(term_option_name(t));
  return out;
}

std::vector<Term> parse_terms(std::string_view list) {
  std::vector<Term> terms;
  while (!list.empty()) {
    const auto comma = list.find(',');
    const auto word = list.substr(0, comma);
    const auto t = term_from_option_name(word);
    if (!t) {
      throw std::invalid_argument("unknown term '" + std::string(word) +
                                  "' (expected dT, dT2, dT3, dT4, gradT, dTdt, channel, "
                                  "gradTdT)");
    }
    for (Term have : terms) {
      if (have == *t) throw std::invalid_argument("term '" + std::string(word) + "' given twice");
    }
    terms.push_back(*t);
    list = comma == std::string_view::npos ? std::string_view{} : list.substr(comma + 1);
  }
  return terms;
}

ModelData model_data_from_bins(std::span<const Bin> bins, double earth_rate_dph) {
  ModelData d;
  for (const Bin& b : bins) {
    if (!b.complete) continue;
    d.bias_dph.push_back(bias_dph(b.rate_dph, earth_rate_dph));
    d.temp_c.push_back(b.temp_c);
    d.grad_c.push_back(b.grad_c);
    d.dtdt_c_per_h.push_back(b.dtdt_c_per_h);
    d.channel.push_back(b.extra);
    d.t_mid_s.push_back(b.t_mid_s);
  }
  return d;
}

}  // namespace station::compensation
