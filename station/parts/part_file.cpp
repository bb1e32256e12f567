// Part file: TOML to PartFile, strictly (unknown keys rejected, every range ordered).
#include "station/parts/part_file.hpp"

#include <fmt/format.h>

#include <fstream>
#include <sstream>
#include <stdexcept>

#include "compensation/fit.hpp"
#include "station/common/text_rule.hpp"
#include "station/config/toml_reader.hpp"
#include "station/parts/deliverable_terms.hpp"
#include "station/store/fit_json.hpp"

namespace station {
namespace {

using nlohmann::json;

// A positive upper bound: zero or less would fail every gyro.
std::optional<double> positive(const TomlView& v, std::string_view key) {
  const auto x = v.opt_number(key);
  if (x && !(*x > 0)) throw v.error(key, fmt::format("{} must be above 0", *x));
  return x;
}

/// A noise term of [noise]: above 0 (or 0 where `zero_ok`: K = 0, no walk) and at most
/// kMaxNoiseTerm; -0 read as 0.
std::optional<double> noise_term(const TomlView& t, std::string_view key, bool zero_ok) {
  const auto x = t.opt_number(key);
  if (!x) return x;
  if (!(zero_ok ? *x >= 0 : *x > 0) || !(*x <= compensation::kMaxNoiseTerm))
    throw t.error(key, fmt::format("{} is outside {}..{}", *x, zero_ok ? "0" : "(0",
                                   compensation::kMaxNoiseTerm));
  return *x == 0 ? 0.0 : *x;
}

constexpr double kMinTrust = compensation::kMinNoiseTrust, kMaxTrust = compensation::kMaxNoiseTrust;

/// [part."PN".noise]: the IEEE 952 terms the part's data sheet gives, and how far to trust them.
std::optional<compensation::NoisePrior> read_noise(const TomlView& part) {
  const auto t = part.opt_table("noise");
  if (!t) return std::nullopt;
  t->allow_only({"arw_deg_rt_h", "bias_instability_dph", "rrw_dph_rt_h", "trust_factor"});
  compensation::NoisePrior n;
  n.arw_deg_rt_h = noise_term(*t, "arw_deg_rt_h", false);
  n.bias_instability_dph = noise_term(*t, "bias_instability_dph", false);
  n.rrw_dph_rt_h = noise_term(*t, "rrw_dph_rt_h", true);
  if (const auto f = t->opt_number("trust_factor")) {
    if (!(*f >= kMinTrust && *f <= kMaxTrust))
      throw t->error("trust_factor", fmt::format("{} is outside {}..{}", *f, kMinTrust, kMaxTrust));
    n.trust_factor = *f;
  }
  if (n.empty())
    throw part.error("noise", "give arw_deg_rt_h, bias_instability_dph or rrw_dph_rt_h");
  return n;
}

/// model = "dT,gradT": checked as `fit --terms` checks it.
std::optional<std::string> read_model(const TomlView& part) {
  const auto m = part.opt_string("model");
  if (!m) return std::nullopt;
  std::vector<compensation::Term> terms;
  try {
    terms = compensation::parse_terms(*m);
  } catch (const std::invalid_argument& e) {
    throw part.error("model", e.what());
  }
  if (terms.empty()) throw part.error("model", "names no term (B0 alone calibrates nothing)");
  if (const auto bad = undeliverable_terms(terms))
    throw part.error("model", *bad + ": a production model must be releasable");
  return m;
}

PartLimits read_part(const TomlView& v, const std::string& number) {
  v.allow_only({"description", "B0_dph", "k1_dph_per_c", "k0_dph_per_c", "max_std_after_dph",
                "max_std_ratio", "max_adev_floor_dph", "min_complete_bins", "max_k1_se_dph_per_c",
                "max_k0_se_dph_per_c", "max_verify_std_dph", "max_verify_ratio", "model", "noise",
                "acceptance"});
  PartLimits p;
  p.number = number;
  p.description = v.opt_string("description").value_or("");
  if (const auto problem = note_problem(p.description, kMaxNoteBytes))
    throw v.error("description", *problem);
  p.b0_dph = read_range(v, "B0_dph");
  p.k1_dph_per_c = read_range(v, "k1_dph_per_c");
  p.k0_dph_per_c = read_range(v, "k0_dph_per_c");
  p.max_std_after_dph = positive(v, "max_std_after_dph");
  p.max_std_ratio = positive(v, "max_std_ratio");
  p.max_adev_floor_dph = positive(v, "max_adev_floor_dph");
  // A fit of B0, k1 and k0 needs at least 3 bins; more than a year of 600 s bins is a typo.
  p.min_complete_bins = v.opt_integer_in("min_complete_bins", 3, 52560);
  p.max_k1_se_dph_per_c = positive(v, "max_k1_se_dph_per_c");
  p.max_k0_se_dph_per_c = positive(v, "max_k0_se_dph_per_c");
  p.max_verify_std_dph = positive(v, "max_verify_std_dph");
  p.max_verify_ratio = positive(v, "max_verify_ratio");
  p.model = read_model(v);
  p.noise = read_noise(v);
  p.acceptance = read_acceptance_limits(v);
  return p;
}

template <typename T>
std::optional<T> opt_from_json(const json& j, const char* key) {
  return j.contains(key) ? std::optional<T>(j.at(key).get<T>()) : std::nullopt;
}

}  // namespace

PartFile parse_part_file(const std::string& text, const std::string& path) {
  const toml::table tbl = TomlView::parse_text(text, path);
  const TomlView root(tbl, path);
  root.allow_only({"part"});
  PartFile f;
  f.path = path;
  const auto parts = root.opt_table("part");
  if (!parts || parts->table().empty())
    throw root.error("part", "no [part.\"NUMBER\"] tables: the file names no part");
  for (const auto& [key, node] : parts->table()) {
    const std::string number(key.str());
    // A part number is an identifier (common/text_rule.hpp): it reaches every export.
    if (const auto problem = identifier_problem(number))
      throw InputError(fmt::format("{}:{}: key 'part.{}': {}", path, parts->line_of(number),
                                   ascii_escaped(number), *problem));
    const auto part = parts->opt_table(number);
    f.parts.emplace(number, read_part(*part, number));
  }
  return f;
}

PartFile load_part_file(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(fmt::format("{}: cannot open the part file", path));
  std::stringstream ss;
  ss << in.rdbuf();
  return parse_part_file(ss.str(), path);
}

std::map<std::string, PartLimits> slot_part_limits(const StationConfig& config,
                                                   const std::string& parts_path) {
  const std::string path = parts_path.empty() ? config.parts_path : parts_path;
  std::optional<PartFile> file;
  if (!path.empty()) file = load_part_file(path);
  std::map<std::string, PartLimits> out;
  for (std::size_t i = 0; i < config.slots.size(); ++i) {
    const auto& s = config.slots[i];
    if (s.part.empty()) continue;
    const auto where = fmt::format("{}:{}: key 'slot[{}].part'", config.path, s.part_line, i);
    if (!file) {
      throw InputError(fmt::format(
          "{}: part '{}' but no part file (give [station] parts or --parts FILE)", where, s.part));
    }
    const auto it = file->parts.find(s.part);
    if (it == file->parts.end()) {
      std::string known;
      for (const auto& [n, p] : file->parts) known += (known.empty() ? "" : ", ") + n;
      throw InputError(
          fmt::format("{}: part '{}' is not in {} (it has: {})", where, s.part, file->path, known));
    }
    out.emplace(s.serial, it->second);
  }
  return out;
}

json part_limits_json(const PartLimits& p) {
  json j{{"number", p.number}};
  if (!p.description.empty()) j["description"] = p.description;
  for (const auto& [key, r] : {std::pair{"B0_dph", &p.b0_dph},
                               {"k1_dph_per_c", &p.k1_dph_per_c},
                               {"k0_dph_per_c", &p.k0_dph_per_c}}) {
    if (r->min || r->max) j[key] = range_json(*r);
  }
  const auto put = [&j](const char* key, const auto& v) {
    if (v) j[key] = *v;
  };
  put("max_std_after_dph", p.max_std_after_dph);
  put("max_std_ratio", p.max_std_ratio);
  put("max_adev_floor_dph", p.max_adev_floor_dph);
  put("min_complete_bins", p.min_complete_bins);
  put("max_k1_se_dph_per_c", p.max_k1_se_dph_per_c);
  put("max_k0_se_dph_per_c", p.max_k0_se_dph_per_c);
  put("max_verify_std_dph", p.max_verify_std_dph);
  put("max_verify_ratio", p.max_verify_ratio);
  put("model", p.model);
  if (p.noise) j["noise"] = noise_json(*p.noise);
  if (p.acceptance) j["acceptance"] = acceptance_limits_json(*p.acceptance);
  return j;
}

PartLimits part_limits_from_json(const json& j) {
  try {
    PartLimits p;
    p.number = j.at("number").get<std::string>();
    p.description = j.value("description", "");
    p.b0_dph = range_from_json(j, "B0_dph");
    p.k1_dph_per_c = range_from_json(j, "k1_dph_per_c");
    p.k0_dph_per_c = range_from_json(j, "k0_dph_per_c");
    p.max_std_after_dph = opt_from_json<double>(j, "max_std_after_dph");
    p.max_std_ratio = opt_from_json<double>(j, "max_std_ratio");
    p.max_adev_floor_dph = opt_from_json<double>(j, "max_adev_floor_dph");
    p.min_complete_bins = opt_from_json<long long>(j, "min_complete_bins");
    p.max_k1_se_dph_per_c = opt_from_json<double>(j, "max_k1_se_dph_per_c");
    p.max_k0_se_dph_per_c = opt_from_json<double>(j, "max_k0_se_dph_per_c");
    p.max_verify_std_dph = opt_from_json<double>(j, "max_verify_std_dph");
    p.max_verify_ratio = opt_from_json<double>(j, "max_verify_ratio");
    p.model = opt_from_json<std::string>(j, "model");
    if (j.contains("noise")) p.noise = noise_prior_from_json(j.at("noise"));
    if (j.contains("acceptance")) p.acceptance = acceptance_limits_from_json(j.at("acceptance"));
    return p;
  } catch (const json::exception& e) {
    throw std::invalid_argument(fmt::format("stored part limits: {}", e.what()));
  }
}

}  // namespace station
