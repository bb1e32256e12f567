#include "station/fleet/noise_proposal.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <set>

namespace station::fleet {
namespace {

namespace sc = station::compensation;
using nlohmann::json;

double median_of(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/// 1.4826 MAD: sigma of normal data, robust to a few wild values (Huber & Ronchetti §5.1).
double robust_sd(const std::vector<double>& v) {
  const double m = median_of(v);
  std::vector<double> dev;
  for (double x : v) dev.push_back(std::abs(x - m));
  return 1.4826 * median_of(dev);
}

struct TermDef {
  const char* key;
  const char* unit;
  std::optional<double> sc::NoiseTerms::*value;
  std::optional<double> sc::NoiseTerms::*se;
};

constexpr TermDef kTerms[] = {
    {"arw_deg_rt_h", "deg/sqrt(h)", &sc::NoiseTerms::angle_random_walk_deg_rth,
     &sc::NoiseTerms::angle_random_walk_se},
    {"bias_instability_dph", "deg/h", &sc::NoiseTerms::bias_instability_dph,
     &sc::NoiseTerms::bias_instability_se},
    {"rrw_dph_rt_h", "deg/h/sqrt(h)", &sc::NoiseTerms::rate_random_walk_dph_rth,
     &sc::NoiseTerms::rate_random_walk_se},
};

PooledTerm pool_term(const TermDef& d, const std::vector<const RunNoise*>& usable) {
  PooledTerm t{d.key, d.unit};
  std::vector<double> all, logs, ses;
  for (const auto* r : usable) {
    const auto& v = (*r->terms).*d.value;
    const bool seen = v && *v > 0;
    all.push_back(seen ? *v : 0.0);
    if (!seen) continue;
    ++t.runs_with;
    logs.push_back(std::log(*v));
    t.min = t.min ? std::min(*t.min, *v) : *v;
    t.max = t.max ? std::max(*t.max, *v) : *v;
    if (const auto& se = (*r->terms).*d.se) ses.push_back(*se);
  }
  if (!ses.empty()) t.median_se = median_of(ses);
  if (t.runs_with >= kMinNoiseRuns) t.log_sd = robust_sd(logs);
  const double m = all.empty() ? 0.0 : median_of(all);
  if (t.runs_with < kMinNoiseRuns)
    t.why_not =
        fmt::format("seen in {} of {} runs (needs {})", t.runs_with, usable.size(), kMinNoiseRuns);
  else if (!(m > 0))
    t.why_not = fmt::format("absent from {} of {} runs: their median is 0",
                            usable.size() - t.runs_with, usable.size());
  else
    t.median = m;
  return t;
}

/// ln of the trust factor: the largest spread of a new part about the medians (header).
double log_trust(const std::vector<PooledTerm>& terms, int n) {
  double worst = 0;
  for (const auto& t : terms)
    if (t.median && t.log_sd)
      worst = std::max(worst, *t.log_sd * std::sqrt(1.0 + std::numbers::pi / (2.0 * n)));
  return worst;
}

NoiseProposal propose_part(const std::string& part, const std::vector<const RunNoise*>& runs) {
  NoiseProposal p;
  p.part = part;
  p.runs = static_cast<int>(runs.size());
  std::vector<const RunNoise*> usable;
  std::set<std::string> stations, serials;
  for (const auto* r : runs) {
    if (!r->terms) {
      p.unusable.push_back(*r);
      continue;
    }
    usable.push_back(r);
    stations.insert(r->station);
    serials.insert(r->serial);
  }
  p.usable = static_cast<int>(usable.size());
  p.stations = static_cast<int>(stations.size());
  p.serials = static_cast<int>(serials.size());
  for (const auto& d : kTerms) p.terms.push_back(pool_term(d, usable));
  if (p.usable < kMinNoiseRuns) {
    p.why_none = fmt::format("{} usable run(s) of {}: a proposal needs at least {}", p.usable,
                             p.runs, kMinNoiseRuns);
    return p;
  }
  sc::NoisePrior prior;
  prior.arw_deg_rt_h = p.terms[0].median;
  prior.bias_instability_dph = p.terms[1].median;
  prior.rrw_dph_rt_h = p.terms[2].median;
  if (prior.empty()) {
    p.why_none = "no term is seen in enough runs";
    return p;
  }
  const double f = std::exp(log_trust(p.terms, p.usable));
  // Two decimals, rounded up: the printed factor is never narrower than the computed one.
  prior.trust_factor =
      std::clamp(std::ceil(f * 100.0) / 100.0, sc::kMinNoiseTrust, sc::kMaxNoiseTrust);
  p.prior = prior;
  return p;
}

}  // namespace

std::vector<NoiseProposal> propose_noise(const std::vector<RunNoise>& runs) {
  std::map<std::string, std::vector<const RunNoise*>> by_part;
  for (const auto& r : runs) by_part[r.part].push_back(&r);
  std::vector<NoiseProposal> out;
  for (const auto& [part, rs] : by_part) out.push_back(propose_part(part, rs));
  return out;
}

std::string noise_toml(const NoiseProposal& p) {
  std::string s = fmt::format(
      "# part {}: {} usable of {} runs ({} stations, {} serials); IEEE 952 terms of each run's "
      "compensated 1 Hz record, median over the runs (station fleet --propose-noise)\n",
      p.part, p.usable, p.runs, p.stations, p.serials);
  for (const auto& r : p.unusable)
    s += fmt::format("# not used: run {} serial {} at {} (fit {}): {}\n", r.run_uuid, r.serial,
                     r.station, r.fit_fleet_id, r.problem);
  if (!p.prior) return s + fmt::format("# no proposal: {}\n", p.why_none);
  s += fmt::format("[part.\"{}\".noise]\n", p.part);
  for (const auto& t : p.terms) {
    if (!t.median) {
      s += fmt::format("# {} not proposed: {}\n", t.key, t.why_not);
      continue;
    }
    s += fmt::format("{} = {:.4g}  # {}: {} runs with it, {:.4g}..{:.4g}, spread x/{:.3g}", t.key,
                     *t.median, t.unit, t.runs_with, *t.min, *t.max, std::exp(*t.log_sd));
    s += t.median_se ? fmt::format(", a run's own SE {:.2g}\n", *t.median_se) : "\n";
  }
  return s + fmt::format(
                 "trust_factor = {:.2f}  # geometric sd of a part's term about these medians: "
                 "the widest spread between runs, widened by the medians' own error\n",
                 p.prior->trust_factor);
}

json noise_proposal_json(const NoiseProposal& p) {
  auto opt = [](const std::optional<double>& v) { return v ? json(*v) : json(); };
  json terms = json::array();
  for (const auto& t : p.terms)
    terms.push_back({{"key", t.key},
                     {"unit", t.unit},
                     {"value", opt(t.median)},
                     {"runs_with_term", t.runs_with},
                     {"log_sd", opt(t.log_sd)},
                     {"min", opt(t.min)},
                     {"max", opt(t.max)},
                     {"median_se", opt(t.median_se)},
                     {"why_not", t.median ? json() : json(t.why_not)}});
  json unusable = json::array();
  for (const auto& r : p.unusable)
    unusable.push_back({{"station", r.station},
                        {"serial", r.serial},
                        {"run_uuid", r.run_uuid},
                        {"fit_fleet_id", r.fit_fleet_id},
                        {"problem", r.problem}});
  return {{"part", p.part},
          {"runs", p.runs},
          {"usable_runs", p.usable},
          {"stations", p.stations},
          {"serials", p.serials},
          {"terms", terms},
          {"trust_factor", p.prior ? json(p.prior->trust_factor) : json()},
          {"toml", noise_toml(p)},
          {"why_none", p.prior ? json() : json(p.why_none)},
          {"unusable", unusable}};
}

}  // namespace station::fleet
