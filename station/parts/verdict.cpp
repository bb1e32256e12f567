// Verdict: every limit of the part, checked against the fit.
#include "station/parts/verdict.hpp"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>

#include "station/store/fit_json.hpp"

namespace station {
namespace {

using nlohmann::json;

/// The value of coefficient `name` and its standard error, if the fit has that term.
struct Coefficient {
  std::optional<double> value, se;
};

Coefficient coefficient(const compensation::FitResult& fit, std::string_view name) {
  for (std::size_t i = 0; i < fit.names.size(); ++i) {
    if (fit.names[i] != name) continue;
    Coefficient c{fit.coefficients[i], std::nullopt};
    if (i < fit.std_errors.size()) c.se = fit.std_errors[i];
    return c;
  }
  return {};
}

class Checker {
 public:
  explicit Checker(Verdict& v) : v_(v) {}
  /// Fails when the value is missing or above the bound.
  void at_most(const std::string& limit, std::optional<double> value, std::optional<double> bound) {
    if (!bound) return;
    ++v_.checked;
    if (!value || !std::isfinite(*value) || *value > *bound) fail(limit, value, *bound);
  }
  /// Fails when the value is missing or below the bound.
  void at_least(const std::string& limit, std::optional<double> value,
                std::optional<double> bound) {
    if (!bound) return;
    ++v_.checked;
    if (!value || !std::isfinite(*value) || *value < *bound) fail(limit, value, *bound);
  }
  void range(const std::string& key, std::optional<double> value, const LimitRange& r) {
    at_least(key + ".min", value, r.min);
    at_most(key + ".max", value, r.max);
  }

 private:
  void fail(const std::string& limit, std::optional<double> value, double bound) {
    v_.pass = false;
    v_.failed.push_back({limit, value, bound});
  }
  Verdict& v_;
};

}  // namespace

Verdict judge_fit(const PartLimits& p, const VerdictInputs& in) {
  Verdict v;
  v.part_number = p.number;
  v.context = walk_text(in.fit);
  Checker c(v);
  const auto b0 = coefficient(in.fit, "B0"), k1 = coefficient(in.fit, "k1"),
             k0 = coefficient(in.fit, "k0");
  c.range("B0_dph", b0.value, p.b0_dph);
  c.range("k1_dph_per_c", k1.value, p.k1_dph_per_c);
  c.range("k0_dph_per_c", k0.value, p.k0_dph_per_c);
  c.at_most("max_std_after_dph", in.eval.std_after_dph, p.max_std_after_dph);
  c.at_most("max_std_ratio", in.eval.std_ratio, p.max_std_ratio);
  c.at_most("max_adev_floor_dph", in.adev_floor_dph, p.max_adev_floor_dph);
  const auto bins = static_cast<double>(in.fit.n_points);
  c.at_least("min_complete_bins", bins,
             p.min_complete_bins ? std::optional<double>(static_cast<double>(*p.min_complete_bins))
                                 : std::nullopt);
  c.at_most("max_k1_se_dph_per_c", k1.se, p.max_k1_se_dph_per_c);
  c.at_most("max_k0_se_dph_per_c", k0.se, p.max_k0_se_dph_per_c);
  return v;
}

std::optional<Verdict> judge_verification(const PartLimits& p, const VerificationFigures& in) {
  Verdict v;
  v.part_number = p.number;
  Checker c(v);
  c.at_most("max_verify_std_dph", in.std_after_dph, p.max_verify_std_dph);
  c.at_most("max_verify_ratio", in.std_ratio, p.max_verify_ratio);
  if (v.checked == 0) return std::nullopt;
  return v;
}

json verdict_json(const Verdict& v) {
  json failed = json::array();
  for (const auto& f : v.failed) {
    failed.push_back({{"limit", f.limit},
                      {"value", f.value ? json(*f.value) : json(nullptr)},
                      {"bound", f.bound}});
  }
  return {{"pass", v.pass},
          {"failed", failed},
          {"part", v.part_number},
          {"checked", v.checked},
          {"context", v.context}};
}

Verdict verdict_from_json(const json& j) {
  try {
    Verdict v;
    v.pass = j.at("pass").get<bool>();
    v.part_number = j.at("part").get<std::string>();
    v.checked = j.at("checked").get<int>();
    v.context = j.value("context", "");
    for (const auto& f : j.at("failed")) {
      const json& value = f.at("value");
      v.failed.push_back({f.at("limit").get<std::string>(),
                          value.is_null() ? std::nullopt : std::optional(value.get<double>()),
                          f.at("bound").get<double>()});
    }
    return v;
  } catch (const json::exception& e) {
    throw std::invalid_argument(fmt::format("stored verdict: {}", e.what()));
  }
}

std::string verdict_text(const std::optional<Verdict>& v) {
  if (!v) return "no part limits";
  if (v->pass) return fmt::format("pass (part {}, {} limits)", v->part_number, v->checked);
  std::string out = fmt::format("FAIL (part {}):", v->part_number);
  for (std::size_t i = 0; i < v->failed.size(); ++i) {
    const auto& f = v->failed[i];
    const bool is_min = f.limit.ends_with(".min") || f.limit.starts_with("min_");
    out += i == 0 ? " " : "; ";
    if (!f.value) {
      out += fmt::format("{} not shown by the fit (bound {:.4g})", f.limit, f.bound);
    } else {
      out += fmt::format("{} {:.4g} {} {:.4g} (by {:.3g})", f.limit, *f.value, is_min ? "<" : ">",
                         f.bound, std::abs(*f.value - f.bound));
    }
  }
  return out;
}

}  // namespace station
